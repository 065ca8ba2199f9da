//! `textile loadtest`: drive a running textile server on this machine with scripted request
//! patterns ([`pattern`]) — closed loop at a fixed concurrency, or open model at a fixed or
//! ramped arrival rate with latency corrected for coordinated omission ([`drive`]) — after an
//! optional warm-up, ended by a request count, a duration (requests still in flight then are
//! counted as timed out), or whichever comes first; then report throughput, HDR latency
//! percentiles, status counts, bytes, a per-second timeline and the server's figures for this run
//! only (the difference of /metrics before and after; "n/a" when a ratio is undefined)
//! ([`report`]), optionally as an SVG chart ([`plot`]); with `--verify`, every answer is checked
//! against reference digests ([`verify`]). Loopback targets only.

mod drive;
mod pattern;
mod plot;
mod report;
mod verify;

use std::io::{IsTerminal, Write};
use std::net::IpAddr;
use std::sync::{Arc, Mutex};

use serde_json::json;

use crate::cmd::args::{CliResult, LoadtestArgs};
use drive::{Load, Model, Phase};

fn loopback(url: &reqwest::Url) -> bool {
    match url.host() {
        Some(url::Host::Domain(d)) => d == "localhost",
        Some(url::Host::Ipv4(ip)) => IpAddr::V4(ip).is_loopback(),
        Some(url::Host::Ipv6(ip)) => IpAddr::V6(ip).is_loopback(),
        None => false,
    }
}

fn scrape(text: &str, name: &str) -> f64 {
    text.lines().find_map(|l| l.strip_prefix(name).and_then(|r| r.trim().parse().ok())).unwrap_or(0.0)
}

/// A run's length when neither `--requests` nor `--duration` is given, in seconds.
const DEFAULT_SECONDS: f64 = 30.0;
/// The longest run, in seconds (what bounds a run given only `--requests`).
const MAX_SECONDS: f64 = 3600.0;
/// How late a send may be before the report says the client could not keep up.
const LATE: std::time::Duration = std::time::Duration::from_millis(10);
/// Longest wait for the server's `/metrics` before and after the run: a run ends at its
/// deadline plus at most this (twice: before it starts and after it ends).
const METRICS_GRACE: std::time::Duration = std::time::Duration::from_secs(2);

/// A ratio of the report as text: three decimals, or "n/a" when undefined.
fn na(v: &serde_json::Value) -> String {
    v.as_f64().map_or("n/a".to_string(), |r| format!("{r:.3}"))
}

/// `--rate-ramp FROM:TO`: two rates, not both zero.
fn ramp(s: &str) -> Result<(f64, f64), String> {
    let bad =
        || format!("--rate-ramp {s}: expected FROM:TO, two rates in requests per second (0..=100000, not both 0)");
    let (a, b) = s.split_once(':').ok_or_else(bad)?;
    let (a, b): (f64, f64) = (a.trim().parse().map_err(|_| bad())?, b.trim().parse().map_err(|_| bad())?);
    if !(0.0..=MAX_RATE).contains(&a) || !(0.0..=MAX_RATE).contains(&b) || a + b == 0.0 {
        return Err(bad());
    }
    Ok((a, b))
}

/// The highest arrival rate, in requests per second.
const MAX_RATE: f64 = 100_000.0;

