//! Analyses cannot starve the service (the real binary, over HTTP): flat and near-flat uploads
//! are refused with a 400 that says why; a degenerate but valid one (a checkerboard) is analysed
//! in its bounded time on the analysis pool while cold tiles of a ready texture keep their idle
//! latency; DELETE stops an analysis at once, whether it began before or after a restart, and
//! `/ready` stays 200 throughout; an analysis over its time budget fails with a message.

mod common;

use std::path::Path;
use std::time::{Duration, Instant};

use common::Server;

const TOKEN: &str = "test-admin-token-0123456789";

/// The tests of this file run one at a time: the latency one measures a server that nothing
/// else on the machine loads.
static ONE_AT_A_TIME: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

fn admin_server(data: &Path, env: &[(&str, &str)]) -> Server {
    let mut b = Server::builder().data_dir(data).env("TEXTILE_ADMIN_TOKEN", TOKEN);
    for (k, v) in env {
        b = b.env(k, v);
    }
    b.start()
}

fn png(img: &image::RgbImage) -> Vec<u8> {
    let mut buf = std::io::Cursor::new(Vec::new());
    img.write_to(&mut buf, image::ImageFormat::Png).unwrap();
    buf.into_inner()
}

/// A checkerboard of `cell`-pixel squares: two neighbourhoods repeated all over.
fn checkerboard(side: u32, cell: u32) -> Vec<u8> {
    png(&image::RgbImage::from_fn(side, side, |x, y| image::Rgb([((x / cell + y / cell) % 2 * 255) as u8; 3])))
}

/// The built-in brick enlarged to `side`² (its analysis takes seconds at 512²).
fn brick(side: u32) -> Vec<u8> {
    let path = format!("{}/../config/exemplars/brick.png", env!("CARGO_MANIFEST_DIR"));
    let img = image::load_from_memory(&std::fs::read(path).unwrap()).unwrap().to_rgb8();
    png(&image::imageops::resize(&img, side, side, image::imageops::FilterType::Triangle))
}

async fn upload(s: &Server, id: &str, body: Vec<u8>) -> (u16, serde_json::Value) {
    let r = s.client.post(s.url(&format!("/admin/textures?id={id}"))).bearer_auth(TOKEN);
    let r = r.header("content-type", "image/png").body(body).send().await.expect("upload");
    let status = r.status().as_u16();
    (status, r.json().await.unwrap_or(serde_json::Value::Null))
}

async fn delete(s: &Server, id: &str) -> u16 {
    let r = s.client.delete(s.url(&format!("/admin/textures/{id}"))).bearer_auth(TOKEN).send().await;
    r.expect("delete").status().as_u16()
}

/// CPU seconds the process has used (user + system), from /proc.
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).expect("/proc/PID/stat");
    // Fields after the command name (in parentheses): utime and stime are the 12th and 13th.
    let rest = &stat[stat.rfind(')').expect("comm") + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
    // SAFETY: sysconf has no preconditions.
    ticks / unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64
}

