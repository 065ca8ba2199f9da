//! End-to-end tile latency and encoding cost (issue: tile server). Starts the real `textile`
//! binary on a free loopback port, then with one connection, one request at a time:
//! * cold: N distinct, never-requested native tiles (synthesis + PNG + HTTP);
//! * cached: the same N tiles again (cache hits);
//! * cold mosaic: N distinct `mode=mosaic` tiles;
//! * cold and cached GLB: N distinct glTF tiles elsewhere (the 288² bordered image: synthesis,
//!   PNG, GLB, HTTP), then the same again (the padding's cost beside the PNG tile);
//! * per zoom (issue 41): for every mode and every zoom from native (7) out to 0, max(5, N/50)
//!   distinct cold PNG tiles, median and ratio to the mode's native median.
//!
//! In process it also times one 256² synthesis and the PNG/JPEG/WebP encoding of a tile.
//! Prints median / p90 / p99 / max per figure.
//!
//! `cargo bench -p textile-server --bench tile_latency [-- N]` (default N = 1000)

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use textile_core::modes::mosaic::MosaicParams;
use textile_core::modes::synth::{render, SynthParams};
use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress, Rect, MODE_NAMES};
use textile_server::encode::{encode, Effort, Format};

fn summary(name: &str, mut v: Vec<Duration>) {
    v.sort();
    let q = |p: f64| v[((v.len() as f64 - 1.0) * p).round() as usize].as_secs_f64() * 1e3;
    println!(
        "{name:<28} n={:<5} median {:>8.3} ms  p90 {:>8.3} ms  p99 {:>8.3} ms  max {:>8.3} ms",
        v.len(),
        q(0.5),
        q(0.9),
        q(0.99),
        q(1.0)
    );
}

