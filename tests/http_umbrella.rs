//! `mode=umbrella` through the real binary: tiles are the same pixels as windows over them, at
//! native zoom, zoomed out and magnified; bytes are identical across processes and thread
//! counts and equal `textile render`'s; parameters are validated with 400s naming them;
//! `textile render --debug-umbrellas` draws the extraction and `textile info` reports it; the
//! extraction is stored beside the analysis; a hand-made set in the configuration is served.

mod common;

use common::{assert_error, binary, paste, Server};

#[tokio::test]
async fn umbrella_tiles_equal_windows_and_processes_agree() {
    let a = Server::builder().args(&["--workers", "1"]).start();
    let b = Server::builder().args(&["--workers", "2"]).start();
    let meta = a.json("/textures/gravel").await;
    assert!(meta["modes"].as_array().unwrap().iter().any(|m| m == "umbrella"), "{meta}");
    assert_eq!(meta["parameters"]["background"]["type"], "choice");
    for (z, tx, ty, q) in [
        (7, 0, 0, "mode=umbrella"),
        (7, -3, 5, "mode=umbrella&seed=4&density=150&shadow=0.6&background=tiling"),
        (6, -1, -1, "mode=umbrella&scale=0.5,0.8"),
        (8, 1, 1, "mode=umbrella"),
    ] {
        let mut tiles = image::RgbImage::new(512, 512);
        for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let t = a.image(&format!("/tiles/gravel/{z}/{}/{}.png?{q}", tx + dx, ty + dy)).await;
            paste(&mut tiles, &t, 256 * dx as u32, 256 * dy as u32);
        }
        let win = b.image(&format!("/windows/gravel.png?x={}&y={}&w=512&h=512&z={z}&{q}", 256 * tx, 256 * ty)).await;
        assert!(tiles == win, "z{z} ({tx},{ty}) {q}");
    }
    for p in ["/tiles/gravel/7/9/-9.png?mode=umbrella&seed=2", "/tiles/grass/7/0/0.png?mode=umbrella&world=2"] {
        assert_eq!(a.get_bytes(p).await, b.get_bytes(p).await, "{p}");
    }
    // Different from the other modes, and periodic with world.
    let u = a.get_bytes("/tiles/gravel/7/0/0.png?mode=umbrella").await;
    assert_ne!(u, a.get_bytes("/tiles/gravel/7/0/0.png?mode=mosaic").await);
    assert_eq!(
        a.get_bytes("/tiles/gravel/7/1/1.png?mode=umbrella&world=2").await.1,
        a.get_bytes("/tiles/gravel/7/3/-1.png?mode=umbrella&world=2").await.1
    );
    // Bad parameters: 400 naming them.
    for (q, name) in [
        ("density=1000", "density"),
        ("scale=2,1", "scale"),
        ("shadow=2", "shadow"),
        ("k=0", "k"),
        ("background=sky", "background"),
    ] {
        let path = format!("/tiles/gravel/7/0/0.png?mode=umbrella&{q}");
        assert_error(&a, &path, 400, "invalid_parameter").await;
        let body: serde_json::Value = a.get(&path).await.json().await.unwrap();
        assert!(body["message"].as_str().unwrap_or("").contains(name), "{q}: {body}");
    }
    // The CLI renders the same pixels.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("u.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--texture", "gravel", "--mode", "umbrella", "--seed", "2", "--x", "9", "--y", "-9"])
        .args(["-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(image::open(&out).unwrap().to_rgb8() == a.image("/tiles/gravel/7/9/-9.png?mode=umbrella&seed=2").await);
}

#[test]
fn the_extraction_is_drawn_and_reported() {
    let dir = tempfile::tempdir().unwrap();
    let sheet = dir.path().join("sheet.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--texture", "gravel", "--mode", "umbrella", "--sheet", "-o"])
        .arg(&sheet)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success() && text.contains("umbrella extraction (") && text.contains(" bases)"),
        "{text}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let img = image::open(&sheet).unwrap().to_rgb8();
    assert!(img.width() > 64 && img.height() > 64);
    // A mode that prepares nothing has no sheet: refused, naming the mode.
    let run = std::process::Command::new(binary())
        .args(["render", "--texture", "gravel", "--mode", "mosaic", "--sheet", "-o"])
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("mode=mosaic prepares nothing"), "{err}");
    // textile info reports the extraction of an analysis file.
    let file = dir.path().join("gravel.tex");
    let exemplar = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
    let run = std::process::Command::new(binary()).arg("analyze").arg(&exemplar).arg("-o").arg(&file).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let run = std::process::Command::new(binary()).arg("info").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("umbrella extraction: ") && text.contains("bases "), "{text}");
    // The extraction is stored beside the analysis, and info reads it from there.
    let beside = dir.path().join("gravel.umbrella");
    assert!(text.contains(&format!("umbrella extraction source: stored in {}", beside.display())), "{text}");
    // A damaged one is named and the extraction computed instead — same report, no panic.
    let mut bytes = std::fs::read(&beside).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 0x55;
    std::fs::write(&beside, &bytes).unwrap();
    let run = std::process::Command::new(binary()).arg("info").arg(&file).output().unwrap();
    let damaged = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && damaged.contains("checksum mismatch"), "{damaged}");
    let elements = |t: &str| t.lines().find(|l| l.starts_with("umbrella extraction:")).map(str::to_string);
    assert_eq!(elements(&damaged), elements(&text));
}

