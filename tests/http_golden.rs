//! Golden answers over HTTP: the served bytes (blake3) and ETags of a few tiles of every kind —
//! zooms, negative coordinates, `@2x`, formats, modes, parameters, periods. Clients and CDNs keep
//! tiles for a year under these ETags, so a change is always deliberate: pixels change with a
//! mode's `VERSION` (core/tests/golden.rs says which), encoded bytes with `ENCODER_VERSION`
//! (server/src/encode.rs), and ETags with either or with the package version. A texture's own
//! identity moves its tiles too: brick's changed once, when its lattice came to be detected
//! (issue 60); the stochastic textures' did not. The ETags of analysis-backed modes follow the
//! analysis file's hash: they changed, with the same bytes, when the file came to carry the
//! exemplar's structure (issue 69), and again when it came to record the exemplar's width and
//! height instead of one side (issue 72: exemplars keep their own shape). Mosaic version 3
//! (issue 70) lays a near-regular exemplar's background tiles on its lattice: brick's mosaic
//! bytes moved, gravel's did not (only its ETag, with the version). Issue 80 (structure decided
//! in noise units, stored typed in the analysis header, analysis version 4) moved the ETags of
//! the analysis-backed modes once more, with the same bytes everywhere.

mod common;

use common::Server;

/// `(path, blake3 of the body (16 hex), ETag)`.
#[rustfmt::skip]
const GOLDEN: &[(&str, &str, &str)] = &[
    ("/tiles/gravel/7/0/0.png", "1e40e3df2f551dd0", "\"e2ba50025c54df6308ff223ad7ce4208\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "8108241be847c41c", "\"53184123fcbd8003a37eaec313c526b6\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "82ea194750ee1522", "\"418b62bd0cb87bf843514acdd2d31f7a\""),
    ("/tiles/brick/7/-2/3@2x.png", "dec483c1292ec062", "\"0e3747cb4c847a5c88735c01b5362a73\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "59a8c566fa1b3a85", "\"63a6afd81617c9f38eb7a3f03feee0b2\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "e9dd048ec909e9a9", "\"bba5e84d9c35deb56b427913b382e656\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "80faecacdcecdbfe", "\"40a47f60b622316a3aa02da1de436928\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "65842de0edc701ae", "\"79ae26e84f61f8383e1d2e251f1f2331\""),
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
