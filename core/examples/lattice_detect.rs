//! Lattice detection on exemplar images, for `bench/README.md` ("Lattice detection"): per image,
//! the lattice found (or none), the strongest ridges the rule weighed, and the time it took.
//!
//! Usage: `cargo run --release -p textile-core --example lattice_detect -- IMAGE…`

use std::time::Instant;

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
        let ridges: Vec<String> = d
            .ridges
            .iter()
            .map(|r| format!("{:.1}°/{:.2}px v {:.3} c {:.3}", r.angle, r.period, r.value, r.contrast))
            .collect();
        let repeat = d.repeat.as_ref().map_or(String::new(), |r| {
            let b: Vec<String> = r.basis.iter().map(|v| format!("({}, {})", v[0], v[1])).collect();
            format!(" copies {} ({:.3}),", b.join(" × "), r.score as f64 / 1000.0)
        });
        let class = d.class().name();
        let found = d.lattice.map_or("none".to_string(), |l| l.to_string());
        println!(
            "{path} ({}x{}): {class}:{repeat} {found} | ridges {} | {ms:.0} ms",
            ex.width,
            ex.height,
            ridges.join("; ")
        );
    }
}
