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
    ("/tiles/gravel/7/0/0.png", "1e40e3df2f551dd0", "\"9aec990d6fd492473a0052dccad061c7\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "8108241be847c41c", "\"93a006722c5078dfcf736743799613d2\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "82ea194750ee1522", "\"7fa90b1b9dcd70a961e0747b2d5d1125\""),
    ("/tiles/brick/7/-2/3@2x.png", "ce2ad8fe16e55fa8", "\"0fe85d7f8c018b6b5ff87ff07a507a6d\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "1a9b1c4ce435ea59", "\"1181f21cd3d1f913411f6699269328a1\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "095cf9b2dad29c4e", "\"039538903be16fbb072a01b87061d0ee\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "027f76d690e84218", "\"3498c6766c5f043b5f2bb9acddf033de\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "65842de0edc701ae", "\"93cac4c4f010dfb2da9f053ba7324306\""),
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