/// The issuing model of the arguments, or why they contradict each other; `entries`: a replay's
/// lines (for `--speed`).
fn model(a: &LoadtestArgs, entries: &[pattern::Entry]) -> Result<Model, String> {
    if let Some(x) = a.speed {
        if a.rate.is_some() || a.rate_ramp.is_some() {
            return Err("--speed plays a log at its own pace: it contradicts --rate and --rate-ramp".into());
        }
        if !(x > 0.0 && x <= 1000.0) {
            return Err("--speed must be more than 0 and at most 1000".into());
        }
        let Some(first) = entries.first().and_then(|e| e.at) else {
            return Err("--speed needs a replay file of access-log lines (their timestamps set the pace)".into());
        };
        let times = entries.iter().map(|e| e.at.map(|t| (t - first).max(0.0) / x)).collect::<Option<Vec<f64>>>();
        let mut times = times.ok_or("--speed: every line of the file needs a timestamp (access-log lines only)")?;
        // Lines are sorted by time when read; equal times keep file order.
        for i in 1..times.len() {
            times[i] = times[i].max(times[i - 1]);
        }
        return if a.honor_retry_after {
            Err("--honor-retry-after is for the closed loop: a log replayed at its pace does not wait for answers"
                .into())
        } else {
            Ok(Model::Timed(Arc::new(times)))
        };
    }
    let open = match (a.rate, &a.rate_ramp) {
        (Some(_), Some(_)) => return Err("--rate and --rate-ramp contradict each other: give one".into()),
        (Some(r), None) if !(r > 0.0 && r <= MAX_RATE) => {
            return Err(format!("--rate must be more than 0 and at most {MAX_RATE} requests per second"))
        }
        (Some(r), None) => Some((r, r)),
        (None, Some(s)) if a.duration.is_none() => {
            return Err(format!("--rate-ramp {s} ramps over the run: it needs --duration"))
        }
        (None, Some(s)) => Some(ramp(s)?),
        (None, None) => None,
    };
    match open {
        Some(_) if a.honor_retry_after => {
            Err("--honor-retry-after is for the closed loop: an open model's arrivals do not wait for answers".into())
        }
        Some((from, to)) => Ok(Model::Open { from, to }),
        None => Ok(Model::Closed { polite: a.honor_retry_after }),
    }
}

