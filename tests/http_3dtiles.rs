//! OGC 3D Tiles 1.1 through the real server, checked against the specification's rules rather
//! than against our own code: the tileset's required properties and implicit-tiling rules, every
//! subtree's binary header and availability layout (sizes of the bitstreams, counts, which
//! levels and child subtrees exist), content URIs that resolve to the glTF tile of the flipped
//! row and lie inside their implicit tile's bounding box, a world of 2^26 texels a side whose
//! levels above zoom 0 show zoom 0's colour, the root transform, ETags, bad input.

mod common;

use common::{assert_error, Server};
use serde_json::Value;

fn u32le(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap())
}

fn u64le(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

/// The 3D Tiles 1.1 tileset rules an implicit, glTF-content tileset must meet (tileset.schema,
/// tile.schema, implicitTiling, boundingVolume); returns (subtreeLevels, availableLevels).
fn check_tileset(t: &Value) -> (u32, u32) {
    assert_eq!(t["asset"]["version"], "1.1", "asset.version");
    let ge = t["geometricError"].as_f64().expect("tileset.geometricError is required");
    let root = &t["root"];
    let root_ge = root["geometricError"].as_f64().expect("tile.geometricError is required");
    assert!(ge >= root_ge && root_ge > 0.0, "geometric errors: {ge} ≥ {root_ge} > 0");
    let bx = root["boundingVolume"]["box"].as_array().expect("a box bounding volume");
    assert_eq!(bx.len(), 12, "box: centre and three half-axes");
    assert!(bx.iter().all(Value::is_f64), "box numbers");
    assert_eq!(root["refine"], "REPLACE");
    assert!(root.get("children").is_none(), "a tile with implicitTiling must not have children");
    let it = &root["implicitTiling"];
    assert_eq!(it["subdivisionScheme"], "QUADTREE");
    let s = it["subtreeLevels"].as_u64().expect("subtreeLevels") as u32;
    let a = it["availableLevels"].as_u64().expect("availableLevels") as u32;
    assert!(s >= 1 && a >= 1);
    for uri in [it["subtrees"]["uri"].as_str().unwrap(), root["content"]["uri"].as_str().unwrap()] {
        for p in ["{level}", "{x}", "{y}"] {
            assert!(uri.contains(p), "template {uri} lacks {p}");
        }
        assert!(!uri.starts_with('/') && !uri.contains("://"), "relative to the tileset: {uri}");
    }
    if let Some(m) = root.get("transform") {
        assert_eq!(m.as_array().unwrap().len(), 16);
    }
    (s, a)
}

/// An availability object: constant, or a bitstream of at least `bits` bits in the binary.
/// Returns the availability of each of the `bits` entries.
fn availability(a: &Value, json: &Value, bin: &[u8], bits: usize) -> Vec<bool> {
    if let Some(c) = a.get("constant") {
        let c = c.as_u64().unwrap();
        assert!(c <= 1, "constant is 0 or 1");
        return vec![c == 1; bits];
    }
    let view = &json["bufferViews"][a["bitstream"].as_u64().expect("constant or bitstream") as usize];
    let buffer = &json["buffers"][view["buffer"].as_u64().unwrap() as usize];
    assert!(buffer.get("uri").is_none(), "our bitstreams are in the internal buffer");
    let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
    assert!(o + l <= buffer["byteLength"].as_u64().unwrap() as usize && o + l <= bin.len());
    assert!(l >= bits.div_ceil(8), "bitstream of {l} bytes for {bits} bits");
    let v: Vec<bool> = (0..bits).map(|i| bin[o + i / 8] >> (i % 8) & 1 == 1).collect();
    if let Some(n) = a.get("availableCount") {
        assert_eq!(n.as_u64().unwrap() as usize, v.iter().filter(|b| **b).count(), "availableCount");
    }
    v
}

/// A subtree file: header, padding, and its three availabilities (tiles, content, children).
fn check_subtree(b: &[u8], levels: u32) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
    assert_eq!(&b[0..4], b"subt", "magic");
    assert_eq!(u32le(b, 4), 1, "version");
    let (jl, bl) = (u64le(b, 8) as usize, u64le(b, 16) as usize);
    assert_eq!(24 + jl + bl, b.len(), "lengths");
    assert_eq!(jl % 8, 0, "JSON padded to 8 bytes");
    assert_eq!(bl % 8, 0, "binary padded to 8 bytes");
    let json: Value = serde_json::from_slice(&b[24..24 + jl]).expect("subtree JSON");
    let bin = &b[24 + jl..];
    if bl > 0 {
        assert!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize <= bl);
    }
    let tiles = ((1usize << (2 * levels)) - 1) / 3;
    let t = availability(&json["tileAvailability"], &json, bin, tiles);
    let contents = json["contentAvailability"].as_array().expect("contentAvailability: one per content");
    assert_eq!(contents.len(), 1);
    let c = availability(&contents[0], &json, bin, tiles);
    let k = availability(&json["childSubtreeAvailability"], &json, bin, 1 << (2 * levels));
    (t, c, k)
}

