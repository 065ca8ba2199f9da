//! Tiles, metadata and HTTP semantics of the real server: sizes and formats, TileJSON 3.0.0,
//! catalog consistency, ETag/304, X-Cache, HEAD, CORS, the OpenAPI document, and a texture's
//! configured κ.

mod common;

use common::{binary, gravel_textures_config, shared_data_dir, Server};

#[tokio::test]
async fn tiles_decode_to_the_right_size_in_every_format() {
    let s = Server::builder().start();
    for fmt in ["png", "jpg", "jpeg", "webp"] {
        let img = s.image(&format!("/tiles/gravel/7/3/-2.{fmt}")).await;
        assert_eq!(img.dimensions(), (256, 256), "{fmt}");
    }
    let big = s.image("/tiles/gravel/6/0/0@2x.png").await;
    assert_eq!(big.dimensions(), (512, 512));
    let native2x = s.image("/tiles/gravel/7/0/0@2x.png").await;
    assert_eq!(native2x.dimensions(), (512, 512));
    let r = s.get("/tiles/gravel/7/0/0.webp").await;
    assert_eq!(r.headers()["content-type"], "image/webp");
    let r = s.get("/tiles/gravel/7/0/0.jpg").await;
    assert_eq!(r.headers()["content-type"], "image/jpeg");
}

#[tokio::test]
async fn tilejson_is_valid_and_its_template_fetches_tiles() {
    let s = Server::builder().start();
    let tj = s.json("/tiles/grass/tilejson.json?seed=5&randomness=0.4").await;
    assert_eq!(tj["tilejson"], "3.0.0");
    assert_eq!(tj["scheme"], "xyz");
    let tiles = tj["tiles"].as_array().expect("tiles array");
    assert!(!tiles.is_empty());
    let (minz, maxz) = (tj["minzoom"].as_u64().unwrap(), tj["maxzoom"].as_u64().unwrap());
    assert!(minz <= maxz && maxz <= 30);
    assert!(tj["name"].is_string() && tj["attribution"].is_string());
    let bounds = tj["bounds"].as_array().unwrap();
    assert_eq!(bounds.len(), 4);
    let center = tj["center"].as_array().unwrap();
    assert_eq!(center.len(), 3);
    let template = tiles[0].as_str().unwrap();
    assert!(
        template.contains("seed=5") && template.contains("randomness=0.4") && template.contains("v="),
        "{template}"
    );
    let url = template.replace("{z}", &maxz.to_string()).replace("{x}", "-1").replace("{y}", "2");
    let path = url.strip_prefix(&s.base).expect("template on this server");
    let via_template = s.get_bytes(path).await;
    assert_eq!(via_template.0, 200);
    // The same tile without the cache-busting version has the same bytes; the template repeats
    // the texture once around the Web-Mercator world its bounds describe (world = 2^native).
    let native = tj["textile"]["native_zoom"].as_u64().unwrap();
    assert!(template.contains(&format!("world={}", 1u64 << native)), "{template}");
    let direct =
        s.get_bytes(&format!("/tiles/grass/{maxz}/-1/2.png?seed=5&randomness=0.40&world={}", 1u64 << native)).await;
    assert_eq!(direct, via_template);
    // Seamless at the date line, at every zoom: the tile past the last column is the first one
    // again (and a column joins its right neighbour seamlessly everywhere).
    for z in [native, native - 2, minz] {
        let tile = |x: i64| {
            let url = template.replace("{z}", &z.to_string()).replace("{x}", &x.to_string()).replace("{y}", "1");
            url.strip_prefix(&s.base).unwrap().to_string()
        };
        let (first, wrapped) = (s.get_bytes(&tile(0)).await, s.get_bytes(&tile(1 << z)).await);
        assert_eq!(first.0, 200);
        assert_eq!(first, wrapped, "zoom {z}: the world wraps exactly");
    }
    // A period the query names is kept.
    let tj = s.json("/tiles/grass/tilejson.json?world=256").await;
    let template = tj["tiles"][0].as_str().unwrap();
    assert!(template.contains("world=256") && !template.contains(&format!("world={}", 1u64 << native)), "{template}");
}

