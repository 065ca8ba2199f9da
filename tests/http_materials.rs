//! Materials (issue 39), through the real binary: a texture's co-registered maps (`[textures.maps]`)
//! served with `map=` on tiles and windows. Looking each prepared map
//! (`/textures/{id}/maps/{name}.png`) up at the `map=uv` coordinates gives that map's tile byte
//! for byte, in every mode with coordinates, near and far; normals are unit length at every zoom
//! and agree with the synthesized height's gradients whichever convention the source used;
//! windows equal stitched tiles for maps and coordinates; a map change changes only its own
//! ETags; a missing, mis-sized or unconventioned map is a clear configuration error; requests a
//! mode cannot serve get a 400 naming why.

mod common;

use common::{assert_error, binary, f32s, parse_glb, Server};

/// Both embedded materials: flagstones (DirectX normals, wraps) and forest floor (OpenGL, does
/// not wrap), with `extra` TOML added to the forest floor's maps.
fn materials_config(dir: &std::path::Path, forest_height: &str) -> std::path::PathBuf {
    let m = |t: &str, f: &str| format!("embedded:materials/{t}/{f}.png");
    let text = format!(
        "[[textures]]\nid = \"flagstones\"\nexemplar = \"{}\"\n[textures.maps]\nnormal = \"{}\"\n\
         normal_convention = \"directx\"\nheight = \"{}\"\nspecular = \"{}\"\n\n\
         [[textures]]\nid = \"forest\"\nexemplar = \"{}\"\n[textures.maps]\nnormal = \"{}\"\n\
         normal_convention = \"opengl\"\nheight = \"{}\"\nspecular = \"{}\"\n",
        m("flagstones", "albedo"),
        m("flagstones", "normal"),
        m("flagstones", "height"),
        m("flagstones", "specular"),
        m("forest_floor", "albedo"),
        m("forest_floor", "normal"),
        forest_height,
        m("forest_floor", "specular"),
    );
    let cfg = dir.join("textile.toml");
    std::fs::write(&cfg, text).unwrap();
    cfg
}

async fn uv(s: &Server, path: &str) -> image::ImageBuffer<image::Rgb<u16>, Vec<u16>> {
    let (status, bytes) = s.get_bytes(path).await;
    assert_eq!(status, 200, "{path}: {}", String::from_utf8_lossy(&bytes));
    image::load_from_memory(&bytes).unwrap_or_else(|e| panic!("{path}: {e}")).to_rgb16()
}

fn decode(p: &image::Rgb<u8>) -> [f64; 3] {
    p.0.map(|c| c as f64 / 127.5 - 1.0)
}

