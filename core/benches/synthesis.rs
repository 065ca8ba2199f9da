//! Engine benchmarks (criterion): analysis time for 64², 128² and 256² exemplars, a cold
//! 256×256 native window (full padded pyramid, nothing cached) and its coordinates alone (the
//! difference is the seam blend), the same with a randomness
//! mask and with request controls (noise and 64 strokes), a zoomed-out tile, a tile magnified one zoom step beyond native, and a 1024×1024 window (report its time ÷ 16 as the cost per 256² of output); chaos-mosaic 256² and
//! 512² windows; cold 256² umbrella tiles from native zoom to the exemplar's minzoom; and cold
//! 256² native windows from exemplars of other shapes (`shape/128x128`, `shape/100x100`,
//! `shape/300x200`: the cost per output pixel of an exemplar at its own size).
//!
//! `cargo bench -p textile-core --bench synthesis`

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use textile_core::modes::mosaic::MosaicParams;
use textile_core::modes::synth::controls::Controls;
use textile_core::modes::synth::{render, synthesize, Synth, SynthParams};
use textile_core::{Analysis, Exemplar, ExemplarOptions, Mode, NoProgress, Pyramid, Rect, Source};

fn exemplar(side: u32) -> Exemplar {
    shaped(side, side)
}

fn shaped(w: u32, h: u32) -> Exemplar {
    // The 256² gravel of the development set, area-resampled to the side wanted.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/exemplars/gravel_256.png");
    let bytes = std::fs::read(&path)
        .or_else(|_| {
            eprintln!(
                "{} not found (the development set beside the repository); using the embedded 128² gravel",
                path.display()
            );
            std::fs::read(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png"))
        })
        .expect("an exemplar");
    let img = image::load_from_memory(&bytes).expect("decode").to_rgba8();
    let img = image::imageops::resize(&img, w, h, image::imageops::FilterType::Triangle);
    let px: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    Exemplar::from_rgba(w, h, &px, &ExemplarOptions::default())
}

fn shapes(c: &mut Criterion) {
    let mut g = c.benchmark_group("shape");
    g.sample_size(30).measurement_time(Duration::from_secs(10));
    let p = SynthParams::default();
    for (w, h) in [(128u32, 128u32), (100, 100), (300, 200)] {
        let an = Analysis::build(&shaped(w, h), &NoProgress);
        let mut i = 0i64;
        g.bench_function(format!("{w}x{h}"), |b| {
            b.iter(|| {
                i += 1;
                render(&an, &p, 0, Rect::new(256 * i, -256 * i, 256, 256)).unwrap()
            })
        });
    }
    g.finish();
}

fn analysis(c: &mut Criterion) {
    let mut g = c.benchmark_group("analysis");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for side in [64u32, 128, 256] {
        let ex = exemplar(side);
        g.bench_with_input(BenchmarkId::from_parameter(side), &ex, |b, ex| b.iter(|| Analysis::build(ex, &NoProgress)));
    }
    g.finish();
}

fn windows(c: &mut Criterion) {
    let ex = exemplar(128);
    let an = Analysis::build(&ex, &NoProgress);
    let p = SynthParams::default();
    let mut g = c.benchmark_group("window");
    g.sample_size(30).measurement_time(Duration::from_secs(10));
    let mut i = 0i64;
    g.bench_function("cold_256_native", |b| {
        b.iter(|| {
            i += 1;
            render(&an, &p, 0, Rect::new(256 * i, -256 * i, 256, 256)).unwrap()
        })
    });
    // The coordinates alone of the same window grown by the seam blend's reach: the difference
    // from `cold_256_native` is what the blend costs.
    g.bench_function("cold_256_native_coords", |b| {
        b.iter(|| {
            i += 1;
            synthesize(&an, &p, an.levels(), Rect::new(256 * i - 3, -256 * i - 3, 262, 262)).unwrap()
        })
    });
    g.bench_function("cold_256_zoom_out_1", |b| {
        b.iter(|| {
            i += 1;
            render(&an, &p, 1, Rect::new(256 * i, 256, 256, 256)).unwrap()
        })
    });
    // The same exemplar with a randomness mask keeping a 16×16 element (a logo): its cost is
    // the jitter's and correction's mask lookups (kept pixels skip correction).
    let logo = |i: usize| (56..72).contains(&(i % 128)) && (56..72).contains(&(i / 128));
    let half: Vec<[u8; 4]> = (0..128 * 128).map(|i| if logo(i) { [0, 0, 0, 255] } else { [255; 4] }).collect();
    let masked = ex
        .clone()
        .with_randomness_mask(&Exemplar::from_rgba(
            128,
            128,
            &half,
            &ExemplarOptions { toroidal: Some(ex.toroidal), ..Default::default() },
        ))
        .expect("mask");
    let man = Analysis::build(&masked, &NoProgress);
    g.bench_function("cold_256_native_masked", |b| {
        b.iter(|| {
            i += 1;
            render(&man, &p, 0, Rect::new(256 * i, -256 * i, 256, 256)).unwrap()
        })
    });
    // Request controls: noise and 64 strokes (R_S), and 32 features, all on one tile.
    let strokes: Vec<String> = (0..64)
        .map(|k| format!(r#"{{"at": [{}, {}], "radius": 20, "soft": 10, "value": 0.2}}"#, (k % 8) * 32, (k / 8) * 32))
        .collect();
    let features: Vec<String> = (0..32)
        .map(|k| {
            format!(
                r#"{{"at": [{}, {}], "source": [60, 60], "inner": 8, "outer": 30}}"#,
                (k % 8) * 32 + 16,
                (k / 8) * 64 + 16
            )
        })
        .collect();
    let json = format!(
        r#"{{"noise": {{"scale": 64, "range": [0.3, 1]}}, "strokes": [{}], "features": [{}]}}"#,
        strokes.join(","),
        features.join(",")
    );
    let mut pc = p.clone();
    pc.controls = Controls::from_json(&serde_json::from_str(&json).expect("json")).expect("controls");
    // The tile they all lie on (nothing is cached: every iteration is cold).
    g.bench_function("cold_256_native_controls", |b| {
        b.iter(|| render(&an, &pc, 0, Rect::new(0, 0, 256, 256)).unwrap())
    });
    g.bench_function("cold_256_magnified_1", |b| {
        b.iter(|| {
            i += 1;
            Synth::magnify(&p, &(), &Source::new(&ex, &an), &Pyramid::off(), 1, Rect::new(256 * i, 512, 256, 256))
                .unwrap()
        })
    });
    g.sample_size(10);
    g.bench_function("cold_1024_native", |b| {
        b.iter(|| {
            i += 1;
            render(&an, &p, 0, Rect::new(1024 * i, 77, 1024, 1024)).unwrap()
        })
    });
    g.finish();
}

fn mosaic(c: &mut Criterion) {
    let ex = exemplar(128);
    let p = MosaicParams::default();
    let mut g = c.benchmark_group("mosaic");
    g.sample_size(100).measurement_time(Duration::from_secs(5));
    let mut i = 0i64;
    for side in [256i64, 512] {
        g.bench_function(format!("window_{side}"), |b| {
            b.iter(|| {
                i += 1;
                textile_core::modes::mosaic::render(&ex, &p, 0, Rect::new(side * i, -side * i, side, side)).unwrap()
            })
        });
    }
    g.finish();
}

fn umbrella(c: &mut Criterion) {
    use textile_core::modes::umbrella::{Extraction, Umbrella, UmbrellaParams};
    use textile_core::View;
    let ex = exemplar(128);
    let an = Analysis::build(&ex, &NoProgress);
    // The texture's prepared state, as the server keeps it: the extraction and its caches.
    let prepared = textile_core::modes::Prepared::new();
    prepared.keep::<Umbrella>(Extraction::extract(&ex));
    let state = prepared.get::<Umbrella>().expect("kept");
    let src = Source::new(&ex, &an).with_prepared(&prepared);
    let p = UmbrellaParams::default();
    let mut g = c.benchmark_group("umbrella");
    g.sample_size(20).measurement_time(Duration::from_secs(5));
    let mut i = 0i64;
    // Cold: every iteration a new place, so no cell list is cached; zoom-out 0 (native) to 7
    // (the 128² exemplar's minzoom).
    for k in [0u32, 1, 2, 3, 5, 7] {
        g.bench_function(format!("cold_256_zoom_out_{k}"), |b| {
            b.iter(|| {
                i += 1;
                let rect = Rect::new(256 * i, -256 * i, 256, 256);
                <Umbrella as Mode>::render(&p, &state, &src, &Pyramid::off(), View::out(k, rect)).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, analysis, windows, mosaic, umbrella, shapes);
criterion_main!(benches);
