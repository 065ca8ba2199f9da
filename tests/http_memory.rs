//! Everything the server keeps is inside its stated bounds: large exemplars (512², made here)
//! served in every mode, at every zoom, as tiles, windows and models, under small limits —
//! and the process's peak resident memory stays within the tile cache's, the level cache's
//! (blocks, kept windows and the box-mean stacks zoomed-out tiles derive), the memory budget
//! and what the textures themselves hold (`/health` → `memory.textures_bytes`: exemplars,
//! analyses, extractions), plus two stated constants: [`START_MIB`] over the textures' bytes
//! once the server is ready (code, thread stacks, the runtime), and [`SERVE_MIB`] over the
//! caches and the budget while it serves (one tile's working memory per worker, which tiles do
//! not reserve, and allocator slack).

mod common;

use common::Server;

/// Resident MiB of a ready server besides its textures' bytes (measured: 6).
const START_MIB: u64 = 32;
/// Resident MiB a serving server grows by besides its caches and its budget (measured: the
/// growth was 74 MiB against 96 of caches and budget).
const SERVE_MIB: u64 = 24;

/// A `side²` exemplar of discs of many colours on a noisy ground, as PNG.
fn exemplar(side: u32, salt: u64) -> Vec<u8> {
    let h = |a: u64, b: u64| {
        let mut z = (a.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ b.wrapping_add(salt)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 31;
        z.wrapping_mul(0x94D0_49BB_1331_11EB) >> 8
    };
    let discs: Vec<(f64, f64, f64, [u8; 3])> = (0..side as u64 / 4)
        .map(|i| {
            let (x, y) = ((h(i, 1) % side as u64) as f64, (h(i, 2) % side as u64) as f64);
            let r = 6.0 + (h(i, 3) % 14) as f64;
            (x, y, r, [(h(i, 4) % 200) as u8 + 40, (h(i, 5) % 200) as u8 + 40, (h(i, 6) % 200) as u8 + 40])
        })
        .collect();
    let img = image::RgbImage::from_fn(side, side, |x, y| {
        let n = (h(x as u64, y as u64 * 7919) % 40) as u8;
        let mut c = [60 + n, 50 + n, 40 + n];
        for &(cx, cy, r, col) in &discs {
            if (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2) <= r * r {
                c = col.map(|v| v.saturating_sub(n / 2));
            }
        }
        image::Rgb(c)
    });
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).expect("encode");
    png
}

/// Resident memory of process `pid` in bytes: `VmRSS` now, or `VmHWM`, the peak.
fn rss(pid: u32, field: &str) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).expect("/proc status");
    let kib: u64 = status
        .lines()
        .find_map(|l| l.strip_prefix(field))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("{field}"));
    kib << 10
}

#[tokio::test]
async fn resident_memory_stays_within_the_counted_bounds() {
    if !std::path::Path::new("/proc/self/status").exists() {
        println!("SKIPPED resident_memory_stays_within_the_counted_bounds: no /proc to read a process's memory from");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let ids = ["big_a", "big_b"];
    let mut cfg = String::from("cache_mib = 8\nlevel_cache_mib = 24\nmemory_budget_mib = 64\n\n");
    for (i, id) in ids.iter().enumerate() {
        std::fs::write(dir.path().join(format!("{id}.png")), exemplar(512, i as u64)).unwrap();
        cfg += &format!("[[textures]]\nid = \"{id}\"\nexemplar = \"{id}.png\"\n\n");
    }
    let config = dir.path().join("textile.toml");
    std::fs::write(&config, cfg).unwrap();
    let data = dir.path().join("data");
    let s = Server::builder().data_dir(&data).args(&["--config", config.to_str().unwrap()]).start();
    // From here on the peak is that of serving (5: reset VmHWM to the current resident size).
    let reset = std::fs::write(format!("/proc/{}/clear_refs", s.pid()), "5").is_ok();
    let started = rss(s.pid(), "VmRSS:");
    let mut requests = 0;
    for id in ids {
        let meta = s.json(&format!("/textures/{id}")).await;
        let native = meta["native_zoom"].as_u64().expect("native zoom") as i64;
        for mode in ["synth", "mosaic", "tiling", "umbrella"] {
            for z in 0..=native + 2 {
                // A few tiles at each zoom, far apart, so nothing is a repeat.
                for k in 0..3i64 {
                    let (x, y) = (k * 37 - 40, 11 - k * 23);
                    let r = s.get(&format!("/tiles/{id}/{z}/{x}/{y}.png?mode={mode}&seed={k}")).await;
                    assert_eq!(r.status(), 200, "{id} {mode} {z}/{x}/{y}");
                    requests += 1;
                }
            }
            let r = s.get(&format!("/windows/{id}.png?mode={mode}&x=-700&y=300&w=1200&h=900&z={}", native - 1)).await;
            assert_eq!(r.status(), 200, "{id} {mode} window");
        }
        for path in ["/gltf/{id}/8/3/-2.glb", "/gltf/{id}/patch.glb?z=6&x=0&y=0&tiles=4"] {
            let r = s.get(&path.replace("{id}", id)).await;
            assert_eq!(r.status(), 200, "{path}");
        }
    }
    let health = s.json("/health").await;
    let mib = 1u64 << 20;
    let field = |a: &str, b: &str| health[a][b].as_u64().unwrap_or_else(|| panic!("/health {a}.{b}"));
    let (tiles, levels) = (field("cache", "limit_bytes"), field("level_cache", "limit_bytes"));
    let (budget, textures) = (field("memory", "budget_bytes"), field("memory", "textures_bytes"));
    assert!(field("cache", "bytes") <= tiles && field("level_cache", "bytes") <= levels, "{health}");
    let peak = rss(s.pid(), "VmHWM:");
    println!(
        "{requests} tiles; resident {} MiB when ready, peak {} MiB while serving (peak reset: {reset}); \
         tile cache {}, level cache {}, budget {}, textures {} MiB",
        started / mib,
        peak / mib,
        tiles / mib,
        levels / mib,
        budget / mib,
        textures / mib
    );
    assert!(
        started <= textures + START_MIB * mib,
        "ready: {} MiB resident, {} MiB counted",
        started / mib,
        textures / mib
    );
    let bound = textures + START_MIB * mib + tiles + levels + budget + SERVE_MIB * mib;
    assert!(peak <= bound, "peak resident {} MiB is over the counted bound {} MiB: {health}", peak / mib, bound / mib);
    if reset {
        let grew = peak.saturating_sub(started);
        let allowed = tiles + levels + budget + SERVE_MIB * mib;
        assert!(
            grew <= allowed,
            "serving grew {} MiB, over {} MiB of caches, budget and constant",
            grew / mib,
            allowed / mib
        );
    }
}