#[tokio::test]
async fn every_map_is_its_exemplar_map_looked_up_at_the_uv_coordinates() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let meta = s.json("/textures/flagstones").await;
    let names: Vec<&str> = meta["maps"].as_array().unwrap().iter().map(|m| m["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["albedo", "height", "normal", "specular", "uv"]);
    for id in ["flagstones", "forest"] {
        let mut maps = Vec::new();
        for name in ["albedo", "normal", "height", "specular"] {
            maps.push((name, s.image(&format!("/textures/{id}/maps/{name}.png")).await));
        }
        let side = maps[0].1.width();
        // The prepared maps carry an ETag (their own hash) and answer a conditional request.
        let r = s.get(&format!("/textures/{id}/maps/normal.png")).await;
        let etag = r.headers()["etag"].to_str().unwrap().to_string();
        let again = s.client.get(s.url(&format!("/textures/{id}/maps/normal.png"))).header("If-None-Match", &etag);
        assert_eq!(again.send().await.unwrap().status(), 304);
        for mode in ["synth", "tiling"] {
            for (x, y) in [(0i64, 0i64), (-3, 2), (40_000, -91_234)] {
                let q = format!("{x}/{y}.png?mode={mode}&seed=3");
                let coords = uv(&s, &format!("/tiles/{id}/8/{q}&map=uv")).await;
                // `synth` blends low frequencies across seams, 3 texels each side: there, the
                // pixels whose 7×7 coordinates continue each other; elsewhere every pixel.
                let reach = if mode == "synth" { 3 } else { 0 };
                let texel = |x: i64, y: i64| {
                    let c = coords.get_pixel(x as u32, y as u32).0;
                    (c[0] as i64 / 64, c[1] as i64 / 64)
                };
                let (w, h) = (coords.width() as i64, coords.height() as i64);
                let coherent = |x: i64, y: i64| {
                    let (tx, ty) = texel(x, y);
                    x >= reach
                        && y >= reach
                        && x + reach < w
                        && y + reach < h
                        && (-reach..=reach).all(|dy| {
                            (-reach..=reach).all(|dx| {
                                let (qx, qy) = texel(x + dx, y + dy);
                                (qx - dx, qy - dy) == (tx, ty)
                            })
                        })
                };
                for (name, exemplar) in &maps {
                    let tile = s.image(&format!("/tiles/{id}/8/{q}&map={name}")).await;
                    let mut checked = 0;
                    for (px, py, c) in coords.enumerate_pixels() {
                        let (u, v) = (c.0[0] as u32 / 64, c.0[1] as u32 / 64);
                        assert!(u < side && v < side, "{id} {mode} {name}: uv {c:?} outside the exemplar");
                        if !coherent(px as i64, py as i64) {
                            continue;
                        }
                        checked += 1;
                        assert_eq!(
                            tile.get_pixel(px, py),
                            exemplar.get_pixel(u, v),
                            "{id} {mode} ({x},{y}) {name} at ({px},{py}) is not the map at ({u},{v})"
                        );
                    }
                    assert!(checked >= 2000, "{id} {mode} {name}: only {checked} pixels checked");
                }
            }
        }
    }
    // The CLI renders the same bytes as the server, for a map and for the coordinates.
    let data = common::shared_data_dir();
    for (map, ext) in [("normal", "png"), ("uv", "png"), ("height", "webp")] {
        let out = dir.path().join(format!("cli-{map}.{ext}"));
        let run = std::process::Command::new(binary())
            .args(["render", "--config", cfg.to_str().unwrap(), "--data-dir", data.to_str().unwrap()])
            .args(["--texture", "forest", "--x", "1", "--y", "-4", "--seed", "5", "--map", map])
            .args(["-o", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(run.status.success(), "render --map {map}: {}", String::from_utf8_lossy(&run.stderr));
        let (status, served) = s.get_bytes(&format!("/tiles/forest/8/1/-4.{ext}?seed=5&map={map}")).await;
        assert_eq!(status, 200);
        assert!(std::fs::read(&out).unwrap() == served, "render --map {map} differs from the served tile");
    }
    // Coordinates and maps of a window are the same pixels as the tiles it covers.
    for map in ["uv", "normal"] {
        let window = uv(&s, &format!("/windows/forest.png?x=-128&y=256&w=512&h=256&z=8&map={map}")).await;
        for x in [-1i64, 0, 1] {
            let tile = uv(&s, &format!("/tiles/forest/8/{x}/1.png?map={map}")).await;
            for (px, py, c) in tile.enumerate_pixels() {
                let wx = 256 * x + px as i64 + 128;
                if (0..512).contains(&wx) {
                    assert_eq!(window.get_pixel(wx as u32, py), c, "{map}: tile ({x},1) pixel ({px},{py})");
                }
            }
        }
    }
}

#[tokio::test]
async fn normals_are_unit_length_at_every_zoom_and_follow_the_synthesized_height() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    for id in ["flagstones", "forest"] {
        for mode in ["synth", "mosaic", "tiling", "umbrella"] {
            for z in [6u32, 7, 8, 9, 10] {
                let tile = s.image(&format!("/tiles/{id}/{z}/5/-2.png?mode={mode}&map=normal")).await;
                for p in tile.pixels() {
                    let n = decode(p);
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    assert!((len - 1.0).abs() <= 1.0 / 127.0, "{id} {mode} z {z}: normal {p:?} has length {len}");
                }
            }
        }
        // Slopes of the synthesized normals against central differences of the synthesized
        // height, in the served (OpenGL, +Y up) convention: x slope ~ -dh/dx, y ~ +dh/drow.
        // Umbrella patches are turned (flagstones up to ±91°) and their normals with them;
        // their rims cut the height where the normal map sees no edge, so they agree less
        // (0.45-0.50; unturned normals gave 0.33-0.38).
        for (mode, least) in [("synth", 0.5), ("umbrella", 0.42)] {
            let q = format!("x=1000&y=-3000&w=512&h=512&seed=7&mode={mode}");
            let normal = s.image(&format!("/windows/{id}.png?{q}&map=normal")).await;
            let height = s.image(&format!("/windows/{id}.png?{q}&map=height")).await;
            let h = |x: u32, y: u32| height.get_pixel(x, y).0[0] as f64;
            let (mut sx, mut sy) = ((Vec::new(), Vec::new()), (Vec::new(), Vec::new()));
            for y in 1..511 {
                for x in 1..511 {
                    let n = decode(normal.get_pixel(x, y));
                    sx.0.push(n[0] / n[2]);
                    sx.1.push(-(h(x + 1, y) - h(x - 1, y)));
                    sy.0.push(n[1] / n[2]);
                    sy.1.push(h(x, y + 1) - h(x, y - 1));
                }
            }
            let (cx, cy) = (correlation(&sx.0, &sx.1), correlation(&sy.0, &sy.1));
            println!("{id} {mode}: correlation of normal slopes with height gradients: x {cx:.3}, y {cy:.3}");
            assert!(cx >= least && cy >= least, "{id} {mode}: normals disagree with the height: x {cx:.3}, y {cy:.3}");
        }
    }
    // Per-sample queries of a map equal its tile's pixels; filtered footprints of normals are
    // unit vectors.
    let tile = s.image("/tiles/forest/8/2/3.png?seed=9&map=normal").await;
    let pts: Vec<[i64; 2]> = (0..40).map(|i| [512 + (i * 37) % 256, 768 + (i * 91) % 256]).collect();
    let r = s
        .client
        .post(s.url("/samples/forest?seed=9&map=normal"))
        .json(&serde_json::json!({ "points": pts, "z": 8 }))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    let colors: serde_json::Value = r.json().await.unwrap();
    for (p, c) in pts.iter().zip(colors["colors"].as_array().unwrap()) {
        let px = tile.get_pixel((p[0] - 512) as u32, (p[1] - 768) as u32);
        let c: Vec<u8> = c.as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u8).collect();
        assert_eq!(px.0.to_vec(), c, "sample {p:?}");
    }
    let fps: Vec<[f64; 3]> =
        (0..40).map(|i| [100.3 + i as f64 * 7.7, -50.6 + i as f64 * 3.1, (i % 4) as f64 * 0.7]).collect();
    let r = s
        .client
        .post(s.url("/samples/forest?map=normal"))
        .json(&serde_json::json!({ "footprints": fps }))
        .send()
        .await
        .unwrap();
    assert_eq!(r.status(), 200);
    let colors: serde_json::Value = r.json().await.unwrap();
    for c in colors["colors"].as_array().unwrap() {
        let p = image::Rgb([0, 1, 2].map(|k| c[k].as_u64().unwrap() as u8));
        let n = decode(&p);
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() <= 1.0 / 127.0, "filtered normal {p:?} has length {len}");
    }
    // Requests a mode cannot serve, and maps a texture does not have.
    assert_error(&s, "/tiles/forest/8/0/0.png?map=uv&mode=umbrella", 400, "invalid_map").await;
    assert_error(&s, "/tiles/forest/8/0/0.png?map=uv&mode=mosaic", 400, "invalid_map").await;
    assert_error(&s, "/tiles/forest/8/0/0.jpg?map=uv", 400, "invalid_map").await;
    assert_error(&s, "/tiles/forest/8/0/0.png?map=roughness", 400, "invalid_map").await;
    assert_error(&s, "/textures/forest/maps/roughness.png", 400, "invalid_map").await;
}

