//! One owner per data directory, through the real binary: a second server on a directory a
//! running server owns is refused at once with a message naming the owner's pid; `textile
//! render` on it reads it and writes nothing there; once the owner is killed (even with
//! SIGKILL) the directory can be served again.

mod common;

use std::path::Path;
use std::process::Command;

use common::{binary, gravel_textures_config, Server};

/// Names in a directory, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn a_second_server_is_refused_naming_the_owner_and_render_writes_nothing() {
    let conf = tempfile::tempdir().unwrap();
    let data = tempfile::tempdir().unwrap();
    let config = gravel_textures_config(conf.path(), &[("mine", "")]);
    let owner = Server::builder().data_dir(data.path()).args(&["--config", config.to_str().unwrap()]).start();
    assert!(data.path().join("mine.tex").exists(), "{:?}", names(data.path()));
    let lock = std::fs::read_to_string(data.path().join("textile.lock")).unwrap();
    assert_eq!(lock.trim(), owner.pid().to_string());

    let second = Command::new(binary())
        .args(["serve", "--bind", "127.0.0.1:0", "--config", config.to_str().unwrap(), "--data-dir"])
        .arg(data.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&second.stderr);
    assert!(!second.status.success(), "the second server must not start: {err}");
    assert!(err.contains(&format!("in use by another textile server (pid {})", owner.pid())), "{err}");
    assert!(String::from_utf8_lossy(&second.stdout).is_empty(), "it never announced itself");

    // A texture the owner does not serve: render computes its analysis and keeps it to itself.
    let before = names(data.path());
    let other = gravel_textures_config(conf.path(), &[("mine", ""), ("other", "")]);
    let out = conf.path().join("tile.png");
    let render = Command::new(binary())
        .args(["render", "--texture", "other", "--config", other.to_str().unwrap(), "--data-dir"])
        .arg(data.path())
        .args(["-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{err}");
    assert!(err.contains(&format!("belongs to the textile server of pid {}", owner.pid())), "{err}");
    assert!(image::open(&out).is_ok());
    assert_eq!(names(data.path()), before, "render wrote nothing in the owned directory");

    // Killed without a chance to clean up: the kernel releases the lock with the process.
    drop(owner);
    let next = Server::builder().data_dir(data.path()).args(&["--config", config.to_str().unwrap()]).start();
    let lock = std::fs::read_to_string(data.path().join("textile.lock")).unwrap();
    assert_eq!(lock.trim(), next.pid().to_string());
}

/// Start `textile serve` on `data`; its exit code within 20 s (`None`: still running, killed)
/// and what it printed on stderr.
fn serve_exit(data: &Path) -> (Option<i32>, String) {
    use std::io::Read;
    let mut child = Command::new(binary())
        .args(["serve", "--bind", "127.0.0.1:0", "--data-dir"])
        .arg(data)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let mut code = None;
    while code.is_none() && started.elapsed() < std::time::Duration::from_secs(20) {
        code = child.try_wait().unwrap().map(|s| s.code().unwrap_or(-1));
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    (code, err)
}

#[test]
fn a_lock_file_that_is_not_a_regular_file_stops_the_start_and_is_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    // A symbolic link: what it points to is neither truncated nor written.
    let data = dir.path().join("linked");
    std::fs::create_dir(&data).unwrap();
    let precious = dir.path().join("precious.txt");
    std::fs::write(&precious, "keep me").unwrap();
    std::os::unix::fs::symlink(&precious, data.join("textile.lock")).unwrap();
    let (code, err) = serve_exit(&data);
    assert!(code.is_some_and(|c| c != 0), "refused: {code:?} {err}");
    assert!(err.contains("textile.lock is a symbolic link, not a regular file"), "{err}");
    assert_eq!(std::fs::read_to_string(&precious).unwrap(), "keep me");
    // A directory, and a FIFO (which must not hang the start).
    let data = dir.path().join("directory");
    std::fs::create_dir_all(data.join("textile.lock")).unwrap();
    let (code, err) = serve_exit(&data);
    assert!(code.is_some_and(|c| c != 0) && err.contains("is a directory, not a regular file"), "{code:?} {err}");
    let data = dir.path().join("fifo");
    std::fs::create_dir(&data).unwrap();
    let fifo = std::ffi::CString::new(data.join("textile.lock").to_str().unwrap()).unwrap();
    // SAFETY: a valid NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(fifo.as_ptr(), 0o600) }, 0);
    let (code, err) = serve_exit(&data);
    assert!(code.is_some_and(|c| c != 0) && err.contains("is a FIFO, not a regular file"), "{code:?} {err}");
}

#[tokio::test]
async fn a_server_whose_directory_is_removed_stores_nothing_more_and_shares_nothing() {
    const TOKEN: &str = "test-admin-token-0123456789";
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let first = Server::builder().data_dir(&data).env("TEXTILE_ADMIN_TOKEN", TOKEN).start();
    std::fs::remove_dir_all(&data).unwrap();
    let brick = std::fs::read(format!("{}/../config/exemplars/brick.png", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let upload = |s: &Server, id: &str| {
        s.client
            .post(s.url(&format!("/admin/textures?id={id}")))
            .header("content-type", "image/png")
            .bearer_auth(TOKEN)
            .body(brick.clone())
            .send()
    };
    let r = upload(&first, "late").await.unwrap();
    assert_eq!(r.status(), 507);
    let body: serde_json::Value = r.json().await.unwrap();
    assert!(body["message"].as_str().unwrap().contains("removed or taken over"), "{body}");
    assert!(!data.exists(), "the removed directory is not recreated");
    assert!(first.log_text().contains("was removed or replaced while this server ran"));
    // A second server takes the new directory; the first still writes nothing there.
    let second = Server::builder().data_dir(&data).env("TEXTILE_ADMIN_TOKEN", TOKEN).start();
    let lock = std::fs::read_to_string(data.join("textile.lock")).unwrap();
    assert_eq!(lock.trim(), second.pid().to_string());
    assert_eq!(upload(&first, "late").await.unwrap().status(), 507);
    assert!(!data.join("uploads").exists(), "{:?}", names(&data));
    assert_eq!(first.get_bytes("/tiles/gravel/7/0/0.png").await.0, 200, "the first still serves");
}
