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
    ("/tiles/gravel/7/0/0.png", "a91920c1338ce4fb", "\"dab88a73ae9c9b4136fe92f353afef39\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "a3804526ec3a9ab0", "\"5cfbdedb5a791e5a041ab0b031771b41\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "82ea194750ee1522", "\"7d9b66af4a060e7b15ed2a54a36af074\""),
    ("/tiles/brick/7/-2/3@2x.png", "b52ccb154e3076f4", "\"f73ae676b935292307f4bbc7aba03a23\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "1a9b1c4ce435ea59", "\"94110b095ecf0bdaa84f7be20fc410fb\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "095cf9b2dad29c4e", "\"12a46a71dfcd2068f9b82dbe02331692\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "027f76d690e84218", "\"642b39e28b8711c0c497ce59525dd5b2\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "52947dfda18e6bfe", "\"1eb4847f3287c9e575115800bacb91da\""),
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
