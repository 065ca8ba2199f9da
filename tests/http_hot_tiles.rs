//! The hot path of cached tiles, through the real binary: a repeated tile request (a texture's
//! and a landscape's) is answered before routing, and its answer — status, every header but the
//! date, bytes, access log line, request metrics — is the one the full path gives the same
//! request. The full path's answer is taken from the same tile under another `v=` (the version
//! parameter, which changes no content): the first request of a URL takes the full path, the
//! next the hot one (`textile_hot_tile_answers_total` says which). Both CORS configurations
//! (any origin; a list, with a listed, an unlisted and no origin), 200 and 304. Requests the hot
//! path leaves to the router (HEAD, percent-encoded paths, oversized headers) are answered as
//! before.

mod common;

use common::Server;
use serde_json::Value;

/// Status, headers but the date, and body of an answer to `path` with `headers`.
type Answer = (u16, Vec<(String, String)>, Vec<u8>);

async fn answer(s: &Server, path: &str, headers: &[(&str, &str)]) -> Answer {
    let mut req = s.client.get(s.url(path));
    for (k, v) in headers {
        req = req.header(*k, *v);
    }
    let r = req.send().await.unwrap();
    let status = r.status().as_u16();
    let head = r
        .headers()
        .iter()
        .filter(|(k, _)| k.as_str() != "date")
        .map(|(k, v)| (k.to_string(), v.to_str().unwrap_or("?").to_owned()))
        .collect();
    (status, head, r.bytes().await.unwrap().to_vec())
}

/// A series of `/metrics` (0 when absent).
async fn metric(s: &Server, series: &str) -> f64 {
    let text = s.get("/metrics").await.text().await.unwrap();
    text.lines()
        .find_map(|l| l.strip_prefix(series).and_then(|v| v.strip_prefix(' ')).and_then(|v| v.parse().ok()))
        .unwrap_or(0.0)
}

const HOT: &str = "textile_hot_tile_answers_total";
const TILES_200: &str = r#"textile_http_requests_total{route="/tiles/{id}/{z}/{x}/{y}",status="200"}"#;
const TILES_304: &str = r#"textile_http_requests_total{route="/tiles/{id}/{z}/{x}/{y}",status="304"}"#;

/// For each tile and each set of request headers: the full path's answer, then the hot path's
/// of the same URL, equal; the metrics count both. Returns the URLs asked twice.
async fn hot_equals_full(s: &Server, origins: &[&str]) -> Vec<String> {
    let mut asked = Vec::new();
    for tile in ["/tiles/gravel/7/1/1.png?seed=5", "/tiles/meadow/7/0/1.png?seed=5"] {
        let cold = answer(s, &format!("{tile}&v=cold"), &[]).await;
        assert_eq!(cold.0, 200, "{tile}");
        let etag = cold.1.iter().find(|(k, _)| k == "etag").map(|(_, v)| v.clone()).expect("an etag");
        let mut variants: Vec<Vec<(&str, &str)>> = vec![vec![], vec![("If-None-Match", &etag)]];
        for o in origins {
            variants.push(vec![("Origin", o)]);
            variants.push(vec![("Origin", o), ("If-None-Match", &etag)]);
        }
        for (k, headers) in variants.iter().enumerate() {
            let url = format!("{tile}&v=asked{k}");
            let (hot, ok, not_modified) =
                (metric(s, HOT).await, metric(s, TILES_200).await, metric(s, TILES_304).await);
            let full = answer(s, &url, headers).await;
            assert_eq!(metric(s, HOT).await, hot, "{url} {headers:?}: the first request takes the full path");
            let again = answer(s, &url, headers).await;
            assert_eq!(metric(s, HOT).await, hot + 1.0, "{url} {headers:?}: the second takes the hot path");
            assert_eq!(full.0, again.0, "{url} {headers:?}");
            assert_eq!(full.1, again.1, "{url} {headers:?}: headers");
            assert!(full.2 == again.2, "{url} {headers:?}: bytes");
            let expected = if headers.iter().any(|(h, _)| *h == "If-None-Match") { 304 } else { 200 };
            assert_eq!(again.0, expected, "{url} {headers:?}");
            if expected == 200 {
                assert!(again.1.contains(&("x-cache".into(), "HIT".into())), "{:?}", again.1);
                assert!(again.2 == cold.2, "{url}: the tile's bytes");
            }
            // Both answers counted under the tile route.
            let (ok2, nm2) = (metric(s, TILES_200).await, metric(s, TILES_304).await);
            let twice = if expected == 200 { (ok + 2.0, not_modified) } else { (ok, not_modified + 2.0) };
            assert_eq!((ok2, nm2), twice, "{url} {headers:?}: request metrics");
            asked.push(url);
        }
    }
    asked
}

