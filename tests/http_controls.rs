//! Controls of synthesis (design note §1.9), through the real binary: a texture's randomness
//! mask (`randomness_mask`, R_E) configured beside the exemplar — black keeps the exemplar as it
//! is, so an all-black mask serves the tiling; the mask is part of the texture's identity
//! (ETags, metadata); a mask of the wrong size is a clear configuration error — and a request's
//! `controls` (R_S: noise and strokes; dropped features) in the URL: canonical, stitched,
//! refused when malformed, a feature's disc the exemplar itself, and the same from
//! `textile render --controls`; a near-regular texture's lattice (the built-in corkboard):
//! shown in its metadata, part of its identity, the same as `textile render --lattice`, and a
//! lattice that does not divide the exemplar a clear configuration error.

mod common;

use common::{binary, Server};

/// Write a 128×128 greyscale mask (`value(x, y)`) into `dir` as `name`.
fn mask(dir: &std::path::Path, name: &str, side: u32, value: impl Fn(u32, u32) -> u8) {
    image::GrayImage::from_fn(side, side, |x, y| image::Luma([value(x, y)])).save(dir.join(name)).unwrap();
}

#[tokio::test]
async fn a_randomness_mask_keeps_black_parts_of_the_exemplar_and_is_part_of_the_identity() {
    let dir = tempfile::tempdir().unwrap();
    mask(dir.path(), "black.png", 128, |_, _| 0);
    mask(dir.path(), "half.png", 128, |x, _| if x < 64 { 0 } else { 255 });
    mask(dir.path(), "small.png", 64, |_, _| 0);
    let texture =
        |id: &str, extra: &str| format!("[[textures]]\nid = \"{id}\"\nexemplar = \"embedded:gravel.png\"\n{extra}\n\n");
    let cfg = dir.path().join("textile.toml");
    let text = texture("plain", "")
        + &texture("black", "randomness_mask = \"black.png\"\ntoroidal = \"true\"")
        + &texture("half", "randomness_mask = \"half.png\"");
    std::fs::write(&cfg, text).unwrap();
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    assert_eq!(s.json("/textures/half").await["exemplar"]["randomness_mask"], true);
    assert_eq!(s.json("/textures/plain").await["exemplar"]["randomness_mask"], false);
    // All black: nothing moves, the synthesis of a toroidal exemplar is the exemplar tiled.
    for (z, x, y) in [(7, -3, 2), (6, 1, 1)] {
        let synth = s.image(&format!("/tiles/black/{z}/{x}/{y}.png")).await;
        let tiling = s.image(&format!("/tiles/black/{z}/{x}/{y}.png?mode=tiling")).await;
        assert!(synth == tiling, "z {z}: an all-black mask differs from the tiling");
    }
    // A mask changes the texture (and its ETags); the cheap modes are unaffected by it.
    let (a, b) = (s.get("/tiles/plain/7/0/0.png").await, s.get("/tiles/half/7/0/0.png").await);
    assert_ne!(a.headers()["etag"], b.headers()["etag"]);
    assert_ne!(a.bytes().await.unwrap(), b.bytes().await.unwrap());
    assert_eq!(
        s.get_bytes("/tiles/plain/7/0/0.png?mode=mosaic").await.1,
        s.get_bytes("/tiles/half/7/0/0.png?mode=mosaic").await.1
    );
    // Windows are still the same pixels as the tiles they cover.
    let mut stitched = image::RgbImage::new(512, 256);
    for i in 0..2 {
        let tile = s.image(&format!("/tiles/half/7/{}/-1.png", 5 + i)).await;
        common::paste(&mut stitched, &tile, 256 * i, 0);
    }
    assert!(stitched == s.image("/windows/half.png?x=1280&y=-256&w=512&h=256").await);
    // A mask that is not the exemplar's size is refused, naming it.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, texture("x", "randomness_mask = \"small.png\"")).unwrap();
    let out = dir.path().join("x.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--config", bad.to_str().unwrap(), "--texture", "x", "--x", "0", "--y", "0"])
        .args(["-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("randomness_mask") && err.contains("128x128"), "{err}");
    assert!(!out.exists());
}

#[tokio::test]
async fn a_lattice_is_configured_served_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let s = Server::builder().start();
    let meta = s.json("/textures/corkboard").await;
    let lattice = &meta["exemplar"]["lattice"];
    assert_eq!((lattice["kind"].as_str(), lattice["origin"].as_str()), (Some("grid"), Some("given")), "{meta}");
    // [dy, dx], as the configuration and `structure` give vectors.
    assert_eq!(lattice["basis"], serde_json::json!([[32.0, 0.0], [0.0, 64.0]]), "{meta}");
    assert_eq!(meta["exemplar"]["toroidal"], true);
    assert_eq!(s.json("/textures/gravel").await["exemplar"]["lattice"], serde_json::Value::Null);
    // Tiles under the lattice are one window, and what `textile render --lattice` makes of the
    // same exemplar file.
    let mut stitched = image::RgbImage::new(512, 256);
    for i in 0..2 {
        let tile = s.image(&format!("/tiles/corkboard/7/{}/3.png?seed=4", i - 1)).await;
        common::paste(&mut stitched, &tile, 256 * i as u32, 0);
    }
    assert!(stitched == s.image("/windows/corkboard.png?x=-256&y=768&w=512&h=256&seed=4").await);
    let exemplar = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/corkboard.png");
    let render = |lattice: Option<&str>, name: &str| {
        let out = dir.path().join(name);
        let mut cmd = std::process::Command::new(binary());
        cmd.args(["render", "--exemplar", exemplar.to_str().unwrap(), "--x", "0", "--y", "3", "--seed", "4"]);
        if let Some(l) = lattice {
            cmd.args(["--lattice", l]);
        }
        let run = cmd.args(["-o", out.to_str().unwrap()]).output().unwrap();
        (run, out)
    };
    let (run, out) = render(Some("2,4"), "lattice.png");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let served = s.image("/tiles/corkboard/7/0/3.png?seed=4").await;
    assert!(image::open(&out).unwrap().to_rgb8() == served, "render --lattice differs from the served tile");
    let (run, out) = render(None, "free.png");
    assert!(run.status.success());
    assert!(image::open(&out).unwrap().to_rgb8() != served, "without its lattice the texture is another");
    // A lattice that does not divide the 128² exemplar: a clear error naming it, nothing written.
    let (run, out) = render(Some("3,4"), "bad.png");
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("lattice") && err.contains("3x4"), "{err}");
    assert!(!out.exists());
    let bad = dir.path().join("bad.toml");
    let text = format!("[[textures]]\nid = \"x\"\nexemplar = {:?}\nlattice = [2, 6]\n", exemplar.to_str().unwrap());
    std::fs::write(&bad, text).unwrap();
    let run = std::process::Command::new(binary())
        .args(["render", "--config", bad.to_str().unwrap(), "--texture", "x", "--x", "0", "--y", "0"])
        .args(["-o", dir.path().join("x.png").to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("lattice") && err.contains("2x6"), "{err}");
}

