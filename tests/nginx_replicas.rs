//! Replicas behind nginx, end to end: runs `deploy/test.sh` with the binary under test — three
//! replicas and nginx running `deploy/textile.nginx.conf` on loopback, the checks of
//! `deploy/check.py` (identical bytes and ETags everywhere, URI affinity, `kill -9` of a
//! replica under load with zero failures, one synthesis for 100 concurrent identical requests,
//! 304 through nginx). Needs nginx (installed by `.ci/run`).

mod common;

use std::process::Command;

#[test]
fn replicas_behind_nginx() {
    let nginx = ["/usr/sbin/nginx", "/usr/bin/nginx"].iter().any(|p| std::path::Path::new(p).exists());
    if !nginx {
        return common::skip("replicas_behind_nginx", "nginx is not installed (apt-get install nginx)");
    }
    let script = format!("{}/../deploy/test.sh", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new("bash").arg(&script).arg(common::binary()).output().expect("run deploy/test.sh");
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "deploy/test.sh failed:\n{text}");
    for check in ["(a)", "(b)", "(c)", "(d)", "(e)", "all checks passed"] {
        assert!(text.contains(check), "{check} missing:\n{text}");
    }
}