#[tokio::test]
async fn any_origin_hot_answers_equal_the_full_paths() {
    let s = Server::builder().start();
    hot_equals_full(&s, &["https://example.org"]).await;

    // What the hot path leaves to the router is answered as before, and not counted as hot.
    let tile = "/tiles/gravel/7/1/1.png?seed=5&v=asked0";
    let hot = metric(&s, HOT).await;
    let head = s.client.head(s.url(tile)).send().await.unwrap();
    assert_eq!(head.status(), 200);
    assert_eq!(head.headers()["x-cache"], "HIT");
    assert!(head.bytes().await.unwrap().is_empty());
    let encoded = answer(&s, "/tiles/grav%65l/7/1/1.png?seed=5&v=asked0", &[]).await;
    let plain = answer(&s, tile, &[]).await;
    assert_eq!((encoded.0, &encoded.1), (plain.0, &plain.1));
    assert!(encoded.2 == plain.2);
    assert_eq!(metric(&s, HOT).await, hot + 1.0, "only the plain GET was hot");
    // Oversized headers on a remembered URL are still refused, as JSON.
    let many: Vec<(String, String)> = (0..120).map(|i| (format!("x-h{i}"), "v".to_owned())).collect();
    let many: Vec<(&str, &str)> = many.iter().map(|(k, v)| (k.as_str(), v.as_str())).collect();
    let (status, _, body) = answer(&s, tile, &many).await;
    assert_eq!(status, 431);
    let v: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(v["error"], "headers_too_large");
}

#[tokio::test]
async fn listed_origins_and_the_access_log_are_the_same_on_the_hot_path() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("textile.toml");
    std::fs::write(&config, "cors_origins = [\"https://a.example\"]\n").unwrap();
    let log = dir.path().join("access.log");
    let s =
        Server::builder().args(&["--config", config.to_str().unwrap(), "--access-log", log.to_str().unwrap()]).start();
    let asked = hot_equals_full(&s, &["https://a.example", "https://b.example"]).await;
    // The listed origin is echoed, another is not, on both paths.
    let listed = answer(&s, &asked[2], &[("Origin", "https://a.example")]).await;
    assert!(listed.1.contains(&("access-control-allow-origin".into(), "https://a.example".into())));
    let other = answer(&s, &asked[4], &[("Origin", "https://b.example")]).await;
    assert!(!other.1.iter().any(|(k, _)| k == "access-control-allow-origin"), "{:?}", other.1);

    // Each URL's two log lines (full path, hot path) agree but for their times.
    let lines = || -> Vec<Value> {
        let text = std::fs::read_to_string(&log).unwrap_or_default();
        text.lines().filter_map(|l| serde_json::from_str(l).ok()).collect()
    };
    let mut waited = 0;
    while lines().iter().filter(|l| asked.iter().any(|u| l["path"] == u.as_str())).count() < 2 * asked.len() + 2 {
        assert!(waited < 200, "the access log has every line");
        std::thread::sleep(std::time::Duration::from_millis(50));
        waited += 1;
    }
    let all = lines();
    for url in &asked {
        let mut of: Vec<Value> = all.iter().filter(|l| l["path"] == url.as_str()).cloned().collect();
        for l in of.iter_mut() {
            let o = l.as_object_mut().unwrap();
            o.remove("time");
            o.remove("ts");
            o.remove("ms");
        }
        assert!(of.len() >= 2, "{url}: {of:?}");
        assert_eq!(of[0], of[1], "{url}");
        let status = of[1]["status"].as_u64();
        assert!(status == Some(200) || status == Some(304), "{of:?}");
        if status == Some(200) {
            assert_eq!(of[1]["cache"], "hit", "{of:?}");
            assert!(of[1]["bytes"].as_u64() > Some(1000), "{of:?}");
        } else {
            assert_eq!(of[1]["bytes"].as_u64(), Some(0), "{of:?}");
        }
    }
}
