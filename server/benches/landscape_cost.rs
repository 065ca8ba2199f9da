//! What a landscape's tile costs beside its layers' own (issue 82). In process, cold (no
//! pyramidal cache, so every tile pays its whole synthesis), one tile at a time, alternating:
//!
//! * inside one layer: a landscape tile where the splat gives one layer all the ground, against
//!   that layer's own tile at the same place (the goal: ≤ 1.1×);
//! * transition: a tile where both layers show, against the sum of the two layers' own tiles
//!   (the goal: ≤ the sum + 20 %);
//!
//! for layers in `synth` (the main engine) and in `mosaic` (cheap: what the landscape adds is
//! most visible there). The landscape is two embedded textures (gravel, grass) and a painted
//! splat (gravel left of texel 1024, grass right, height blend), as in tests/http_landscapes.rs.
//!
//! `cargo bench -p textile-server --bench landscape_cost [-- N]` (default N = 40 tiles per figure)

use std::sync::Arc;
use std::time::{Duration, Instant};

use textile_core::maps::MapChoice;
use textile_core::{Cancel, ParamReader, Pyramid};
use textile_server::config::{Config, Overrides};
use textile_server::encode::Format;
use textile_server::pipeline::landscape::{LandscapeJob, LandscapeMap};
use textile_server::pipeline::{ImageJob, Target};
use textile_server::request::{params, TileSpec};
use textile_server::textures::{load_registry, Registry};

fn median(mut v: Vec<Duration>) -> f64 {
    v.sort();
    v[v.len() / 2].as_secs_f64() * 1e3
}

fn tile(z: u32, x: i64, y: i64) -> Target {
    Target::Tile(TileSpec { z, x, y, scale: 1, format: Format::Png })
}

fn own(reg: &Registry, id: &str, mode: &str, t: Target) -> ImageJob {
    let tex = reg.get(id).expect("texture").clone();
    let p = params(&tex, ParamReader::request([("mode", mode)]).expect("query")).expect("params");
    ImageJob { tex, params: p, target: t, map: MapChoice::Albedo, dem: None }
}

fn time(f: impl FnOnce()) -> Duration {
    let t = Instant::now();
    f();
    t.elapsed()
}

fn main() {
    let n: i64 = std::env::args().skip(1).find_map(|a| a.parse().ok()).unwrap_or(40);
    let dir = tempfile::tempdir().expect("tmp");
    image::RgbImage::from_fn(16, 2, |x, _| image::Rgb(if x < 8 { [255, 0, 0] } else { [0, 0, 255] }))
        .save(dir.path().join("splat.png"))
        .expect("splat");
    let land = |id: &str, mode: &str| {
        format!(
            "[[landscapes]]\nid = \"{id}\"\n[[landscapes.layers]]\ntexture = \"gravel\"\nmode = \"{mode}\"\ncolour = \"#ff0000\"\n\
             [[landscapes.layers]]\ntexture = \"grass\"\nmode = \"{mode}\"\ncolour = \"#0000ff\"\n[landscapes.splat]\n\
             kind = \"image\"\nimage = \"splat.png\"\ntexels_per_pixel = 128\n\n"
        )
    };
    let text = format!(
        "data_dir = \"{}\"\n[[textures]]\nid = \"gravel\"\nexemplar = \"embedded:gravel.png\"\n\
         [[textures]]\nid = \"grass\"\nexemplar = \"embedded:grass.png\"\n{}{}",
        dir.path().join("data").display(),
        land("ground_synth", "synth"),
        land("ground_mosaic", "mosaic")
    );
    let cfg_path = dir.path().join("textile.toml");
    std::fs::write(&cfg_path, text).expect("config");
    let cfg = Config::load(Some(&cfg_path), &Overrides::default()).expect("config");
    let reg = load_registry(&cfg, &|_| {}).expect("registry");
    let off = Pyramid::off();
    println!("landscape tile cost, cold, median of {n} tiles (ms):");
    for mode in ["synth", "mosaic"] {
        let l = Arc::clone(reg.landscape(&format!("ground_{mode}")).expect("landscape"));
        let job = |t| {
            LandscapeJob::new(
                l.clone(),
                t,
                (LandscapeMap::Albedo, None),
                ParamReader::request(Vec::<(String, String)>::new()).expect("q"),
            )
            .expect("job")
        };
        let (mut inside, mut layer, mut trans, mut sum) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for i in 0..n {
            // Rows far apart; columns 1 (gravel alone) and 3 (the transition at texel 1024).
            let y = 7 * i - 3 * n;
            inside.push(time(|| drop(job(tile(7, 1, y)).bytes(&off, &Cancel::default()).expect("tile"))));
            layer.push(time(|| drop(own(&reg, "gravel", mode, tile(7, 1, y)).bytes(&off).expect("tile"))));
            trans.push(time(|| drop(job(tile(7, 3, y)).bytes(&off, &Cancel::default()).expect("tile"))));
            sum.push(time(|| {
                drop(own(&reg, "gravel", mode, tile(7, 3, y)).bytes(&off).expect("tile"));
                drop(own(&reg, "grass", mode, tile(7, 3, y)).bytes(&off).expect("tile"));
            }));
        }
        let splat: Vec<Duration> = (0..n).map(|i| time(|| drop(job(tile(7, 3, 7 * i)).splat_weights()))).collect();
        let made: Vec<Duration> = (0..n).map(|i| time(|| drop(job(tile(7, 3, 7 * i))))).collect();
        println!(
            "  {mode:<7} of which: reading the request {:.3} ms, the splat's weights {:.3} ms",
            median(made),
            median(splat)
        );
        let (a, b, c, d) = (median(inside), median(layer), median(trans), median(sum));
        println!(
            "  {mode:<7} inside one layer {a:7.2} vs the layer's own {b:7.2}: {:.3}x | transition {c:7.2} vs both layers' {d:7.2}: {:.3}x",
            a / b,
            c / d
        );
    }
}
