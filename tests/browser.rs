//! The web viewer in headless Chromium, driven by Playwright (`tests/browser/viewer.test.mjs`,
//! and MapLibre on the terrain tiles: `tests/browser/terrain.test.mjs`) against the real binary. Needs node and Debian's `chromium` (.ci/run installs it); the test
//! runs `npm ci` in `tests/browser` itself when its packages are missing. Without them the test
//! says on the terminal that it skipped, and why; under CI it fails instead.

mod common;

use std::path::PathBuf;
use std::process::Command;

use common::Server;

/// One browser suite at a time: each runs Chromium with software WebGL and a server, and two at
/// once on a 2-core machine only make both slow enough to time out.
static ONE_BROWSER: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn viewer_in_headless_chromium() {
    let _one = ONE_BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/browser");
    if !PathBuf::from(&chromium).exists() {
        return common::skip(
            "viewer_in_headless_chromium",
            &format!("no Chromium at {chromium} (Debian: apt-get install chromium; or set CHROMIUM=PATH)"),
        );
    }
    if let Err(why) = common::npm_ready(&dir, "playwright-core") {
        return common::skip("viewer_in_headless_chromium", &why);
    }
    // The viewer opens with a burst of cold tiles; on a slow machine some would wait out the
    // default 1 s queue bound and be shed. Shedding is the second server's subject, so the first
    // one queues instead and every tile it is asked for must come back 200.
    let server = Server::builder().queueing().start();
    // A server that sheds almost everything a viewer asks for at once.
    let shedding = Server::builder().args(&["--max-in-flight", "2", "--workers", "1"]).start();
    // A server with the admin API, on a data directory of its own (the upload test adds to it).
    let admin_data = tempfile::tempdir().expect("temp dir");
    let token = "browser-test-token-0123456789";
    let admin = Server::builder().data_dir(admin_data.path()).env("TEXTILE_ADMIN_TOKEN", token).start();
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("viewer.png");
    let status = Command::new("node")
        .args(["--test", "--test-concurrency=1", "viewer.test.mjs"])
        .current_dir(&dir)
        .env("TEXTILE_URL", &server.base)
        .env("TEXTILE_URL_SHEDDING", &shedding.base)
        .env("TEXTILE_URL_ADMIN", &admin.base)
        .env("TEXTILE_ADMIN_TOKEN", token)
        .env("TEXTILE_SCREENSHOT", &shot)
        .env("CHROMIUM", &chromium)
        .status()
        .expect("run node");
    assert!(status.success(), "browser tests failed (see the node test output above)");
    eprintln!("viewer screenshot: {}", shot.display());
    // MapLibre on the same server: the README's terrain style and the terrain page.
    let status = Command::new("node")
        .args(["--test", "--test-concurrency=1", "terrain.test.mjs"])
        .current_dir(&dir)
        .env("TEXTILE_URL", &server.base)
        .env("CHROMIUM", &chromium)
        .status()
        .expect("run node");
    assert!(status.success(), "terrain tests failed (see the node test output above)");
}

#[test]
fn exported_archive_in_headless_chromium() {
    let _one = ONE_BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/browser");
    if !PathBuf::from(&chromium).exists() {
        return common::skip("exported_archive_in_headless_chromium", &format!("no Chromium at {chromium}"));
    }
    if let Err(why) = common::npm_ready(&dir, "playwright-core") {
        return common::skip("exported_archive_in_headless_chromium", &why);
    }
    let archives = tempfile::tempdir().unwrap();
    let data = common::shared_data_dir();
    let out = archives.path().join("world.pmtiles");
    let status = Command::new(common::binary())
        .args(["export", "--texture", "gravel", "--world", "8", "--data-dir", data.to_str().unwrap(), "-o"])
        .arg(&out)
        .status()
        .expect("export");
    assert!(status.success());
    // A part of the world, far from [0, 0]: the page must open on it, not on an empty map.
    let status = Command::new(common::binary())
        .args(["export", "--texture", "gravel", "--bbox", "100,40,104,43", "--data-dir", data.to_str().unwrap(), "-o"])
        .arg(archives.path().join("part.pmtiles"))
        .status()
        .expect("export");
    assert!(status.success());
    let server = Server::builder().env("TEXTILE_ARCHIVES_DIR", archives.path().to_str().unwrap()).start();
    let status = Command::new("node")
        .args(["--test", "pmtiles.test.mjs"])
        .current_dir(&dir)
        .env("TEXTILE_URL", &server.base)
        .env("TEXTILE_ARCHIVE", "/archives/world.pmtiles")
        .env("TEXTILE_ARCHIVE_PART", "/archives/part.pmtiles")
        .env("CHROMIUM", &chromium)
        .status()
        .expect("run node");
    assert!(status.success(), "archive page test failed (see the node test output above)");
}

/// textile's 3D documents in the clients users run (`tests/browser/clients3d.test.mjs`): three.js
/// `GLTFLoader` on bordered, mipmapped glTF tiles (no seams up close, less aliasing far away,
/// both measured against one-texture references); X_ITE on X3D tile and patch documents (they
/// show the tile, seen from above; a material's is lit by its normal map the right way round); 3DTilesRendererJS streaming the 3D Tiles tileset on
/// `/3d.html` (levels follow the camera); CesiumJS loading it anchored on the globe. Pictures go
/// to `target/tmp/clients3d/`.
#[test]
fn three_d_clients_in_headless_chromium() {
    let _one = ONE_BROWSER.lock().unwrap_or_else(|e| e.into_inner());
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/browser");
    if !PathBuf::from(&chromium).exists() {
        return common::skip("three_d_clients_in_headless_chromium", &format!("no Chromium at {chromium}"));
    }
    for package in ["playwright-core", "three", "x_ite", "cesium"] {
        if let Err(why) = common::npm_ready(&dir, package) {
            return common::skip("three_d_clients_in_headless_chromium", &why);
        }
    }
    let server = Server::builder().queueing().start();
    let artefacts = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clients3d");
    let status = Command::new("node")
        .args(["--test", "--test-concurrency=1", "clients3d.test.mjs"])
        .current_dir(&dir)
        .env("TEXTILE_URL", &server.base)
        .env("TEXTILE_ARTEFACTS", &artefacts)
        .env("CHROMIUM", &chromium)
        .status()
        .expect("run node");
    assert!(status.success(), "3D client tests failed (see the node test output above)");
    eprintln!("3D client pictures: {}", artefacts.display());
}
