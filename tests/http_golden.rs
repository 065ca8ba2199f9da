//! Golden answers over HTTP: the served bytes (blake3) and ETags of a few tiles of every kind —
//! zooms, negative coordinates, `@2x`, formats, modes, parameters, periods. Clients and CDNs keep
//! tiles for a year under these ETags, so a change is always deliberate: pixels change with a
//! mode's `VERSION` (core/tests/golden.rs says which), encoded bytes with `ENCODER_VERSION`
//! (server/src/encode.rs), and ETags with either or with the package version.

mod common;

use common::Server;

/// `(path, blake3 of the body (16 hex), ETag)`.
#[rustfmt::skip]
const GOLDEN: &[(&str, &str, &str)] = &[
    ("/tiles/gravel/7/0/0.png", "9295943ca283ca24", "\"3b633f780049db6fcccdfcb858a34954\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "f123065ce348fb93", "\"e57078dfab7e3cdd538c16e6615057bc\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "b243c55a37a30252", "\"2e7307877c85708e8548d3a51f03aa83\""),
    ("/tiles/brick/7/-2/3@2x.png", "96c3ec8be2d3bdc6", "\"3c4ecedc006c4a318d6a463560055ff7\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "a74ecb94a6c4139b", "\"825547a1f9b5e290ccdf6d691e132663\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "095cf9b2dad29c4e", "\"e83c8b3a43aab0b71ff1c15e996d7764\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "bf40f43dd27957a4", "\"de3fdb2bad197a8664fbb6cb7f4fcd44\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "3c495d934d1d3751", "\"3d22541df3dd23936d011123cb1c8eb1\""),
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