#[tokio::test]
async fn catalog_and_metadata_agree() {
    let s = Server::builder().start();
    let cat = s.json("/catalog").await;
    let list = cat["textures"].as_array().unwrap();
    let ids: Vec<&str> = list.iter().map(|t| t["id"].as_str().unwrap()).collect();
    for id in ["gravel", "grass", "brick", "corkboard", "flagstones"] {
        assert!(ids.contains(&id), "{ids:?}");
    }
    for t in list {
        let id = t["id"].as_str().unwrap();
        let meta = s.json(&format!("/textures/{id}")).await;
        assert_eq!(meta["id"], t["id"]);
        assert_eq!(meta["modes"], t["modes"]);
        assert_eq!(meta["default_mode"], t["default_mode"]);
        let tj_path = t["tilejson"].as_str().unwrap().strip_prefix(&s.base).unwrap().to_string();
        let tj = s.json(&tj_path).await;
        assert_eq!(tj["maxzoom"], meta["maxzoom"]);
        assert_eq!(tj["minzoom"], meta["minzoom"]);
        // Served magnified beyond native zoom.
        let steps = meta["magnification"]["steps"].as_u64().unwrap();
        assert_eq!(meta["native_zoom"].as_u64().unwrap() + steps, meta["maxzoom"].as_u64().unwrap());
        assert_eq!(steps, 3);
        let side = meta["exemplar"]["width"].as_u64().unwrap();
        let ex = s.image(&format!("/textures/{id}/exemplar.png")).await;
        assert_eq!(ex.dimensions(), (side as u32, side as u32));
        let r = meta["parameters"]["randomness"]["default"].as_array().unwrap();
        assert_eq!(r.len() as u64, meta["levels"].as_u64().unwrap());
    }
}

#[tokio::test]
async fn etag_304_cache_headers_head_and_cors() {
    let s = Server::builder().start();
    let path = "/tiles/brick/7/11/-7.png?seed=77";
    let first = s.client.get(s.url(path)).header("Origin", "https://example.org").send().await.unwrap();
    assert_eq!(first.status(), 200);
    assert_eq!(first.headers()["x-cache"], "MISS");
    assert_eq!(first.headers()["access-control-allow-origin"], "*");
    assert_eq!(first.headers()["cache-control"], "public, max-age=31536000, immutable");
    let etag = first.headers()["etag"].to_str().unwrap().to_string();
    assert!(etag.starts_with('"') && etag.ends_with('"') && !etag.starts_with("W/"));
    let body = first.bytes().await.unwrap();
    let second = s.get(path).await;
    assert_eq!(second.headers()["x-cache"], "HIT");
    assert_eq!(second.headers()["etag"].to_str().unwrap(), etag);
    assert_eq!(second.bytes().await.unwrap(), body);
    let cond = s.client.get(s.url(path)).header("If-None-Match", &etag).send().await.unwrap();
    assert_eq!(cond.status(), 304);
    assert!(cond.bytes().await.unwrap().is_empty());
    let other = s.client.get(s.url(path)).header("If-None-Match", "\"nope\"").send().await.unwrap();
    assert_eq!(other.status(), 200);
    let head = s.client.head(s.url(path)).send().await.unwrap();
    assert_eq!(head.status(), 200);
    assert_eq!(head.headers()["etag"].to_str().unwrap(), etag);
    assert_eq!(head.headers()["content-type"], "image/png");
    assert!(head.bytes().await.unwrap().is_empty());
    // Another parameter is another ETag; the version parameter is not.
    let seeded = s.get("/tiles/brick/7/11/-7.png?seed=78").await;
    assert_ne!(seeded.headers()["etag"].to_str().unwrap(), etag);
    let versioned = s.get("/tiles/brick/7/11/-7.png?seed=77&v=abc").await;
    assert_eq!(versioned.headers()["etag"].to_str().unwrap(), etag);
}