fn main() {
    let n: usize = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(1000);
    // Encoding cost, in process.
    let bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../config/exemplars/gravel.png")).unwrap();
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).unwrap();
    let an = Analysis::build(&ex, &NoProgress);
    let tile = render(&an, &SynthParams::default(), 0, Rect::new(0, 0, 256, 256)).unwrap();
    let mut synth = Vec::new();
    for i in 0..50 {
        let t = Instant::now();
        let _ = render(&an, &SynthParams::default(), 0, Rect::new(256 * i, 0, 256, 256)).unwrap();
        synth.push(t.elapsed());
    }
    summary("synthesis 256² (in process)", synth);
    // Each effort on the tiles it is used for: Tight on a synthesized tile, Quick on a mosaic one.
    let mosaic_tile =
        textile_core::modes::mosaic::render(&ex, &MosaicParams::default(), 0, Rect::new(0, 0, 256, 256)).unwrap();
    for (fmt, effort, px, what) in [
        (Format::Png, Effort::Tight, &tile.pixels, "synth"),
        (Format::Png, Effort::Quick, &mosaic_tile.pixels, "mosaic"),
        (Format::Jpeg, Effort::Tight, &tile.pixels, "synth"),
        (Format::Webp, Effort::Tight, &tile.pixels, "synth"),
    ] {
        let mut v = Vec::new();
        let mut size = 0;
        for _ in 0..100 {
            let t = Instant::now();
            size = encode(px, 256, 256, fmt, effort).unwrap().len();
            v.push(t.elapsed());
        }
        summary(&format!("encode {} {effort:?}, {what} ({} KiB)", fmt.ext(), size / 1024), v);
    }

    // The real server over HTTP.
    let data = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bench-data");
    let mut child = Command::new(env!("CARGO_BIN_EXE_textile"))
        .args(["serve", "--bind", "127.0.0.1:0", "--data-dir"])
        .arg(&data)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("start textile");
    let mut line = String::new();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    while !line.starts_with("textile ready") {
        line.clear();
        if out.read_line(&mut line).unwrap_or(0) == 0 {
            panic!("server exited");
        }
    }
    let base = line.split_whitespace().nth(4).unwrap().trim_end_matches('/').to_string();
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    rt.block_on(async {
        let client = reqwest::Client::new();
        let urls: Vec<String> = (0..n as i64)
            .map(|i| format!("{base}/tiles/gravel/7/{}/{}.png", (i * 7919) % 100_003 - 50_000, (i * 104_729) % 99_991))
            .collect();
        let mosaic: Vec<String> = urls.iter().map(|u| format!("{u}?mode=mosaic")).collect();
        let glb: Vec<String> = (0..n as i64)
            .map(|i| {
                format!(
                    "{base}/gltf/gravel/7/{}/{}.glb",
                    (i * 7919) % 100_003 - 50_000,
                    200_000 + (i * 104_729) % 99_991
                )
            })
            .collect();
        for (name, pass, list) in [
            ("cold synth tile over HTTP", 0, &urls),
            ("cached tile over HTTP", 1, &urls),
            ("cold mosaic tile over HTTP", 0, &mosaic),
            ("cold GLB tile over HTTP", 0, &glb),
            ("cached GLB tile over HTTP", 1, &glb),
        ] {
            let mut v = Vec::with_capacity(n);
            for u in list {
                let t = Instant::now();
                let r = client.get(u).send().await.unwrap();
                assert_eq!(r.headers()["x-cache"], if pass == 0 { "MISS" } else { "HIT" });
                let _ = r.bytes().await.unwrap();
                v.push(t.elapsed());
            }
            summary(name, v);
        }
        // Cold tiles per mode and zoom, far from everything requested before.
        let per_zoom = (n / 50).max(5);
        println!("cold PNG tiles over HTTP per zoom, median of {per_zoom} (ratio to the mode's native zoom 7):");
        for mode in MODE_NAMES {
            let mut row = format!("{mode:<9}");
            let mut native = 0.0;
            for z in (0..=7u32).rev() {
                let mut v = Vec::with_capacity(per_zoom);
                for i in 0..per_zoom as i64 {
                    let (x, y) = ((i * 7919) % 100_003 - 50_000, 400_000 + 1000 * z as i64 + (i * 104_729) % 997);
                    let t = Instant::now();
                    let r =
                        client.get(format!("{base}/tiles/gravel/{z}/{x}/{y}.png?mode={mode}")).send().await.unwrap();
                    assert_eq!(r.headers()["x-cache"], "MISS");
                    let _ = r.bytes().await.unwrap();
                    v.push(t.elapsed().as_secs_f64() * 1e3);
                }
                v.sort_by(f64::total_cmp);
                let median = v[v.len() / 2];
                if z == 7 {
                    native = median;
                }
                row += &format!("  z{z} {median:6.2} ms ({:.2}×)", median / native);
            }
            println!("{row}");
        }
        // Materials (issue 39): a cold colour tile of the built-in flagstones, then each other
        // map of the same tile (its coordinates kept: lookups and encoding only), and cold tiles
        // of each map alone, at native zoom 8.
        let per_map = (n / 20).max(10);
        println!("flagstones material tiles over HTTP, median of {per_map} (synth, native zoom 8):");
        let mut table: Vec<(String, Vec<f64>)> = Vec::new();
        let mut time = |name: String, ms: f64| match table.iter_mut().find(|(n, _)| *n == name) {
            Some((_, v)) => v.push(ms),
            None => table.push((name, vec![ms])),
        };
        for i in 0..per_map as i64 {
            let (x, y) = ((i * 7919) % 100_003 - 50_000, 700_000 + (i * 104_729) % 997);
            for (what, map) in [
                ("cold albedo", "albedo"),
                ("second map: normal", "normal"),
                ("second map: height", "height"),
                ("second map: specular", "specular"),
                ("second map: uv", "uv"),
            ] {
                let t = Instant::now();
                let r = client.get(format!("{base}/tiles/flagstones/8/{x}/{y}.png?map={map}")).send().await.unwrap();
                assert_eq!(r.status(), 200);
                let _ = r.bytes().await.unwrap();
                time(what.to_string(), t.elapsed().as_secs_f64() * 1e3);
            }
            for (k, map) in ["normal", "height"].into_iter().enumerate() {
                let y = y + 5000 * (k as i64 + 1);
                let t = Instant::now();
                let r = client.get(format!("{base}/tiles/flagstones/8/{x}/{y}.png?map={map}")).send().await.unwrap();
                assert_eq!(r.status(), 200);
                let _ = r.bytes().await.unwrap();
                time(format!("cold {map} alone"), t.elapsed().as_secs_f64() * 1e3);
            }
        }
        for (name, mut v) in table {
            v.sort_by(f64::total_cmp);
            println!("  {name:<22} {:6.2} ms", v[v.len() / 2]);
        }
    });
    let _ = child.kill();
    let _ = child.wait();
}
