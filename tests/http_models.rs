//! 3D asset endpoints through the real server: GLB structure (chunks, lengths, alignment), the
//! embedded image is the tile's bytes, .gltf images resolve to the tile, patches have one node
//! per tile, X3D is well-formed with the expected nodes, ETags and bad inputs as for tiles.

mod common;

use common::{assert_error, Server};
use serde_json::Value;

fn u32le(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]])
}

/// Check a GLB's container and return (JSON, BIN chunk).
fn parse_glb(b: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&b[0..4], b"glTF");
    assert_eq!(u32le(b, 4), 2);
    assert_eq!(u32le(b, 8) as usize, b.len());
    let jlen = u32le(b, 12) as usize;
    assert_eq!(u32le(b, 16), 0x4E4F_534A);
    assert_eq!(jlen % 4, 0);
    let json: Value = serde_json::from_slice(&b[20..20 + jlen]).expect("JSON chunk");
    let at = 20 + jlen;
    let blen = u32le(b, at) as usize;
    assert_eq!(u32le(b, at + 4), 0x004E_4942);
    assert_eq!(blen % 4, 0);
    assert_eq!(at + 8 + blen, b.len());
    let bin = b[at + 8..].to_vec();
    assert_eq!(json["buffers"][0]["byteLength"].as_u64().unwrap() as usize, blen);
    for v in json["bufferViews"].as_array().unwrap() {
        let (o, l) = (v["byteOffset"].as_u64().unwrap() as usize, v["byteLength"].as_u64().unwrap() as usize);
        assert!(o % 4 == 0 && o + l <= blen);
    }
    (json, bin)
}

fn image_bytes(json: &Value, bin: &[u8], i: usize) -> Vec<u8> {
    let view = &json["bufferViews"][json["images"][i]["bufferView"].as_u64().unwrap() as usize];
    let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
    bin[o..o + l].to_vec()
}

#[tokio::test]
async fn glb_embeds_the_tile_and_is_well_formed() {
    let s = Server::builder().start();
    let r = s.get("/gltf/gravel/6/-3/2.glb?seed=4").await;
    assert_eq!(r.status(), 200);
    assert_eq!(r.headers()["content-type"], "model/gltf-binary");
    let etag = r.headers()["etag"].to_str().unwrap().to_string();
    let b = r.bytes().await.unwrap();
    let (json, bin) = parse_glb(&b);
    assert_eq!(json["asset"]["version"], "2.0");
    assert!(json["asset"]["generator"].as_str().unwrap().starts_with("textile"));
    assert_eq!(json["samplers"][0]["wrapS"], 33071);
    assert_eq!(json["samplers"][0]["wrapT"], 33071);
    let prim = &json["meshes"][0]["primitives"][0];
    for a in ["POSITION", "NORMAL", "TEXCOORD_0"] {
        assert!(prim["attributes"][a].is_u64(), "{a}");
    }
    assert!(prim["indices"].is_u64());
    // Zoom 6 is one step out of native 7: the quad is 512 texels wide, at (-3·512, 0, 2·512).
    assert_eq!(json["nodes"][0]["translation"], serde_json::json!([-1536.0, 0.0, 1024.0]));
    assert_eq!(json["accessors"][0]["max"], serde_json::json!([512.0, 0.0, 512.0]));
    let tile = s.get_bytes("/tiles/gravel/6/-3/2.png?seed=4").await;
    assert_eq!(image_bytes(&json, &bin, 0), tile.1, "the embedded image is the tile");
    let cond =
        s.client.get(s.url("/gltf/gravel/6/-3/2.glb?seed=4")).header("If-None-Match", &etag).send().await.unwrap();
    assert_eq!(cond.status(), 304);
    let again = s.get("/gltf/gravel/6/-3/2.glb?seed=4").await;
    assert_eq!(again.headers()["x-cache"], "HIT");
    assert_eq!(again.bytes().await.unwrap(), b);
}

#[tokio::test]
async fn gltf_json_images_resolve_to_the_tile() {
    let s = Server::builder().start();
    for q in ["", "?seed=9&mode=mosaic"] {
        let r = s.get(&format!("/gltf/brick/7/5/-6.gltf{q}")).await;
        assert_eq!(r.status(), 200);
        assert_eq!(r.headers()["content-type"], "model/gltf+json");
        let json: Value = r.json().await.unwrap();
        let uri = json["images"][0]["uri"].as_str().unwrap();
        assert!(!uri.contains('?') && !uri.contains("://") && !uri.starts_with('/'), "{uri}");
        assert!(json["buffers"][0]["uri"].as_str().unwrap().starts_with("data:application/octet-stream;base64,"));
        let resolved = s.get_bytes(&format!("/gltf/brick/7/5/{uri}")).await;
        let tile = s.get_bytes(&format!("/tiles/brick/7/5/-6.png{q}")).await;
        assert_eq!(resolved, tile, "{uri}");
        let abs = json["images"][0]["extras"]["tile_url"].as_str().unwrap();
        assert_eq!(s.get_bytes(abs.strip_prefix(&s.base).unwrap()).await, tile);
    }
}

