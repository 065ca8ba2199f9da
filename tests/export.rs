//! `textile export` against the real binary: PMTiles and MBTiles archives read back by
//! independent readers (PyPI `pmtiles`, Python's sqlite3 — `tests/export/check_archive.py`)
//! whose tiles equal the running server's answers for the same URLs; world and bbox areas;
//! clear errors; and an interrupted export leaves nothing under the target name.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{binary, check_archive as check, reader_available, shared_data_dir, skip, Server};

fn textile(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(binary()).args(args).output().expect("run textile");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn export(args: &[&str], out: &Path) {
    let data = shared_data_dir();
    let mut all =
        vec!["export", "--texture", "gravel", "--data-dir", data.to_str().unwrap(), "-o", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let (code, stdout, err) = textile(&all);
    assert_eq!(code, 0, "export {args:?}: {err}");
    assert!(stdout.contains("tiles/s"), "{stdout}");
}

#[tokio::test]
async fn archives_hold_the_servers_tiles() {
    if !reader_available() {
        return skip(
            "archives_hold_the_servers_tiles",
            "python3 with the pmtiles package (pip install -r tests/export/requirements.txt)",
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let (world, mosaic, bbox) =
        (dir.path().join("world.pmtiles"), dir.path().join("mosaic.mbtiles"), dir.path().join("part.pmtiles"));
    // A world of 8 native tiles: archive zooms 0..3 are textile zooms 4..7.
    export(&["--world", "8"], &world);
    export(&["--world", "4", "--mode", "mosaic", "--seed", "3", "--format", "webp"], &mosaic);
    export(&["--bbox", "3,5,9,8", "--zoom", "5..7", "--format", "jpg", "-p", "randomness=0.5"], &bbox);
    // A material map of the built-in flagstones (archive zooms 0..1 = textile zooms 7..8).
    let normal = dir.path().join("normal.mbtiles");
    let data = shared_data_dir();
    let (code, _, err) = textile(&[
        "export",
        "--texture",
        "flagstones",
        "--world",
        "2",
        "--map",
        "normal",
        "--data-dir",
        data.to_str().unwrap(),
        "-o",
        normal.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("'flagstones?map=normal'") || err.contains("map=normal"), "{err}");
    let s = Server::builder().start();
    for a in [&world, &mosaic, &bbox, &normal] {
        check(a, &s, 24);
    }
    // Nothing but the archives was left in the directory.
    let names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    assert_eq!(names.len(), 4, "{names:?}");
}

#[test]
fn bad_exports_are_clear_errors_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.pmtiles");
    let data = shared_data_dir();
    let base = ["export", "--texture", "gravel", "--data-dir", data.to_str().unwrap()];
    for (args, what) in [
        (vec!["--world", "6", "-o", out.to_str().unwrap()], "power of two"),
        (vec!["--world", "8", "--zoom", "0..5", "-o", out.to_str().unwrap()], "archive zooms 0..=3"),
        (vec!["--bbox", "0,0,200,1", "-o", out.to_str().unwrap()], "--bbox"),
        (vec!["--bbox", "1,2,3", "-o", out.to_str().unwrap()], "--bbox"),
        (vec!["-p", "kappa=0.5", "-o", out.to_str().unwrap()], "kappa"),
        (vec!["-o", dir.path().join("x.zip").to_str().unwrap()], ".pmtiles or .mbtiles"),
    ] {
        let (code, _, err) = textile(&[&base[..], &args[..]].concat());
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(what), "{args:?}: {err}");
    }
    let (code, _, err) = textile(&["export", "--texture", "nosuch", "-o", out.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("nosuch"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
}

#[test]
fn an_interrupted_export_leaves_no_file_under_the_target_name() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.pmtiles");
    let data = shared_data_dir();
    // 21 845 tiles: minutes of work, killed once it is under way.
    let mut child = Command::new(binary())
        .args(["export", "--texture", "gravel", "--data-dir", data.to_str().unwrap(), "--world", "128"])
        .args(["-o", out.to_str().unwrap()])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("start export");
    let started = Instant::now();
    // Tiles go to a part file beside the target (`.big.pmtiles.part.partial`, kept for resuming),
    // then into the archive under a temporary name.
    let temp = || {
        std::fs::read_dir(dir.path()).unwrap().any(|e| {
            let name = e.unwrap().file_name().to_string_lossy().into_owned();
            name.ends_with(".partial") || name.contains(".tmp-")
        })
    };
    while !temp() && started.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(temp(), "the export writes under a temporary name");
    std::thread::sleep(Duration::from_millis(500));
    child.kill().expect("kill -9");
    child.wait().expect("wait");
    assert!(!out.exists(), "no file under the target name after kill -9");
}

#[test]
fn an_export_without_parameters_names_urls_without_an_empty_query() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plain.mbtiles");
    let data = shared_data_dir();
    let (code, _, err) = textile(&[
        "export",
        "--texture",
        "gravel",
        "--bbox",
        "0,0,1,1",
        "--data-dir",
        data.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("tiles of 'gravel' (archive zooms"), "no trailing '?' after the texture: {err}");
    let db = rusqlite::Connection::open(&out).unwrap();
    let json: String = db.query_row("SELECT value FROM metadata WHERE name = 'json'", [], |r| r.get(0)).unwrap();
    let meta: serde_json::Value = serde_json::from_str(&json).unwrap();
    let url = meta["textile"]["tile_url"].as_str().unwrap();
    assert!(url.ends_with("{y}.png"), "{url}");
}
