//! Landscapes wherever a texture goes, through the real binary: 3D (glTF, X3D, 3D Tiles with
//! relief by the blended heights), per-sample queries, exports (one archive and shards merged)
//! and the load tool. The built-in meadow (grass, gravel, flagstones at scale −1) serves them.

mod common;

use common::{f32s, glb_image, parse_glb, Server};

/// A GLB of the meadow shows the landscape's window of the tile and its border; its relief
/// follows the blended heights; its 3D Tiles tileset follows the landscape's native zoom; X3D
/// points at images that are the same windows.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_landscape_in_3d() {
    let s = Server::builder().start();
    let meta = s.json("/textures/meadow").await;
    let native = meta["native_zoom"].as_u64().expect("native zoom");
    // The tile (8, 3, 4) with its 16-texel border: the landscape's window.
    let (z, x, y) = (8i64, 3i64, 4i64);
    let window = format!("/windows/meadow.png?z={z}&x={}&y={}&w=288&h=288", 256 * x - 16, 256 * y - 16);
    let (code, want) = s.get_bytes(&window).await;
    assert_eq!(code, 200);
    let (code, glb) = s.get_bytes(&format!("/gltf/meadow/{z}/{x}/{y}.glb")).await;
    assert_eq!(code, 200);
    let (json, bin) = parse_glb(&glb);
    assert_eq!(glb_image(&json, &bin, 0), want, "the GLB's image is the landscape's window");
    // The tile's quad: 256 · 2^(native − z) texels, at its place.
    let side = 256.0 * 2f64.powi(native as i32 - z as i32);
    assert_eq!(json["nodes"][0]["translation"], serde_json::json!([side * x as f64, 0.0, side * y as f64]));
    // Relief: heights from the blended height map, within (0, 8] texels, not flat.
    let (code, raised) = s.get_bytes(&format!("/gltf/meadow/{z}/{x}/{y}.glb?relief=8")).await;
    assert_eq!(code, 200);
    let (rj, rb) = parse_glb(&raised);
    let heights: Vec<f32> = f32s(&rj, &rb, 0).chunks(3).map(|p| p[1]).filter(|h| *h >= 0.0).collect();
    let (lo, hi) = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), h| (a.min(*h), b.max(*h)));
    eprintln!("meadow relief=8: {} vertices, heights {lo:.2}..{hi:.2}", heights.len());
    assert!(hi <= 8.0 && hi - lo > 1.0, "heights {lo}..{hi}");
    // The relief follows the landscape's height map: a vertex's height is the mean of the
    // 8 × 8 height texels around it (corner (16, 16) of the tile here).
    let (code, hpng) = s.get_bytes(&format!("{window}&map=height")).await;
    assert_eq!(code, 200);
    let hmap = image::load_from_memory(&hpng).expect("height").to_luma8();
    let mean: f32 = (0..8u32)
        .flat_map(|j| (0..8u32).map(move |i| (i, j)))
        .map(|(i, j)| hmap.get_pixel(16 + 128 - 4 + i, 16 + 128 - 4 + j)[0] as f32)
        .sum::<f32>()
        / (64.0 * 255.0);
    let pos = f32s(&rj, &rb, 0);
    let v = pos.chunks(3).nth(16 * 33 + 16).expect("vertex (16, 16)");
    assert!((v[1] - 8.0 * mean).abs() < 1e-3, "vertex height {} against the mean height {}", v[1], 8.0 * mean);
    // Seeds and bad parameters read as the landscape's tiles read them.
    let (code, reseeded) = s.get_bytes(&format!("/gltf/meadow/{z}/{x}/{y}.glb?seed=9")).await;
    assert_eq!(code, 200);
    assert_ne!(reseeded, glb);
    common::assert_error(&s, "/gltf/meadow/8/3/4.glb?mode=synth", 400, "invalid_parameter").await;
    common::assert_error(&s, "/gltf/meadow/8/3/4.glb?relief=300", 400, "invalid_parameter").await;

    // 3D Tiles: the tree follows the landscape's native zoom; the content of the level of zoom
    // z is the tile's GLB.
    let ts = s.json("/3dtiles/meadow/tileset.json?relief=8").await;
    let lift = ts["extras"]["level_of_zoom_0"].as_u64().expect("level of zoom 0");
    let world = ts["extras"]["world_texels"].as_f64().expect("world");
    assert_eq!(256.0 * 2f64.powi((native + lift) as i32), world, "the root tile spans the world");
    let level = z as u64 + lift;
    let half = 1i64 << (level - 1);
    let content = format!("/3dtiles/meadow/tiles/{level}/{}/{}.glb?relief=8", x + half, half - 1 - y);
    let (code, tile) = s.get_bytes(&content).await;
    assert_eq!(code, 200);
    assert_eq!(tile, raised, "3D Tiles content is the tile's GLB");
    let (code, _) = s.get_bytes("/3dtiles/meadow/subtrees/0/0/0.subtree").await;
    assert_eq!(code, 200);

    // X3D: its image URLs answer the same windows.
    let (code, doc) = s.get_bytes(&format!("/x3d/meadow/{z}/{x}/{y}.x3d")).await;
    assert_eq!(code, 200);
    let doc = String::from_utf8(doc).expect("utf-8");
    let url = doc.split("url='\"").nth(1).and_then(|r| r.split('"').next()).expect("an image URL");
    let path = url.strip_prefix(&s.base).expect("absolute URL of this server");
    assert_eq!(path, format!("/gltf/meadow/{z}/{x}/{y}.png"));
    let (code, img) = s.get_bytes(path).await;
    assert_eq!((code, img), (200, want));
    // A patch: one node per tile.
    let (code, patch) = s.get_bytes("/gltf/meadow/patch.glb?z=8&x=3&y=4&tiles=2").await;
    assert_eq!(code, 200);
    let (pj, pb) = parse_glb(&patch);
    assert_eq!(pj["nodes"].as_array().map(Vec::len), Some(4));
    assert_eq!(glb_image(&pj, &pb, 0), glb_image(&json, &bin, 0));
}

