//! Landscapes over HTTP: several textures composed by a splat and a blend, served like a
//! texture. Deep inside one layer a tile is that layer's own tile, byte for byte; tiles join
//! into windows; the height blend lets the taller material through; the catalogue, the
//! description and TileJSON describe it; bad configurations stop the start-up naming the field.

mod common;

use std::path::Path;
use std::process::Command;

use common::{binary, Server};

/// Splat palette colours of the two layers.
const A: [u8; 3] = [255, 0, 0];
const B: [u8; 3] = [0, 0, 255];

/// A painted splat: 16 × 2 pixels of 128 texels, gravel (A) left of texel 1024, grass (B) right.
fn splat_png(dir: &Path) {
    let img = image::RgbImage::from_fn(16, 2, |x, _| image::Rgb(if x < 8 { A } else { B }));
    img.save(dir.join("splat.png")).expect("splat");
}

fn landscape(id: &str, blend: &str, splat: &str) -> String {
    format!(
        "[[landscapes]]\nid = \"{id}\"\n\n[[landscapes.layers]]\ntexture = \"gravel\"\ncolour = \"#ff0000\"\n\n\
         [[landscapes.layers]]\ntexture = \"grass\"\ncolour = \"#0000ff\"\n\n[landscapes.splat]\n{splat}\n\n\
         [landscapes.blend]\nkind = \"{blend}\"\ndepth = 0.1\n\n"
    )
}

const PAINTED: &str = "kind = \"image\"\nimage = \"splat.png\"\ntexels_per_pixel = 128\noutside = \"repeat\"";

/// A configuration of gravel and grass with two landscapes of them (height and linear blends)
/// and a third whose painted splat is shown once.
fn config(dir: &Path) -> std::path::PathBuf {
    splat_png(dir);
    let textures = "[[textures]]\nid = \"gravel\"\nexemplar = \"embedded:gravel.png\"\n\n\
                    [[textures]]\nid = \"grass\"\nexemplar = \"embedded:grass.png\"\n\n";
    let once = "kind = \"image\"\nimage = \"splat.png\"\ntexels_per_pixel = 128\noutside = \"gravel\"\nwarp = 20";
    let text = format!(
        "{textures}{}{}{}",
        landscape("ground", "height", PAINTED),
        landscape("fade", "linear", PAINTED),
        landscape("island", "height", once)
    );
    let path = dir.join("textile.toml");
    std::fs::write(&path, text).expect("config");
    path
}

fn start(dir: &Path, extra: &[&str]) -> Server {
    let cfg = config(dir);
    let mut args = vec!["--config", cfg.to_str().expect("utf-8")];
    args.extend_from_slice(extra);
    Server::builder().args(&args).start()
}

fn luma(p: &image::Rgb<u8>) -> f32 {
    (0.299 * p[0] as f32 + 0.587 * p[1] as f32 + 0.114 * p[2] as f32) / 255.0
}