/// The ETag of the forest's tile (1, 1) in every map.
async fn etags(s: &Server) -> Vec<String> {
    let mut out = Vec::new();
    for map in ["albedo", "normal", "height", "specular", "uv"] {
        let r = s.get(&format!("/tiles/forest/8/1/1.png?map={map}")).await;
        assert_eq!(r.status(), 200);
        out.push(r.headers()["etag"].to_str().unwrap().to_string());
    }
    out
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += (x - ma) * (y - mb);
        aa += (x - ma) * (x - ma);
        bb += (y - mb) * (y - mb);
    }
    ab / (aa * bb).sqrt()
}

#[tokio::test]
async fn a_map_change_changes_only_its_own_tiles_and_bad_maps_are_configuration_errors() {
    let dir = tempfile::tempdir().unwrap();
    let a = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let first = etags(&Server::builder().args(&["--config", a.to_str().unwrap()]).start()).await;
    // The forest's height replaced by its specular map: only the height tiles change.
    let b = materials_config(dir.path(), "embedded:materials/forest_floor/specular.png");
    let second = etags(&Server::builder().args(&["--config", b.to_str().unwrap()]).start()).await;
    for (i, map) in ["albedo", "normal", "height", "specular", "uv"].iter().enumerate() {
        assert_eq!(first[i] == second[i], *map != "height", "{map}: {} vs {}", first[i], second[i]);
    }
    // Mis-sized, missing, and a normal map without its convention: the binary refuses the
    // configuration, naming the map.
    image::RgbImage::from_pixel(128, 128, image::Rgb([9, 9, 9])).save(dir.path().join("small.png")).unwrap();
    let cases = [
        ("height = \"small.png\"", "map 'height' is 128x128; it must be the size of the exemplar image, 256x256"),
        ("height = \"missing.png\"", "missing.png"),
        ("normal = \"embedded:materials/forest_floor/normal.png\"", "normal_convention"),
        ("uv = \"small.png\"", "built in"),
    ];
    for (line, expected) in cases {
        let cfg = dir.path().join("bad.toml");
        std::fs::write(
            &cfg,
            format!("[[textures]]\nid = \"x\"\nexemplar = \"embedded:materials/forest_floor/albedo.png\"\n[textures.maps]\n{line}\n"),
        )
        .unwrap();
        let out = std::process::Command::new(binary())
            .args(["render", "--config", cfg.to_str().unwrap(), "--texture", "x", "--x", "0", "--y", "0"])
            .args(["--output", dir.path().join("o.png").to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{line}: accepted");
        assert!(err.contains(expected), "{line}: error does not say '{expected}': {err}");
    }
}

/// World positions of a relief GLB's vertices (node translation + local), with its grid side.
async fn relief(s: &Server, path: &str) -> (usize, Vec<[f32; 3]>) {
    let (status, bytes) = s.get_bytes(path).await;
    assert_eq!(status, 200, "{path}: {}", String::from_utf8_lossy(&bytes));
    let (json, bin) = parse_glb(&bytes);
    let t: Vec<f32> =
        json["nodes"][0]["translation"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap() as f32).collect();
    let prim = &json["meshes"][0]["primitives"][0];
    let pos = f32s(&json, &bin, prim["attributes"]["POSITION"].as_u64().unwrap() as usize);
    let world: Vec<[f32; 3]> = pos.chunks(3).map(|p| [p[0] + t[0], p[1] + t[1], p[2] + t[2]]).collect();
    assert!(prim["attributes"]["TANGENT"].is_u64(), "a relief with a normal map has tangents");
    // The grid's side, from the vertices besides the skirts (`n² + 4n`).
    let n = (1..=257).find(|n| n * n + 4 * n == world.len()).unwrap_or(0);
    (n, world)
}

#[tokio::test]
async fn relief_meshes_are_displaced_by_the_height_map_and_neighbours_share_their_edges() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let q = "relief=12&seed=3";
    let (n, a) = relief(&s, &format!("/gltf/flagstones/8/3/-2.glb?{q}")).await;
    let (_, right) = relief(&s, &format!("/gltf/flagstones/8/4/-2.glb?{q}")).await;
    let (_, below) = relief(&s, &format!("/gltf/flagstones/8/3/-1.glb?{q}")).await;
    assert_eq!(n, 33, "a vertex per corner of 8-texel cells, exactly over the tile");
    for k in 0..n {
        // A's last column is its right neighbour's first, A's last row its lower neighbour's first.
        assert_eq!(a[k * n + n - 1], right[k * n], "shared vertical edge, row {k}");
        assert_eq!(a[(n - 1) * n + k], below[k], "shared horizontal edge, column {k}");
    }
    // Heights are the height tile's 8×8 texels around each corner, 12 texels for white.
    let height = s.image("/tiles/flagstones/8/3/-2.png?seed=3&map=height").await;
    for (i, j) in [(1u32, 1u32), (2, 25), (31, 31), (16, 3)] {
        let v = a[j as usize * n + i as usize];
        assert_eq!([v[0], v[2]], [768.0 + 8.0 * i as f32, -512.0 + 8.0 * j as f32]);
        let sum: u32 = (8 * j - 4..8 * j + 4)
            .flat_map(|y| (8 * i - 4..8 * i + 4).map(move |x| (x, y)))
            .map(|(x, y)| height.get_pixel(x, y).0[0] as u32)
            .sum();
        let h = 12.0 * sum as f32 / (255.0 * 64.0);
        assert!((v[1] - h).abs() < 1e-4, "vertex ({i},{j}) at {} not {h}", v[1]);
    }
    assert!(a[..n * n].iter().map(|v| v[1]).fold(0.0, f32::max) > 5.0, "the relief rises");
    // The skirts hang below the ground along every edge.
    assert_eq!(a.len(), n * n + 4 * n);
    assert!(a[n * n..].iter().all(|v| v[1] == -0.5), "skirt vertices at the skirt's foot");
    // Where a mesh has no relief, or a texture no height: clear errors.
    for (path, code) in [
        ("/gltf/flagstones/8/3/-2.gltf?relief=12", "invalid_parameter"),
        ("/gltf/flagstones/patch.glb?z=8&x=0&y=0&tiles=2&relief=12", "invalid_parameter"),
        ("/x3d/flagstones/8/3/-2.x3d?relief=12", "invalid_parameter"),
        ("/gltf/flagstones/8/3/-2.glb?relief=0", "invalid_parameter"),
        ("/gltf/flagstones/8/3/-2.glb?relief=1e9", "invalid_parameter"),
    ] {
        assert_error(&s, path, 400, code).await;
    }
    // Every mode has a height map to displace by, umbrella patches included.
    let (n, _) = relief(&s, "/gltf/flagstones/8/3/-2.glb?relief=12&mode=umbrella").await;
    assert_eq!(n, 33);
}

#[tokio::test]
async fn roughness_and_metallic_maps_are_packed_into_the_gltf_metallic_roughness_texture() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::rough_metal_config(dir.path());
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let (status, bytes) = s.get_bytes("/gltf/rough/8/-2/5.glb?seed=4").await;
    assert_eq!(status, 200);
    let (json, bin) = parse_glb(&bytes);
    let pbr = &json["materials"][0]["pbrMetallicRoughness"];
    assert_eq!((pbr["metallicFactor"].as_f64(), pbr["roughnessFactor"].as_f64()), (Some(1.0), Some(1.0)));
    let texture = pbr["metallicRoughnessTexture"]["index"].as_u64().unwrap() as usize;
    let image = json["textures"][texture]["source"].as_u64().unwrap() as usize;
    let view = &json["bufferViews"][json["images"][image]["bufferView"].as_u64().unwrap() as usize];
    let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
    let packed = image::load_from_memory(&bin[o..o + l]).unwrap().to_rgb8();
    let window =
        |map: &str| format!("/windows/rough.png?x={}&y={}&w=288&h=288&z=8&seed=4&map={map}", -512 - 16, 1280 - 16);
    let (rough, metal) = (s.image(&window("roughness")).await, s.image(&window("metallic")).await);
    for (x, y, p) in packed.enumerate_pixels() {
        assert_eq!(p.0, [255, rough.get_pixel(x, y).0[0], metal.get_pixel(x, y).0[0]], "packed texel ({x},{y})");
    }
}