#[tokio::test]
async fn health_ready_viewer_and_openapi() {
    let s = Server::builder().start();
    let h = s.json("/health").await;
    assert_eq!(h["status"], "ok");
    let r = s.json("/ready").await;
    assert_eq!(r["status"], "ready");
    let page = s.get("/").await;
    assert_eq!(page.status(), 200);
    assert!(page.headers()["content-type"].to_str().unwrap().starts_with("text/html"));
    let doc = s.json("/openapi.json").await;
    assert!(doc["openapi"].as_str().unwrap().starts_with("3."));
    let paths = doc["paths"].as_object().unwrap();
    for p in [
        "/",
        "/world.html",
        "/health",
        "/ready",
        "/metrics",
        "/catalog",
        "/openapi.json",
        "/textures/{id}",
        "/textures/{id}/exemplar.png",
        "/tiles/{id}/tilejson.json",
        "/tiles/{id}/{z}/{x}/{y}.{fmt}",
        "/windows/{id}.{fmt}",
        "/gltf/{id}/{z}/{x}/{y}.{ext}",
        "/gltf/{id}/patch.glb",
        "/x3d/{id}/{z}/{x}/{y}.x3d",
        "/x3d/{id}/patch.x3d",
        "/3dtiles/{id}/tileset.json",
        "/3dtiles/{id}/subtrees/{level}/{x}/{y}.subtree",
        "/3dtiles/{id}/tiles/{level}/{x}/{y}.glb",
        "/3d.html",
    ] {
        assert!(paths.contains_key(p), "openapi lacks {p}");
    }
}

