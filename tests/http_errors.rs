//! Bad input gets a clear JSON 4xx and never a 500, an HTML page, a panic or a hang; damaged
//! analyses at start-up are recomputed; an invalid configuration stops start-up with a message
//! naming the key; SIGTERM drains and exits 0.

mod common;

use std::process::Command;

use common::{assert_error, binary, Server};

#[tokio::test]
async fn bad_requests_are_json_4xx() {
    let s = Server::builder().start();
    let cases: &[(&str, u16, &str)] = &[
        ("/tiles/gravel/7/abc/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/x/0/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/7/0/1.5.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/7/99999999999999999999999/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/7/2147483648/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/7/0/-2147483649.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/11/0/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/-1/0/0.png", 400, "invalid_coordinate"),
        ("/tiles/gravel/7/0/0.gif", 400, "invalid_format"),
        ("/tiles/gravel/7/0/0", 400, "invalid_format"),
        ("/tiles/nosuch/7/0/0.png", 404, "unknown_texture"),
        ("/tiles/..%2F..%2Fetc%2Fpasswd/7/0/0.png", 404, "unknown_texture"),
        // The client resolves "%2e%2e" as "..": the request reaches no route.
        ("/tiles/%2e%2e/7/0/0.png", 404, "not_found"),
        ("/textures/..%2Fconfig", 404, "unknown_texture"),
        ("/tiles/gravel/7/0/0.png?bogus=1", 400, "unknown_parameter"),
        ("/tiles/gravel/7/0/0.png?seed=1&seed=2", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?seed=-1", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?seed=18446744073709551616", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?seed=abc", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?randomness=1.5", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?randomness=-0.1", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?randomness=NaN", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?randomness=0.1,0.2", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?mode=teleport", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?world=3", 400, "invalid_parameter"),
        ("/tiles/gravel/7/0/0.png?world=0", 400, "invalid_parameter"),
        ("/windows/gravel.png?x=0&y=0&w=4097&h=10", 400, "invalid_coordinate"),
        ("/windows/gravel.png?x=0&y=0&w=0&h=10", 400, "invalid_coordinate"),
        ("/windows/gravel.png?x=0&y=0&w=10", 400, "missing_parameter"),
        ("/windows/gravel.tiff?x=0&y=0&w=10&h=10", 400, "invalid_format"),
        ("/windows/nosuch.png?x=0&y=0&w=10&h=10", 404, "unknown_texture"),
        ("/nowhere", 404, "not_found"),
        ("/tiles/gravel/7/0/0/extra.png", 404, "not_found"),
    ];
    for &(path, status, code) in cases {
        assert_error(&s, path, status, code).await;
    }
    // 405: the JSON error names the methods the route takes, as its Allow header does.
    for (method, path, allow, says) in [
        ("POST", "/tiles/gravel/7/0/0.png", "GET,HEAD", "use GET or HEAD"),
        ("DELETE", "/catalog", "GET,HEAD", "use GET or HEAD"),
        ("PUT", "/health", "GET,HEAD", "use GET or HEAD"),
        ("GET", "/samples/gravel", "POST", "use POST"),
        ("GET", "/admin/textures", "POST", "use POST"),
    ] {
        let r = s.client.request(method.parse().unwrap(), s.url(path)).send().await.unwrap();
        assert_eq!(r.status(), 405, "{method} {path}");
        assert_eq!(r.headers()["allow"].to_str().unwrap().replace(' ', ""), allow, "{method} {path}");
        let body: serde_json::Value = r.json().await.unwrap();
        assert_eq!(body["error"], "method_not_allowed");
        let msg = body["message"].as_str().unwrap();
        assert!(msg.starts_with(&format!("{method} is not allowed on '{path}'")) && msg.ends_with(says), "{msg}");
    }
    // The server is still healthy after all of that.
    assert_eq!(s.json("/health").await["status"], "ok");
}

#[tokio::test]
async fn corrupt_analysis_at_start_up_is_recomputed() {
    let dir = tempfile::tempdir().unwrap();
    let s = Server::builder().data_dir(dir.path()).start();
    let before = s.get_bytes("/tiles/gravel/7/2/3.png").await;
    assert_eq!(s.terminate(), Some(0));
    let file = dir.path().join("gravel.tex");
    let mut bytes = std::fs::read(&file).unwrap();
    let n = bytes.len();
    bytes[n / 2] ^= 0xFF;
    std::fs::write(&file, &bytes).unwrap();
    std::fs::write(dir.path().join("grass.tex"), &bytes[..100]).unwrap();
    let s = Server::builder().data_dir(dir.path()).start();
    assert_eq!(s.get_bytes("/tiles/gravel/7/2/3.png").await, before);
    assert_eq!(s.get("/tiles/grass/7/0/0.png").await.status(), 200);
    drop(s);
    assert!(textile_core::Analysis::load(&file).is_ok(), "the damaged file was rewritten");
}

#[test]
fn invalid_configuration_stops_start_up_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("bad.toml");
    let run = |args: &[&str], env: &[(&str, &str)]| {
        let out = Command::new(binary()).args(args).envs(env.iter().copied()).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).to_string())
    };
    std::fs::write(&cfg, "cache_mib = 0\n").unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("cache_mib"), "{err}");
    let (code, err) = run(&["serve", "--level-cache-mib", "70000"], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("level_cache_mib") && err.contains("0 = off"), "{err}");
    let (code, err) = run(&["serve", "--bind", "127.0.0.1:0"], &[("TEXTILE_LEVEL_CACHE_MIB", "lots")]);
    assert_ne!(code, Some(0));
    assert!(err.to_lowercase().contains("level_cache_mib"), "{err}");
    std::fs::write(&cfg, "cache_mb = 10\n").unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("cache_mb"), "{err}");
    // A bad value names the key and the file it came from.
    std::fs::write(&cfg, "cache_mib = \"lots\"\n").unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("key 'cache_mib'") && err.contains(cfg.to_str().unwrap()), "{err}");
    std::fs::write(&cfg, "[[textures]]\nid = \"x\"\nname = \"X\"\nexemplar = \"e.png\"\ndefault_mode = \"magic\"\n")
        .unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("default_mode") && err.contains("synth"), "{err}");
    let texture = "[[textures]]\nid = \"x\"\nname = \"X\"\nexemplar = \"e.png\"\n";
    std::fs::write(&cfg, format!("{texture}[textures.synth]\nkappa = 1.5\n")).unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("textures[0].synth.kappa") && err.contains("[0, 1]"), "{err}");
    // The spelling before per-mode tables names the new one.
    std::fs::write(&cfg, format!("{texture}kappa = 0.5\n")).unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("textures[0].kappa") && err.contains("[textures.synth] kappa"), "{err}");
    // A key no mode has, in a mode's table, names the mode's keys.
    std::fs::write(&cfg, format!("{texture}[textures.mosaic]\nrandomness = 0.5\n")).unwrap();
    let (code, err) = run(&["serve", "--config", cfg.to_str().unwrap()], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("textures[0].mosaic.randomness") && err.contains("iterations"), "{err}");
    let (code, err) = run(&["serve"], &[("TEXTILE_BIND", "not-an-address")]);
    assert_ne!(code, Some(0));
    assert!(err.contains("bind"), "{err}");
    let (code, err) = run(&["serve", "--config", "/nonexistent/textile.toml"], &[]);
    assert_ne!(code, Some(0));
    assert!(err.contains("does not exist"), "{err}");
}

#[tokio::test]
async fn sigterm_exits_cleanly() {
    let s = Server::builder().start();
    assert_eq!(s.get("/health").await.status(), 200);
    assert_eq!(s.terminate(), Some(0));
}

#[tokio::test]
async fn bare_binary_serves_with_environment_configuration() {
    // `textile` with no sub-command is `textile serve`; configured here only through TEXTILE_*.
    let data = common::shared_data_dir();
    let s = Server::builder()
        .bare()
        .env("TEXTILE_BIND", "127.0.0.1:0")
        .env("TEXTILE_DATA_DIR", data.to_str().unwrap())
        .start();
    assert_eq!(s.json("/ready").await["status"], "ready");
    assert_eq!(s.get("/tiles/brick/7/0/0.png").await.status(), 200);
}
