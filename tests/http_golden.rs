//! Golden answers over HTTP: the served bytes (blake3) and ETags of a few tiles of every kind —
//! zooms, negative coordinates, `@2x`, formats, modes, parameters, periods. Clients and CDNs keep
//! tiles for a year under these ETags, so a change is always deliberate: pixels change with a
//! mode's `VERSION` (core/tests/golden.rs says which), encoded bytes with `ENCODER_VERSION`
//! (server/src/encode.rs), and ETags with either or with the package version.

mod support;

use support::Server;

/// `(path, blake3 of the body (16 hex), ETag)`.
#[rustfmt::skip]
const GOLDEN: &[(&str, &str, &str)] = &[
    ("/tiles/gravel/7/0/0.png", "b30e429344eebfe0", "\"98a453fd011826946278abed7fdb1e06\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "e96e1ea66a5f7926", "\"92e430a49f724ccf0075814d91a8063f\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "ad20fba12d353a1d", "\"1aabfa92502b1505292a510bdc5ec23e\""),
    ("/tiles/brick/7/-2/3@2x.png", "92e387e887b4711f", "\"63303f4ac702aa3c2d3966c7a993388b\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "b449bafe15d9d56f", "\"f0525b65e99ca2f222570fec3a4ed8c9\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "095cf9b2dad29c4e", "\"e83c8b3a43aab0b71ff1c15e996d7764\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "bf40f43dd27957a4", "\"de3fdb2bad197a8664fbb6cb7f4fcd44\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "aea91ed48ea3852a", "\"85ad9450a546d0a22b41aef4a1655a4d\""),
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