#[tokio::test]
async fn a_textures_configured_kappa_shapes_its_synthesis_and_only_that() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = gravel_textures_config(dir.path(), &[("plain", ""), ("coherent", "[textures.synth]\nkappa = 0.3")]);
    let data = shared_data_dir();
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let k = |v: &serde_json::Value| v["settings"]["synth"]["kappa"].as_f64().unwrap();
    assert_eq!(k(&s.json("/textures/plain").await), 1.0, "the default κ");
    assert_eq!(k(&s.json("/textures/coherent").await), 0.3);
    let (plain, coherent) = (s.get("/tiles/plain/7/1/2.png").await, s.get("/tiles/coherent/7/1/2.png").await);
    assert_ne!(plain.headers()["etag"], coherent.headers()["etag"]);
    let coherent = coherent.bytes().await.unwrap();
    assert_ne!(plain.bytes().await.unwrap(), coherent, "κ changes the synthesis");
    // Same exemplar, other κ: the TileJSON version parameter differs too, so immutable cached
    // copies of one are never taken for the other.
    let v = |t: serde_json::Value| t["tiles"][0].as_str().unwrap().split("v=").nth(1).unwrap()[..12].to_string();
    assert_ne!(v(s.json("/tiles/plain/tilejson.json").await), v(s.json("/tiles/coherent/tilejson.json").await));
    // The cheap mode has no κ: same bytes for both.
    assert_eq!(
        s.get_bytes("/tiles/plain/7/1/2.png?mode=mosaic").await,
        s.get_bytes("/tiles/coherent/7/1/2.png?mode=mosaic").await
    );
    // `textile render --texture` uses the texture's κ too.
    let out = dir.path().join("tile.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--config", cfg.to_str().unwrap(), "--data-dir", data.to_str().unwrap()])
        .args(["--texture", "coherent", "--x", "1", "--y", "2", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(std::fs::read(&out).unwrap(), coherent);
    // The shipped configuration gives brick κ = 0.5, gravel the default.
    let d = Server::builder().start();
    assert_eq!(k(&d.json("/textures/brick").await), 0.5);
    assert_eq!(k(&d.json("/textures/gravel").await), 1.0);
}

#[tokio::test]
async fn every_listed_mode_is_served_and_its_tiles_equal_one_window() {
    // Whatever modes the server lists (a new mode is covered without editing this test): 2×2
    // tiles equal the same area as one window, at native zoom, one step out and two in; a mode's key
    // given to another mode is refused naming the mode it belongs to; /metrics counts each.
    let s = Server::builder().start();
    let meta = s.json("/textures/brick").await;
    let modes: Vec<String> =
        meta["modes"].as_array().unwrap().iter().map(|m| m.as_str().unwrap().to_string()).collect();
    assert!(modes.len() >= 2, "{modes:?}");
    for mode in &modes {
        // A mode that declines brick (umbrella: it is near-regular) is checked on gravel.
        let id = if meta["declined_modes"][mode.as_str()].is_string() { "gravel" } else { "brick" };
        for (z, x0, y0) in [(7, -1, 2), (6, 3, -4), (9, -3, 5)] {
            let mut stitched = image::RgbImage::new(512, 512);
            for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let tile = s.image(&format!("/tiles/{id}/{z}/{}/{}.png?mode={mode}&seed=5", x0 + i, y0 + j)).await;
                common::paste(&mut stitched, &tile, 256 * i as u32, 256 * j as u32);
            }
            let window = s
                .image(&format!("/windows/{id}.png?mode={mode}&seed=5&x={}&y={}&w=512&h=512&z={z}", 256 * x0, 256 * y0))
                .await;
            assert!(window == stitched, "mode={mode}: 2x2 tiles at z={z} differ from one window");
        }
        for (name, spec) in meta["parameters"].as_object().unwrap() {
            let Some(owners) = spec["modes"].as_array() else { continue };
            if owners.iter().any(|m| m == mode.as_str()) {
                continue;
            }
            let r = s.get(&format!("/tiles/{id}/7/0/0.png?mode={mode}&{name}=1")).await;
            assert_eq!(r.status(), 400, "{name} given to mode={mode}");
            let body: serde_json::Value = r.json().await.unwrap();
            assert!(
                body["message"].as_str().unwrap().contains(&format!("mode={}", owners[0].as_str().unwrap())),
                "{body}"
            );
        }
    }
    let metrics = s.get("/metrics").await.text().await.unwrap();
    for mode in &modes {
        assert!(metrics.contains(&format!("textile_syntheses_total{{mode=\"{mode}\"}}")), "{mode} not counted");
    }
}

#[tokio::test]
async fn magnified_zooms_are_served_up_to_maxzoom_and_stay_true_to_native() {
    let s = Server::builder().start();
    let meta = s.json("/textures/gravel").await;
    let (native, max) = (meta["native_zoom"].as_u64().unwrap(), meta["maxzoom"].as_u64().unwrap());
    assert_eq!(max, native + 3);
    // One step in: a native tile's four children, box-filtered 2×2, are close to it (the
    // magnification interpolates between texel centres: a slight blur, not a different image).
    let parent = s.image(&format!("/tiles/gravel/{native}/3/-2.png")).await;
    let mut children = image::RgbImage::new(512, 512);
    for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let tile = s.image(&format!("/tiles/gravel/{}/{}/{}.png", native + 1, 6 + i, -4 + j)).await;
        common::paste(&mut children, &tile, 256 * i as u32, 256 * j as u32);
    }
    let mad = box_difference(&children, &parent);
    assert!(mad < 14.0, "mean absolute difference {mad:.2}");
    // `@2x` at a magnified zoom is the next zoom's pixels.
    let big = s.image(&format!("/tiles/gravel/{}/1/-1@2x.png", native + 1)).await;
    let window = s.image(&format!("/windows/gravel.png?z={}&x=512&y=-512&w=512&h=512", native + 2)).await;
    assert!(big == window, "@2x at z = native + 1 differs from the window at native + 2");
    // The highest zoom is served; past it, a 400 naming the range.
    assert_eq!(s.image(&format!("/tiles/gravel/{max}/-5/7.png")).await.dimensions(), (256, 256));
    let r = s.get(&format!("/tiles/gravel/{}/0/0.png", max + 1)).await;
    assert_eq!(r.status(), 400);
    let body: serde_json::Value = r.json().await.unwrap();
    assert!(body["message"].as_str().unwrap().contains(&max.to_string()), "{body}");
    // Samples stay at native zoom or coarser.
    let body = serde_json::json!({ "points": [[0, 0, native + 1]] }).to_string().into_bytes();
    let (status, _, answer) = s.post("/samples/gravel", "application/json", body).await;
    assert_eq!(status, 400, "{}", String::from_utf8_lossy(&answer));
    assert!(String::from_utf8_lossy(&answer).contains("not magnified"));
}

