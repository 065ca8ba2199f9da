//! The access log (`serve --access-log`), through the real binary: a scripted 10 s load is
//! logged, replayed from that log at its own pace against a second server, whose log shows the
//! same requests in the same order at the same offsets; a writer that cannot write (a FIFO no one
//! reads) drops lines, counts them in `/metrics`, and no answer waits for it; SIGHUP reopens the
//! file after it was moved away (logrotate), here in Combined Log Format.

mod common;

use std::io::Read;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use common::{binary, Server};
use serde_json::Value;

/// The JSON lines of a log, parsed.
fn json_lines(p: &Path) -> Vec<Value> {
    let text = std::fs::read_to_string(p).unwrap_or_default();
    text.lines().map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}"))).collect()
}

/// `(arrival ms, path)` of a log's tile requests, in arrival order.
fn tile_requests(p: &Path) -> Vec<(u64, String)> {
    let mut v: Vec<(u64, String)> = json_lines(p)
        .iter()
        .filter(|l| l["path"].as_str().is_some_and(|p| p.starts_with("/tiles/")))
        .map(|l| (l["ts"].as_u64().expect("ts"), l["path"].as_str().unwrap_or_default().to_owned()))
        .collect();
    v.sort();
    v
}

fn loadtest(base: &str, args: &[&str]) {
    let out = Command::new(binary()).args(["loadtest", "--url", base, "--json"]).args(args).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// Wait until `cond` holds, at most `secs`.
fn wait_for(secs: u64, mut cond: impl FnMut() -> bool) -> bool {
    let end = Instant::now() + Duration::from_secs(secs);
    while Instant::now() < end {
        if cond() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    cond()
}

#[test]
fn a_logged_load_replays_at_its_pace_in_the_same_order() {
    let dir = tempfile::tempdir().unwrap();
    let (log_a, log_b) = (dir.path().join("a.log"), dir.path().join("b.log"));
    let a = Server::builder().args(&["--access-log", log_a.to_str().unwrap()]).start();
    loadtest(
        &a.base,
        &["--texture", "gravel", "--pattern", "pan", "--rate", "15", "--duration", "10", "--concurrency", "32"],
    );
    // Lines are written when answers end: wait for the last of the load's.
    let mut settled = 0;
    wait_for(30, || {
        let n = json_lines(&log_a).len();
        let same = n == settled;
        settled = n;
        same && n > 0 && {
            std::thread::sleep(Duration::from_millis(500));
            json_lines(&log_a).len() == n
        }
    });
    let logged = tile_requests(&log_a);
    assert!(logged.len() >= 100, "a 10 s load at 15/s logged {} tile requests", logged.len());
    for l in json_lines(&log_a).iter().filter(|l| l["path"].as_str().is_some_and(|p| p.starts_with("/tiles/"))) {
        assert_eq!(l["method"], "GET", "{l}");
        assert_eq!(l["status"], 200, "{l}");
        assert!(l["bytes"].as_u64().is_some_and(|b| b > 1000), "{l}");
        assert!(l["ms"].as_f64().is_some_and(|ms| ms > 0.0), "{l}");
        assert!(matches!(l["cache"].as_str(), Some("hit" | "miss")), "{l}");
        assert_eq!(l["client"], "127.0.0.1", "{l}");
        assert!(l["time"].as_str().is_some_and(|t| t.ends_with('Z') && t.len() == 24), "{l}");
    }

    let b = Server::builder().args(&["--access-log", log_b.to_str().unwrap()]).start();
    loadtest(
        &b.base,
        &["--texture", "gravel", "--pattern", "replay", "--file", log_a.to_str().unwrap(), "--speed", "1"],
    );
    let complete = wait_for(30, || tile_requests(&log_b).len() >= logged.len());
    let replayed = tile_requests(&log_b);
    assert!(complete, "replayed {} of {} tile requests", replayed.len(), logged.len());
    let paths = |v: &[(u64, String)]| v.iter().map(|(_, p)| p.clone()).collect::<Vec<_>>();
    assert_eq!(paths(&replayed), paths(&logged), "the same requests in the same order");
    let span = (logged[logged.len() - 1].0 - logged[0].0) as f64;
    for (i, (got, want)) in replayed.iter().zip(&logged).enumerate() {
        let (got, want) = ((got.0 - replayed[0].0) as f64, (want.0 - logged[0].0) as f64);
        assert!((got - want).abs() <= 0.05 * span, "request {i} at {got} ms, logged at {want} ms of {span} ms");
    }
    drop((a, b));
}

#[test]
fn a_writer_that_cannot_write_drops_lines_and_no_answer_waits() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("log.fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    // Held open for reading (and writing, so that opening does not wait), never read until the end.
    let mut reader = std::fs::OpenOptions::new().read(true).write(true).open(&fifo).unwrap();
    let s =
        Server::builder().args(&["--access-log", fifo.to_str().unwrap()]).env("TEXTILE_ACCESS_LOG_BUFFER", "1").start();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let metric = |name: &str| -> f64 {
        let text = rt.block_on(async { s.get("/metrics").await.text().await.unwrap() });
        let line = text.lines().find(|l| l.starts_with(name)).unwrap_or_else(|| panic!("no {name} in /metrics"));
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    // 3000 lines are ~500 KB: far beyond the pipe (64 KiB) and the writer's buffer (64 KiB).
    let answered = rt.block_on(async {
        let client = reqwest::Client::builder().timeout(Duration::from_secs(10)).build().unwrap();
        let mut ok = 0;
        for round in 0..30 {
            let mut batch = tokio::task::JoinSet::new();
            for i in 0..100 {
                let (c, url) = (client.clone(), s.url(&format!("/health?round={round}&i={i}")));
                batch.spawn(async move { c.get(url).send().await.is_ok_and(|r| r.status() == 200) });
            }
            while let Some(r) = batch.join_next().await {
                ok += usize::from(r.unwrap_or(false));
            }
        }
        ok
    });
    assert_eq!(answered, 3000, "every answer arrives while the log cannot be written");
    let dropped = metric("textile_access_log_dropped_total");
    let written = metric("textile_access_log_lines_total");
    assert!(dropped >= 1000.0, "dropped {dropped}, written {written}");
    // What did reach the FIFO is whole JSON lines, in the order written.
    let mut buf = vec![0u8; 64 << 10];
    let n = reader.read(&mut buf).unwrap();
    let text = String::from_utf8_lossy(&buf[..n]);
    let first = text.lines().next().unwrap();
    let v: Value = serde_json::from_str(first).unwrap();
    assert!(v["path"].as_str().unwrap().starts_with("/health?round=0"), "{v}");
}

#[test]
fn sighup_reopens_the_log_after_it_was_moved() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("access.log");
    let moved = dir.path().join("access.log.1");
    let s = Server::builder()
        .args(&["--access-log", log.to_str().unwrap()])
        .env("TEXTILE_ACCESS_LOG_FORMAT", "combined")
        .start();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let get = |p: &str| rt.block_on(async { s.get(p).await.status().as_u16() });
    let read = |p: &Path| std::fs::read_to_string(p).unwrap_or_default();
    assert_eq!(get("/health?n=1"), 200);
    assert!(wait_for(10, || read(&log).contains("/health?n=1")), "{}", read(&log));
    let line = read(&log);
    assert!(line.starts_with("127.0.0.1 - - ["), "{line}");
    assert!(line.contains("+0000] \"GET /health?n=1 HTTP/1.1\" 200 "), "{line}");
    std::fs::rename(&log, &moved).unwrap();
    assert!(Command::new("kill").args(["-HUP", &s.pid().to_string()]).status().unwrap().success());
    assert!(wait_for(10, || s.log_text().contains("access log reopened")), "{}", s.log_text());
    assert_eq!(get("/health?n=2"), 200);
    assert!(wait_for(10, || read(&log).contains("/health?n=2")), "the reopened log: {:?}", read(&log));
    assert!(!read(&log).contains("n=1") && !read(&moved).contains("n=2"));
    assert_eq!(get("/health"), 200, "the server lives on after SIGHUP");
}

#[test]
fn lines_a_full_disk_refuses_count_as_dropped() {
    // /dev/full: every write fails with ENOSPC, as on a full disk.
    let s = Server::builder().args(&["--access-log", "/dev/full"]).start();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let metric = |name: &str| -> f64 {
        let text = rt.block_on(async { s.get("/metrics").await.text().await.unwrap() });
        let line = text.lines().find(|l| l.starts_with(name)).unwrap_or_else(|| panic!("no {name} in /metrics"));
        line.rsplit(' ').next().unwrap().parse().unwrap()
    };
    for i in 0..50 {
        assert_eq!(rt.block_on(async { s.get(&format!("/health?i={i}")).await.status().as_u16() }), 200);
    }
    // Every request so far (the 50, and the /metrics reads) is dropped once its write fails.
    assert!(wait_for(10, || metric("textile_access_log_dropped_total") >= 50.0), "dropped lines are counted");
    assert_eq!(metric("textile_access_log_lines_total"), 0.0, "nothing was written");
    assert!(s.log_text().contains("No space left on device"), "{}", s.log_text());
}
