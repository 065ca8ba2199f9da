//! `textile loadtest`: drive a running textile server on this machine with scripted request
//! patterns — `pan` (a 1920×1080 viewport dragged across the plane), `zoom` (in and out around a
//! drifting centre), `random` (uniform tiles and zooms), `hot` (one tile) and `replay FILE` — at a
//! fixed concurrency, ended by a request count, a duration (requests still in flight then are
//! counted as timed out), or whichever comes first; then print throughput, latency percentiles,
//! status counts, bytes and the server's figures for this run only (the difference of /metrics
//! before and after; "n/a" when a ratio is undefined).
//! Loopback targets only.

use std::collections::BTreeMap;
use std::net::IpAddr;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use std::io::Write;

use serde_json::json;

use crate::cmd::args::{CliResult, LoadtestArgs};

type Paths = Box<dyn Iterator<Item = String> + Send>;

/// Tiles of a `w × h` viewport whose top-left is texel-at-zoom `(x, y)`.
fn viewport(x: i64, y: i64, w: i64, h: i64) -> impl Iterator<Item = (i64, i64)> {
    let (tx0, ty0) = (x.div_euclid(256), y.div_euclid(256));
    let (tx1, ty1) = ((x + w - 1).div_euclid(256), (y + h - 1).div_euclid(256));
    (ty0..=ty1).flat_map(move |ty| (tx0..=tx1).map(move |tx| (tx, ty)))
}

/// SplitMix64, for reproducible random patterns.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        textile_core::hash::mix(self.0)
    }
    fn range(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next() % (hi - lo + 1) as u64) as i64
    }
}

/// The request paths of a pattern (endless except `replay`, which cycles its file).
pub fn pattern(name: &str, id: &str, native: u32, minzoom: u32, query: &str, lines: Vec<String>, seed: u64) -> Paths {
    let q = if query.is_empty() { String::new() } else { format!("?{query}") };
    let id = id.to_string();
    let tile = move |z: u32, x: i64, y: i64| format!("/tiles/{id}/{z}/{x}/{y}.png{q}");
    let tile = Arc::new(tile);
    match name {
        "hot" => {
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || t(native, 0, 0)))
        }
        "random" => {
            let mut rng = Rng(seed);
            let t = tile.clone();
            Box::new(std::iter::repeat_with(move || {
                let z = rng.range(minzoom as i64, native as i64) as u32;
                t(z, rng.range(-(1 << 20), 1 << 20), rng.range(-(1 << 20), 1 << 20))
            }))
        }
        "zoom" => {
            // Zoom out from native to minzoom and back in, centred on a point that drifts by
            // three screens per cycle; every step requests the visible tiles.
            let t = tile.clone();
            let zooms: Vec<u32> = (minzoom..=native).rev().chain(minzoom + 1..native).collect();
            Box::new((0i64..).flat_map(move |cycle| {
                let t = t.clone();
                let (cx, cy) = (cycle * 3 * 1920, cycle * 1080);
                zooms.clone().into_iter().flat_map(move |z| {
                    let t = t.clone();
                    let k = native - z;
                    let (x, y) = ((cx >> k) - 960, (cy >> k) - 540);
                    viewport(x, y, 1920, 1080).map(move |(tx, ty)| t(z, tx, ty))
                })
            }))
        }
        "replay" => Box::new(lines.into_iter().cycle()),
        _ => {
            // pan: drag a 1920×1080 viewport right and slightly down, 64 px per frame; request
            // each tile the first time it becomes visible (a browser caches the rest).
            let t = tile.clone();
            let mut seen = std::collections::HashSet::new();
            Box::new((0i64..).flat_map(move |f| {
                let (x, y) = (64 * f - 960, 16 * f - 540);
                viewport(x, y, 1920, 1080)
                    .filter(|c| seen.insert(*c))
                    .map(|(tx, ty)| t(native, tx, ty))
                    .collect::<Vec<_>>()
            }))
        }
    }
}

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
/// The status recorded for a request still in flight at the deadline.
const TIMED_OUT: u16 = u16::MAX;

