//! Hardening of the real binary against hostile or unlucky conditions (issue: hardening):
//! silent, slow and idle connections are closed and never exhaust the descriptors; SIGTERM
//! drains with a deadline even with a half-sent request open, and during start-up stops the
//! loading without announcing ready; exemplar reads are bounded (a FIFO is refused); a data
//! directory that cannot store analyses is survived; stale temporary files are removed.

mod common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::{binary, shared_data_dir, Server};

/// Wait for `child` to exit within `limit`; its exit code.
fn exit_within(child: &mut std::process::Child, limit: Duration) -> Option<i32> {
    let t = Instant::now();
    while t.elapsed() < limit {
        if let Ok(Some(s)) = child.try_wait() {
            return Some(s.code().unwrap_or(-1));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    None
}

fn addr(s: &Server) -> String {
    s.base.trim_start_matches("http://").to_string()
}

/// Whether the server closed `c` (read returns EOF or an error) within `limit`.
fn closed_within(c: &mut TcpStream, limit: Duration) -> bool {
    c.set_read_timeout(Some(limit)).unwrap();
    let mut b = [0u8; 64];
    !matches!(c.read(&mut b), Err(ref e) if e.kind() == std::io::ErrorKind::WouldBlock || e.kind() == std::io::ErrorKind::TimedOut)
}

#[test]
fn silent_slow_and_idle_connections_are_closed() {
    let s = Server::builder().env("TEXTILE_HEADER_READ_TIMEOUT_SECS", "1").start();
    // Silent: connected, nothing sent.
    let mut silent: Vec<TcpStream> = (0..20).map(|_| TcpStream::connect(addr(&s)).unwrap()).collect();
    // Slowloris: a header byte every 200 ms.
    let mut slow = TcpStream::connect(addr(&s)).unwrap();
    let started = Instant::now();
    for b in b"GET /health HTTP/1.1\r\nHost: x\r\nX-Slow: aaaaaaaaaaaaaaaaaaaa".iter() {
        if slow.write_all(&[*b]).is_err() || started.elapsed() > Duration::from_secs(4) {
            break;
        }
        std::thread::sleep(Duration::from_millis(200));
    }
    assert!(closed_within(&mut slow, Duration::from_secs(3)), "slowloris connection still open");
    for c in silent.iter_mut() {
        assert!(closed_within(c, Duration::from_secs(3)), "silent connection still open");
    }
    // Idle keep-alive: one request, then nothing.
    let mut idle = TcpStream::connect(addr(&s)).unwrap();
    idle.write_all(b"GET /health HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    let mut buf = [0u8; 4096];
    let n = idle.read(&mut buf).unwrap();
    assert!(String::from_utf8_lossy(&buf[..n]).starts_with("HTTP/1.1 200"));
    assert!(closed_within(&mut idle, Duration::from_secs(3)), "idle keep-alive connection still open");
}

#[test]
fn more_idle_connections_than_descriptors_do_not_stop_service() {
    // 300 idle connections against a process limited to 256 descriptors.
    let dir = shared_data_dir();
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -n 256 && exec {} serve --bind 127.0.0.1:{port} --data-dir {}", binary(), dir.display()))
        .env("TEXTILE_HEADER_READ_TIMEOUT_SECS", "2")
        .env("TEXTILE_MAX_CONNECTIONS", "200")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let base = format!("127.0.0.1:{port}");
    let health = |limit: Duration| -> bool {
        let t = Instant::now();
        while t.elapsed() < limit {
            if let Ok(mut c) = TcpStream::connect(&base) {
                c.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
                let _ = c.write_all(b"GET /health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
                let mut s = String::new();
                if c.read_to_string(&mut s).is_ok() && s.starts_with("HTTP/1.1 200") {
                    return true;
                }
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        false
    };
    assert!(health(Duration::from_secs(60)), "server never answered");
    let idle: Vec<TcpStream> = (0..300).filter_map(|_| TcpStream::connect(&base).ok()).collect();
    assert!(idle.len() >= 250, "only {} connections", idle.len());
    // Service goes on: at once for requests that find a free slot, else once idle ones time out.
    assert!(health(Duration::from_secs(20)), "no service with 300 idle connections open");
    drop(idle);
    let _ = Command::new("kill").arg(child.id().to_string()).status();
    assert_eq!(exit_within(&mut child, Duration::from_secs(15)), Some(0));
}

#[test]
fn sigterm_with_a_half_sent_request_exits_after_the_drain_deadline() {
    let s = Server::builder()
        .env("TEXTILE_SHUTDOWN_GRACE_SECS", "2")
        .env("TEXTILE_HEADER_READ_TIMEOUT_SECS", "120")
        .start();
    let mut half = TcpStream::connect(addr(&s)).unwrap();
    half.write_all(b"GET /tiles/gravel/7/0/0.png HTTP/1.1\r\nHost: x\r\nX-Half: ").unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let started = Instant::now();
    let code = s.terminate();
    assert_eq!(code, Some(0), "exit code");
    assert!(started.elapsed() < Duration::from_secs(8), "took {:?}", started.elapsed());
}

#[test]
fn sigterm_during_start_up_stops_loading_and_never_announces_ready() {
    // A 512² exemplar analysed from scratch: seconds of work to interrupt.
    let dir = tempfile::tempdir().unwrap();
    let img = image::RgbImage::from_fn(512, 512, |x, y| {
        let v = ((x * 7 + y * 13) ^ (x * y)) as u8;
        image::Rgb([v, v.wrapping_mul(3), 255 - v])
    });
    img.save(dir.path().join("big.png")).unwrap();
    let cfg = dir.path().join("t.toml");
    std::fs::write(&cfg, "[[textures]]\nid = \"big\"\nexemplar = \"big.png\"\n").unwrap();
    let mut child = Command::new(binary())
        .args(["serve", "--bind", "127.0.0.1:0", "--config", cfg.to_str().unwrap(), "--data-dir"])
        .arg(dir.path().join("data"))
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let _ = Command::new("kill").arg(child.id().to_string()).status();
    assert_eq!(exit_within(&mut child, Duration::from_secs(5)), Some(0), "exits promptly and cleanly");
    let mut out = String::new();
    child.stdout.take().unwrap().read_to_string(&mut out).unwrap();
    assert!(!out.contains("textile ready"), "announced ready: {out}");
    assert!(!dir.path().join("data/big.tex").exists(), "no analysis was finished");
}

#[test]
fn a_fifo_exemplar_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.png");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let cfg = dir.path().join("t.toml");
    std::fs::write(&cfg, "[[textures]]\nid = \"pipe\"\nexemplar = \"pipe.png\"\n").unwrap();
    let mut child = Command::new(binary())
        .args(["serve", "--bind", "127.0.0.1:0", "--config", cfg.to_str().unwrap(), "--data-dir"])
        .arg(dir.path().join("data"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let code = exit_within(&mut child, Duration::from_secs(10));
    assert!(code.is_some_and(|c| c != 0), "exits with an error, not a hang: {code:?}");
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    assert!(err.contains("pipe.png") && err.contains("not a regular file"), "{err}");
}

#[tokio::test]
async fn a_data_directory_that_cannot_store_analyses_is_survived() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("plain-file");
    std::fs::write(&file, "not a directory").unwrap();
    // A data directory below a regular file can never be created.
    let s = Server::builder().data_dir(&file.join("data")).start();
    assert_eq!(s.get_bytes("/tiles/gravel/7/0/0.png").await.0, 200);
    let log = s.log_text();
    assert!(log.contains("cannot be stored") && log.contains("memory only"), "{log}");
}

#[tokio::test]
async fn stale_temporary_files_are_removed_at_start() {
    let dir = tempfile::tempdir().unwrap();
    let dead = dir.path().join(".gravel.tex.tmp-4000000");
    let live = dir.path().join(format!(".brick.tex.tmp-{}", std::process::id()));
    std::fs::write(&dead, "half").unwrap();
    std::fs::write(&live, "being written").unwrap();
    let _s = Server::builder().data_dir(dir.path()).start();
    assert!(!dead.exists(), "left by a dead process: removed");
    assert!(live.exists(), "of a live process: kept");
}

#[tokio::test]
async fn hostile_input_is_not_echoed_in_full_and_v_is_carried() {
    let s = Server::builder().start();
    let long = "k".repeat(12_000);
    for (path, status) in [
        (format!("/tiles/gravel/7/0/0.png?{long}=1"), 400),
        (format!("/tiles/gravel/7/0/0.png?mode={long}"), 400),
        (format!("/tiles/{long}/7/0/0.png"), 404),
        (format!("/tiles/gravel/7/{long}/0.png"), 400),
        (format!("/nothing/{long}"), 404),
    ] {
        let (st, body) = s.get_bytes(&path).await;
        assert_eq!(st, status, "{}", &path[..40]);
        assert!(body.len() < 1200, "{} bytes of error for {}", body.len(), &path[..40]);
        let v: serde_json::Value = serde_json::from_slice(&body).expect("JSON error");
        let m = v["message"].as_str().unwrap();
        assert!(m.contains(" bytes)") && !m.contains(&"k".repeat(101)), "{v}");
    }
    // TileJSON carries a caller's `v` after its own version; its tiles accept it.
    let tj = s.json("/tiles/gravel/tilejson.json?v=abc&seed=4").await;
    let tiles = tj["tiles"][0].as_str().unwrap();
    let v = tiles.split("v=").nth(1).unwrap().split('&').next().unwrap();
    assert!(v.len() == 16 && v.ends_with("-abc"), "{tiles}");
    let tile = tiles.replace("{z}", "7").replace("{x}", "1").replace("{y}", "2");
    let path = tile.trim_start_matches(&s.base);
    assert_eq!(s.get_bytes(path).await.0, 200, "{path}");
    let plain = s.json("/tiles/gravel/tilejson.json?seed=4").await;
    assert_ne!(plain["tiles"][0], tj["tiles"][0]);
    assert_eq!(s.get_bytes(&format!("/tiles/gravel/tilejson.json?v={}", "x".repeat(65))).await.0, 400);
}

/// Send raw bytes on a new connection; the status and body of the answer ("" when closed).
fn raw(s: &Server, request: &[u8]) -> (u16, String) {
    let mut c = TcpStream::connect(addr(s)).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let _ = c.write_all(request);
    let mut out = Vec::new();
    let _ = c.read_to_end(&mut out);
    let text = String::from_utf8_lossy(&out).to_string();
    let status = text.split(' ').nth(1).and_then(|v| v.parse().ok()).unwrap_or(0);
    let body = text.split("\r\n\r\n").nth(1).unwrap_or("").to_string();
    (status, body)
}

#[tokio::test]
async fn oversized_requests_get_json_errors() {
    let s = Server::builder().start();
    let long_uri = format!(
        "GET /tiles/gravel/7/0/0.png?seed={} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
        "1".repeat(20_000)
    );
    let (st, body) = raw(&s, long_uri.as_bytes());
    assert_eq!(st, 414, "{body}");
    assert!(body.contains("\"uri_too_long\""), "{body}");
    let many: String = (0..150).map(|i| format!("X-H{i}: v\r\n")).collect();
    let (st, body) = raw(&s, format!("GET /health HTTP/1.1\r\nHost: x\r\n{many}Connection: close\r\n\r\n").as_bytes());
    assert_eq!(st, 431, "{body}");
    assert!(body.contains("\"headers_too_large\""), "{body}");
    let big = "b".repeat(100_000);
    let (st, body) =
        raw(&s, format!("GET /health HTTP/1.1\r\nHost: x\r\nX-Big: {big}\r\nConnection: close\r\n\r\n").as_bytes());
    assert_eq!(st, 431, "{body}");
    assert!(body.contains("\"headers_too_large\""), "{body}");
    // Beyond what hyper parses or reads at all, it answers itself: a request line of 64 KiB or
    // more, headers of a megabyte. The same JSON errors all the same (the client may see the
    // connection reset while it still sends a megabyte), and service goes on.
    for n in [65_535, 70_000, 200_000] {
        let path = format!("/tiles/gravel/7/0/0.png?seed={}", "1".repeat(n));
        let (st, body) = raw(&s, format!("GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n").as_bytes());
        assert_eq!(st, 414, "{n}: {body}");
        let v: serde_json::Value = serde_json::from_str(&body).expect("JSON 414");
        assert_eq!(v["error"], "uri_too_long", "{n}: {v}");
        assert!(v["message"].as_str().unwrap().contains("65535 bytes or more"), "{v}");
    }
    let huge = "h".repeat(1 << 20);
    let (st, body) = raw(&s, format!("GET /health HTTP/1.1\r\nHost: x\r\nX-Huge: {huge}\r\n\r\n").as_bytes());
    assert!(st == 431 || st == 0, "{st}");
    if st == 431 {
        assert!(body.contains("\"headers_too_large\""), "{body}");
    }
    assert_eq!(s.get_bytes("/health").await.0, 200);
}

#[tokio::test]
async fn big_windows_are_rendered_in_pieces_and_leave_a_worker_for_tiles() {
    let s = Server::builder().args(&["--workers", "2"]).env("TEXTILE_MAX_QUEUE_WAIT_MS", "1000").start();
    // A window over 1024² (rendered in pieces) equals the tiles it covers.
    let win = s.image("/windows/gravel.png?x=-256&y=0&w=1280&h=1024&seed=6").await;
    let mut tiles = image::RgbImage::new(1280, 1024);
    for tx in -1..4i64 {
        for ty in 0..4i64 {
            let t = s.image(&format!("/tiles/gravel/7/{tx}/{ty}.png?seed=6")).await;
            common::paste(&mut tiles, &t, (256 * (tx + 1)) as u32, (256 * ty) as u32);
        }
    }
    assert!(win == tiles, "pieces stitched differ from the tiles");
    // Three big windows at once: tiles asked for meanwhile are served, not shed.
    let mut big = Vec::new();
    for seed in 20..23 {
        let c = s.client.clone();
        let url = s.url(&format!("/windows/gravel.png?x=0&y=0&w=3072&h=3072&seed={seed}"));
        big.push(tokio::spawn(async move { c.get(url).send().await.map(|r| r.status().as_u16()).unwrap_or(0) }));
    }
    tokio::time::sleep(Duration::from_millis(500)).await;
    for (i, tx) in (40..44).enumerate() {
        let (st, _) = s.get_bytes(&format!("/tiles/gravel/7/{tx}/{i}.png?seed=9")).await;
        assert_eq!(st, 200, "a tile during big windows");
    }
    for b in big {
        let st = b.await.unwrap();
        assert!(st == 200 || st == 503, "big window: {st}");
    }
}

#[tokio::test]
async fn work_for_a_client_that_went_away_is_cancelled() {
    let s = Server::builder().args(&["--workers", "2"]).start();
    let metric = |text: &str| {
        text.lines()
            .find(|l| l.contains("syntheses_cancelled_total") && !l.starts_with('#'))
            .and_then(|l| l.rsplit(' ').next()?.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    let before = metric(&s.get("/metrics").await.text().await.unwrap());
    // A big window whose client gives up after half a second.
    let impatient = reqwest::Client::builder().timeout(Duration::from_millis(500)).build().unwrap();
    let r = impatient.get(s.url("/windows/gravel.png?x=0&y=0&w=4096&h=4096&seed=77")).send().await;
    assert!(r.is_err(), "the client gave up");
    let t = Instant::now();
    let mut after = before;
    while t.elapsed() < Duration::from_secs(60) && after <= before {
        tokio::time::sleep(Duration::from_millis(200)).await;
        after = metric(&s.get("/metrics").await.text().await.unwrap());
    }
    assert!(after > before, "the abandoned window was not cancelled");
    // And the server serves on.
    assert_eq!(s.get_bytes("/tiles/gravel/7/0/0.png").await.0, 200);
}

#[tokio::test]
async fn the_memory_budget_admits_windows_by_their_size_and_tiles_always() {
    let s = Server::builder()
        .args(&["--workers", "2"])
        .env("TEXTILE_MEMORY_BUDGET_MIB", "64")
        .env("TEXTILE_MAX_QUEUE_WAIT_MS", "300")
        .start();
    let reserved = |h: &serde_json::Value| h["memory"]["reserved_bytes"].as_u64().unwrap();
    let health = s.json("/health").await;
    assert_eq!((health["memory"]["budget_bytes"].as_u64(), reserved(&health)), (Some(64 << 20), 0));
    // An eighth is set aside for the textures' prepared caches; the rest is working memory.
    let working = (64 << 20) - health["memory"]["prepared_caches_bytes"].as_u64().unwrap();
    assert_eq!(working, 56 << 20);
    // A 4096² window (about 110 MiB of work) takes the whole working budget while it runs…
    let (c, url) = (s.client.clone(), s.url("/windows/gravel.png?x=0&y=0&w=4096&h=4096&seed=31"));
    let big = tokio::spawn(async move { c.get(url).send().await.map(|r| r.status().as_u16()).unwrap_or(0) });
    let t = Instant::now();
    while reserved(&s.json("/health").await) == 0 {
        assert!(t.elapsed() < Duration::from_secs(20), "the big window never reserved memory");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    assert_eq!(reserved(&s.json("/health").await), working);
    // …so another window waits for room and, past the queue-wait bound, is shed with 503…
    let r = s.get("/windows/gravel.png?x=9000&y=0&w=2048&h=2048&seed=31").await;
    assert_eq!(r.status(), 503);
    assert!(r.headers().contains_key("retry-after"));
    // …while tiles, which reserve nothing, are served.
    assert_eq!(s.get_bytes("/tiles/gravel/7/50/50.png?seed=31").await.0, 200);
    assert_eq!(big.await.unwrap(), 200);
    // Given back when the work is done: the next window is served.
    assert_eq!(reserved(&s.json("/health").await), 0);
    assert_eq!(s.get_bytes("/windows/gravel.png?x=9000&y=0&w=2048&h=2048&seed=31").await.0, 200);
}