#[tokio::test]
async fn patch_has_one_node_per_tile() {
    let s = Server::builder().start();
    let (status, b) = s.get_bytes("/gltf/grass/patch.glb?z=7&x=-1&y=4&tiles=3&seed=2").await;
    assert_eq!(status, 200);
    let (json, bin) = parse_glb(&b);
    assert_eq!(json["nodes"].as_array().unwrap().len(), 9);
    assert_eq!(json["images"].as_array().unwrap().len(), 9);
    assert_eq!(json["scenes"][0]["nodes"].as_array().unwrap().len(), 9);
    for (k, (i, j)) in (0..3).flat_map(|j| (0..3).map(move |i| (i, j))).enumerate() {
        let (x, y) = (-1 + i, 4 + j);
        assert_eq!(json["nodes"][k]["translation"], serde_json::json!([256.0 * x as f64, 0.0, 256.0 * y as f64]));
        let tile = s.get_bytes(&format!("/tiles/grass/7/{x}/{y}.png?seed=2")).await;
        assert_eq!(image_bytes(&json, &bin, k), tile.1, "tile ({x},{y})");
    }
}

#[tokio::test]
async fn x3d_is_well_formed_and_points_at_the_tile() {
    let s = Server::builder().start();
    let r = s.get("/x3d/gravel/7/1/2.x3d?seed=3").await;
    assert_eq!(r.status(), 200);
    assert_eq!(r.headers()["content-type"], "model/x3d+xml");
    let text = r.text().await.unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "X3D");
    for tag in [
        "Scene",
        "Transform",
        "Shape",
        "Appearance",
        "ImageTexture",
        "IndexedFaceSet",
        "Coordinate",
        "TextureCoordinate",
    ] {
        assert!(doc.descendants().any(|n| n.tag_name().name() == tag), "missing {tag}");
    }
    let tex = doc.descendants().find(|n| n.tag_name().name() == "ImageTexture").unwrap();
    let url = tex.attribute("url").unwrap().trim_matches('"');
    let path = url.strip_prefix(&s.base).expect("absolute tile URL");
    assert_eq!(s.get_bytes(path).await, s.get_bytes("/tiles/gravel/7/1/2.png?seed=3").await);
    let t = doc.descendants().find(|n| n.tag_name().name() == "Transform").unwrap();
    assert_eq!(t.attribute("translation"), Some("256 0 512"));
}

#[tokio::test]
async fn bad_model_requests_are_json_4xx() {
    let s = Server::builder().start();
    for (path, status, code) in [
        ("/gltf/gravel/11/0/0.glb", 400, "invalid_coordinate"),
        ("/gltf/gravel/7/x/0.glb", 400, "invalid_coordinate"),
        ("/gltf/gravel/7/0/0.obj", 400, "invalid_format"),
        ("/gltf/nosuch/7/0/0.glb", 404, "unknown_texture"),
        ("/gltf/gravel/7/0/0.glb?bogus=1", 400, "unknown_parameter"),
        ("/gltf/gravel/7/0/0.gltf?randomness=2", 400, "invalid_parameter"),
        ("/gltf/gravel/7/0/0.!!!.png", 400, "invalid_parameter"),
        ("/gltf/gravel/patch.glb?z=7&x=0&y=0&tiles=9", 400, "invalid_parameter"),
        ("/gltf/gravel/patch.glb?z=7&x=0&y=0&tiles=0", 400, "invalid_parameter"),
        ("/gltf/gravel/patch.glb?z=7&x=0&tiles=2", 400, "missing_parameter"),
        ("/gltf/gravel/patch.glb?z=7&x=2147483647&y=0&tiles=2", 400, "invalid_coordinate"),
        ("/x3d/gravel/7/0/0.glb", 400, "invalid_format"),
        ("/x3d/gravel/99/0/0.x3d", 400, "invalid_coordinate"),
    ] {
        assert_error(&s, path, status, code).await;
    }
}
