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
