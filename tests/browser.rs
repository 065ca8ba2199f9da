//! The web viewer in headless Chromium, driven by Playwright (`tests/browser/viewer.test.mjs`)
//! against the real binary. Needs Debian's `chromium` and `npm ci` in `tests/browser` (.ci/run
//! installs both). Without them the test is skipped locally and fails under CI.

mod support;

use std::path::PathBuf;
use std::process::Command;

use support::Server;

#[test]
fn viewer_in_headless_chromium() {
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/browser");
    let node = Command::new("node").arg("--version").output().is_ok_and(|o| o.status.success());
    let missing = !PathBuf::from(&chromium).exists() || !dir.join("node_modules/playwright-core").exists() || !node;
    if missing {
        assert!(
            std::env::var_os("CI").is_none(),
            "browser tests need node, {chromium} and `npm ci` in tests/browser (.ci/run installs them)"
        );
        eprintln!("SKIPPED viewer_in_headless_chromium: install chromium and run `npm ci` in tests/browser");
        return;
    }
    // The viewer opens with a burst of cold tiles; on a slow machine some would wait out the
    // default 1 s queue bound and be shed. Shedding is the second server's subject, so the first
    // one queues instead and every tile it is asked for must come back 200.
    let server = Server::builder().queueing().start();
    // A server that sheds almost everything a viewer asks for at once.
    let shedding = Server::builder().args(&["--max-in-flight", "2", "--workers", "1"]).start();
    let shot = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("viewer.png");
    let status = Command::new("node")
        .args(["--test", "--test-concurrency=1", "viewer.test.mjs"])
        .current_dir(&dir)
        .env("TEXTILE_URL", &server.base)
        .env("TEXTILE_URL_SHEDDING", &shedding.base)
        .env("TEXTILE_SCREENSHOT", &shot)
        .env("CHROMIUM", &chromium)
        .status()
        .expect("run node");
    assert!(status.success(), "browser tests failed (see the node test output above)");
    eprintln!("viewer screenshot: {}", shot.display());
}
