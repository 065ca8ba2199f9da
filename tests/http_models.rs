//! 3D asset endpoints through the real server: GLB structure (chunks, lengths, alignment), the
//! embedded image is the tile with a 16-texel border of its neighbours (the window around it:
//! inner square = the tile, border = the neighbouring tiles), texture coordinates map the inner
//! square, samplers mipmap, .gltf images resolve to the same image, patches have one node per
//! tile, X3D tiles and patches are well-formed with a top-down viewpoint, ETags and bad inputs as
//! for tiles.

mod common;

use common::{assert_error, f32s, parse_glb, Server};
use serde_json::Value;

/// The padded image of tile `z/x/y` as the window endpoint serves it (`q`: more parameters).
fn padded(id: &str, z: i64, x: i64, y: i64, q: &str) -> String {
    format!("/windows/{id}.png?x={}&y={}&w=288&h=288&z={z}{q}", 256 * x - 16, 256 * y - 16)
}

fn decode(png: &[u8]) -> image::RgbImage {
    image::load_from_memory(png).expect("PNG").to_rgb8()
}

fn crop(img: &image::RgbImage, x: u32, y: u32, w: u32, h: u32) -> image::RgbImage {
    image::imageops::crop_imm(img, x, y, w, h).to_image()
}

fn image_bytes(json: &Value, bin: &[u8], i: usize) -> Vec<u8> {
    common::glb_image(json, bin, i)
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
    assert_eq!(json["samplers"][0]["minFilter"], 9987, "LINEAR_MIPMAP_LINEAR");
    assert_eq!(json["samplers"][0]["magFilter"], 9729);
    assert_eq!(json["nodes"][0]["name"], "tile_6_-3_2");
    let prim = &json["meshes"][0]["primitives"][0];
    for a in ["POSITION", "NORMAL", "TEXCOORD_0"] {
        assert!(prim["attributes"][a].is_u64(), "{a}");
    }
    assert!(prim["indices"].is_u64());
    // Zoom 6 is one step out of native 7: the quad is 512 texels wide, at (-3·512, 0, 2·512).
    assert_eq!(json["nodes"][0]["translation"], serde_json::json!([-1536.0, 0.0, 1024.0]));
    assert_eq!(json["accessors"][0]["max"], serde_json::json!([512.0, 0.0, 512.0]));
    // The texture coordinates map the quad onto the inner 256² of the 288² image.
    let (near, far) = (16.0 / 288.0, 272.0 / 288.0);
    assert_eq!(f32s(&json, &bin, 2), vec![near, near, far, near, far, far, near, far]);
    let embedded = image_bytes(&json, &bin, 0);
    assert_eq!(embedded, s.get_bytes(&padded("gravel", 6, -3, 2, "&seed=4")).await.1, "the window around the tile");
    let img = decode(&embedded);
    assert_eq!(img.dimensions(), (288, 288));
    assert_eq!(crop(&img, 16, 16, 256, 256), s.image("/tiles/gravel/6/-3/2.png?seed=4").await, "inner square = tile");
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
        let extra = q.replace('?', "&");
        assert_eq!(resolved, s.get_bytes(&padded("brick", 7, 5, -6, &extra)).await, "{uri}");
        let abs = json["images"][0]["extras"]["tile_url"].as_str().unwrap();
        let tile = s.get_bytes(&format!("/tiles/brick/7/5/-6.png{q}")).await;
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
        assert_eq!(json["nodes"][k]["name"], format!("tile_7_{x}_{y}"));
        let window = s.get_bytes(&padded("grass", 7, x, y, "&seed=2")).await;
        assert_eq!(image_bytes(&json, &bin, k), window.1, "tile ({x},{y})");
    }
}