/// Wait until `id`'s analysis is under way (progress above 0), or fail after 60 s.
async fn until_analysing(s: &Server, id: &str) {
    let t = Instant::now();
    loop {
        let m = s.json(&format!("/textures/{id}")).await;
        assert_eq!(m["status"], "analysing", "{m}");
        if m["progress"].as_u64().unwrap_or(0) > 0 {
            return;
        }
        assert!(t.elapsed() < Duration::from_secs(60), "no progress within 60 s: {m}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// DELETE `id` mid-analysis: the process's CPU use falls to idle within 2 s, and `/ready`
/// answers 200 throughout (asked every 50 ms from before the DELETE to the end).
async fn delete_and_assert_idle_soon(s: &Server, id: &str) {
    let (client, ready) = (s.client.clone(), s.url("/ready"));
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let poller = {
        let done = done.clone();
        tokio::spawn(async move {
            let mut statuses = Vec::new();
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                statuses.push(client.get(&ready).send().await.map_or(0, |r| r.status().as_u16()));
                tokio::time::sleep(Duration::from_millis(50)).await;
            }
            statuses
        })
    };
    assert_eq!(delete(s, id).await, 204);
    tokio::time::sleep(Duration::from_secs(2)).await;
    let before = cpu_seconds(s.pid());
    tokio::time::sleep(Duration::from_secs(1)).await;
    let used = cpu_seconds(s.pid()) - before;
    assert!(used < 0.25, "the analysis went on after DELETE: {used:.2} CPU s in the second after");
    done.store(true, std::sync::atomic::Ordering::Relaxed);
    let statuses = poller.await.unwrap();
    assert!(statuses.len() >= 20 && statuses.iter().all(|&st| st == 200), "/ready answered {statuses:?}");
}

/// Median and 99th percentile (of 30: the largest) of the latencies of cold synth tiles of
/// gravel: every request another seed, so none shares a cached level with another.
async fn cold_tile_latencies(s: &Server, seeds: std::ops::Range<u32>) -> (Duration, Duration) {
    let mut t = Vec::new();
    for seed in seeds {
        let started = Instant::now();
        let (status, body) = s.get_bytes(&format!("/tiles/gravel/7/3/5.png?seed={seed}")).await;
        t.push(started.elapsed());
        assert_eq!(status, 200, "{}", String::from_utf8_lossy(&body));
    }
    t.sort();
    (t[t.len() / 2], t[t.len() - 1])
}

#[tokio::test]
async fn degenerate_uploads_are_refused_or_bounded_and_tiles_keep_their_latency() {
    let _alone = ONE_AT_A_TIME.lock().await;
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);

    // Flat: all black at 1024², and noise of one level about grey.
    let black = png(&image::RgbImage::new(1024, 1024));
    let mut z = 7u32;
    let near_flat = png(&image::RgbImage::from_fn(256, 256, |_, _| {
        image::Rgb([0; 3].map(|_: u8| {
            z = z.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            127 + (z >> 30) as u8 % 3
        }))
    }));
    for (id, body) in [("black", black), ("nearflat", near_flat)] {
        let (status, answer) = upload(&s, id, body).await;
        assert_eq!(status, 400, "{id}: {answer}");
        assert_eq!(answer["error"], "flat_image", "{id}: {answer}");
        let msg = answer["message"].as_str().unwrap();
        assert!(msg.contains("flat") && msg.contains("standard deviation") && msg.contains("under the 2"), "{msg}");
        common::assert_error(&s, &format!("/textures/{id}"), 404, "unknown_texture").await;
    }
    assert!(!data.path().join("uploads/black.png").exists(), "a refused upload leaves nothing");

    // Idle latency of cold tiles of a ready texture; then the same while a 512² checkerboard is
    // analysed (seconds of work on both cores if it could take them).
    let (idle_median, idle_p99) = cold_tile_latencies(&s, 1000..1030).await;
    let (status, answer) = upload(&s, "checker", checkerboard(512, 8)).await;
    assert_eq!(status, 202, "{answer}");
    until_analysing(&s, "checker").await;
    let (busy_median, busy_p99) = cold_tile_latencies(&s, 2000..2030).await;
    let m = s.json("/textures/checker").await;
    assert_eq!(m["status"], "analysing", "the analysis ran during the measurement: {m}");
    eprintln!(
        "cold tiles: idle median {idle_median:?} p99 {idle_p99:?}; analysing median {busy_median:?} p99 {busy_p99:?}"
    );
    assert!(busy_p99 <= 3 * idle_p99, "p99 {busy_p99:?} while analysing, against {idle_p99:?} idle");
    // The cheap modes of every texture answer too.
    for id in ["gravel", "grass", "brick", "checker"] {
        let (status, _) = s.get_bytes(&format!("/tiles/{id}/7/9/9.png?mode=mosaic")).await;
        assert_eq!(status, 200, "{id}");
    }
    // And it finishes, well within its bound.
    let t = Instant::now();
    loop {
        let m = s.json("/textures/checker").await;
        if m["status"] == "ready" {
            break;
        }
        assert_eq!(m["status"], "analysing", "{m}");
        assert!(t.elapsed() < Duration::from_secs(120), "the checkerboard's analysis took over 120 s: {m}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let (status, _) = s.get_bytes("/tiles/checker/9/4/4.png").await;
    assert_eq!(status, 200);
}

#[tokio::test]
async fn delete_stops_an_analysis_before_and_after_a_restart() {
    let _alone = ONE_AT_A_TIME.lock().await;
    let data = tempfile::tempdir().unwrap();
    let s = admin_server(data.path(), &[]);
    let (status, answer) = upload(&s, "slow", brick(512)).await;
    assert_eq!(status, 202, "{answer}");
    until_analysing(&s, "slow").await;
    assert_eq!(s.get("/ready").await.status(), 200, "an upload being analysed never makes the service unready");
    delete_and_assert_idle_soon(&s, "slow").await;
    assert!(!data.path().join("slow.tex").exists());

    // Again, with the analysis begun by a restart: uploaded, stopped by SIGTERM mid-analysis,
    // restarted — ready at once, the upload analysed in the background — then deleted.
    let (status, answer) = upload(&s, "again", brick(512)).await;
    assert_eq!(status, 202, "{answer}");
    until_analysing(&s, "again").await;
    assert_eq!(s.terminate(), Some(0));
    let s = admin_server(data.path(), &[]);
    assert_eq!(s.get("/ready").await.status(), 200);
    until_analysing(&s, "again").await;
    assert_eq!(s.get("/ready").await.status(), 200);
    delete_and_assert_idle_soon(&s, "again").await;
    assert!(!data.path().join("again.tex").exists() && !data.path().join("uploads/again.png").exists());
}

#[tokio::test]
async fn an_analysis_over_its_time_budget_fails_with_a_message() {
    let _alone = ONE_AT_A_TIME.lock().await;
    let data = tempfile::tempdir().unwrap();
    // The built-in textures' analyses are stored first (at 1 s they would not start).
    assert_eq!(admin_server(data.path(), &[]).terminate(), Some(0));
    let s = admin_server(data.path(), &[("TEXTILE_ANALYSIS_TIMEOUT_SECS", "1")]);
    let (status, answer) = upload(&s, "slow", brick(512)).await;
    assert_eq!(status, 202, "{answer}");
    let t = Instant::now();
    let m = loop {
        let m = s.json("/textures/slow").await;
        if m["status"] != "analysing" {
            break m;
        }
        assert!(t.elapsed() < Duration::from_secs(30), "still analysing after 30 s: {m}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert_eq!(m["status"], "failed", "{m}");
    let why = m["analysis"]["error"].as_str().or(m["error"].as_str()).unwrap_or_default().to_string();
    assert!(why.contains("budget of 1 s") && why.contains("analysis_timeout_secs"), "{m}");
    common::assert_error(&s, "/tiles/slow/9/0/0.png", 503, "not_ready").await;
}