#[tokio::test]
async fn a_landscape_is_served_like_a_texture_and_its_layers_show_through() {
    let dir = tempfile::tempdir().expect("tmp");
    let s = start(dir.path(), &[]);

    // Exactness: deep inside one layer (texels 64–960 are gravel alone, 1088–1984 grass alone)
    // a tile is that layer's own tile, byte for byte.
    for (x, layer) in [(1, "gravel"), (2, "gravel"), (5, "grass")] {
        let (st, land) = s.get_bytes(&format!("/tiles/ground/7/{x}/0.png")).await;
        let (_, own) = s.get_bytes(&format!("/tiles/{layer}/7/{x}/0.png")).await;
        assert_eq!(st, 200);
        assert!(land == own, "tile 7/{x}/0 of the landscape is {layer}'s own tile");
    }
    // A seed reseeds every layer: still one layer's tile, now under its derived seed.
    let d = s.json("/textures/ground").await;
    assert_eq!(d["kind"], "landscape");
    assert_eq!(d["status"], "ready");
    assert_eq!(d["layers"][0]["texture"], "gravel");
    assert_eq!(d["splat"]["kind"], "image");
    assert_eq!(d["blend"]["kind"], "height");

    // Seams: 2×2 tiles across the transition are the 512² window.
    let window = s.image("/windows/ground.png?z=7&x=768&y=0&w=512&h=512").await;
    for (tx, ty) in [(3u32, 0u32), (4, 0), (3, 1), (4, 1)] {
        let tile = s.image(&format!("/tiles/ground/7/{tx}/{ty}.png")).await;
        for (x, y, p) in tile.enumerate_pixels() {
            assert_eq!(*p, *window.get_pixel(256 * (tx - 3) + x, 256 * ty + y), "tile {tx},{ty} at {x},{y}");
        }
    }

    // Blend: in the transition band, where the splat mixes the two, the layer whose height
    // (luma: neither has a height map) is higher by more than the depth gives the pixel under
    // the height blend; the linear blend mixes them instead.
    let splat = s.image("/tiles/ground/7/3/0.png?map=splat").await;
    let (gravel, grass) = (s.image("/tiles/gravel/7/3/0.png").await, s.image("/tiles/grass/7/3/0.png").await);
    let (height, linear) = (s.image("/tiles/ground/7/3/0.png").await, s.image("/tiles/fade/7/3/0.png").await);
    let supplied = |img: &image::RgbImage| {
        let (mut band, mut higher) = (0, 0);
        for (x, y, p) in img.enumerate_pixels() {
            let wa = splat.get_pixel(x, y)[0] as f32 / 255.0;
            let (a, b) = (gravel.get_pixel(x, y), grass.get_pixel(x, y));
            let (ha, hb) = (luma(a), luma(b));
            if !(0.25..=0.75).contains(&wa) || (ha - hb).abs() <= 0.1 + (2.0 * wa - 1.0).abs() {
                continue;
            }
            band += 1;
            let top = if ha > hb { a } else { b };
            let other = if ha > hb { b } else { a };
            let d = |q: &image::Rgb<u8>| (0..3).map(|c| (q[c] as i32 - p[c] as i32).abs()).sum::<i32>();
            if d(top) < d(other) {
                higher += 1;
            }
        }
        assert!(band > 500, "the band holds {band} pixels");
        higher as f64 / band as f64
    };
    let (h, l) = (supplied(&height), supplied(&linear));
    eprintln!("transition band: the higher layer gives {h:.3} of the pixels (height), {l:.3} (linear)");
    assert!(h >= 0.9, "height blend: the higher layer gives {h:.3} of the band's pixels");
    assert!(l < 0.75, "linear blend: {l:.3}");

    // The height map is the blended one: deep inside a layer, that layer's luma.
    let hm = s.image("/tiles/ground/7/5/0.png?map=height").await;
    let grass5 = s.image("/tiles/grass/7/5/0.png").await;
    let p = grass5.get_pixel(10, 10);
    assert!((hm.get_pixel(10, 10)[0] as f32 - 255.0 * luma(p)).abs() <= 1.0);

    // Catalogue and TileJSON.
    let cat = s.json("/catalog").await;
    let ground = cat["landscapes"].as_array().expect("landscapes").iter().find(|l| l["id"] == "ground").cloned();
    assert_eq!(ground.expect("listed")["layers"], serde_json::json!(["gravel", "grass"]));
    let tj = s.json("/tiles/ground/tilejson.json").await;
    assert_eq!(tj["maxzoom"], 10);
    assert!(tj["tiles"][0].as_str().expect("tiles").contains("world=128"));
    let once = s.json("/tiles/island/tilejson.json").await;
    assert!(!once["tiles"][0].as_str().expect("tiles").contains("world="), "a splat shown once does not wrap");

    // Errors name the problem.
    for (path, status, what) in [
        ("/textures/ground/exemplar.png", 404, "no exemplar"),
        ("/tiles/ground/7/0/0.png?mode=tiling", 400, "configuration"),
        ("/tiles/ground/7/0/0.png?map=uv", 400, "no such map"),
        ("/tiles/ground/7/0/0.jpg?map=splat", 400, "PNG only"),
        ("/tiles/island/7/0/0.png?world=64", 400, "does not repeat"),
        ("/tiles/ground/7/0/0.png?world=4", 400, "divide"),
        ("/tiles/ground/11/0/0.png", 400, "outside"),
        ("/gltf/ground/7/0/0.glb?mode=synth", 400, "configuration"),
    ] {
        let (st, body) = s.get_bytes(path).await;
        let body = String::from_utf8_lossy(&body);
        assert_eq!(st, status, "{path}: {body}");
        assert!(body.contains(what), "{path}: {body}");
    }
    // A period the splat divides is served, and repeats.
    let (a, b) = (
        s.get_bytes("/tiles/ground/7/1/0.png?world=8").await.1,
        s.get_bytes("/tiles/ground/7/9/0.png?world=8").await.1,
    );
    assert!(a == b, "world=8 repeats every 8 tiles");
}

#[tokio::test]
async fn landscape_bytes_are_the_same_across_processes_threads_and_orders() {
    let dir = tempfile::tempdir().expect("tmp");
    let paths = ["/tiles/ground/7/3/0.png", "/tiles/ground/6/1/0.png?seed=5", "/tiles/ground/7/4/1@2x.webp"];
    let one = start(dir.path(), &["--workers", "1"]);
    let mut first = Vec::new();
    for p in paths {
        first.push(one.get_bytes(p).await);
    }
    drop(one);
    let two = start(dir.path(), &["--workers", "2"]);
    for (i, p) in paths.iter().enumerate().rev() {
        let got = two.get_bytes(p).await;
        assert_eq!(got.0, 200, "{p}");
        assert!(got == first[i], "{p}: the same bytes");
    }
}

