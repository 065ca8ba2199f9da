//! Zero randomness on a toroidal exemplar reproduces the exemplar tiled exactly, with the full
//! correction running (design note §8).

mod common;

use textile_core::modes::synth::{render, Randomness, SynthParams};
use textile_core::{Analysis, NoProgress, Rect};

fn toroidal(side: u32, salt: u64) -> Analysis {
    Analysis::build(&common::toroidal_exemplar(side, salt), &NoProgress)
}

#[test]
fn zero_randomness_on_toroidal_exemplars_is_exact_tiling() {
    for (name, side, salt) in [("64² waves", 64, 1), ("128² waves", 128, 2)] {
        let an = toroidal(side, salt);
        assert!(an.header.toroidal, "{name} should be detected as toroidal");
        let p = SynthParams { randomness: Randomness::Uniform(0), ..SynthParams::default() };
        let m = an.width() as i64;
        let r = Rect::new(-m - 5, 3 * m + 1, 2 * m + 9, m + 7);
        let img = render(&an, &p, 0, r).unwrap();
        for j in 0..r.height() {
            for i in 0..r.width() {
                let (ex, ey) = ((r.x0 + i).rem_euclid(m), (r.y0 + j).rem_euclid(m));
                assert_eq!(img.pixel(i as u32, j as u32), an.exemplar[(ey * m + ex) as usize], "{name} ({i},{j})");
            }
        }
    }
}

#[test]
fn randomness_changes_the_tiling() {
    let an = toroidal(64, 3);
    let m = an.width() as i64;
    let r = Rect::new(0, 0, 2 * m, 2 * m);
    let tiled =
        render(&an, &SynthParams { randomness: Randomness::Uniform(0), ..SynthParams::default() }, 0, r).unwrap();
    let synth = render(&an, &SynthParams::default(), 0, r).unwrap();
    assert_ne!(tiled, synth);
}
