//! `textile loadtest`'s open model, figures and verification against the real binary: a fixed
//! `--rate` sends what it offers; with the server stalled (SIGSTOP) the latency corrected for
//! coordinated omission holds the stall and the uncorrected one does not; a ramp rises; a warm-up
//! stays out of the figures; the timeline adds up; the HdrHistogram text file is written;
//! `--verify` passes on a healthy server and names a URL whose reference differs; an access log
//! replays once at its pace; the `--plot` SVG holds every series; contradictory flags are clear
//! errors. (Run control and accounting: `http_metrics.rs`.)

mod common;

use std::process::Command;
use std::time::Duration;

use common::{binary, Server};
use serde_json::Value;

fn loadtest(base: &str, args: &[&str]) -> Value {
    let out = Command::new(binary()).args(["loadtest", "--url", base, "--json"]).args(args).output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON report")
}

fn ms(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn a_fixed_rate_sends_what_it_offers_and_the_timeline_adds_up() {
    let s = Server::builder().start();
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("run.svg");
    let r = loadtest(
        &s.base,
        &[
            "--texture",
            "grass",
            "--pattern",
            "hot",
            "--rate",
            "200",
            "--duration",
            "3",
            "--warmup",
            "0.5",
            "--plot",
            svg.to_str().unwrap(),
        ],
    );
    assert_eq!(r["model"], "open");
    // The chart: valid XML, with every series in its legend and a line per series.
    let text = std::fs::read_to_string(&svg).unwrap();
    let doc = roxmltree::Document::parse(&text).expect("the plot is well-formed XML");
    assert_eq!(doc.root_element().tag_name().name(), "svg");
    let labels: Vec<&str> =
        doc.descendants().filter(|n| n.has_tag_name("text")).filter_map(|n| n.text()).map(str::trim).collect();
    for series in ["p50 latency (ms)", "p99 latency (ms)", "requests/s", "errors/s"] {
        assert!(labels.contains(&series), "{series} not in {labels:?}");
    }
    assert!(doc.descendants().filter(|n| n.has_tag_name("polyline")).count() >= 4, "{text}");
    let n = r["requests"].as_u64().unwrap();
    assert!((570..=630).contains(&n), "--rate 200 for 3 s sent {n}: {r}");
    assert_eq!(r["status"]["200"].as_u64(), Some(n), "{r}");
    assert_eq!(r["unsent"], 0);
    let timeline = r["timeline"].as_array().unwrap();
    assert_eq!(timeline.len(), 3, "{r}");
    assert_eq!(timeline.iter().map(|t| t["requests"].as_u64().unwrap()).sum::<u64>(), n);
    for t in timeline {
        assert!((150..=250).contains(&t["requests"].as_u64().unwrap()), "{t}");
    }
    for k in ["p50", "p90", "p99", "p99_9", "max"] {
        assert!(ms(&r["latency_ms"][k]) >= ms(&r["latency_ms_uncorrected"][k]) - 1e-9, "{k}: {r}");
    }
    // A ramp from 50 to 150 req/s over 2 s offers 200, fewer in the first second than the second.
    let ramp =
        loadtest(&s.base, &["--texture", "grass", "--pattern", "hot", "--rate-ramp", "50:150", "--duration", "2"]);
    let n = ramp["requests"].as_u64().unwrap();
    assert!((190..=210).contains(&n), "ramp sent {n}: {ramp}");
    let t = ramp["timeline"].as_array().unwrap();
    assert!(t[0]["requests"].as_u64() < t[1]["requests"].as_u64(), "{ramp}");
}

/// With the server stopped for a second, a closed loop (or an open one measured from the actual
/// send) waits with the server and hides the stall; measured from the intended send times, the
/// requests that were due during the stall carry it.
#[test]
fn coordinated_omission_is_corrected() {
    let s = Server::builder().start();
    let pid = s.pid().to_string();
    // The tile is cached before the run, and the run is long enough that the stall falls inside
    // it even if the loader takes a second to start on a busy machine.
    let rt = tokio::runtime::Runtime::new().unwrap();
    assert_eq!(rt.block_on(s.get_bytes("/tiles/grass/7/0/0.png")).0, 200);
    let base = s.base.clone();
    let run = std::thread::spawn(move || {
        loadtest(
            &base,
            &["--texture", "grass", "--pattern", "hot", "--rate", "200", "--duration", "5", "--concurrency", "2"],
        )
    });
    std::thread::sleep(Duration::from_millis(1500));
    assert!(Command::new("kill").args(["-STOP", &pid]).status().unwrap().success());
    std::thread::sleep(Duration::from_secs(1));
    assert!(Command::new("kill").args(["-CONT", &pid]).status().unwrap().success());
    let r = run.join().unwrap();
    let (corrected, uncorrected) = (ms(&r["latency_ms"]["p99"]), ms(&r["latency_ms_uncorrected"]["p99"]));
    assert!(corrected >= 500.0, "the corrected p99 holds the 1 s stall: {corrected} ms; {r}");
    assert!(uncorrected < 200.0, "the uncorrected p99 does not: {uncorrected} ms; {r}");
    assert!(r["late_sends"].as_u64().unwrap() > 50, "requests due during the stall were sent late: {r}");
    assert_eq!(r["status"]["200"], r["requests"], "{r}");
}

/// A server stalled past the end of the run (SIGSTOP at 1 s, SIGCONT only after the run should
/// have ended): the run ends at its deadline plus the stated grace; what timed out in flight
/// and what was due but never sent count in the corrected latency at least until the end; every
/// second has its timeline row; the summary says no answer came (issue 62, items 1–3).
#[test]
fn a_stall_past_the_end_shows_in_the_figures_and_does_not_hold_the_run() {
    let s = Server::builder().start();
    let pid = s.pid().to_string();
    let base = s.base.clone();
    let started = std::time::Instant::now();
    let run = std::thread::spawn(move || {
        let args = ["--texture", "grass", "--pattern", "hot", "--rate", "100", "--duration", "4", "--concurrency", "4"];
        let out = Command::new(binary()).args(["loadtest", "--url", &base]).args(args).output().unwrap();
        (out, started.elapsed())
    });
    std::thread::sleep(Duration::from_secs(1));
    assert!(Command::new("kill").args(["-STOP", &pid]).status().unwrap().success());
    // Resumed well after the run's 4 s and its 2 s grace: the run must not wait for it.
    std::thread::sleep(Duration::from_secs(9));
    assert!(Command::new("kill").args(["-CONT", &pid]).status().unwrap().success());
    let (out, took) = run.join().unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(took < Duration::from_secs(9), "the 4 s run returned after {took:?}, when the server resumed: {text}");
    assert!(text.contains("NO ANSWER for"), "the summary hides the stall: {text}");
    assert!(text.contains("did not answer within"), "{text}");
    // The same run as JSON: the figures themselves.
    let s2 = Server::builder().start();
    let pid = s2.pid().to_string();
    let base = s2.base.clone();
    let run = std::thread::spawn(move || {
        let args = ["--texture", "grass", "--pattern", "hot", "--rate", "100", "--duration", "4", "--concurrency", "4"];
        loadtest(&base, &args)
    });
    std::thread::sleep(Duration::from_secs(1));
    assert!(Command::new("kill").args(["-STOP", &pid]).status().unwrap().success());
    std::thread::sleep(Duration::from_secs(9));
    assert!(Command::new("kill").args(["-CONT", &pid]).status().unwrap().success());
    let r = run.join().unwrap();
    let (unsent, timed_out) = (r["unsent"].as_u64().unwrap(), r["timed_out"].as_u64().unwrap());
    assert!(unsent > 150 && timed_out >= 1, "{r}");
    assert_eq!(r["offered"].as_u64().unwrap(), r["requests"].as_u64().unwrap() + unsent, "{r}");
    // Due from about 1 s on and unanswered at 4 s: the corrected p99 is seconds, not the
    // healthy second's milliseconds.
    let p99 = ms(&r["latency_ms"]["p99"]);
    assert!(p99 >= 2000.0, "the corrected p99 is {p99} ms: the stall vanished from it; {r}");
    assert!(ms(&r["latency_ms"]["p50"]) >= 500.0, "{r}");
    let timeline = r["timeline"].as_array().unwrap();
    assert_eq!(timeline.len(), 4, "a row per second of the 4 s run: {r}");
    for t in &timeline[2..] {
        assert_eq!(t["requests"], 0, "nothing sent while stalled: {t}");
        assert!(t["unanswered"].as_u64().unwrap() >= 80, "{t}");
        // Due in second k and unanswered at 4 s: at least (3 − k) s, up to (4 − k) s.
        let k = t["second"].as_f64().unwrap();
        assert!(t["p99_ms"].as_f64().is_some_and(|v| v >= 1000.0 * (3.9 - k)), "{t}");
    }
    assert_eq!(r["server_metrics"], false, "{r}");
}

#[test]
fn warmup_stays_out_of_the_figures_and_the_histogram_is_written() {
    let s = Server::builder().start();
    let dir = tempfile::tempdir().unwrap();
    let hist = dir.path().join("latency.hgrm");
    // A hot tile nobody asked for yet: its one synthesis happens in the warm-up.
    let r = loadtest(
        &s.base,
        &[
            "--texture",
            "grass",
            "--pattern",
            "hot",
            "--query",
            "seed=77",
            "--warmup",
            "0.5",
            "--requests",
            "30",
            "--histogram",
            hist.to_str().unwrap(),
        ],
    );
    assert_eq!(r["model"], "closed");
    assert_eq!(r["requests"], 30, "{r}");
    assert_eq!(r["server_syntheses"], 0, "the warm-up's synthesis is not in the run: {r}");
    assert!(r["server_computation_ratio"].is_null(), "{r}");
    assert_eq!(r["server_cache_hit_ratio"], 1.0, "{r}");
    let text = std::fs::read_to_string(&hist).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
    assert_eq!(head, ["Value", "Percentile", "TotalCount", "1/(1-Percentile)"], "{text}");
    let rows: Vec<Vec<f64>> = lines
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 5, "{text}");
    assert!(rows.windows(2).all(|w| w[0][0] <= w[1][0] && w[0][1] <= w[1][1]), "values and percentiles rise: {text}");
    assert_eq!(rows.last().unwrap()[2], 30.0, "the last row counts every request: {text}");
    assert!(text.contains("#[Max"), "{text}");
}