/// Run the load test.
pub fn run(a: LoadtestArgs) -> CliResult {
    let base = reqwest::Url::parse(&a.url).map_err(|e| format!("--url {}: {e}", a.url))?;
    if !loopback(&base) {
        return Err(
            format!("--url {}: loadtest only targets this machine (localhost, 127.0.0.0/8 or ::1)", a.url).into()
        );
    }
    if !(1..=1024).contains(&a.concurrency) {
        return Err("--concurrency must be 1..=1024".into());
    }
    if a.requests.is_some_and(|n| !(1..=10_000_000).contains(&n)) {
        return Err("--requests must be 1..=10000000".into());
    }
    if a.duration.is_some_and(|d| !(d > 0.0 && d <= 3600.0)) {
        return Err("--duration must be more than 0 and at most 3600 seconds".into());
    }
    if a.warmup.is_some_and(|d| !(d > 0.0 && d <= 3600.0)) {
        return Err("--warmup must be more than 0 and at most 3600 seconds".into());
    }
    if a.pattern != "replay" && (a.once || a.speed.is_some() || !a.replay_status.is_empty()) {
        return Err("--once, --speed and --replay-status are for --pattern replay".into());
    }
    let (entries, left_out) = match (&a.pattern[..], &a.file) {
        ("replay", Some(f)) => pattern::replay_lines(f, &a.replay_status)?,
        ("replay", None) => return Err("--pattern replay needs --file".into()),
        _ => Default::default(),
    };
    let model = model(&a, &entries)?;
    let once = a.once || a.speed.is_some();
    let verifying = a.verify || a.expect.is_some() || a.record.is_some();
    if verifying && a.pattern != "replay" && a.requests.is_none() {
        return Err(format!(
            "--verify needs the run's URLs before it starts: give --requests N (the first N of pattern '{}'), or --pattern replay",
            a.pattern
        )
        .into());
    }
    let mut references = match &a.expect {
        Some(f) => verify::read(f)?,
        None => verify::References::new(),
    };
    // Each bound ends the run alone; with neither, 30 s (a replay played once: until its end).
    let (max_requests, duration) = match (a.requests, a.duration) {
        (None, None) if once => (u64::MAX, MAX_SECONDS),
        (None, None) => (u64::MAX, DEFAULT_SECONDS),
        (Some(n), None) => (n, MAX_SECONDS),
        (n, Some(d)) => (n.unwrap_or(u64::MAX), d),
    };
    // The paths alone (the times, if any, are in the model): no second copy of them.
    let lines: Vec<Box<str>> = entries.into_iter().map(|e| e.path).collect();
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    rt.block_on(async move {
        // Redirects are answers to count (3xx), never followed: a run stays on its server.
        let client = reqwest::Client::builder()
            .pool_max_idle_per_host(a.concurrency)
            .redirect(reqwest::redirect::Policy::none())
            .build()?;
        let root = a.url.trim_end_matches('/').to_string();
        let meta: serde_json::Value = client
            .get(pattern::target(&base, &format!("/textures/{}", a.texture)))
            .send()
            .await
            .map_err(|e| format!("cannot reach {root}: {e}"))?
            .json()
            .await?;
        let native = meta["native_zoom"].as_u64().ok_or_else(|| format!("no texture '{}' at {root}", a.texture))? as u32;
        let minzoom = meta["minzoom"].as_u64().unwrap_or(0) as u32;
        let paths = Arc::new(Mutex::new(pattern::pattern(
            &a.pattern,
            &a.texture,
            native,
            minzoom,
            &a.query,
            (lines, once),
            a.seed,
        )));
        let progress = !a.json && std::io::stderr().is_terminal();
        let make = |references: Option<Arc<verify::References>>| {
            Arc::new(Load {
                client: client.clone(),
                root: base.clone(),
                paths: paths.clone(),
                concurrency: a.concurrency,
                model: model.clone(),
                progress,
                references,
                mismatches: Default::default(),
                unchecked: Default::default(),
            })
        };
        // The warm-up runs the same load; nothing of it enters the figures.
        if let Some(w) = a.warmup {
            let _ = make(None).run(Phase { seconds: w, max_requests: u64::MAX }).await;
        }
        // Verification: the run plays known paths (a replay's lines, or the next N of the
        // pattern); answers are checked during the run against the references `--expect` gave,
        // and against those fetched after the run (one at a time, nothing else running) for the
        // rest — after, so that fetching them does not warm the cache the run measures.
        let known = if verifying {
            if a.pattern != "replay" {
                let mut p = paths.lock().unwrap_or_else(|e| e.into_inner());
                let drawn: Vec<String> = p.by_ref().take(max_requests as usize).collect();
                *p = Box::new(drawn.into_iter());
            }
            Some(Arc::new(references.clone()))
        } else {
            None
        };
        let load = make(known);
        // The server's counters around the run, each asked for at most METRICS_GRACE: a stalled
        // server must not hold the run past its deadline (its figures are then unknown).
        let metrics = || async {
            let get = async { client.get(format!("{root}/metrics")).send().await?.text().await };
            tokio::time::timeout(METRICS_GRACE, get).await.ok().and_then(Result::ok)
        };
        let metrics_before = metrics().await;
        let out = load.run(Phase { seconds: duration, max_requests }).await;
        let metrics_after = metrics().await;
        let server_known = metrics_before.is_some() && metrics_after.is_some();
        let (before, after) = (metrics_before.unwrap_or_default(), metrics_after.unwrap_or_default());
        let (all, elapsed) = (&out.samples, out.seconds);
        let sent = all.iter().filter(|s| s.was_sent()).count();
        let d = |n: &str| scrape(&after, n) - scrape(&before, n);
        let (hits, misses) = (d("textile_cache_hits_total"), d("textile_cache_misses_total"));
        let open = !matches!(model, Model::Closed { .. });
        // The figure the report leads with: from the intended send time in the open model.
        let leading = report::latencies(all, false, open);
        let lat = report::percentiles(&leading);
        let ok = report::percentiles(&report::latencies(all, true, open));
        let statuses = report::statuses(all);
        let bytes: u64 = all.iter().map(|r| r.bytes as u64).sum();
        // Pixels synthesized at all levels ÷ pixels delivered, over the syntheses of this run.
        let px = |kind: &str| {
            textile_core::MODE_NAMES.iter().map(|m| d(&format!("textile_pixels_{kind}_total{{mode=\"{m}\"}}"))).sum::<f64>()
        };
        let (synthesized, delivered) = (px("synthesized"), px("delivered"));
        // Undefined (no synthesis, no lookup in this run): null, printed "n/a".
        let ratio = (delivered > 0.0).then(|| synthesized / delivered);
        let late = all.iter().filter(|s| s.sent.saturating_sub(s.intended) > LATE).count();
        let mut report = json!({
            "pattern": a.pattern, "texture": a.texture, "concurrency": a.concurrency,
            "model": if open { "open" } else { "closed" },
            "requests": sent, "seconds": elapsed, "requests_per_second": sent as f64 / elapsed,
            "warmup_seconds": a.warmup,
            "latency_ms": lat, "latency_ms_200": ok,
            "status": statuses, "bytes": bytes,
            "timed_out": statuses.get("timed_out").copied().unwrap_or(0),
            "server_cache_hit_ratio": (server_known && hits + misses > 0.0).then(|| hits / (hits + misses)),
            "server_syntheses": server_known.then(|| textile_core::MODE_NAMES.iter().map(|m| d(&format!("textile_syntheses_total{{mode=\"{m}\"}}"))).sum::<f64>() as u64),
            "server_computation_ratio": ratio.filter(|_| server_known),
            "server_metrics": server_known,
            // A row per second of the run as asked (its measured end is a hair later).
            "timeline": report::timeline(all, duration.min(elapsed), open),
        });
        if a.pattern == "replay" {
            report["replay_left_out"] = left_out.json();
        }
        if open {
            report["rate"] = match &model {
                Model::Open { from, to } => json!({ "from": from, "to": to }),
                _ => json!({ "log_speed": a.speed }),
            };
            report["latency_ms_uncorrected"] = report::percentiles(&report::latencies(all, false, false));
            report["late_sends"] = json!(late);
            report["unsent"] = json!(out.unsent);
            report["offered"] = json!(all.len());
        }
        // The answers of paths that had no reference, against the references fetched now.
        let unchecked = std::mem::take(&mut *load.unchecked.lock().unwrap_or_else(|e| e.into_inner()));
        let mut late_mismatched = 0u64;
        if verifying {
            verify::fetch(&client, &base, unchecked.keys().cloned(), &mut references).await?;
            let mut m = load.mismatches.lock().unwrap_or_else(|e| e.into_inner());
            for (path, digests) in &unchecked {
                let Some(want) = references.get(path) else { continue };
                for (got, n) in digests.iter().filter(|(got, _)| *got != want) {
                    m.entry(path.clone()).or_insert_with(|| (want.clone(), got.clone(), 0)).2 += n;
                    late_mismatched += n;
                }
            }
            if let Some(f) = &a.record {
                verify::write(f, &root, &references)?;
            }
        }
        let mismatches = load.mismatches.lock().unwrap_or_else(|e| e.into_inner()).clone();
        let mismatched: u64 = all.iter().filter(|s| s.mismatch).count() as u64 + late_mismatched;
        if verifying {
            report["verified"] = json!(all.iter().filter(|s| s.status == 200).count());
            report["mismatched"] = json!(mismatched);
            report["mismatches"] = mismatches
                .iter()
                .map(|(p, (want, got, n))| json!({ "url": format!("{root}{p}"), "expected": want, "got": got, "count": n }))
                .collect();
        }
        if let Some(f) = &a.plot {
            let title = format!("textile loadtest: {} on '{}', {}", a.pattern, a.texture, report["model"].as_str().unwrap_or(""));
            plot::write(f, &title, report["timeline"].as_array().map(Vec::as_slice).unwrap_or(&[]))?;
        }
        if let Some(f) = &a.histogram {
            let text = report::distribution_text(&leading);
            textile_core::files::write_atomic(f, text.as_bytes()).map_err(|e| format!("{}: {e}", f.display()))?;
        }
        // Write the report; a reader that went away (a closed pipe) is not an error worth a panic.
        let mut w = std::io::stdout().lock();
        // A mismatch fails the command, after the report.
        let verdict: Result<(), Box<dyn std::error::Error>> = match mismatched {
            0 => Ok(()),
            n => Err(format!(
                "{n} answers differed from their reference: {}",
                mismatches.keys().map(|p| format!("{root}{p}")).collect::<Vec<_>>().join(", ")
            )
            .into()),
        };
        if a.json {
            let _ = writeln!(w, "{}", serde_json::to_string_pretty(&report)?);
            return verdict;
        }
        let how = match &model {
            Model::Closed { .. } => format!("{} connections", a.concurrency),
            Model::Open { from, to } if from == to => format!("{from} req/s offered, {} connections", a.concurrency),
            Model::Open { from, to } => format!("{from}→{to} req/s offered, {} connections", a.concurrency),
            Model::Timed(_) => format!("the log's pace × {}, {} connections", a.speed.unwrap_or(1.0), a.concurrency),
        };
        let _ = writeln!(
            w,
            "{} ({how}) on '{}' for {:.2}s: {} requests, {:.1} req/s, {:.1} MiB",
            a.pattern,
            a.texture,
            elapsed,
            sent,
            sent as f64 / elapsed,
            bytes as f64 / 1048576.0
        );
        if open {
            let _ = writeln!(w, "latency ms from intended send (corrected): {}", report::line(&report["latency_ms"]));
            let _ = writeln!(w, "latency ms from actual send (uncorrected): {}", report::line(&report["latency_ms_uncorrected"]));
        } else {
            let _ = writeln!(w, "latency ms: {}", report::line(&report["latency_ms"]));
        }
        if report["latency_ms_200"] != report["latency_ms"] {
            let _ = writeln!(w, "  200 only: {}", report::line(&report["latency_ms_200"]));
        }
        let _ = writeln!(w, "status: {}", statuses.iter().map(|(k, v)| format!("{k}×{v}")).collect::<Vec<_>>().join("  "));
        if let Some(line) = left_out.line() {
            let _ = writeln!(w, "{line}");
        }
        let timed_out = statuses.get("timed_out").copied().unwrap_or(0);
        if open && (timed_out > 0 || out.unsent > 0) {
            let unanswered = timed_out + out.unsent;
            let _ = writeln!(
                w,
                "NO ANSWER for {unanswered} of {} requests offered ({:.0} %): {timed_out} timed out in flight, {} never \
                 sent (every connection was waiting on the server); each counts in the corrected latency at least \
                 until the end of the run",
                all.len(),
                100.0 * unanswered as f64 / all.len().max(1) as f64,
                out.unsent
            );
        }
        if open && late > 0 {
            let _ = writeln!(w, "{late} sends more than {} ms late", LATE.as_millis());
        }
        if server_known {
            let _ = writeln!(
                w,
                "server: cache hit ratio {} ({hits} hits, {misses} misses), {} syntheses, computation ratio {}",
                na(&report["server_cache_hit_ratio"]),
                report["server_syntheses"],
                na(&report["server_computation_ratio"])
            );
        } else {
            let _ = writeln!(w, "server: its /metrics did not answer within {} s: figures unknown", METRICS_GRACE.as_secs());
        }
        if verifying {
            let _ = writeln!(w, "verified: {} answers against their references, {mismatched} differed", report["verified"]);
        }
        verdict

    })
}
