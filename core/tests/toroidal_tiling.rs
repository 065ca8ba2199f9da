//! Zero randomness on a toroidal exemplar reproduces the exemplar tiled exactly, with the full
//! correction running (design note §8).

mod common;

use textile_core::modes::synth::{render, Randomness, SynthParams};
use textile_core::{ExemplarOptions, Rect};

#[test]
fn zero_randomness_on_toroidal_exemplars_is_exact_tiling() {
    for name in ["smallstone_tile.png", "leaves_tile.png"] {
        let an = common::analyse(&common::shared_exemplar(name), ExemplarOptions::default());
        assert!(an.header.toroidal, "{name} should be detected as toroidal");
        let p = SynthParams { randomness: Randomness::Uniform(0), ..SynthParams::default() };
        let m = an.side() as i64;
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
    let an = common::analyse(&common::shared_exemplar("smallstone_tile.png"), ExemplarOptions::default());
    let m = an.side() as i64;
    let r = Rect::new(0, 0, 2 * m, 2 * m);
    let tiled =
        render(&an, &SynthParams { randomness: Randomness::Uniform(0), ..SynthParams::default() }, 0, r).unwrap();
    let synth = render(&an, &SynthParams::default(), 0, r).unwrap();
    assert_ne!(tiled, synth);
}