#[test]
fn the_server_stores_each_textures_extraction_and_reads_it_back() {
    // First start: extracted and stored beside the analyses; second start: loaded from there.
    let data = tempfile::tempdir().unwrap();
    for (round, word) in [(1, "stored"), (2, "loaded umbrella extraction")] {
        let server = Server::builder().data_dir(data.path()).start();
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
        let line = loop {
            let log = server.log_text();
            if let Some(l) = log.lines().find(|l| l.contains("texture 'gravel'") && l.contains("umbrella")) {
                break l.to_string();
            }
            assert!(std::time::Instant::now() < deadline, "start {round}: no umbrella line in {log}");
            std::thread::sleep(std::time::Duration::from_millis(100));
        };
        assert!(line.contains(word), "start {round}: {line}");
        assert!(data.path().join("gravel.umbrella").exists(), "start {round}");
        server.terminate();
    }
}

/// A PNG element image with alpha: a disc of colour `rgb` on a transparent `side²` canvas.
fn disc_png(side: u32, rgb: [u8; 3]) -> Vec<u8> {
    let r = side as f64 / 2.0 - 1.0;
    let img = image::RgbaImage::from_fn(side, side, |x, y| {
        let (dx, dy) = (x as f64 + 0.5 - side as f64 / 2.0, y as f64 + 0.5 - side as f64 / 2.0);
        if dx * dx + dy * dy <= r * r {
            image::Rgba([rgb[0], rgb[1].saturating_add((x % 7) as u8 * 4), rgb[2], 255])
        } else {
            image::Rgba([0, 0, 0, 0])
        }
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    png
}

#[tokio::test]
async fn a_hand_made_umbrella_set_is_configured_and_served() {
    let dir = tempfile::tempdir().unwrap();
    let set = dir.path().join("set");
    std::fs::create_dir_all(&set).unwrap();
    std::fs::write(set.join("red.png"), disc_png(18, [220, 30, 30])).unwrap();
    std::fs::write(set.join("red2.png"), disc_png(14, [190, 50, 40])).unwrap();
    std::fs::write(set.join("yellow.png"), disc_png(12, [230, 210, 40])).unwrap();
    std::fs::write(
        set.join("set.json"),
        r#"{"bases": [{"image": "red.png", "variants": ["red2.png"]}, {"image": "yellow.png"}], "foreground": 0.8}"#,
    )
    .unwrap();
    let cfg = common::gravel_textures_config(
        dir.path(),
        &[("plain", ""), ("made", "[textures.umbrella]\nset = \"set/set.json\"")],
    );
    let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).start();
    let made = s.image("/tiles/made/7/2/3.png?mode=umbrella").await;
    let plain = s.image("/tiles/plain/7/2/3.png?mode=umbrella").await;
    assert!(made != plain);
    // The set's red and yellow discs cover much of the tile; gravel has neither colour.
    let vivid = |img: &image::RgbImage| img.pixels().filter(|p| p[0] > 160 && p[2] < 90).count();
    assert!(vivid(&made) > 256 * 256 / 4 && vivid(&plain) < 256 * 256 / 100, "{} / {}", vivid(&made), vivid(&plain));
    // The same bytes as textile render with that configuration.
    let out = dir.path().join("made.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--config", cfg.to_str().unwrap(), "--texture", "made", "--mode", "umbrella"])
        .args(["--z", "7", "--x", "2", "--y", "3", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert!(image::open(&out).unwrap().to_rgb8() == made);
    // A set whose image has no alpha: a clear error naming the key and the image, nothing written.
    std::fs::write(set.join("flat.png"), {
        let mut png = Vec::new();
        image::RgbImage::new(16, 16).write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
        png
    })
    .unwrap();
    std::fs::write(set.join("bad.json"), r#"{"bases": [{"image": "flat.png"}]}"#).unwrap();
    let bad = common::gravel_textures_config(dir.path(), &[("bad", "[textures.umbrella]\nset = \"set/bad.json\"")]);
    let out = dir.path().join("bad.png");
    let run = std::process::Command::new(binary())
        .args(["render", "--config", bad.to_str().unwrap(), "--texture", "bad", "--mode", "umbrella"])
        .args(["--x", "0", "--y", "0", "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("set") && err.contains("flat.png") && err.contains("alpha"), "{err}");
    assert!(!out.exists());
}

/// A hand-made set belongs to the umbrella mode's prepared state, not to the exemplar: editing
/// it changes the umbrella tiles' ETags and nothing else — the synth, mosaic and tiling ETags
/// stay, and the stored analysis is loaded, not recomputed, its file untouched.
#[tokio::test]
async fn editing_a_hand_made_set_changes_only_the_umbrella_etags() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let set = dir.path().join("set");
    std::fs::create_dir_all(&set).unwrap();
    std::fs::write(set.join("red.png"), disc_png(18, [220, 30, 30])).unwrap();
    std::fs::write(set.join("blue.png"), disc_png(16, [30, 40, 220])).unwrap();
    let cfg = common::gravel_textures_config(dir.path(), &[("made", "[textures.umbrella]\nset = \"set/set.json\"")]);
    let mut seen = Vec::new();
    for (round, image) in [(1, "red.png"), (2, "blue.png")] {
        std::fs::write(set.join("set.json"), format!(r#"{{"bases": [{{"image": "{image}"}}]}}"#)).unwrap();
        let s = Server::builder().args(&["--config", cfg.to_str().unwrap()]).data_dir(&data).start();
        let meta = s.json("/textures/made").await;
        assert_eq!(meta["prepared"]["umbrella"]["source"], "hand-made", "{meta}");
        let analysis = std::fs::read(data.join("made.tex")).unwrap();
        if round == 2 {
            assert!(s.log_text().contains("texture 'made': loaded analysis"), "{}", s.log_text());
        }
        let mut etags = Vec::new();
        for mode in ["synth", "mosaic", "tiling", "umbrella"] {
            let r = s.get(&format!("/tiles/made/8/1/2.png?mode={mode}")).await;
            assert_eq!(r.status(), 200, "{mode}");
            etags.push(r.headers()["etag"].to_str().unwrap().to_string());
        }
        seen.push((etags, analysis));
        s.terminate();
    }
    let ((before, a1), (after, a2)) = (&seen[0], &seen[1]);
    assert_eq!(before[..3], after[..3], "synth, mosaic and tiling keep their ETags");
    assert_ne!(before[3], after[3], "the umbrella tiles change with the set");
    assert!(a1 == a2, "the analysis file is the same bytes");
}