/// Mean absolute difference per channel between `a` box-filtered 2×2 and `b` (half its size).
fn box_difference(a: &image::RgbImage, b: &image::RgbImage) -> f64 {
    let mut diff = 0u64;
    for (x, y, p) in b.enumerate_pixels() {
        for c in 0..3 {
            let sum: u32 =
                [(0, 0), (1, 0), (0, 1), (1, 1)].iter().map(|(i, j)| a.get_pixel(2 * x + i, 2 * y + j)[c] as u32).sum();
            diff += ((sum + 2) / 4).abs_diff(p[c] as u32) as u64;
        }
    }
    diff as f64 / (3 * b.width() * b.height()) as f64
}

#[tokio::test]
async fn a_high_resolution_exemplar_gives_magnified_tiles_its_own_detail() {
    // `plain` is the embedded gravel reduced 2×2 to 64²; `hires` is made from the 128² gravel
    // with `exemplar_hires`, so its exemplar is the same 64² image.
    let dir = tempfile::tempdir().unwrap();
    let gravel = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
    let big = image::open(&gravel).unwrap().to_rgb8();
    let small = image::RgbImage::from_fn(64, 64, |x, y| {
        image::Rgb(std::array::from_fn(|c| {
            let s: u32 = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .map(|(i, j)| big.get_pixel(2 * x + i, 2 * y + j)[c] as u32)
                .sum();
            ((s + 2) / 4) as u8
        }))
    });
    small.save(dir.path().join("small.png")).unwrap();
    let cfg = dir.path().join("textile.toml");
    let text = format!(
        "[[textures]]\nid = \"plain\"\nexemplar = \"small.png\"\n\n[[textures]]\nid = \"hires\"\nexemplar_hires = \"{}\"\n",
        gravel.display()
    );
    std::fs::write(&cfg, text).unwrap();
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let meta = s.json("/textures/hires").await;
    assert_eq!(meta["exemplar"]["width"], 64);
    assert_eq!(meta["native_zoom"], 6);
    assert_eq!(meta["magnification"]["detail"], "exemplar_hires 128x128", "{meta}");
    assert_eq!(s.json("/textures/plain").await["magnification"]["detail"], "exemplar");
    // Same exemplar pixels: the same native tiles; different identities (the detail image is
    // part of the texture), so different ETags.
    let (a, b) = (s.get("/tiles/plain/6/2/-1.png").await, s.get("/tiles/hires/6/2/-1.png").await);
    assert_ne!(a.headers()["etag"], b.headers()["etag"]);
    assert_eq!(a.bytes().await.unwrap(), b.bytes().await.unwrap());
    // One step in, the hires texture copies the 128² image inside every patch, whose 2×2
    // averages are the exemplar: box-filtered back, nearly the native tile (differences only
    // where patches meet); the plain one interpolates, a blur.
    let native = s.image("/tiles/plain/6/2/-1.png").await;
    let mut close = Vec::new();
    for id in ["plain", "hires"] {
        let mut children = image::RgbImage::new(512, 512);
        for (i, j) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let tile = s.image(&format!("/tiles/{id}/7/{}/{}.png", 4 + i, -2 + j)).await;
            common::paste(&mut children, &tile, 256 * i as u32, 256 * j as u32);
        }
        close.push(box_difference(&children, &native));
    }
    assert!(close[1] < 0.5 * close[0], "box-filtered back: plain {:.2}, hires {:.2}", close[0], close[1]);
    // A texture cannot name both images.
    let both = dir.path().join("both.toml");
    std::fs::write(&both, "[[textures]]\nid = \"x\"\nexemplar = \"small.png\"\nexemplar_hires = \"small.png\"\n")
        .unwrap();
    let out = dir.path().join("x.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--config", both.to_str().unwrap(), "--texture", "x", "--x", "0", "--y", "0"])
        .args(["-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(
        String::from_utf8_lossy(&run.stderr).contains("exemplar_hires"),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

#[tokio::test]
async fn a_users_texture_beside_the_built_ins() {
    // The README's worked example: one [[textures]] entry with only id and exemplar (a
    // non-square image, path relative to the configuration file), keeping the built-ins.
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(300, 200, |x, y| {
        image::Rgb([(x * 7 % 256) as u8, (y * 11 % 256) as u8, ((x ^ y) % 256) as u8])
    });
    std::fs::create_dir(dir.path().join("textures")).unwrap();
    img.save(dir.path().join("textures/mine.png")).unwrap();
    let cfg = dir.path().join("textile.toml");
    std::fs::write(
        &cfg,
        "include_default_textures = true\n\n[[textures]]\nid = \"mine\"\nexemplar = \"textures/mine.png\"\n",
    )
    .unwrap();
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let ids: Vec<String> = s.json("/catalog").await["textures"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["id"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(ids, ["gravel", "grass", "brick", "corkboard", "flagstones", "mine"]);
    let meta = s.json("/textures/mine").await;
    assert_eq!(meta["name"], "mine", "name defaults to the id");
    let e = &meta["exemplar"];
    // Used at its own size: no crop, no resample.
    assert_eq!(
        [&e["input_width"], &e["input_height"], &e["width"], &e["height"]].map(|v| v.as_u64()),
        [Some(300), Some(200), Some(300), Some(200)]
    );
    assert_eq!(meta["native_zoom"], 9, "⌈log2 300⌉");
    assert_eq!(s.image("/tiles/mine/9/0/0.png").await.dimensions(), (256, 256));
}

#[tokio::test]
async fn modes_that_need_only_the_exemplar_serve_while_the_analysis_is_computed() {
    // A 512² exemplar takes far longer to analyse than these requests take.
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(512, 512, |x, y| {
        let h = (x.wrapping_mul(2_654_435_761) ^ y.wrapping_mul(40_503)).wrapping_mul(2_246_822_519) >> 24;
        image::Rgb([(h & 0xFF) as u8, ((x / 8 + y / 5) % 256) as u8, ((x ^ y) % 256) as u8])
    });
    img.save(dir.path().join("big.png")).unwrap();
    let cfg = dir.path().join("textile.toml");
    std::fs::write(&cfg, "[[textures]]\nid = \"big\"\nexemplar = \"big.png\"\n").unwrap();
    let data = dir.path().join("data");
    let s = Server::builder().data_dir(&data).args(&["--config", cfg.to_str().unwrap()]).start_loading().await;
    // The registry appears as soon as the exemplar is decoded.
    let mut meta = serde_json::Value::Null;
    for _ in 0..200 {
        let r = s.get("/textures/big").await;
        if r.status() == 200 {
            meta = r.json().await.unwrap();
            break;
        }
        tokio::time::sleep(std::time::Duration::from_millis(50)).await;
    }
    assert_eq!(meta["analysis"]["status"], "analysing", "{meta}");
    assert_eq!(meta["native_zoom"], 9);
    assert_eq!(s.get("/ready").await.status(), 503);
    assert_eq!(s.image("/tiles/big/9/0/-1.png?mode=mosaic").await.dimensions(), (256, 256));
    assert_eq!(s.image("/tiles/big/6/2/2.png?mode=tiling").await.dimensions(), (256, 256));
    let r = s.get("/tiles/big/9/0/0.png").await;
    assert_eq!(r.status(), 503, "synth needs the analysis");
    assert!(r.headers().contains_key("retry-after"));
    let body: serde_json::Value = r.json().await.unwrap();
    assert_eq!(body["error"], "not_ready", "{body}");
    assert!(body["message"].as_str().unwrap().contains("mode=synth"), "{body}");
}

/// A value of the described parameter `d` other than its default `default`, from its type and
/// range as `GET /textures/{id}` describes them.
fn another_value(d: &serde_json::Value, default: &serde_json::Value) -> String {
    let num = |k: &str| d[k].as_f64().unwrap_or_else(|| panic!("{d} has no {k}"));
    let pick = |a: String, b: String, a_is_default: bool| if a_is_default { b } else { a };
    match d["type"].as_str().expect("type") {
        "choice" => {
            let values: Vec<&str> = d["values"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
            values.iter().find(|v| default.as_str() != Some(**v)).unwrap().to_string()
        }
        "integer" | "power_of_two" => {
            let (min, max) = (d["min"].as_u64().unwrap(), d["max"].as_u64().unwrap());
            pick(min.to_string(), max.min(min * 4).max(min + 1).to_string(), default.as_u64() == Some(min))
        }
        "number" => pick(num("min").to_string(), num("max").to_string(), default.as_f64() == Some(num("min"))),
        "levels" => {
            let all = |v: f64| default.as_array().is_some_and(|a| a.iter().all(|x| x.as_f64() == Some(v)));
            pick("0".into(), "1".into(), all(0.0))
        }
        "interval" => {
            let (lo, hi) = (num("min"), num("max"));
            let is = |a: f64, b: f64| {
                default.as_array().is_some_and(|x| x[0].as_f64() == Some(a) && x[1].as_f64() == Some(b))
            };
            pick(format!("{lo},{lo}"), format!("{hi},{hi}"), is(lo, lo))
        }
        // {"strokes":[{"at":[3,4],"radius":8,"value":0}]}
        "text" => "eyJzdHJva2VzIjpbeyJhdCI6WzMsNF0sInJhZGl1cyI6OCwidmFsdWUiOjB9XX0".into(),
        other => panic!("no value to try for a parameter of type {other}"),
    }
}

#[tokio::test]
async fn every_request_parameter_of_every_mode_changes_the_etag() {
    let s = Server::builder().start();
    let meta = s.json("/textures/gravel").await;
    let params = meta["parameters"].as_object().expect("parameters");
    let etag = |query: String| {
        let s = &s;
        async move {
            let r = s.get(&format!("/tiles/gravel/3/1/-1.png?{query}")).await;
            assert_eq!(r.status(), 200, "{query}");
            r.headers()["etag"].to_str().unwrap().to_string()
        }
    };
    let mut tried = 0;
    for (name, d) in params {
        let modes: Vec<String> = match d["modes"].as_array() {
            Some(m) => m.iter().map(|m| m.as_str().unwrap().to_string()).collect(),
            // The common keys: every mode whose pixels they change (the tiling's depend on neither).
            None if name == "mode" => continue,
            None => ["synth", "mosaic", "umbrella"].map(String::from).to_vec(),
        };
        for mode in modes {
            let default = d["default"].clone();
            let value = another_value(d, &default);
            let (base, changed) =
                (etag(format!("mode={mode}")).await, etag(format!("mode={mode}&{name}={value}")).await);
            assert_ne!(base, changed, "mode={mode}: {name}={value} (default {default}) keeps the ETag");
            tried += 1;
        }
    }
    assert!(tried >= 12, "only {tried} parameters tried");
}