#[tokio::test]
async fn tileset_and_subtrees_follow_the_specification() {
    let s = Server::builder().start();
    let r = s.get("/3dtiles/gravel/tileset.json?seed=4").await;
    assert_eq!(r.status(), 200);
    assert_eq!(r.headers()["content-type"], "application/json");
    let etag = r.headers()["etag"].to_str().unwrap().to_string();
    let t: Value = r.json().await.unwrap();
    let (sl, levels) = check_tileset(&t);
    let meta = s.json("/textures/gravel").await;
    // The world has no edge a viewer reaches: 2^26 texels a side around texel (0, 0), levels
    // above zoom 0 to cover it, then one level per zoom 0..=maxzoom.
    let lift = t["extras"]["level_of_zoom_0"].as_u64().unwrap();
    let side = t["extras"]["world_texels"].as_f64().unwrap();
    let b = &t["root"]["boundingVolume"]["box"];
    assert_eq!(
        (b[0].as_f64(), b[1].as_f64(), b[3].as_f64(), b[7].as_f64()),
        (Some(0.0), Some(0.0), Some(side / 2.0), Some(side / 2.0))
    );
    assert_eq!(side, (256u64 << (meta["native_zoom"].as_u64().unwrap() + lift)) as f64, "the root is zoom 0 lifted");
    assert!(side >= 67_108_864.0, "a world of {side} texels");
    assert_eq!(levels as u64, lift + meta["maxzoom"].as_u64().unwrap() + 1, "one level per zoom 0..=maxzoom");
    // Every subtree root level: the availability says exactly which levels exist.
    for root in (0..levels).step_by(sl as usize) {
        let n = 1i64 << root;
        for (x, y) in [(0, 0), (n - 1, n / 2)] {
            let (status, b) = s.get_bytes(&format!("/3dtiles/gravel/subtrees/{root}/{x}/{y}.subtree")).await;
            assert_eq!(status, 200, "subtree {root}/{x}/{y}");
            let (tiles, content, children) = check_subtree(&b, sl);
            let mut i = 0;
            for l in 0..sl {
                for _ in 0..1usize << (2 * l) {
                    assert_eq!(tiles[i], root + l < levels, "tile bit {i} of subtree {root}");
                    assert_eq!(content[i], tiles[i], "every available tile has content");
                    i += 1;
                }
            }
            assert!(children.iter().all(|c| *c == (root + sl < levels)), "child subtrees of {root}");
        }
    }
    let cond = s.client.get(s.url("/3dtiles/gravel/tileset.json?seed=4")).header("If-None-Match", &etag).send().await;
    assert_eq!(cond.unwrap().status(), 304);
}