#[test]
fn bad_landscapes_stop_the_start_naming_the_field() {
    let dir = tempfile::tempdir().expect("tmp");
    splat_png(dir.path());
    std::fs::write(dir.path().join("broken.png"), b"\x89PNG\r\n\x1a\nnot really").expect("write");
    image::RgbImage::new(4097, 1).save(dir.path().join("huge.png")).expect("huge");
    let textures = "[[textures]]\nid = \"gravel\"\nexemplar = \"embedded:gravel.png\"\n\n\
                    [[textures]]\nid = \"grass\"\nexemplar = \"embedded:grass.png\"\n\n";
    let cases = [
        (landscape("l", "height", PAINTED).replace("\"grass\"", "\"moss\""), "landscapes[0].layers[1].texture"),
        (landscape("gravel", "height", PAINTED), "landscapes[0].id"),
        (
            format!(
                "{}{}",
                landscape("l", "height", PAINTED),
                landscape("m", "height", PAINTED).replace("\"grass\"", "\"l\"")
            ),
            "is a landscape",
        ),
        (landscape("l", "height", PAINTED).replace("colour = \"#0000ff\"", "scale = 9"), "layers[1].scale"),
        (landscape("l", "height", &PAINTED.replace("splat.png", "broken.png")), "not a decodable PNG"),
        (landscape("l", "height", &PAINTED.replace("splat.png", "huge.png")), "4096"),
        (landscape("l", "cubic", PAINTED), "blend.kind"),
    ];
    for (text, what) in cases {
        let cfg = dir.path().join("bad.toml");
        std::fs::write(&cfg, format!("{textures}{text}")).expect("write");
        let out = Command::new("timeout")
            .args(["60", binary(), "serve", "--config", cfg.to_str().expect("utf-8"), "--bind", "127.0.0.1:0"])
            .arg("--data-dir")
            .arg(dir.path().join("data"))
            .output()
            .expect("run");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{what}: started");
        assert!(err.contains(what), "expected '{what}' in: {err}");
    }
}

#[tokio::test]
async fn render_writes_the_landscape_tile_the_server_serves() {
    let dir = tempfile::tempdir().expect("tmp");
    let s = start(dir.path(), &[]);
    let cfg = dir.path().join("textile.toml");
    let data = common::shared_data_dir();
    for (args, path) in [
        (vec!["--z", "7", "--x", "3", "--y", "0"], "/tiles/ground/7/3/0.png"),
        (
            vec!["--z", "6", "--x", "1", "--y", "0", "--seed", "9", "--map", "height"],
            "/tiles/ground/6/1/0.png?seed=9&map=height",
        ),
    ] {
        let out = dir.path().join("tile.png");
        let run = Command::new(binary())
            .args(["render", "--config", cfg.to_str().expect("utf-8"), "--texture", "ground", "-o"])
            .arg(&out)
            .arg("--data-dir")
            .arg(&data)
            .args(&args)
            .output()
            .expect("render");
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let (_, served) = s.get_bytes(path).await;
        assert!(std::fs::read(&out).expect("written") == served, "render {args:?} writes what {path} serves");
    }
}

/// Mean |a − b| per channel, in 1/255, between a tile and its four children box-filtered 2×2.
async fn zoom_error(s: &Server, id: &str, z: u32, x: u32, y: u32) -> f64 {
    let parent = s.image(&format!("/tiles/{id}/{z}/{x}/{y}.png")).await;
    let mut children = image::RgbImage::new(512, 512);
    for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let c = s.image(&format!("/tiles/{id}/{}/{}/{}.png", z + 1, 2 * x + dx, 2 * y + dy)).await;
        common::paste(&mut children, &c, 256 * dx, 256 * dy);
    }
    let mut sum = 0.0;
    for (px, py, p) in parent.enumerate_pixels() {
        for c in 0..3 {
            let mean: f64 = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .map(|(u, v)| children.get_pixel(2 * px + u, 2 * py + v)[c] as f64)
                .sum::<f64>()
                / 4.0;
            sum += (p[c] as f64 - mean).abs();
        }
    }
    sum / (3.0 * 256.0 * 256.0)
}

#[tokio::test]
async fn a_zoomed_out_landscape_is_as_close_to_its_native_tiles_as_its_layers_are() {
    let dir = tempfile::tempdir().expect("tmp");
    let s = start(dir.path(), &[]);
    // Tiles one step out across the transition (texels 512–1535 at native zoom 7).
    for x in [1, 2] {
        let land = zoom_error(&s, "ground", 6, x, 0).await;
        let gravel = zoom_error(&s, "gravel", 6, x, 0).await;
        let grass = zoom_error(&s, "grass", 6, x, 0).await;
        eprintln!("zoom 6/{x}/0 against its children: landscape {land:.2}, gravel {gravel:.2}, grass {grass:.2}");
        assert!(land <= gravel.max(grass) * 1.15 + 0.5, "landscape {land:.2} vs layers {gravel:.2}, {grass:.2}");
    }
}
