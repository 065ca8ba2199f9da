//! Cost per zoom (issue 41): a cold 256² tile of every mode at every zoom from native out to
//! the exemplar's minzoom, on the embedded 128² gravel (native zoom 7), nothing cached: every
//! iteration renders a new place. A zoomed-out tile should cost at most 1.5× the mode's native
//! one.
//!
//! `cargo bench -p textile-core --bench zoom` (criterion's `zoom/MODE/zoom_out_K` lines).

use std::path::PathBuf;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use textile_core::modes::umbrella::{Extraction, Umbrella};
use textile_core::modes::Prepared;
use textile_core::{
    Analysis, Defaults, Exemplar, ExemplarOptions, NoProgress, ParamReader, Pyramid, Rect, Source, View, MODE_NAMES,
};

fn zoom(c: &mut Criterion) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
    let bytes = std::fs::read(path).expect("the embedded gravel");
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("decode");
    let an = Analysis::build(&ex, &NoProgress);
    // What the server prepares per texture, as it keeps it.
    let prepared = Prepared::new();
    prepared.keep::<Umbrella>(Extraction::extract(&ex));
    let src = Source::new(&ex, &an).with_prepared(&prepared);
    let defaults = Defaults::builtin(&src);
    let mut g = c.benchmark_group("zoom");
    g.sample_size(10).measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    let mut i = 0i64;
    for mode in MODE_NAMES {
        let p = defaults.request(&src, ParamReader::request([("mode", *mode)]).expect("query")).expect("params");
        for k in 0..=src.levels() {
            g.bench_function(format!("{mode}/zoom_out_{k}"), |b| {
                b.iter(|| {
                    i += 1;
                    let rect = Rect::new(256 * (i * 7919 % 100_003), -256 * (i * 104_729 % 99_991), 256, 256);
                    p.render(&src, &Pyramid::off(), View::out(k, rect)).expect("render")
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, zoom);
criterion_main!(benches);
