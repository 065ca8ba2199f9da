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
    ("/tiles/gravel/7/0/0.png", "d2620e364349573b", "\"9e649a2c4f004d8cf04033ff061a2c37\""),
    ("/tiles/gravel/5/-3/2.png?seed=9", "1cc1bca5444509e9", "\"b6a1e939324793cdad4c8f4dce19cb7b\""),
    ("/tiles/grass/6/1/-1.jpg?randomness=0.5", "a086ef0447a0ed6a", "\"dd645b829226ab5ba3a6d1d160cd1d5e\""),
    ("/tiles/brick/7/-2/3@2x.png", "547528ce27bcfe5e", "\"3fb54aba4ba33465af3a4649bf304707\""),
    ("/tiles/brick/6/1/1@2x.webp?world=4", "5939bc48a5b7234e", "\"da949b96413036cc37015a0b8ce5426e\""),
    ("/tiles/gravel/7/4/-4.png?mode=mosaic", "095cf9b2dad29c4e", "\"8c2c8ca57951d054533aefc06c5808e0\""),
    ("/tiles/brick/3/0/0.png?mode=mosaic&iterations=3&block_area=0.3,0.6&smoothing=1", "bf40f43dd27957a4", "\"3b4c26ffccea2379cd7c9536efebc19f\""),
    ("/windows/grass.png?x=-100&y=50&w=300&h=200&z=6", "a42b43491225813d", "\"feb91d647da421f9033ca3ad860b8618\""),
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
