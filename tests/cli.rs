//! The command line: `analyze` (with its file), `info`, `render` (same bytes as the server's
//! tile), and clear errors with nothing half-written.

mod common;

use std::process::Command;

use common::{binary, shared_data_dir, Server};

fn run(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(binary()).args(args).output().expect("run textile");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn exemplar(name: &str) -> String {
    format!("{}/../config/exemplars/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn analyze_then_info() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("grass.tex");
    let (code, stdout, err) = run(&["analyze", &exemplar("grass.png"), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("analysed"), "{stdout}");
    let (code, info, err) = run(&["info", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(info.contains("128x128") && info.contains("analysis id"), "{info}");
    assert!(info.contains("candidate search:  exact"), "128² is searched exactly by default: {info}");
    let coherent = dir.path().join("coherent.tex");
    let (code, stdout, err) =
        run(&["analyze", &exemplar("grass.png"), "--index", "coherent", "-o", coherent.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("coherent search"), "{stdout}");
    let (_, info2, _) = run(&["info", coherent.to_str().unwrap()]);
    assert!(info2.contains("candidate search:  coherent"), "{info2}");
    let id = |s: &str| s.lines().find(|l| l.starts_with("analysis id")).map(str::to_string);
    assert_ne!(id(&info), id(&info2), "the search is part of the analysis id");
    let (code, _, err) = run(&["analyze", &exemplar("grass.png"), "--index", "tsvq", "-o", coherent.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("tsvq") && err.contains("coherent"), "{err}");
}

#[test]
fn analyze_detects_a_lattice_and_info_prints_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("brick.tex");
    let (code, stdout, err) = run(&["analyze", &exemplar("brick.png"), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("lattice: stripes every [dy, dx] [0.00, 18."), "brick's courses are found: {stdout}");
    let (code, info, err) = run(&["info", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        info.contains("lattice:           stripes every [dy, dx] [0.00, 18.") && info.contains("detected"),
        "{info}"
    );
    assert!(info.contains("structure:         lattice, 1-D: basis [dy, dx] [0, 18."), "{info}");
    // Turned off, and given as waves.
    let (code, stdout, err) =
        run(&["analyze", &exemplar("brick.png"), "--lattice", "none", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("lattice: none"), "{stdout}");
    let (code, stdout, err) =
        run(&["analyze", &exemplar("brick.png"), "--lattice", "18.5@0", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("stripes every [dy, dx] [0.00, 18.50] texels, given"), "{stdout}");
    // Gravel has none; a bad spelling is a clear error that writes nothing.
    let (_, stdout, _) = run(&["analyze", &exemplar("gravel.png"), "-o", out.to_str().unwrap()]);
    assert!(stdout.contains("structure: none (stochastic)") && stdout.contains("lattice: none"), "{stdout}");
    // The rectified corkboard is its 64 × 32 cell repeated: exact, and `info` says so.
    let (code, stdout, err) = run(&["analyze", &exemplar("corkboard.png"), "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("structure: exact: a 64×32 tile repeated (copies [dy, dx] [32, 0] × [0, 64]"), "{stdout}");
    let (_, info, _) = run(&["info", out.to_str().unwrap()]);
    assert!(info.contains("structure:         exact: a 64×32 tile repeated"), "{info}");
    let bad = dir.path().join("bad.tex");
    // Basis vectors [dy, dx]: brick's columns with the half-brick stagger, given.
    let (code, stdout, err) =
        run(&["analyze", &exemplar("brick.png"), "--lattice", "[[16,18],[-16,18]]", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("lattice: grid of") && stdout.contains("given"), "{stdout}");
    for spelling in ["sometimes", "1@0,1@1", "20@0,20@5", "3,4", "[[0,0]]", "[[10,10],[20,21]]", "[[0,500]]", "[[1,x]]"]
    {
        let (code, _, err) =
            run(&["analyze", &exemplar("brick.png"), "--lattice", spelling, "-o", bad.to_str().unwrap()]);
        assert_ne!(code, 0, "{spelling}");
        assert!(err.contains("lattice"), "{spelling}: {err}");
        assert!(!bad.exists(), "{spelling}");
    }
}

#[test]
fn bad_inputs_are_clear_errors_and_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let text = dir.path().join("notes.png");
    std::fs::write(&text, "just text").unwrap();
    let out = dir.path().join("out.tex");
    let (code, _, err) = run(&["analyze", text.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("notes.png") && err.contains("not a decodable image"), "{err}");
    assert!(std::fs::read_dir(dir.path()).unwrap().count() == 1, "nothing else was written");
    // A flat exemplar (one grey): refused at once, saying why and what the threshold is.
    let flat = dir.path().join("flat.png");
    image::RgbImage::from_pixel(256, 256, image::Rgb([128, 128, 128])).save(&flat).unwrap();
    let (code, _, err) = run(&["analyze", flat.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("flat.png") && err.contains("exemplar is flat") && err.contains("under the 2"), "{err}");
    assert!(!out.exists());
    std::fs::remove_file(&flat).unwrap();
    let truncated = dir.path().join("short.tex");
    std::fs::write(&truncated, b"TXTLANA\0\x01\0\0\0").unwrap();
    let (code, _, err) = run(&["info", truncated.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("short.tex") && err.contains("truncated"), "{err}");
    let (code, _, err) = run(&["render", "--texture", "nosuch", "-o", "/tmp/x.png"]);
    assert_ne!(code, 0);
    assert!(err.contains("nosuch") && err.contains("gravel"), "{err}");
    let (code, _, _) = run(&["render", "--texture", "gravel", "--z", "99", "-o", "/tmp/x.png"]);
    assert_ne!(code, 0);
    let (code, _, err) = run(&["render", "--exemplar", text.to_str().unwrap(), "-o", "/tmp/x.png"]);
    assert_ne!(code, 0, "{err}");
}

#[tokio::test]
async fn render_writes_the_same_bytes_as_the_server() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tile.png");
    let data = shared_data_dir();
    let (code, _, err) = run(&[
        "render",
        "--texture",
        "gravel",
        "--data-dir",
        data.to_str().unwrap(),
        "--x",
        "-3",
        "--y",
        "4",
        "--seed",
        "8",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let s = Server::builder().start();
    let (status, body) = s.get_bytes("/tiles/gravel/7/-3/4.png?seed=8").await;
    assert_eq!(status, 200);
    assert_eq!(std::fs::read(&out).unwrap(), body);
    let win = dir.path().join("win.png");
    let (code, _, err) = run(&[
        "render",
        "--exemplar",
        &exemplar("brick.png"),
        "--window=-100,-50,300,200",
        "-o",
        win.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let img = image::open(&win).unwrap();
    assert_eq!((img.width(), img.height()), (300, 200));
}

#[tokio::test]
async fn render_writes_the_glb_the_server_serves() {
    let dir = tempfile::tempdir().unwrap();
    let data = shared_data_dir();
    let s = Server::builder().start();
    // A plain tile's model, and a material's with its maps and a displaced mesh.
    for (texture, z, x, y, params, query) in [
        ("gravel", "6", "1", "-1", vec!["--seed", "3"], "?seed=3"),
        ("flagstones", "8", "3", "-2", vec!["--param", "relief=4"], "?relief=4"),
        // A landscape's, raised by its blended heights.
        ("meadow", "7", "0", "1", vec!["--param", "relief=8", "--seed", "4"], "?relief=8&seed=4"),
    ] {
        let out = dir.path().join(format!("{texture}.glb"));
        let mut args = vec!["render", "--texture", texture, "--data-dir", data.to_str().unwrap()];
        args.extend(["--z", z, "--x", x, "--y", y, "-o", out.to_str().unwrap()]);
        args.extend(params);
        let (code, _, err) = run(&args);
        assert_eq!(code, 0, "{err}");
        let (status, body) = s.get_bytes(&format!("/gltf/{texture}/{z}/{x}/{y}.glb{query}")).await;
        assert_eq!(status, 200);
        let written = std::fs::read(&out).unwrap();
        assert_eq!(&written[..4], b"glTF");
        assert!(
            written == body,
            "{texture}: the CLI's GLB ({} bytes) is not the served one ({})",
            written.len(),
            body.len()
        );
    }
    // A model takes no window, and relief needs a height map.
    let out = dir.path().join("bad.glb");
    let (code, _, err) = run(&[
        "render",
        "--texture",
        "gravel",
        "--data-dir",
        data.to_str().unwrap(),
        "--window=0,0,8,8",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(code != 0 && err.contains(".glb"), "{err}");
    let (code, _, err) = run(&[
        "render",
        "--texture",
        "gravel",
        "--data-dir",
        data.to_str().unwrap(),
        "--param",
        "relief=4",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(code != 0 && err.contains("height map"), "{err}");
    assert!(!out.exists());
}

#[test]
fn help_describes_every_command() {
    let (code, out, _) = run(&["--help"]);
    assert_eq!(code, 0);
    for c in ["serve", "analyze", "render", "info", "tileable"] {
        assert!(out.contains(c), "{out}");
    }
    let (code, out, _) = run(&["render", "--help"]);
    assert_eq!(code, 0);
    assert!(out.contains("--param") && out.contains("--window") && out.contains("synth, mosaic"), "{out}");
    // Every mode's parameters, from their specs.
    let (code, out, _) = run(&["render", "--list-params"]);
    assert_eq!(code, 0);
    for p in ["seed", "world", "randomness", "kappa", "iterations", "block_area", "smoothing"] {
        assert!(out.contains(p), "{p}: {out}");
    }
}

#[tokio::test]
async fn camera_view_is_made_of_samples_equal_to_the_texture() {
    let dir = tempfile::tempdir().unwrap();
    let data = shared_data_dir();
    let data = data.to_str().unwrap();
    // Straight down with a 90° lens from 32 texels up: 64×64 pixels see 64×64 texels, each
    // pixel's centre a texel centre at level 0 — the window under the camera.
    let down = dir.path().join("down.png");
    let args = ["render", "--texture", "gravel", "--data-dir", data, "--seed", "4", "--size", "64x64"];
    let (code, out, err) =
        run(&[&args[..], &["--camera", "32,90,0,90", "--at=10,-20", "-o", down.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("4096 ground samples"), "{out}");
    let s = Server::builder().start();
    let win = s.image("/windows/gravel.png?x=-22&y=-52&w=64&h=64&seed=4").await;
    assert!(image::open(&down).unwrap().to_rgb8() == win, "the camera looking down sees the window below it");
    // A level view: sky above the horizon, the plane below.
    let level = dir.path().join("level.png");
    let (code, _, err) = run(&[&args[..], &["--camera", "20,0,45,60", "-o", level.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
    let img = image::open(&level).unwrap().to_rgb8();
    assert_eq!(img.get_pixel(5, 5), img.get_pixel(60, 20), "sky");
    assert_ne!(img.get_pixel(5, 60), img.get_pixel(5, 5), "ground");
    // Bad cameras are clear errors, and nothing is written.
    for (cam, size, what) in [
        ("0,30,0,60", "64x64", "height"),
        ("20,30,0,180", "64x64", "field of view"),
        ("20,30,0", "64x64", "--camera"),
        ("20,30,0,60", "0x5", "--size"),
    ] {
        let bad = dir.path().join("bad.png");
        let (code, _, err) = run(&[
            "render",
            "--texture",
            "gravel",
            "--data-dir",
            data,
            "--camera",
            cam,
            "--size",
            size,
            "-o",
            bad.to_str().unwrap(),
        ]);
        assert_ne!(code, 0);
        assert!(err.contains(what), "{cam} {size}: {err}");
        assert!(!bad.exists());
    }
}

#[test]
fn tileable_writes_a_seamless_texture_deterministically_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let gravel = exemplar("gravel.png");
    let (code, said, err) = run(&["tileable", &gravel, "--size", "64", "--seed", "3", "-o", &out("a.png")]);
    assert_eq!(code, 0, "{err}");
    assert!(said.contains("64x64, tileable"), "{said}");
    let a = image::open(out("a.png")).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), (64, 64));
    let (code, _, err) = run(&["tileable", &gravel, "--size", "64", "--seed", "3", "-o", &out("b.png")]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(std::fs::read(out("a.png")).unwrap(), std::fs::read(out("b.png")).unwrap(), "same seed, same bytes");
    // Bad input: a clear message, a failing exit code, and no file.
    let tiny = out("tiny.png");
    image::RgbImage::new(4, 4).save(&tiny).unwrap();
    for (args, says) in [
        (vec!["tileable", &gravel, "--size", "100", "-o", &out("c.png")], "multiple of 8"),
        (vec!["tileable", &gravel, "--size", "16", "-o", &out("c.png")], "outside 32"),
        (vec!["tileable", &tiny, "-o", &out("c.png")], "4x4"),
        (vec!["tileable", &gravel, "-o", &out("c.txt")], "must end in"),
        (vec!["tileable", &gravel, "--backtrack", "0", "-o", &out("c.png")], "at least 1"),
    ] {
        let (code, _, err) = run(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(says), "{args:?}: {err}");
        assert!(!dir.path().join("c.png").exists() && !dir.path().join("c.txt").exists());
    }
}

/// Every service setting with a flag is a flag of `textile serve` (and `--data-dir` of every
/// command that reads the configuration) with the table's help, and the flag sets that key.
#[test]
fn setting_flags_come_from_the_settings_table() {
    use textile_server::config::settings::{describe, ValueKind, SERVICE};
    let (code, help, err) = run(&["serve", "--help"]);
    assert_eq!(code, 0, "{err}");
    let flagged: Vec<_> = SERVICE.iter().filter(|s| s.flag.is_some()).collect();
    assert!(flagged.len() >= 6, "{} flagged settings", flagged.len());
    for s in &flagged {
        let flag = s.flag.unwrap();
        let line = help.lines().find(|l| l.trim_start().starts_with(&format!("--{} ", flag.long)));
        let line = line.unwrap_or_else(|| panic!("--{} is not in serve --help:\n{help}", flag.long));
        assert!(line.contains(s.help), "--{}: {line}", flag.long);
        // The flag sets its key, as --print-config shows.
        let value = match s.kind {
            ValueKind::Int { min, max, .. } => (min + (max - min) / 3).max(1).min(max).to_string(),
            _ if s.key == "bind" => "127.0.0.1:9".to_string(),
            _ => "/tmp/textile-flag-test".to_string(),
        };
        let (code, out, err) = run(&["serve", &format!("--{}", flag.long), &value, "--print-config"]);
        assert_eq!(code, 0, "--{} {value}: {err}", flag.long);
        let shown = out.lines().find(|l| l.starts_with(&format!("{} = ", s.key))).unwrap_or_default();
        assert!(shown.contains(&value), "--{} {value} gave '{shown}' ({})", flag.long, describe(s));
        if flag.every_command {
            let (_, help, _) = run(&["render", "--help"]);
            assert!(help.contains(&format!("--{}", flag.long)), "render --help lacks --{}", flag.long);
        }
    }
}

/// The settings table drives `--print-config` (each service key preceded by what it does, its
/// range, default and environment variable), the environment keys, and the upload fields the
/// OpenAPI document lists.
#[tokio::test]
async fn settings_are_declared_once_and_shown_everywhere() {
    let (code, out, err) = run(&["serve", "--print-config"]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("cache_mib = ")).expect("cache_mib");
    assert_eq!(lines[at - 1], "# tile cache size in MiB (1..=65536; default 256; env TEXTILE_CACHE_MIB)");
    let at = lines.iter().position(|l| l.starts_with("worker_threads = ")).expect("worker_threads");
    assert!(lines[at - 1].contains("0 = one per core"), "{}", lines[at - 1]);
    // The environment variable it names is read, and its range checked.
    let bad = std::process::Command::new(common::binary())
        .args(["serve", "--print-config"])
        .env("TEXTILE_MAX_UPLOAD_MIB", "5000")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && e.contains("max_upload_mib") && e.contains("1..=4096"), "{e}");
    // The upload's fields in the OpenAPI document, with their types and ranges.
    let s = common::Server::builder().start();
    let doc = s.json("/openapi.json").await;
    for path in ["/admin/textures", "/textures"] {
        let params = doc["paths"][path]["post"]["parameters"].as_array().expect("parameters");
        let field = |n: &str| params.iter().find(|p| p["name"] == n).cloned().unwrap_or_default();
        assert_eq!(field("toroidal")["schema"]["enum"], serde_json::json!(["auto", "true", "false", "synthesize"]));
        assert_eq!(field("index")["schema"]["enum"], serde_json::json!(["auto", "exact", "coherent"]));
        assert!(field("default_mode")["schema"]["enum"].as_array().is_some_and(|m| m.len() >= 4), "{path}");
        assert!(field("id")["description"].as_str().is_some_and(|d| d.contains("required")), "{path}");
    }
}

/// One recipe, one result (issue 81): `textile analyze IMG` and `textile render --exemplar IMG`
/// make the exemplar as serving IMG as a configured texture with the same settings does — the
/// same analysis id, and a tile of the same bytes — for a plain exemplar, a non-square one, and
/// one with a lattice (brick's courses, detected) and a randomness mask.
#[tokio::test]
async fn analyze_and_render_make_the_exemplar_serve_makes() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // A non-square crop of gravel, and a mask keeping the left half of brick.
    let gravel = image::open(exemplar("gravel.png")).unwrap().to_rgb8();
    image::imageops::crop_imm(&gravel, 0, 16, 128, 96).to_image().save(p("wide.png")).unwrap();
    image::GrayImage::from_fn(128, 128, |x, _| image::Luma([if x < 64 { 0 } else { 255 }]))
        .save(p("mask.png"))
        .unwrap();
    let cases: [(&str, String, Option<String>); 3] = [
        ("plain", exemplar("grass.png"), None),
        ("wide", p("wide.png"), None),
        ("masked", exemplar("brick.png"), Some(p("mask.png"))),
    ];
    let config: String = cases
        .iter()
        .map(|(id, image, mask)| {
            let mask = mask.as_ref().map(|m| format!("randomness_mask = \"{m}\"\n")).unwrap_or_default();
            format!("[[textures]]\nid = \"{id}\"\nexemplar = \"{image}\"\n{mask}\n")
        })
        .collect();
    std::fs::write(p("textile.toml"), config).unwrap();
    let s = Server::builder().args(&["--config", &p("textile.toml")]).start();
    for (id, image, mask) in &cases {
        let with_mask = |mut args: Vec<String>| {
            if let Some(m) = mask {
                args.extend(["--randomness-mask".to_string(), m.clone()]);
            }
            args
        };
        let out = p(&format!("{id}.tex"));
        let args = with_mask(vec!["analyze".into(), image.clone(), "-o".into(), out]);
        let (code, stdout, err) = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(code, 0, "{id}: {err}");
        let analysed = stdout.rsplit("(id ").next().and_then(|t| t.split(')').next()).unwrap_or_default().to_string();
        let meta = s.json(&format!("/textures/{id}")).await;
        assert_eq!(meta["analysis"]["id"].as_str(), Some(analysed.as_str()), "{id}: the served analysis: {meta}");
        assert_eq!(meta["exemplar"]["randomness_mask"], mask.is_some(), "{id}");

        let tile = p(&format!("{id}.png"));
        let args = with_mask(vec![
            "render".into(),
            "--exemplar".into(),
            image.clone(),
            "--z".into(),
            "7".into(),
            "--x".into(),
            "1".into(),
            "--y".into(),
            "-1".into(),
            "-o".into(),
            tile.clone(),
        ]);
        let (code, _, err) = run(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert_eq!(code, 0, "{id}: {err}");
        let (status, served) = s.get_bytes(&format!("/tiles/{id}/7/1/-1.png")).await;
        assert_eq!(status, 200, "{id}");
        assert!(std::fs::read(&tile).unwrap() == served, "{id}: textile render --exemplar draws the served tile");
    }
}