fn encode(json: &str) -> String {
    use base64::Engine;
    base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(json)
}

#[tokio::test]
async fn request_controls_modulate_randomness_in_the_url_and_in_the_cli() {
    let s = Server::builder().start();
    let spec = &s.json("/textures/gravel").await["parameters"]["controls"];
    assert_eq!(spec["type"], "text", "{spec}");
    // A stroke straddling the border of tiles (0,0) and (1,0), over noise.
    let json = r#"{"noise": {"scale": 64, "range": [0.2, 1]}, "strokes": [{"at": [256, 100], "radius": 30, "soft": 20, "value": 0}]}"#;
    let same =
        r#"{"strokes":[{"value":0.0,"soft":20,"radius":30,"at":[256,100]}],"noise":{"range":[0.20,1.0],"scale":64}}"#;
    let (c, c2) = (encode(json), encode(same));
    let plain = s.get("/tiles/gravel/7/0/0.png").await;
    let with = s.get(&format!("/tiles/gravel/7/0/0.png?controls={c}")).await;
    assert_eq!(with.status(), 200);
    let etag = with.headers()["etag"].clone();
    assert_ne!(plain.headers()["etag"], etag);
    let bytes = with.bytes().await.unwrap();
    assert_ne!(plain.bytes().await.unwrap(), bytes);
    // The same controls written otherwise are the same request.
    let again = s.get(&format!("/tiles/gravel/7/0/0.png?controls={c2}")).await;
    assert_eq!(again.headers()["etag"], etag);
    assert_eq!(again.bytes().await.unwrap(), bytes);
    // Tiles under the stroke are one window.
    let mut stitched = image::RgbImage::new(512, 256);
    for i in 0..2 {
        let tile = s.image(&format!("/tiles/gravel/7/{i}/0.png?controls={c}")).await;
        common::paste(&mut stitched, &tile, 256 * i, 0);
    }
    assert!(stitched == s.image(&format!("/windows/gravel.png?x=0&y=0&w=512&h=256&controls={c}")).await);
    // Bad controls: 400 naming the parameter.
    for bad in ["%%%".to_string(), encode(r#"{"strokes": 3}"#), "A".repeat(3000)] {
        let r = s.get(&format!("/tiles/gravel/7/0/0.png?controls={bad}")).await;
        assert_eq!(r.status(), 400, "{bad}");
        let body: serde_json::Value = r.json().await.unwrap();
        assert!(body["message"].as_str().unwrap().contains("controls"), "{body}");
    }
    // A feature dropped across the border of two tiles: within its inner radius, the exemplar
    // around its source, texel for texel, on both tiles.
    let ex = s.image("/textures/gravel/exemplar.png").await;
    let f = encode(r#"{"features": [{"at": [256, 60], "source": [64, 64], "inner": 12, "outer": 40}]}"#);
    let tiles = [
        s.image(&format!("/tiles/gravel/7/0/0.png?controls={f}")).await,
        s.image(&format!("/tiles/gravel/7/1/0.png?controls={f}")).await,
    ];
    for dy in -11i64..=11 {
        for dx in -11i64..=11 {
            if dx * dx + dy * dy >= 144 {
                continue;
            }
            let (x, y) = (256 + dx, 60 + dy);
            let got = tiles[(x / 256) as usize].get_pixel((x % 256) as u32, y as u32);
            assert_eq!(got, ex.get_pixel((64 + dx) as u32, (64 + dy) as u32), "({dx}, {dy})");
        }
    }
    // `textile render --controls FILE.json` renders what the server serves.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("c.json"), json).unwrap();
    let out = dir.path().join("t.png");
    let data = common::shared_data_dir();
    let run = std::process::Command::new(binary())
        .args(["render", "--texture", "gravel", "--x", "0", "--y", "0", "--data-dir", data.to_str().unwrap()])
        .args(["--controls", dir.path().join("c.json").to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(std::fs::read(&out).unwrap(), bytes.to_vec());
}