/// A landscape's samples: at a tile's pixel centre, the tile's pixel (its colour, a map, at the
/// native zoom and coarser, as JSON and binary records); footprints between levels lie between
/// them; too many tiles at once is a 400 naming the limit.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_landscape_sampled() {
    let s = Server::builder().start();
    let native = s.json("/textures/meadow").await["native_zoom"].as_u64().expect("native") as i64;
    let post = |body: serde_json::Value, query: &'static str| {
        let url = s.url(&format!("/samples/meadow{query}"));
        let client = s.client.clone();
        async move {
            let r = client.post(url).json(&body).send().await.expect("post");
            let code = r.status().as_u16();
            (code, r.json::<serde_json::Value>().await.expect("JSON"))
        }
    };
    let colours =
        |v: &serde_json::Value| -> Vec<[u8; 3]> { serde_json::from_value(v["colors"].clone()).expect("colours") };
    // Pixels of tile (3, 4) at native zoom and of (1, 2) one zoom out; seed 5.
    let tile = s.image(&format!("/tiles/meadow/{native}/3/4.png?seed=5")).await;
    let coarse = s.image(&format!("/tiles/meadow/{}/1/2.png?seed=5", native - 1)).await;
    let height = s.image(&format!("/tiles/meadow/{native}/3/4.png?seed=5&map=height")).await;
    let picks: Vec<(u32, u32)> = vec![(0, 0), (255, 255), (17, 200), (128, 3), (201, 99)];
    let points: Vec<[i64; 3]> = picks
        .iter()
        .flat_map(|&(x, y)| [[768 + x as i64, 1024 + y as i64, native], [256 + x as i64, 512 + y as i64, native - 1]])
        .collect();
    let (code, body) = post(serde_json::json!({ "points": points }), "?seed=5").await;
    assert_eq!(code, 200, "{body}");
    let got = colours(&body);
    for (i, &(x, y)) in picks.iter().enumerate() {
        assert_eq!(got[2 * i], tile.get_pixel(x, y).0, "native pixel ({x}, {y})");
        assert_eq!(got[2 * i + 1], coarse.get_pixel(x, y).0, "coarser pixel ({x}, {y})");
    }
    // Footprints at texel centres, lod 0: the native tile's pixels; map=height: the height tile's.
    let fps: Vec<[f64; 3]> = picks.iter().map(|&(x, y)| [768.5 + x as f64, 1024.5 + y as f64, 0.0]).collect();
    let (code, body) = post(serde_json::json!({ "footprints": fps }), "?seed=5&map=height").await;
    assert_eq!(code, 200, "{body}");
    for (c, &(x, y)) in colours(&body).iter().zip(&picks) {
        assert_eq!(*c, height.get_pixel(x, y).0, "height at ({x}, {y})");
    }
    // Halfway between the levels: between the native pixel's mean with its neighbours and the
    // coarser one (every channel within the two levels' bilinear values' range).
    let (code, body) = post(serde_json::json!({ "footprints": [[768.0 + 40.0, 1024.0 + 40.0, 0.5]] }), "?seed=5").await;
    assert_eq!(code, 200, "{body}");
    let c = colours(&body)[0];
    let near: Vec<[u8; 3]> =
        [(39, 39), (40, 39), (39, 40), (40, 40)].iter().map(|&(x, y)| tile.get_pixel(x, y).0).collect();
    let far: Vec<[u8; 3]> =
        [(19, 19), (20, 19), (19, 20), (20, 20)].iter().map(|&(x, y)| coarse.get_pixel(x, y).0).collect();
    for ch in 0..3 {
        let all: Vec<u8> = near.iter().chain(&far).map(|p| p[ch]).collect();
        let (lo, hi) = (*all.iter().min().unwrap(), *all.iter().max().unwrap());
        assert!((lo..=hi).contains(&c[ch]), "channel {ch}: {} outside {lo}..={hi}", c[ch]);
    }
    // Binary texel records: the same pixels, packed.
    let mut rec = Vec::new();
    for &(x, y) in &picks {
        rec.extend_from_slice(&(768 + x as i64).to_le_bytes());
        rec.extend_from_slice(&(1024 + y as i64).to_le_bytes());
        rec.extend_from_slice(&(native as u32).to_le_bytes());
    }
    let r = s
        .client
        .post(s.url("/samples/meadow?seed=5"))
        .header("content-type", "application/octet-stream")
        .body(rec)
        .send()
        .await
        .expect("post");
    assert_eq!(r.status().as_u16(), 200);
    let rgb = r.bytes().await.expect("body");
    for (c, &(x, y)) in rgb.chunks(3).zip(&picks) {
        assert_eq!(c, tile.get_pixel(x, y).0, "binary sample ({x}, {y})");
    }
    // Samples spread over more tiles than a request may read; a texture's parameter.
    let spread: Vec<[i64; 2]> = (0..300).map(|i| [i * 256, 0]).collect();
    let (code, body) = post(serde_json::json!({ "points": spread }), "").await;
    assert_eq!((code, body["error"].as_str()), (400, Some("too_many_tiles")), "{body}");
    assert!(body["message"].as_str().unwrap_or("").contains("256"), "{body}");
    let (code, body) = post(serde_json::json!({ "points": [[0, 0]] }), "?mode=synth").await;
    assert_eq!((code, body["error"].as_str()), (400, Some("invalid_parameter")), "{body}");
}

