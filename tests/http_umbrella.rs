//! `mode=umbrella` through the real binary: tiles are the same pixels as windows over them, at
//! native zoom, zoomed out and magnified; bytes are identical across processes and thread
//! counts and equal `textile render`'s; parameters are validated with 400s naming them;
//! `textile render --debug-umbrellas` draws the extraction and `textile info` reports it.

mod support;

use support::{assert_error, binary, paste, Server};

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
        .args(["render", "--texture", "gravel", "--mode", "umbrella", "--debug-umbrellas", "-o"])
        .arg(&sheet)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && text.contains("bases of"), "{text}{}", String::from_utf8_lossy(&run.stderr));
    let img = image::open(&sheet).unwrap().to_rgb8();
    assert!(img.width() > 64 && img.height() > 64);
    // Without --mode umbrella the flag is refused.
    let run = std::process::Command::new(binary())
        .args(["render", "--texture", "gravel", "--debug-umbrellas", "-o"])
        .arg(dir.path().join("x.png"))
        .output()
        .unwrap();
    assert!(!run.status.success() && String::from_utf8_lossy(&run.stderr).contains("--mode umbrella"));
    // textile info reports the extraction of an analysis file.
    let file = dir.path().join("gravel.tex");
    let exemplar = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
    let run = std::process::Command::new(binary()).arg("analyze").arg(&exemplar).arg("-o").arg(&file).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let run = std::process::Command::new(binary()).arg("info").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&run.stdout);
    assert!(text.contains("umbrella elements:") && text.contains("bases"), "{text}");
    // The extraction is stored beside the analysis, and info reads it from there.
    let beside = dir.path().join("gravel.umbrella");
    assert!(text.contains(&format!("umbrella source:   stored in {}", beside.display())), "{text}");
    // A damaged one is named and the extraction computed instead — same report, no panic.
    let mut bytes = std::fs::read(&beside).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 0x55;
    std::fs::write(&beside, &bytes).unwrap();
    let run = std::process::Command::new(binary()).arg("info").arg(&file).output().unwrap();
    let damaged = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && damaged.contains("checksum mismatch"), "{damaged}");
    let elements = |t: &str| t.lines().find(|l| l.starts_with("umbrella elements:")).map(str::to_string);
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