/// The border is the neighbours' texels: each side of a tile's image equals the facing edge of
/// the neighbouring tile, in a periodic world (`world=1`) too, and at a magnified zoom.
#[tokio::test]
async fn the_border_is_the_neighbouring_tiles() {
    let s = Server::builder().start();
    for (id, z, x, y, q) in
        [("gravel", 7, 1, 1, "?mode=mosaic&world=1"), ("brick", 7, -4, 9, ""), ("gravel", 8, 3, -2, "?seed=5")]
    {
        let (status, b) = s.get_bytes(&format!("/gltf/{id}/{z}/{x}/{y}.glb{q}")).await;
        assert_eq!(status, 200, "{id} {z}/{x}/{y}{q}");
        let (json, bin) = parse_glb(&b);
        let img = decode(&image_bytes(&json, &bin, 0));
        let mut tiles = std::collections::HashMap::new();
        for (dx, dy) in [(0, 0), (1, 0), (-1, 0), (0, -1), (0, 1), (1, 1)] {
            tiles.insert((dx, dy), s.image(&format!("/tiles/{id}/{z}/{}/{}.png{q}", x + dx, y + dy)).await);
        }
        let tile = |dx: i64, dy: i64| &tiles[&(dx, dy)];
        assert_eq!(&crop(&img, 16, 16, 256, 256), tile(0, 0));
        assert_eq!(crop(&img, 272, 16, 16, 256), crop(tile(1, 0), 0, 0, 16, 256), "east");
        assert_eq!(crop(&img, 0, 16, 16, 256), crop(tile(-1, 0), 240, 0, 16, 256), "west");
        assert_eq!(crop(&img, 16, 0, 256, 16), crop(tile(0, -1), 0, 240, 256, 16), "north");
        assert_eq!(crop(&img, 16, 272, 256, 16), crop(tile(0, 1), 0, 0, 256, 16), "south");
        assert_eq!(crop(&img, 272, 272, 16, 16), crop(tile(1, 1), 0, 0, 16, 16), "south-east");
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
        "Viewpoint",
        "Transform",
        "Shape",
        "Appearance",
        "ImageTexture",
        "TextureProperties",
        "IndexedFaceSet",
        "Coordinate",
        "TextureCoordinate",
    ] {
        assert!(doc.descendants().any(|n| n.tag_name().name() == tag), "missing {tag}");
    }
    // Unlit: no Material, so the texture shows as it is.
    assert!(!doc.descendants().any(|n| n.tag_name().name() == "Material"));
    let tex = doc.descendants().find(|n| n.tag_name().name() == "ImageTexture").unwrap();
    let url = tex.attribute("url").unwrap().trim_matches('"');
    let path = url.strip_prefix(&s.base).expect("absolute image URL");
    assert_eq!(s.get_bytes(path).await, s.get_bytes(&padded("gravel", 7, 1, 2, "&seed=3")).await);
    let t = doc.descendants().find(|n| n.tag_name().name() == "Transform").unwrap();
    assert_eq!(t.attribute("translation"), Some("256 0 512"));
    // Above the tile's centre, as high as the tile is wide, looking down.
    let v = doc.descendants().find(|n| n.tag_name().name() == "Viewpoint").unwrap();
    assert_eq!(v.attribute("position"), Some("384 256 640"));
    assert!(v.attribute("orientation").unwrap().starts_with("1 0 0 -1.57"));
}

#[tokio::test]
async fn x3d_patch_has_one_transform_per_tile() {
    let s = Server::builder().start();
    let r = s.get("/x3d/gravel/patch.x3d?z=7&x=-1&y=-1&tiles=3&seed=3").await;
    assert_eq!(r.status(), 200);
    let etag = r.headers()["etag"].to_str().unwrap().to_string();
    let text = r.text().await.unwrap();
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let transforms: Vec<_> = doc.descendants().filter(|n| n.tag_name().name() == "Transform").collect();
    assert_eq!(transforms.len(), 9);
    assert_eq!(transforms[5].attribute("translation"), Some("256 0 0"), "row 0 (y = 0), column 1");
    assert_eq!(transforms[5].attribute("DEF"), Some("tile_7_1_0"));
    let v = doc.descendants().find(|n| n.tag_name().name() == "Viewpoint").unwrap();
    assert_eq!(v.attribute("position"), Some("128 768 128"));
    let urls: Vec<_> = doc.descendants().filter_map(|n| n.attribute("url")).collect();
    assert_eq!(urls.len(), 9);
    let path = urls[5].trim_matches('"').strip_prefix(&s.base).unwrap().to_string();
    assert_eq!(s.get_bytes(&path).await, s.get_bytes(&padded("gravel", 7, 1, 0, "&seed=3")).await);
    let cond = s
        .client
        .get(s.url("/x3d/gravel/patch.x3d?z=7&x=-1&y=-1&tiles=3&seed=3"))
        .header("If-None-Match", &etag)
        .send()
        .await
        .unwrap();
    assert_eq!(cond.status(), 304);
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
        ("/x3d/gravel/patch.x3d?z=7&x=0&y=0&tiles=9", 400, "invalid_parameter"),
        ("/x3d/gravel/patch.x3d?z=7&x=0&y=0", 400, "missing_parameter"),
        ("/x3d/nosuch/patch.x3d?z=7&x=0&y=0&tiles=2", 404, "unknown_texture"),
    ] {
        assert_error(&s, path, status, code).await;
    }
}
