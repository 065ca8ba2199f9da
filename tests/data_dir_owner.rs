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
