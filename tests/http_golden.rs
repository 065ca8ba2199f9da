//! Golden answers over HTTP: the served bytes (blake3) and ETags of a few tiles of every kind —
//! zooms, negative coordinates, `@2x`, formats, modes, parameters, periods. Clients and CDNs keep
//! tiles for a year under these ETags, so a change is always deliberate: pixels change with a
//! mode's `VERSION` (core/tests/golden.rs says which), encoded bytes with `ENCODER_VERSION`
//! (server/src/encode.rs), and ETags with either or with the package version. A texture's own
//! identity moves its tiles too: brick's changed once, when its lattice came to be detected
//! (issue 60); the stochastic textures' did not.

mod common;

use common::Server;

/// `(path, blake3 of the body (16 hex), ETag)`.
#[rustfmt::skip]
const GOLDEN: &[(&str, &str, &str)] = &[
    ("/tiles/gravel/7/0/0.png", "1e40e3df2f551dd0", "\"3bd30175dfcdf9d9bc1c83f1c5d83b50\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "8108241be847c41c", "\"0821f3ba4a6b2e30d4bc786e62e8d33d\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "82ea194750ee1522", "\"1dc26c9d0d1fc9db60e0ceeff72d08be\""),
    ("/tiles/brick/7/-2/3@2x.png", "dec483c1292ec062", "\"dc5a3b04dc752ab561c37871dabfe942\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "59a8c566fa1b3a85", "\"5e2aa2faf8b495f4b6454184cbd8fd76\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "e9dd048ec909e9a9", "\"33ee46fd5f624766ea162529b64c0f45\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "e228a65bf35d34db", "\"9863e479683ef047fccb31ee44ea9946\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "65842de0edc701ae", "\"724bb62f269a4af01cd17858dd665f77\""),
];

#[tokio::test]
async fn served_bytes_and_etags_match_the_pinned_values() {
    let paths = [
        "/tiles/gravel/7/0/0.png",
        "/tiles/gravel/5/-3/2.png?seed=9",
        "/tiles/grass/6/1/-1.jpg?randomness=0.5",
        "/tiles/brick/7/-2/3@2x.png",
        "/tiles/brick/6/1/1@2x.webp?world=4",
        "/tiles/gravel/7/4/-4.png?mode=mosaic",
        "/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1",
        "/windows/grass.png?x=-100&y=50&w=300&h=200&z=6",
    ];
    let s = Server::builder().start();
    let mut got = Vec::new();
    for p in paths {
        let r = s.get(p).await;
        assert_eq!(r.status(), 200, "GET {p}");
        let etag = r.headers()["etag"].to_str().unwrap().to_string();
        let body = r.bytes().await.unwrap();
        got.push((p, blake3::hash(&body).to_hex()[..16].to_string(), etag));
    }
    let printed: String = got.iter().map(|(p, d, e)| format!("    ({p:?}, {d:?}, {e:?}),\n")).collect();
    let differ: Vec<String> = got
        .iter()
        .filter(|row| !GOLDEN.iter().any(|g| (g.0, g.1, g.2) == (row.0, row.1.as_str(), row.2.as_str())))
        .map(|row| row.0.to_string())
        .collect();
    assert!(
        differ.is_empty() && GOLDEN.len() == got.len(),
        "served bytes or ETags changed for: {differ:?}\n\nIf this was not intended, it is a bug. If it was (a mode's VERSION, \
         ENCODER_VERSION or the package version was bumped on purpose), replace GOLDEN in tests/http_golden.rs with:\n{printed}"
    );
}
