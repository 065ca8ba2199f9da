//! Behind a reverse proxy: absolute URLs in documents (TileJSON `tiles`, the catalog, glTF
//! extras, X3D textures) follow `X-Forwarded-Proto`/`X-Forwarded-Host` or `Forwarded` only from
//! trusted proxies, and a configured `public_url` wins over everything.

mod common;

use common::Server;

async fn tiles_url(s: &Server, headers: &[(&str, &str)]) -> String {
    let mut req = s.client.get(s.url("/tiles/gravel/tilejson.json"));
    for (k, v) in headers {
        req = req.header(*k, *v);
    }
    let r = req.send().await.expect("tilejson");
    assert_eq!(r.status(), 200);
    let v: serde_json::Value = r.json().await.expect("json");
    v["tiles"][0].as_str().expect("tiles").to_string()
}

async fn body(s: &Server, path: &str, headers: &[(&str, &str)]) -> String {
    let mut req = s.client.get(s.url(path));
    for (k, v) in headers {
        req = req.header(*k, *v);
    }
    let r = req.send().await.expect("request");
    assert_eq!(r.status(), 200, "{path}");
    r.text().await.expect("body")
}

const XF: &[(&str, &str)] = &[("x-forwarded-proto", "https"), ("x-forwarded-host", "tiles.example.org")];

#[tokio::test]
async fn forwarded_headers_count_only_from_trusted_proxies() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("proxy.toml");
    std::fs::write(&cfg, "trusted_proxies = [\"127.0.0.1\"]\n").unwrap();
    let trusting = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    assert!(tiles_url(&trusting, XF).await.starts_with("https://tiles.example.org/tiles/gravel/{z}/{x}/{y}.png?"));
    let fwd = [("forwarded", "for=10.0.0.1;proto=https;host=maps.example.net")];
    assert!(tiles_url(&trusting, &fwd).await.starts_with("https://maps.example.net/tiles/gravel/"));
    // Without forwarded headers: the Host header, as before.
    assert!(tiles_url(&trusting, &[]).await.starts_with(&format!("{}/tiles/gravel/", trusting.base)));
    // Hostile values are not put into URLs.
    let bad = [("x-forwarded-host", "evil.example\"><script>"), ("x-forwarded-proto", "javascript")];
    assert!(tiles_url(&trusting, &bad).await.starts_with(&format!("{}/tiles/", trusting.base)));
    // Every document with absolute URLs follows.
    let catalog = body(&trusting, "/catalog", XF).await;
    assert!(catalog.contains("https://tiles.example.org/tiles/gravel/tilejson.json"), "{catalog}");
    let x3d = body(&trusting, "/x3d/gravel/7/0/0.x3d", XF).await;
    assert!(x3d.contains("https://tiles.example.org/gltf/gravel/7/0/0.png"), "{x3d}");
    let gltf = body(&trusting, "/gltf/gravel/7/0/0.gltf", XF).await;
    assert!(gltf.contains("https://tiles.example.org/tiles/gravel/7/0/0.png"), "{gltf}");

    // The default trusts no one: forwarded headers are ignored.
    let plain = Server::builder().start();
    assert!(tiles_url(&plain, XF).await.starts_with(&format!("{}/tiles/gravel/", plain.base)));
}

#[tokio::test]
async fn a_configured_public_url_wins() {
    let s = Server::builder().env("TEXTILE_PUBLIC_URL", "https://cdn.example.com/textile/").start();
    assert!(tiles_url(&s, XF).await.starts_with("https://cdn.example.com/textile/tiles/gravel/{z}/{x}/{y}.png?"));
    let x3d = body(&s, "/x3d/gravel/7/0/0.x3d", &[]).await;
    assert!(x3d.contains("https://cdn.example.com/textile/gltf/gravel/7/0/0.png"), "{x3d}");
    // A bad one is refused at start, naming the key.
    let out = std::process::Command::new(common::binary())
        .args(["serve", "--bind", "127.0.0.1:0"])
        .env("TEXTILE_PUBLIC_URL", "ftp://nope")
        .output()
        .expect("run");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("public_url"), "{}", String::from_utf8_lossy(&out.stderr));
}