/// A ratio of the report as text: three decimals, or "n/a" when undefined.
fn na(v: &serde_json::Value) -> String {
    v.as_f64().map_or("n/a".to_string(), |r| format!("{r:.3}"))
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
    // Each bound ends the run alone; with neither, 30 s.
    let (max_requests, duration) = match (a.requests, a.duration) {
        (None, None) => (u64::MAX, DEFAULT_SECONDS),
        (Some(n), None) => (n, MAX_SECONDS),
        (n, Some(d)) => (n.unwrap_or(u64::MAX), d),
    };
    let lines = match (&a.pattern[..], &a.file) {
        ("replay", Some(f)) => {
            let text = std::fs::read_to_string(f).map_err(|e| format!("{}: {e}", f.display()))?;
            let mut v = Vec::new();
            for l in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
                let path = match reqwest::Url::parse(l) {
                    Ok(u) => format!("{}{}", u.path(), u.query().map(|q| format!("?{q}")).unwrap_or_default()),
                    Err(_) if l.starts_with('/') => l.to_string(),
                    Err(_) => return Err(format!("{}: '{l}' is neither a URL nor a /path", f.display()).into()),
                };
                v.push(path);
            }
            if v.is_empty() {
                return Err(format!("{}: no URLs", f.display()).into());
            }
            v
        }
        ("replay", None) => return Err("--pattern replay needs --file".into()),
        _ => Vec::new(),
    };
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    rt.block_on(async move {
        let client = reqwest::Client::builder().pool_max_idle_per_host(a.concurrency).build()?;
        let root = a.url.trim_end_matches('/').to_string();
        let meta: serde_json::Value = client
            .get(format!("{root}/textures/{}", a.texture))
            .send()
            .await
            .map_err(|e| format!("cannot reach {root}: {e}"))?
            .json()
            .await?;
        let native = meta["native_zoom"].as_u64().ok_or_else(|| format!("no texture '{}' at {root}", a.texture))? as u32;
        let minzoom = meta["minzoom"].as_u64().unwrap_or(0) as u32;
        let metrics_before = client.get(format!("{root}/metrics")).send().await?.text().await?;
        let paths = Arc::new(Mutex::new(pattern(&a.pattern, &a.texture, native, minzoom, &a.query, lines, a.seed)));
        let issued = Arc::new(std::sync::atomic::AtomicU64::new(0));
        let started = Instant::now();
        let deadline = started + Duration::from_secs_f64(duration);
        let mut tasks = Vec::new();
        for _ in 0..a.concurrency {
            let (client, paths, issued, root) = (client.clone(), paths.clone(), issued.clone(), root.clone());
            let (max, polite) = (max_requests, a.honor_retry_after);
            tasks.push(tokio::spawn(async move {
                let mut out = Vec::new();
                while Instant::now() < deadline && issued.fetch_add(1, std::sync::atomic::Ordering::Relaxed) < max {
                    let Some(path) = paths.lock().unwrap_or_else(|e| e.into_inner()).next() else { break };
                    let t = Instant::now();
                    let left = deadline.saturating_duration_since(t).max(Duration::from_millis(1));
                    let r = tokio::time::timeout(left, async {
                        let resp = client.get(format!("{root}{path}")).send().await?;
                        let status = resp.status().as_u16();
                        let retry = resp.headers().get("retry-after").and_then(|v| v.to_str().ok()?.parse::<u64>().ok());
                        let n = resp.bytes().await?.len();
                        Ok::<_, reqwest::Error>((status, n, retry))
                    })
                    .await;
                    match r {
                        Ok(Ok((status, n, retry))) => {
                            out.push((t.elapsed(), status, n));
                            if let Some(secs) = retry.filter(|_| polite && status == 503) {
                                let wait = Duration::from_secs(secs.min(60));
                                tokio::time::sleep(wait.min(deadline.saturating_duration_since(Instant::now()))).await;
                            }
                        }
                        Ok(Err(_)) => out.push((t.elapsed(), 0, 0)),
                        // Still in flight at the deadline: counted, as timed out.
                        Err(_) => {
                            out.push((t.elapsed(), TIMED_OUT, 0));
                            break;
                        }
                    }
                }
                out
            }));
        }
        let mut all = Vec::new();
        for t in tasks {
            all.extend(t.await?);
        }
        let elapsed = started.elapsed().as_secs_f64();
        let metrics_after = client.get(format!("{root}/metrics")).send().await?.text().await?;
        let d = |n: &str| scrape(&metrics_after, n) - scrape(&metrics_before, n);
        let (hits, misses) = (d("textile_cache_hits_total"), d("textile_cache_misses_total"));
        // Latencies of the requests that ended (a timed-out one's is unknown: it is counted apart).
        let sorted = |ok_only: bool| {
            let mut v: Vec<f64> = all
                .iter()
                .filter(|r| r.1 != TIMED_OUT && (!ok_only || r.1 == 200))
                .map(|r| r.0.as_secs_f64() * 1e3)
                .collect();
            v.sort_by(f64::total_cmp);
            v
        };
        let pct = |v: &[f64], p: f64| if v.is_empty() { 0.0 } else { v[((v.len() - 1) as f64 * p).round() as usize] };
        let (lat, ok) = (sorted(false), sorted(true));
        let q = |p: f64| pct(&lat, p);
        let mut statuses = BTreeMap::new();
        for r in &all {
            let key = match r.1 {
                0 => "error".to_string(),
                TIMED_OUT => "timed_out".to_string(),
                s => s.to_string(),
            };
            *statuses.entry(key).or_insert(0u64) += 1;
        }
        let bytes: u64 = all.iter().map(|r| r.2 as u64).sum();
        // Pixels synthesized at all levels ÷ pixels delivered, over the syntheses of this run.
        let px = |kind: &str| {
            textile_core::MODE_NAMES.iter().map(|m| d(&format!("textile_pixels_{kind}_total{{mode=\"{m}\"}}"))).sum::<f64>()
        };
        let (synthesized, delivered) = (px("synthesized"), px("delivered"));
        // Undefined (no synthesis, no lookup in this run): null, printed "n/a".
        let ratio = (delivered > 0.0).then(|| synthesized / delivered);
        let report = json!({
            "pattern": a.pattern, "texture": a.texture, "concurrency": a.concurrency,
            "requests": all.len(), "seconds": elapsed, "requests_per_second": all.len() as f64 / elapsed,
            "latency_ms": { "p50": q(0.5), "p90": q(0.9), "p99": q(0.99), "max": q(1.0) },
            "latency_ms_200": { "p50": pct(&ok, 0.5), "p90": pct(&ok, 0.9), "p99": pct(&ok, 0.99), "max": pct(&ok, 1.0) },
            "status": statuses, "bytes": bytes,
            "timed_out": statuses.get("timed_out").copied().unwrap_or(0),
            "server_cache_hit_ratio": (hits + misses > 0.0).then(|| hits / (hits + misses)),
            "server_syntheses": textile_core::MODE_NAMES.iter().map(|m| d(&format!("textile_syntheses_total{{mode=\"{m}\"}}"))).sum::<f64>() as u64,
            "server_computation_ratio": ratio,
        });
        // Write the report; a reader that went away (a closed pipe) is not an error worth a panic.
        let mut out = std::io::stdout().lock();
        if a.json {
            let _ = writeln!(out, "{}", serde_json::to_string_pretty(&report)?);
        } else {
            let _ = writeln!(
                out,
                "{} × {} on '{}' for {:.2}s: {} requests, {:.1} req/s, {:.1} MiB",
                a.pattern,
                a.concurrency,
                a.texture,
                elapsed,
                all.len(),
                all.len() as f64 / elapsed,
                bytes as f64 / 1048576.0
            );
            let _ = writeln!(out, "latency ms: p50 {:.2}  p90 {:.2}  p99 {:.2}  max {:.2}", q(0.5), q(0.9), q(0.99), q(1.0));
            if ok.len() != lat.len() {
                let o = |p| pct(&ok, p);
                let _ =
                    writeln!(out, "  200 only: p50 {:.2}  p90 {:.2}  p99 {:.2}  max {:.2}", o(0.5), o(0.9), o(0.99), o(1.0));
            }
            let _ =
                writeln!(out, "status: {}", statuses.iter().map(|(k, v)| format!("{k}×{v}")).collect::<Vec<_>>().join("  "));
            let _ = writeln!(
                out,
                "server: cache hit ratio {} ({hits} hits, {misses} misses), {} syntheses, computation ratio {}",
                na(&report["server_cache_hit_ratio"]),
                report["server_syntheses"],
                na(&report["server_computation_ratio"])
            );
        }
        Ok::<(), Box<dyn std::error::Error>>(())
    })
}