/// An embedded material file's bytes, as the repository holds it.
fn material_file(material: &str, map: &str) -> Vec<u8> {
    let path = format!("{}/../config/exemplars/materials/{material}/{map}.png", env!("CARGO_MANIFEST_DIR"));
    std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// POST a multipart upload of the forest floor's colour with `maps` (part name, bytes) and
/// `fields`: status and JSON body.
async fn upload_material(
    s: &Server,
    token: &str,
    fields: &[(&str, &str)],
    maps: &[(&str, Vec<u8>)],
) -> (u16, serde_json::Value) {
    let part = |b: Vec<u8>| reqwest::multipart::Part::bytes(b).file_name("m.png").mime_str("image/png").unwrap();
    let mut form = reqwest::multipart::Form::new().part("image", part(material_file("forest_floor", "albedo")));
    for (k, v) in fields {
        form = form.text(k.to_string(), v.to_string());
    }
    for (name, bytes) in maps {
        form = form.part(name.to_string(), part(bytes.clone()));
    }
    let r = s.client.post(s.url("/admin/textures")).bearer_auth(token).multipart(form).send().await.unwrap();
    let status = r.status().as_u16();
    (status, r.json().await.unwrap_or(serde_json::Value::Null))
}

/// Wait until the texture at `location` is analysed (or fail after a minute).
async fn ready(s: &Server, location: &str) {
    for _ in 0..600 {
        if s.json(location).await["status"] == "ready" {
            return;
        }
        tokio::time::sleep(std::time::Duration::from_millis(100)).await;
    }
    panic!("{location} was not analysed within a minute");
}

fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| d.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

#[tokio::test]
async fn uploads_carry_maps_that_serve_as_a_configured_material_does() {
    let (dir, data) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let cfg = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let token = "materials-admin-token-0123456789";
    let start = || {
        Server::builder()
            .args(&["--config", cfg.to_str().unwrap()])
            .data_dir(data.path())
            .env("TEXTILE_ADMIN_TOKEN", token)
            .start()
    };
    let s = start();
    let uploads = data.path().join("uploads");
    let (normal, height) = (material_file("forest_floor", "normal"), material_file("forest_floor", "height"));
    let small = {
        let mut buf = std::io::Cursor::new(Vec::new());
        image::RgbImage::from_pixel(100, 100, image::Rgb([9, 99, 199]))
            .write_to(&mut buf, image::ImageFormat::Png)
            .unwrap();
        buf.into_inner()
    };
    // An all-black "normal map" of the exemplar's size: every texel decodes into the surface.
    let black = {
        let side = image::load_from_memory(&normal).unwrap().width();
        let mut buf = std::io::Cursor::new(Vec::new());
        image::RgbImage::new(side, side).write_to(&mut buf, image::ImageFormat::Png).unwrap();
        buf.into_inner()
    };
    // Refused: each with a 400 naming the problem, and nothing stored.
    type Refusal<'a> = (&'a [(&'a str, &'a str)], Vec<(&'a str, Vec<u8>)>, &'a str, &'a str);
    let refusals: [Refusal; 6] = [
        (
            &[("id", "mat"), ("normal_convention", "opengl")],
            vec![("map.normal", black.clone())],
            "invalid_map",
            "into the surface",
        ),
        (&[("id", "mat")], vec![("map.normal", normal.clone())], "invalid_upload", "normal_convention"),
        (
            &[("id", "mat"), ("normal_convention", "opengl")],
            vec![("map.normal", small.clone())],
            "invalid_map",
            "normal",
        ),
        (&[("id", "mat")], vec![("map.height", b"not an image".to_vec())], "invalid_map", "height"),
        (&[("id", "mat")], vec![("map.uv", height.clone())], "invalid_map", "uv"),
        (
            &[("id", "mat"), ("normal_convention", "sideways")],
            vec![("map.normal", normal.clone())],
            "invalid_upload",
            "sideways",
        ),
    ];
    for (fields, maps, code, names) in refusals {
        let (status, body) = upload_material(&s, token, fields, &maps).await;
        assert_eq!((status, body["error"].as_str()), (400, Some(code)), "{fields:?}: {body}");
        let message = body["message"].as_str().unwrap_or_default();
        assert!(message.contains(names), "{fields:?}: '{message}' does not name {names}");
        assert!(files_in(&uploads).is_empty(), "{fields:?} left {:?}", files_in(&uploads));
        common::assert_error(&s, "/textures/mat", 404, "unknown_texture").await;
    }
    // Accepted: the forest floor's colour, normals and height, as the configured forest has them.
    let maps = [("map.normal", normal.clone()), ("map.height", height.clone())];
    let (status, body) = upload_material(&s, token, &[("id", "mat"), ("normal_convention", "opengl")], &maps).await;
    assert_eq!(status, 202, "{body}");
    ready(&s, "/textures/mat").await;
    let meta = s.json("/textures/mat").await;
    let names: Vec<&str> = meta["maps"].as_array().unwrap().iter().map(|m| m["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["albedo", "height", "normal", "uv"]);
    assert_eq!(files_in(&uploads), ["mat.map.height.png", "mat.map.normal.png", "mat.png", "mat.toml"]);
    let mut served = Vec::new();
    for (map, mode) in [("normal", "synth"), ("height", "synth"), ("normal", "umbrella"), ("uv", "tiling")] {
        let q = format!("7/-2.png?seed=4&mode={mode}&map={map}");
        let (status, mine) = s.get_bytes(&format!("/tiles/mat/8/{q}")).await;
        let (_, theirs) = s.get_bytes(&format!("/tiles/forest/8/{q}")).await;
        assert_eq!(status, 200);
        assert!(mine == theirs, "{map} in {mode}: the upload's tile differs from the configured material's");
        served.push(mine);
    }
    drop(s);
    // A restart serves the upload's maps with the same bytes; deleting it removes every file.
    let s = start();
    ready(&s, "/textures/mat").await;
    let (_, again) = s.get_bytes("/tiles/mat/8/7/-2.png?seed=4&mode=synth&map=normal").await;
    assert!(again == served[0], "the restarted server's normal tile differs");
    let r = s.client.delete(s.url("/admin/textures/mat")).bearer_auth(token).send().await.unwrap();
    assert_eq!(r.status(), 204);
    assert!(files_in(&uploads).is_empty(), "{:?}", files_in(&uploads));
}

#[tokio::test]
async fn gltf_documents_reference_the_same_material_images_the_glb_embeds() {
    let dir = tempfile::tempdir().unwrap();
    // Both embedded materials, and the forest floor with roughness and metallic maps.
    let both = materials_config(dir.path(), "embedded:materials/forest_floor/height.png");
    let rough = std::fs::read_to_string(common::rough_metal_config(dir.path())).unwrap();
    let text = std::fs::read_to_string(&both).unwrap() + "\n" + &rough;
    std::fs::write(&both, text).unwrap();
    let s = Server::builder().args(&["--config", both.to_str().unwrap()]).start();
    for (id, slots) in [
        ("flagstones", vec![("normalTexture", "normal"), ("specular", "specular")]),
        ("rough", vec![("metallicRoughnessTexture", "metallic_roughness")]),
    ] {
        let base = format!("/gltf/{id}/8/3/-2");
        let doc = s.json(&format!("{base}.gltf?seed=6")).await;
        let (status, glb) = s.get_bytes(&format!("{base}.glb?seed=6")).await;
        assert_eq!(status, 200);
        let (embedded, bin) = parse_glb(&glb);
        // The same material, slot for slot; its images by URI beside the document.
        assert_eq!(doc["materials"], embedded["materials"], "{id}");
        assert_eq!(
            doc["meshes"][0]["primitives"][0]["attributes"].get("TANGENT").is_some(),
            embedded["meshes"][0]["primitives"][0]["attributes"].get("TANGENT").is_some()
        );
        let images = doc["images"].as_array().unwrap();
        assert_eq!(images.len(), 1 + slots.len(), "{id}: {doc}");
        for (i, image) in images.iter().enumerate() {
            let uri = image["uri"].as_str().unwrap();
            let (status, bytes) = s.get_bytes(&format!("/gltf/{id}/8/3/{uri}")).await;
            assert_eq!(status, 200, "{id}: {uri}");
            let view = &embedded["bufferViews"][embedded["images"][i]["bufferView"].as_u64().unwrap() as usize];
            let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
            assert!(bytes == bin[o..o + l], "{id}: image {i} ({uri}) differs from the GLB's");
        }
        for (key, _) in &slots {
            assert!(doc.to_string().contains(key), "{id}: no {key} in {doc}");
        }
    }
    // X3D: the GLB's colour and normal images in a PhysicalMaterial, with its tangent space.
    let x3d = s.client.get(s.url("/x3d/flagstones/8/3/-2.x3d?seed=6")).send().await.unwrap().text().await.unwrap();
    let doc = roxmltree::Document::parse(&x3d).expect("well-formed XML");
    let textures: Vec<(&str, &str)> = doc
        .descendants()
        .filter(|n| n.has_tag_name("ImageTexture"))
        .map(|n| (n.attribute("containerField").unwrap_or_default(), n.attribute("url").unwrap().trim_matches('"')))
        .collect();
    assert_eq!(textures.iter().map(|t| t.0).collect::<Vec<_>>(), ["baseTexture", "normalTexture"], "{x3d}");
    let (_, glb) = s.get_bytes("/gltf/flagstones/8/3/-2.glb?seed=6").await;
    let (embedded, bin) = parse_glb(&glb);
    for (i, (field, url)) in textures.iter().enumerate() {
        let (status, bytes) = s.get_bytes(url.strip_prefix(&s.base).expect("absolute URL")).await;
        assert_eq!(status, 200, "{field}: {url}");
        let view = &embedded["bufferViews"][embedded["images"][i]["bufferView"].as_u64().unwrap() as usize];
        let (o, l) = (view["byteOffset"].as_u64().unwrap() as usize, view["byteLength"].as_u64().unwrap() as usize);
        assert!(bytes == bin[o..o + l], "X3D {field} differs from the GLB's image {i}");
    }
    let tangent = doc.descendants().find(|n| n.has_tag_name("Tangent")).expect("a Tangent node");
    assert_eq!(tangent.attribute("vector"), Some("1 0 0 1, 1 0 0 1, 1 0 0 1, 1 0 0 1"));
    assert_eq!(doc.root_element().attribute("version"), Some("4.0"));
    let patch = s.client.get(s.url("/x3d/flagstones/patch.x3d?z=8&x=0&y=0&tiles=2")).send().await.unwrap();
    let patch = patch.text().await.unwrap();
    assert_eq!(patch.matches("<PhysicalMaterial").count(), 4, "{patch}");
    // A slot the texture has no map for, or no slot at all.
    use base64::Engine;
    let token = |q: &str| base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(q);
    assert_error(&s, &format!("/gltf/rough/8/3/-2.{}.png", token("seed=6&slot=normal")), 400, "invalid_map").await;
    assert_error(&s, &format!("/gltf/flagstones/8/3/-2.{}.png", token("slot=albedo")), 400, "invalid_map").await;
    assert_error(&s, "/gltf/forest/8/0/0.png?slot=occlusion", 400, "invalid_map").await;
}
