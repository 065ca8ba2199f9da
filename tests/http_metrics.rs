//! `/metrics` in the Prometheus text format and the `textile loadtest` tool against the real
//! server: every pattern runs, reports statuses and the server's cache hit ratio, and refuses
//! non-loopback targets.

mod common;

use std::process::Command;

use common::{binary, Server};

fn value(text: &str, series: &str) -> f64 {
    text.lines()
        .find_map(|l| l.strip_prefix(series).and_then(|r| r.trim().parse().ok()))
        .unwrap_or_else(|| panic!("no series {series} in\n{text}"))
}

#[tokio::test]
async fn metrics_count_requests_cache_and_syntheses() {
    let s = Server::builder().start();
    for _ in 0..3 {
        assert_eq!(s.get("/tiles/gravel/7/4/4.png?mode=mosaic").await.status(), 200);
    }
    assert_eq!(s.get("/tiles/gravel/7/4/5.png").await.status(), 200);
    assert_eq!(s.get("/tiles/gravel/7/x/5.png").await.status(), 400);
    let r = s.get("/metrics").await;
    assert_eq!(r.status(), 200);
    assert!(r.headers()["content-type"].to_str().unwrap().starts_with("text/plain; version=0.0.4"));
    let text = r.text().await.unwrap();
    assert_eq!(value(&text, r#"textile_http_requests_total{route="/tiles/{id}/{z}/{x}/{y}",status="200"}"#), 4.0);
    assert_eq!(value(&text, r#"textile_http_requests_total{route="/tiles/{id}/{z}/{x}/{y}",status="400"}"#), 1.0);
    assert_eq!(value(&text, "textile_cache_hits_total"), 2.0);
    assert_eq!(value(&text, "textile_cache_misses_total"), 2.0);
    assert_eq!(value(&text, r#"textile_syntheses_total{mode="mosaic"}"#), 1.0);
    assert_eq!(value(&text, r#"textile_syntheses_total{mode="synth"}"#), 1.0);
    assert!(value(&text, "textile_cache_bytes") > 0.0);
    assert_eq!(value(&text, "textile_syntheses_in_flight"), 0.0);
    assert!(text.contains("textile_http_request_duration_seconds_bucket"));
    assert!(text.contains("textile_shed_total"));
    assert!(text.contains("textile_cache_evictions_total"));
    // Computation ratio parts. One native synth tile at even coordinates (m = 128) computes the
    // padded pyramid of design note §1.6 with level 3 uncorrected (core's FIRST_CORRECTED_LEVEL)
    // and one pass more at level 5 (L − 2, core's plan::Schedules), for the tile grown by the
    // seam blend's 3 texels a side (262², core's synth::seams): 126 295 pixels for 65 536
    // delivered (ratio 1.93; 120 913 for the bare 256²). One mosaic tile evaluates
    // its tile grown by the 4-pixel smoothing margin, 264² = 69 696.
    assert_eq!(value(&text, r#"textile_pixels_synthesized_total{mode="synth"}"#), 126_295.0);
    assert_eq!(value(&text, r#"textile_pixels_delivered_total{mode="synth"}"#), 65_536.0);
    assert_eq!(value(&text, r#"textile_pixels_synthesized_total{mode="mosaic"}"#), 69_696.0);
    assert_eq!(value(&text, r#"textile_pixels_delivered_total{mode="mosaic"}"#), 65_536.0);
    // The right-hand neighbour reuses the first tile's coarse levels and shared padding from the
    // pyramidal cache: it synthesizes less than a cold tile (126 295), at least its own pixels.
    assert_eq!(s.get("/tiles/gravel/7/5/5.png").await.status(), 200);
    let text = s.get("/metrics").await.text().await.unwrap();
    let second = value(&text, r#"textile_pixels_synthesized_total{mode="synth"}"#) - 126_295.0;
    assert!((65_536.0..110_000.0).contains(&second), "neighbour synthesized {second}");
    assert!(value(&text, "textile_level_cache_hits_total") > 0.0);
    assert!(value(&text, "textile_level_cache_bytes") > 0.0);
    assert!(text.contains("textile_level_cache_evictions_total"));
}

/// The JSON report of `textile loadtest` against `base` (40 requests, within 300 s) with `args`.
fn loadtest_json(base: &str, args: &[&str]) -> serde_json::Value {
    let out = Command::new(binary())
        .args(["loadtest", "--url", base, "--requests", "40", "--duration", "300", "--json"])
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON report")
}

#[test]
fn loadtest_runs_every_pattern_and_reports() {
    let s = Server::builder().start();
    let dir = tempfile::tempdir().unwrap();
    let replay = dir.path().join("urls.txt");
    std::fs::write(&replay, format!("# recorded\n/tiles/grass/7/0/0.png\n{}/tiles/grass/6/1/1.png?seed=2\n", s.base))
        .unwrap();
    // One request at a time, the pan's computation ratio is a property of the pyramidal cache alone:
    // native tiles computed alone cost ≈ 1.84 (design note §1.6) and neighbours share coarse levels
    // and padding. (Concurrent neighbours may both compute a level they share, so with concurrency
    // the ratio also depends on timing; brick has not been requested yet, so its levels start cold.)
    let report = loadtest_json(&s.base, &["--texture", "brick", "--pattern", "pan", "--concurrency", "1"]);
    let ratio = report["server_computation_ratio"].as_f64().unwrap();
    assert!((1.0..1.45).contains(&ratio), "sequential pan computation ratio {ratio}");
    let replay = replay.to_str().unwrap();
    for pattern in ["pan", "zoom", "random", "hot", "replay"] {
        let report = loadtest_json(
            &s.base,
            &["--texture", "grass", "--pattern", pattern, "--concurrency", "4", "--file", replay],
        );
        assert_eq!(report["requests"], 40, "{pattern}: {report}");
        assert_eq!(report["status"]["200"], 40, "{pattern}: {report}");
        assert!(report["latency_ms"]["p99"].as_f64().unwrap() >= report["latency_ms"]["p50"].as_f64().unwrap());
        if pattern == "pan" {
            // Four at a time, neighbours still share most of their levels: clearly under the
            // 1.84 of tiles computed alone, whatever the timing.
            let ratio = report["server_computation_ratio"].as_f64().unwrap();
            assert!((1.0..1.7).contains(&ratio), "pan computation ratio {ratio}");
        }
        let ratio = report["server_cache_hit_ratio"].as_f64().unwrap();
        if pattern == "hot" || pattern == "replay" {
            // Concurrent first requests of a URL are coalesced and count as misses.
            assert!(ratio >= 0.85, "{pattern}: hit ratio {ratio}");
        }
        if pattern == "pan" {
            assert!(ratio < 0.5, "pan requests new tiles: {ratio}");
        }
    }
    // A landscape takes every pattern too; its layers' syntheses are counted by their modes.
    std::fs::write(dir.path().join("meadow.txt"), "/tiles/meadow/7/0/0.png\n/tiles/meadow/6/1/1.png?seed=2\n").unwrap();
    let replay = dir.path().join("meadow.txt");
    for pattern in ["pan", "zoom", "random", "hot", "replay"] {
        let report = loadtest_json(
            &s.base,
            &["--texture", "meadow", "--pattern", pattern, "--concurrency", "4", "--file", replay.to_str().unwrap()],
        );
        assert_eq!(report["status"]["200"], 40, "meadow {pattern}: {report}");
        if pattern == "pan" {
            let ratio = report["server_computation_ratio"].as_f64().expect("a landscape's computation ratio");
            assert!((1.0..2.5).contains(&ratio), "meadow pan computation ratio {ratio}");
        }
    }
    let text = Command::new(binary())
        .args(["loadtest", "--url", &s.base, "--texture", "grass", "--pattern", "hot", "--requests", "5"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&text.stdout);
    assert!(stdout.contains("req/s") && stdout.contains("p99") && stdout.contains("cache hit ratio"), "{stdout}");
    let far = Command::new(binary()).args(["loadtest", "--url", "http://192.168.1.1:8080"]).output().unwrap();
    assert!(!far.status.success());
    assert!(String::from_utf8_lossy(&far.stderr).contains("only targets this machine"));
}

/// The loadtest's run control and accounting: `--duration` alone ends the run at that time
/// however many requests that takes, `--requests` alone at that count; requests still in
/// flight at the deadline are counted as timed out, so every request started is in the report;
/// an undefined server ratio is null ("n/a"), not a number.
#[test]
fn loadtest_bounds_end_runs_alone_and_every_request_is_counted() {
    let s = Server::builder().start();
    let run = |args: &[&str]| {
        let out = Command::new(binary()).args(["loadtest", "--url", &s.base, "--json"]).args(args).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice::<serde_json::Value>(&out.stdout).expect("JSON report")
    };
    // Hot tiles at 16 connections: far more than the old default of 1000 requests in 2 s would
    // have ended the run early; now the duration alone ends it.
    let timed = run(&["--texture", "grass", "--pattern", "hot", "--concurrency", "16", "--duration", "2"]);
    let secs = timed["seconds"].as_f64().unwrap();
    assert!((1.5..3.5).contains(&secs), "--duration 2 ran {secs} s: {timed}");
    let counted = run(&["--texture", "grass", "--pattern", "hot", "--concurrency", "4", "--requests", "50"]);
    assert_eq!(counted["requests"], 50, "{counted}");
    // A hot tile, served from the cache: no synthesis in this run, so no computation ratio.
    assert!(counted["server_computation_ratio"].is_null(), "{counted}");
    // Cold synth tiles at 8 connections for 1 s: requests are in flight at the deadline. They
    // are counted as timed out, and the statuses add up to every request started.
    let rt = tokio::runtime::Runtime::new().unwrap();
    let tiles_counted = || {
        let text =
            rt.block_on(async { reqwest::get(format!("{}/metrics", s.base)).await.unwrap().text().await.unwrap() });
        text.lines()
            .filter(|l| l.starts_with("textile_http_requests_total{route=\"/tiles/{id}/{z}/{x}/{y}\""))
            .map(|l| l.rsplit(' ').next().unwrap().parse::<f64>().unwrap())
            .sum::<f64>() as u64
    };
    let before = tiles_counted();
    let busy = run(&["--texture", "brick", "--pattern", "random", "--concurrency", "8", "--duration", "1"]);
    let timed_out = busy["timed_out"].as_u64().unwrap();
    assert!(timed_out >= 1, "{busy}");
    let sum: u64 = busy["status"].as_object().unwrap().values().map(|v| v.as_u64().unwrap()).sum();
    assert_eq!(sum, busy["requests"].as_u64().unwrap(), "{busy}");
    assert_eq!(busy["status"]["timed_out"].as_u64(), Some(timed_out));
    // Against the server's own count: every request the loader saw answered, the server counted;
    // beyond those, at most the timed-out ones (the server counts an answer it finishes, and a
    // request whose client went away at the deadline may or may not be finished).
    std::thread::sleep(std::time::Duration::from_secs(2));
    let counted = tiles_counted() - before;
    let requests = busy["requests"].as_u64().unwrap();
    assert!((requests - timed_out..=requests).contains(&counted), "server counted {counted}: {busy}");
    // Bad bounds are clear errors.
    let bad = Command::new(binary()).args(["loadtest", "--url", &s.base, "--duration", "0"]).output().unwrap();
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("--duration"));
}