#[tokio::test]
async fn content_tiles_are_the_gltf_tiles_inside_their_boxes() {
    let s = Server::builder().start();
    let t = s.json("/3dtiles/gravel/tileset.json?seed=4&mode=mosaic").await;
    let template = t["root"]["content"]["uri"].as_str().unwrap();
    assert!(template.ends_with(".glb?mode=mosaic&seed=4"), "{template}");
    let b: Vec<f64> =
        t["root"]["boundingVolume"]["box"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    // The root box is axis-aligned here: its x and y extent.
    let (x0, y0, side) = (b[0] - b[3], b[1] - b[7], 2.0 * b[3]);
    assert_eq!(b[3], b[7]);
    let lift = t["extras"]["level_of_zoom_0"].as_u64().unwrap() as u32;
    let l = |d: u32| lift + d;
    let zoom0 = s.get_bytes("/tiles/gravel/0/0/0.png?seed=4&mode=mosaic").await.1;
    let zoom0 = image::load_from_memory(&zoom0).unwrap().to_rgb8();
    let tiles =
        [(0u32, 0i64, 0i64), (3, 2, 5), (lift - 1, 1 << (lift - 2), 0), (l(0), 1 << (lift - 1), (1 << (lift - 1)) - 1)];
    let tiles = tiles.into_iter().chain([(l(3), 2, 5), (l(7), 100 << lift, 3 << lift), (l(9), 511 << lift, 0)]);
    for (level, x, y) in tiles {
        let uri = template
            .replace("{level}", &level.to_string())
            .replace("{x}", &x.to_string())
            .replace("{y}", &y.to_string());
        let (status, glb) = s.get_bytes(&format!("/3dtiles/gravel/{uri}")).await;
        assert_eq!(status, 200, "{uri}");
        let (json, bin) = common::parse_glb(&glb);
        if level >= lift {
            // The same bytes as the XYZ tile of the flipped row, the root centred on texel 0.
            let half = 1i64 << (level - 1);
            let (z, col, row) = (level - lift, x - half, half - 1 - y);
            let xyz = s.get_bytes(&format!("/gltf/gravel/{z}/{col}/{row}.glb?seed=4&mode=mosaic")).await.1;
            assert!(glb == xyz, "{uri} is /gltf/gravel/{z}/{col}/{row}.glb");
        } else {
            // Above zoom 0: zoom 0's colour, uniform.
            let png = common::glb_image(&json, &bin, 0);
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            assert!(img.pixels().all(|p| p == zoom0.get_pixel(0, 0)), "{uri} shows zoom 0's colour");
        }
        // CesiumJS carries the tileset's query (anchoring included) into content URLs.
        let carried = s.get_bytes(&format!("/3dtiles/gravel/{uri}&lon=2.35&lat=48.85&height=35")).await.1;
        assert!(carried == glb, "{uri} with the anchoring parameters");
        // Its quad, Y-up turned Z-up ((x, y, z) → (x, −z, y)), covers the implicit tile.
        let jl = u32le(&glb, 12) as usize;
        let json: Value = serde_json::from_slice(&glb[20..20 + jl]).unwrap();
        let tr = &json["nodes"][0]["translation"];
        let size = json["accessors"][0]["max"][0].as_f64().unwrap();
        let (qx0, qx1) = (tr[0].as_f64().unwrap(), tr[0].as_f64().unwrap() + size);
        let (qy1, qy0) = (-tr[2].as_f64().unwrap(), -tr[2].as_f64().unwrap() - size);
        let w = side / (1u64 << level) as f64;
        let (bx0, by0) = (x0 + w * x as f64, y0 + w * y as f64);
        assert_eq!((qx0, qx1, qy0, qy1), (bx0, bx0 + w, by0, by0 + w), "tile {level}/{x}/{y}");
    }
}

#[tokio::test]
async fn the_root_transform_anchors_on_the_ellipsoid() {
    let s = Server::builder().start();
    let t = s.json("/3dtiles/gravel/tileset.json?lon=2.35&lat=48.85&height=35&seed=1").await;
    check_tileset(&t);
    let m: Vec<f64> = t["root"]["transform"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let col = |i: usize| [m[4 * i], m[4 * i + 1], m[4 * i + 2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // East, north, up: orthonormal, up along the position for a sphere-like Earth.
    for i in 0..3 {
        assert!((dot(col(i), col(i)) - 1.0).abs() < 1e-9);
    }
    assert!(dot(col(0), col(1)).abs() < 1e-9 && dot(col(1), col(2)).abs() < 1e-9);
    let r = dot(col(3), col(3)).sqrt();
    assert!((6_356_000.0..6_379_000.0).contains(&r), "ECEF radius {r}");
    assert!(dot(col(2), col(3)) / r > 0.99, "up points away from the centre");
    assert_eq!(m[15], 1.0);
    assert!(t["root"]["content"]["uri"].as_str().unwrap().ends_with(".glb?seed=1"), "anchoring stays out of tiles");
    assert!(s.json("/3dtiles/gravel/tileset.json").await["root"].get("transform").is_none());
}

#[tokio::test]
async fn bad_3dtiles_requests_are_json_4xx() {
    let s = Server::builder().start();
    for (path, status, code) in [
        ("/3dtiles/gravel/tileset.json?lon=3", 400, "missing_parameter"),
        ("/3dtiles/gravel/tileset.json?height=3", 400, "missing_parameter"),
        ("/3dtiles/gravel/tileset.json?lon=3&lat=91", 400, "invalid_parameter"),
        ("/3dtiles/gravel/tileset.json?lon=x&lat=1", 400, "invalid_parameter"),
        ("/3dtiles/gravel/tileset.json?bogus=1", 400, "unknown_parameter"),
        ("/3dtiles/nosuch/tileset.json", 404, "unknown_texture"),
        ("/3dtiles/gravel/tiles/99/0/0.glb", 400, "invalid_coordinate"),
        ("/3dtiles/gravel/tiles/2/4/0.glb", 400, "invalid_coordinate"),
        ("/3dtiles/gravel/tiles/2/0/-1.glb", 400, "invalid_coordinate"),
        ("/3dtiles/gravel/tiles/2/0/0.png", 400, "invalid_format"),
        ("/3dtiles/gravel/tiles/2/0/0.glb?seed=x", 400, "invalid_parameter"),
        ("/3dtiles/gravel/subtrees/1/0/0.subtree", 400, "invalid_coordinate"),
        ("/3dtiles/gravel/subtrees/4/16/0.subtree", 400, "invalid_coordinate"),
        ("/3dtiles/gravel/subtrees/99999999999/0/0.subtree", 400, "invalid_coordinate"),
    ] {
        assert_error(&s, path, status, code).await;
    }
    // The refusal names the levels the tileset has, and the last of them is served.
    let levels = s.json("/3dtiles/gravel/tileset.json").await["root"]["implicitTiling"]["availableLevels"]
        .as_u64()
        .expect("availableLevels");
    let body: serde_json::Value =
        s.get(&format!("/3dtiles/gravel/tiles/{levels}/0/0.glb")).await.json().await.expect("JSON error");
    let message = body["message"].as_str().unwrap_or_default();
    assert!(message.contains(&format!("levels 0 to {}", levels - 1)), "{message}");
    let last = s.get(&format!("/3dtiles/gravel/tiles/{}/0/0.glb", levels - 1)).await;
    assert_eq!(last.status(), 200, "level {} is named as served", levels - 1);
}

#[tokio::test]
async fn a_tileset_with_relief_serves_displaced_content() {
    let s = Server::builder().start();
    let tileset = s.json("/3dtiles/flagstones/tileset.json?relief=8").await;
    let uri = tileset["root"]["content"]["uri"].as_str().unwrap_or_default().to_string();
    assert!(uri.contains("relief=8"), "content URIs carry the relief: {uri}");
    // The root box holds the relief: from the skirts' foot below the ground to 8 above.
    let b: Vec<f64> =
        tileset["root"]["boundingVolume"]["box"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let (z0, z1) = (b[2] - b[11], b[2] + b[11]);
    assert!(z0 <= -0.5 && (8.0..=8.5).contains(&z1), "the box's height {z0}..{z1} holds the relief");
    let (x0, y0, side) = (b[0] - b[3], b[1] - b[7], 2.0 * b[3]);
    let lift = tileset["extras"]["level_of_zoom_0"].as_u64().unwrap() as u32;
    for (level, x, y) in
        [(2u32, 1i64, 1i64), (lift + 2, 1, 1), (lift + 5, 3, 30), (lift + 8, 200, 17), (lift + 9, 0, 511)]
    {
        let (status, bytes) = s.get_bytes(&format!("/3dtiles/flagstones/tiles/{level}/{x}/{y}.glb?relief=8")).await;
        assert_eq!(status, 200);
        // Compact: a 33² grid with skirts, 16-bit indices, beside the tile's images.
        assert!(bytes.len() <= 600_000, "{level}/{x}/{y}: {} bytes", bytes.len());
        let (json, bin) = common::parse_glb(&bytes);
        let prim = &json["meshes"][0]["primitives"][0];
        assert_eq!(json["accessors"][0]["count"], 33 * 33 + 4 * 33, "a displaced grid with its skirts");
        assert_eq!(json["accessors"][prim["indices"].as_u64().unwrap() as usize]["componentType"], 5123);
        // Compact vertex data: normals and tangents as normalized bytes, texture coordinates as
        // normalized u16 (KHR_mesh_quantization, required), positions as floats.
        assert_eq!(json["extensionsRequired"], serde_json::json!(["KHR_mesh_quantization"]));
        for (attribute, component) in [("POSITION", 5126), ("NORMAL", 5120), ("TANGENT", 5120), ("TEXCOORD_0", 5123)] {
            let a = &json["accessors"][prim["attributes"][attribute].as_u64().unwrap() as usize];
            assert_eq!(a["componentType"], component, "{level}/{x}/{y}: {attribute}");
            assert_eq!(a["normalized"].as_bool().unwrap_or(false), component != 5126, "{level}/{x}/{y}: {attribute}");
        }
        // Every vertex, Y-up turned Z-up ((x, y, z) → (x, −z, y)), lies inside the implicit
        // tile's box (the root's, split `level` times across).
        let t: Vec<f64> =
            json["nodes"][0]["translation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        let w = side / (1u64 << level) as f64;
        let (bx0, by0) = (x0 + w * x as f64, y0 + w * y as f64);
        let pos = common::f32s(&json, &bin, prim["attributes"]["POSITION"].as_u64().unwrap() as usize);
        for v in pos.chunks(3) {
            let (px, py, pz) = (t[0] + v[0] as f64, -(t[2] + v[2] as f64), t[1] + v[1] as f64);
            let inside = (bx0..=bx0 + w).contains(&px) && (by0..=by0 + w).contains(&py) && (z0..=z1).contains(&pz);
            assert!(inside, "{level}/{x}/{y}: vertex ({px}, {py}, {pz}) outside its box");
        }
    }
    // A texture without a height map has no relief.
    assert_error(&s, "/3dtiles/gravel/tileset.json?relief=8", 400, "invalid_parameter").await;
}
