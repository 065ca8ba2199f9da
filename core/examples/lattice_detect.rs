//! Lattice detection on exemplar images, for `bench/README.md` ("Structure on materials never
//! seen"): per image, the class and lattice found, the best 1-D and 2-D candidates the rule
//! weighed with their scores, and the time it took.
//!
//! Usage: `cargo run --release -p textile-core --example lattice_detect -- IMAGE…`

use std::time::Instant;

use textile_core::lattice::{cell_margin, ridge_margin};
use textile_core::{Exemplar, ExemplarOptions};

fn main() {
    for path in std::env::args().skip(1) {
        let bytes = match std::fs::read(&path) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("{path}: {e}");
                continue;
            }
        };
        let ex = match Exemplar::from_bytes(&bytes, &ExemplarOptions::default()) {
            Ok(ex) => ex,
            Err(e) => {
                eprintln!("{path}: {e}");
                continue;
            }
        };
        let started = Instant::now();
        let d = textile_core::lattice::detect(&ex.pixels, ex.width, ex.height);
        let ms = started.elapsed().as_secs_f64() * 1000.0;
        let ridge = d.ridge.map_or("-".to_string(), |r| {
            format!("{:.1}°/{:.2} c {:.3} z {:.1} m {:.2}", r.angle, r.period, r.contrast, r.z, ridge_margin(&r))
        });
        let cell = d.cell.map_or("-".to_string(), |c| {
            format!(
                "[{:.1}, {:.1}] x [{:.1}, {:.1}] c {:.3} z {:.1} m {:.2}",
                c.t1[1],
                c.t1[0],
                c.t2[1],
                c.t2[0],
                c.contrast,
                c.z,
                cell_margin(&c)
            )
        });
        let structure = textile_core::lattice::Structure::of(&d);
        println!("{path} ({}x{}): {structure} | ridge {ridge} | cell {cell} | {ms:.0} ms", ex.width, ex.height);
    }
}
