//! What a raster-dem tile costs beside the `map=height` tile it encodes (issue 83: the goal is
//! ≤ 1.2×). In process, one tile at a time, alternating, on the built-in flagstones material
//! (a height map) and gravel (no height map: its luma), cold (no pyramidal cache) and warm (the
//! place's synthesis cached before either is timed, as when a client asks for the colour, the
//! heights and the terrain of one place: what is left is lookups and encoding).
//!
//! `cargo bench -p textile-server --bench terrain_cost [-- N]` (default N = 40 tiles per figure)

use std::time::{Duration, Instant};

use textile_core::maps::MapChoice;
use textile_core::{ParamReader, Pyramid};
use textile_server::config::{Config, Overrides};
use textile_server::encode::Format;
use textile_server::pipeline::{ImageJob, Target};
use textile_server::request::{params, TileSpec};
use textile_server::terrain::{Dem, Encoding};
use textile_server::textures::load_registry;

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn main() {
    let n: i64 = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(40);
    let dir = tempfile::tempdir().expect("tmp");
    let o = Overrides(
        [("data_dir".to_string(), serde_json::json!(dir.path().display().to_string()))].into_iter().collect(),
    );
    let mut cfg = Config::load(None, &o).expect("config");
    cfg.textures.retain(|t| t.id == "flagstones" || t.id == "gravel");
    cfg.landscapes.clear();
    let reg = load_registry(&cfg, &|_| {}).expect("registry");
    println!("raster-dem tile cost against the height tile it encodes, median of {n} tiles (ms):");
    for (id, z) in [("flagstones", 8), ("gravel", 7)] {
        let tex = reg.get(id).expect("texture").clone();
        let p = params(&tex, ParamReader::request(Vec::<(String, String)>::new()).expect("q")).expect("params");
        let height =
            if tex.exemplar.map("height").is_some() { MapChoice::Map("height".into()) } else { MapChoice::Albedo };
        for enc in [Encoding::Terrarium, Encoding::Mapbox] {
            for warm in [false, true] {
                let cache = if warm { Pyramid::new(256 << 20) } else { Pyramid::off() };
                let (mut plain, mut dem) = (Vec::new(), Vec::new());
                for i in 0..n {
                    let target =
                        Target::Tile(TileSpec { z, x: 5 * i - 2 * n, y: 3 * i, scale: 1, format: Format::Png });
                    let job = ImageJob { tex: tex.clone(), params: p.clone(), target, map: height.clone(), dem: None };
                    let d = Dem { encoding: enc, height_scale: tex.height_scale(), base: 0.0 };
                    let dem_job = ImageJob { dem: Some(d), ..job.clone() };
                    if warm {
                        drop(job.bytes(&cache).expect("tile"));
                    }
                    let t = Instant::now();
                    drop(job.bytes(&cache).expect("tile"));
                    plain.push(t.elapsed());
                    let t = Instant::now();
                    drop(dem_job.bytes(&cache).expect("tile"));
                    dem.push(t.elapsed());
                }
                let (a, b) = (median(plain), median(dem));
                let what = if height == MapChoice::Albedo { "luma" } else { "height map" };
                let state = if warm { "warm" } else { "cold" };
                println!(
                    "  {id:<10} ({what:<10}) {:<9} {state}: height tile {a:7.2}, raster-dem {b:7.2}: {:.3}x",
                    enc.name(),
                    b / a
                );
            }
        }
    }
}