fn textile(args: &[&str]) -> (bool, String) {
    let out = std::process::Command::new(common::binary()).args(args).output().expect("run textile");
    (out.status.success(), format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr)))
}

/// The meadow exported as a 16-tile world: one process's archive and three shards merged are
/// the same bytes; an independent reader reads every tile back equal to the server's; merge
/// refuses a part of another version of the landscape, naming its identity; a splat that does
/// not repeat refuses a world export.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_landscape_exported_whole_and_in_shards() {
    let dir = tempfile::tempdir().expect("temp dir");
    let data = common::shared_data_dir();
    let data = data.to_str().expect("utf-8");
    let out = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let base = ["export", "--texture", "meadow", "--world", "16", "--data-dir", data];
    let whole = out("whole.pmtiles");
    let (ok, log) = textile(&[&base[..], &["-o", &whole]].concat());
    assert!(ok, "{log}");
    let parts: Vec<String> = (0..3).map(|i| out(&format!("p{i}.part"))).collect();
    let running: Vec<_> = (0..3)
        .map(|i| {
            let shard = format!("{i}/3");
            let args = [&base[..], &["--shard", &shard, "--workers", "1", "-o", &parts[i]]].concat();
            std::process::Command::new(common::binary()).args(&args).output()
        })
        .collect();
    for r in running {
        let r = r.expect("shard");
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    }
    let merged = out("merged.pmtiles");
    let (ok, log) =
        textile(&[&["merge"][..], &parts.iter().map(String::as_str).collect::<Vec<_>>(), &["-o", &merged]].concat());
    assert!(ok, "{log}");
    let (a, b) = (std::fs::read(&whole).expect("whole"), std::fs::read(&merged).expect("merged"));
    eprintln!("meadow world 16: {} bytes, whole and merged equal: {}", a.len(), a == b);
    assert!(a == b, "three shards merged differ from the whole export");
    if common::reader_available() {
        let s = Server::builder().start();
        common::check_archive(std::path::Path::new(&whole), &s, 1000);
    } else {
        common::skip("a_landscape_exported_whole_and_in_shards (reader)", "python pmtiles is not installed");
    }

    // Another version of the meadow (two layers, other shares): its part is refused.
    let cfg = dir.path().join("other.toml");
    std::fs::write(
        &cfg,
        "[[textures]]\nid = \"gravel\"\nexemplar = \"embedded:gravel.png\"\n\n[[textures]]\nid = \"grass\"\n\
         exemplar = \"embedded:grass.png\"\n\n[[landscapes]]\nid = \"meadow\"\n\n[[landscapes.layers]]\n\
         texture = \"grass\"\nshare = 0.7\n\n[[landscapes.layers]]\ntexture = \"gravel\"\nshare = 0.3\n\n\
         [landscapes.splat]\nkind = \"noise\"\nfeature = 384\n",
    )
    .expect("config");
    let other = out("other.part");
    let cfg = cfg.to_str().expect("utf-8");
    let (ok, log) = textile(&[&base[..], &["--config", cfg, "--shard", "1/3", "-o", &other]].concat());
    assert!(ok, "{log}");
    let (ok, log) = textile(&["merge", &parts[0], &other, &parts[2], "-o", &out("mixed.pmtiles")]);
    assert!(!ok && log.contains("another export") && log.contains("parameters"), "{log}");
    assert!(!dir.path().join("mixed.pmtiles").exists());

    // A splat shown once does not repeat: no world of it.
    let img = image::RgbImage::from_fn(4, 4, |x, _| image::Rgb(if x < 2 { [255, 0, 0] } else { [0, 0, 255] }));
    img.save(dir.path().join("splat.png")).expect("splat");
    let once = dir.path().join("once.toml");
    std::fs::write(
        &once,
        "[[textures]]\nid = \"gravel\"\nexemplar = \"embedded:gravel.png\"\n\n[[textures]]\nid = \"grass\"\n\
         exemplar = \"embedded:grass.png\"\n\n[[landscapes]]\nid = \"island\"\n\n[[landscapes.layers]]\n\
         texture = \"gravel\"\ncolour = \"#ff0000\"\n\n[[landscapes.layers]]\ntexture = \"grass\"\ncolour = \"#0000ff\"\n\n\
         [landscapes.splat]\nkind = \"image\"\nimage = \"splat.png\"\ntexels_per_pixel = 128\noutside = \"gravel\"\n",
    )
    .expect("config");
    let once = once.to_str().expect("utf-8");
    let args = ["export", "--texture", "island", "--world", "16", "--config", once, "--data-dir", data];
    let (ok, log) = textile(&[&args[..], &["-o", &out("island.pmtiles")]].concat());
    assert!(!ok && log.contains("world"), "{log}");
    eprintln!("island world export: {}", log.lines().last().unwrap_or(""));
}