#[test]
fn contradictory_or_absurd_flags_are_clear_errors() {
    let s = Server::builder().start();
    for (args, says) in [
        (&["--rate", "10", "--rate-ramp", "1:2", "--duration", "1"][..], "--rate and --rate-ramp"),
        (&["--rate-ramp", "1:2"][..], "needs --duration"),
        (&["--rate", "10", "--honor-retry-after"][..], "--honor-retry-after"),
        (&["--rate", "0"][..], "--rate"),
        (&["--rate-ramp", "0:0", "--duration", "1"][..], "--rate-ramp"),
        (&["--rate-ramp", "fast", "--duration", "1"][..], "FROM:TO"),
        (&["--warmup", "0"][..], "--warmup"),
    ] {
        let out = Command::new(binary()).args(["loadtest", "--url", &s.base]).args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{args:?}: {err}");
    }
}

#[test]
fn verification_passes_on_a_healthy_server_and_names_a_mismatch() {
    let s = Server::builder().start();
    let dir = tempfile::tempdir().unwrap();
    let urls = dir.path().join("urls.txt");
    std::fs::write(&urls, "/tiles/grass/7/0/0.png\n/tiles/grass/7/1/0.png?seed=3\n/tiles/brick/6/2/2.png\n").unwrap();
    let refs = dir.path().join("refs.txt");
    let (urls_s, refs_s) = (urls.to_str().unwrap(), refs.to_str().unwrap());
    let common = ["--pattern", "replay", "--file", urls_s, "--requests", "30", "--concurrency", "4"];
    let r = loadtest(&s.base, &[&common[..], &["--verify", "--record", refs_s]].concat());
    assert_eq!(r["verified"], 30, "{r}");
    assert_eq!(r["mismatched"], 0, "{r}");
    // The references are fetched after the run: the measured run made its three tiles itself
    // (fetched before, they would have been cache hits: 0 syntheses).
    assert_eq!(r["server_syntheses"], 3, "{r}");
    let text = std::fs::read_to_string(&refs).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(lines.iter().all(|l| l.starts_with(&s.base) && l.rsplit(' ').next().unwrap().len() == 64), "{text}");
    // One reference wrong: every answer for that URL is a reported error naming it, and the
    // command fails after its report.
    let bad = dir.path().join("bad.txt");
    let wrong = text
        .lines()
        .map(|l| {
            if l.contains("seed=3") {
                format!("{} {}", l.split(' ').next().unwrap(), "0".repeat(64))
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&bad, wrong).unwrap();
    let out = Command::new(binary())
        .args(["loadtest", "--url", &s.base, "--json", "--expect", bad.to_str().unwrap()])
        .args(common)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let r: Value = serde_json::from_slice(&out.stdout).expect("the report is still written");
    assert_eq!(r["mismatched"], 10, "{r}");
    let m = &r["mismatches"][0];
    assert!(m["url"].as_str().unwrap().ends_with("/tiles/grass/7/1/0.png?seed=3"), "{r}");
    assert_eq!(m["expected"], "0".repeat(64));
    assert!(String::from_utf8_lossy(&out.stderr).contains("seed=3"));
    // URLs must be known before the run.
    let out =
        Command::new(binary()).args(["loadtest", "--url", &s.base, "--verify", "--duration", "1"]).output().unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("--requests"));
}

/// An nginx/Apache combined access log: `--once` plays its GET lines (of the statuses asked for)
/// exactly once; `--speed` honours its timestamps; a bad line is an error naming its number.
#[test]
fn access_logs_replay_once_at_their_pace() {
    let s = Server::builder().start();
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("access.log");
    let line = |sec: u32, method: &str, path: &str, status: u16| {
        format!(
            r#"10.0.0.7 - - [02/Dec/2026:10:00:{sec:02} +0100] "{method} {path} HTTP/1.1" {status} 1234 "-" "Mozilla/5.0""#
        )
    };
    let lines = [
        line(0, "GET", "/tiles/grass/7/0/0.png", 200),
        line(1, "GET", "/tiles/grass/7/1/0.png?seed=2", 200),
        line(1, "POST", "/samples/grass", 200),
        line(2, "GET", "/tiles/grass/7/2/0.png", 304),
        line(3, "GET", "/tiles/grass/7/3/0.png", 200),
        line(4, "GET", "/tiles/grass/6/0/0.png", 200),
    ];
    std::fs::write(&log, lines.join("\n")).unwrap();
    let log_s = log.to_str().unwrap();
    // Once, in order: the five GETs (the POST is left out), and no more.
    let r = loadtest(&s.base, &["--pattern", "replay", "--file", log_s, "--once", "--concurrency", "1"]);
    assert_eq!(r["requests"], 5, "{r}");
    assert_eq!(r["status"]["200"], 5, "{r}");
    // A status filter.
    let r = loadtest(&s.base, &["--pattern", "replay", "--file", log_s, "--once", "--replay-status", "200"]);
    assert_eq!(r["requests"], 4, "{r}");
    // At the log's pace: 4 s of log at 4× real time take about 1 s, at 2× about 2 s.
    for (speed, secs) in [("4", 1.0), ("2", 2.0)] {
        let r = loadtest(&s.base, &["--pattern", "replay", "--file", log_s, "--speed", speed]);
        assert_eq!(r["requests"], 5, "{r}");
        let took = r["seconds"].as_f64().unwrap();
        assert!(took >= secs - 0.05 && took < secs + 0.6, "--speed {speed}: {took} s, {r}");
        assert_eq!(r["model"], "open", "{r}");
    }
    // A bad line is left out, counted and named; a file of nothing else is an error.
    let bad = dir.path().join("bad.log");
    std::fs::write(&bad, format!("{}\n{}\nnot a request\n", lines[0], lines[1])).unwrap();
    let r = loadtest(&s.base, &["--pattern", "replay", "--file", bad.to_str().unwrap(), "--once"]);
    assert_eq!(r["requests"], 2, "{r}");
    assert_eq!(r["replay_left_out"]["malformed"], 1, "{r}");
    assert!(r["replay_left_out"]["malformed_lines"][0].as_str().unwrap().contains("bad.log:3:"), "{r}");
    std::fs::write(&bad, "not a request\n").unwrap();
    let out = Command::new(binary())
        .args(["loadtest", "--url", &s.base, "--pattern", "replay", "--file", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no requests to replay") && err.contains("bad.log:1:"), "{err}");
    // --speed needs timestamps; --once is for replays.
    let plain = dir.path().join("plain.txt");
    std::fs::write(&plain, "/tiles/grass/7/0/0.png\n").unwrap();
    for (args, says) in [
        (vec!["--pattern", "replay", "--file", plain.to_str().unwrap(), "--speed", "1"], "timestamps"),
        (vec!["--pattern", "hot", "--once"], "--pattern replay"),
    ] {
        let out = Command::new(binary()).args(["loadtest", "--url", &s.base]).args(&args).output().unwrap();
        assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains(says), "{args:?}");
    }
}

/// A listener on this machine that counts the connections it is offered (and answers none).
fn trap() -> (u16, std::sync::Arc<std::sync::atomic::AtomicUsize>) {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let hits = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let h = hits.clone();
    std::thread::spawn(move || {
        for c in listener.incoming() {
            h.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            drop(c);
        }
    });
    (port, hits)
}

/// A replay stays on `--url`: lines that name another host (a scheme, `@`, `//`) never reach it,
/// redirects are counted, not followed, and lines left out are counted by reason.
#[test]
fn a_replay_stays_on_its_target() {
    let s = Server::builder().start();
    let (port, hits) = trap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("hostile.txt");
    let lines = [
        format!("x:@127.0.0.1:{port}/p"),
        format!("mailto:@127.0.0.1:{port}/p"),
        format!("//127.0.0.1:{port}/p"),
        format!("/@127.0.0.1:{port}/p"),
        "/tiles/grass/7/0/0.png".to_string(),
    ];
    std::fs::write(&file, lines.join("\n")).unwrap();
    let f = file.to_str().unwrap();
    let r = loadtest(&s.base, &["--pattern", "replay", "--file", f, "--once", "--verify"]);
    assert_eq!(r["requests"], 3, "{r}");
    assert_eq!(r["replay_left_out"]["malformed"], 2, "{r}");
    assert!(r["replay_left_out"]["malformed_lines"][0].as_str().unwrap().contains("hostile.txt:1:"), "{r}");
    assert_eq!(r["status"]["200"], 1, "{r}");

    // A server that redirects every tile to the trap: 3xx counted, nothing followed.
    let redirecting = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let base = format!("http://{}", redirecting.local_addr().unwrap());
    std::thread::spawn(move || {
        use std::io::{Read, Write};
        for c in redirecting.incoming() {
            let Ok(mut c) = c else { continue };
            let mut buf = [0u8; 4096];
            let n = c.read(&mut buf).unwrap_or(0);
            let head = String::from_utf8_lossy(&buf[..n]);
            let answer = if head.starts_with("GET /textures/") {
                let body = r#"{"native_zoom": 7, "minzoom": 0}"#;
                format!("HTTP/1.1 200 OK\r\ncontent-type: application/json\r\ncontent-length: {}\r\nconnection: close\r\n\r\n{body}", body.len())
            } else {
                format!("HTTP/1.1 302 Found\r\nlocation: http://127.0.0.1:{port}/stolen\r\ncontent-length: 0\r\nconnection: close\r\n\r\n")
            };
            let _ = c.write_all(answer.as_bytes());
        }
    });
    let plain = dir.path().join("plain.txt");
    std::fs::write(&plain, "/tiles/grass/7/0/0.png\n/tiles/grass/7/1/0.png\n").unwrap();
    let r =
        loadtest(&base, &["--texture", "grass", "--pattern", "replay", "--file", plain.to_str().unwrap(), "--once"]);
    assert_eq!(r["status"]["302"], 2, "{r}");

    // Times out of range (before 1970, after 2100) are left out and counted, the rest played.
    let log = dir.path().join("times.log");
    let mut text: Vec<String> = (0..19)
        .map(|i| {
            format!(
                r#"{{"ts":{},"method":"GET","path":"/tiles/grass/7/{i}/0.png","status":200}}"#,
                1_765_000_000_000u64 + i * 10
            )
        })
        .collect();
    text.push(r#"{"ts":-5000,"method":"GET","path":"/tiles/grass/7/0/1.png","status":200}"#.into());
    text.push(r#"{"ts":253402300799000,"method":"GET","path":"/tiles/grass/7/0/2.png","status":200}"#.into());
    std::fs::write(&log, text.join("\n")).unwrap();
    let r = loadtest(&s.base, &["--pattern", "replay", "--file", log.to_str().unwrap(), "--speed", "10"]);
    assert_eq!(r["requests"], 19, "{r}");
    assert_eq!(r["replay_left_out"]["time_out_of_range"], 2, "{r}");
    assert_eq!(hits.load(std::sync::atomic::Ordering::SeqCst), 0, "nothing reached another server");
}
