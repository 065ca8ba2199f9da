//! The pyramidal cache changes the work, never the result: windows synthesized through a shared
//! cache (large, evicting, or off), in any order, overlapping or not, equal cold windows; and
//! neighbouring windows share their padding and coarse levels.

mod common;

use proptest::prelude::*;
use textile_core::modes::synth::{render_with, synthesize, SynthParams};
use textile_core::modes::synth::{synthesis_cost, synthesize_with};
use textile_core::Pyramid;
use textile_core::Rect;

fn windows() -> impl Strategy<Value = Vec<(u32, Rect)>> {
    let one = (3u32..=6, -200i64..200, -200i64..200, 1i64..90, 1i64..90)
        .prop_map(|(l, x, y, w, h)| (l, Rect::new(x, y, w, h)));
    prop::collection::vec(one, 1..7)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Any sequence of windows, through a large cache and through one small enough to evict
    /// all the time, equals the same windows computed cold.
    #[test]
    fn cached_windows_equal_cold_windows(list in windows(), seed in 0u64..3) {
        let an = common::small();
        // Seed 2 also exercises one all-pixel subpass per pass, seed 1 three passes.
        let (passes, subpasses) = [(2, 4), (3, 4), (2, 1)][seed as usize];
        let p = SynthParams { seed, passes, subpasses, ..SynthParams::default() };
        let (big, tiny) = (Pyramid::new(64 << 20), Pyramid::new(40_000));
        for &(level, r) in list.iter().chain(list.iter().rev()) {
            let cold = synthesize(an, &p, level, r).unwrap();
            prop_assert_eq!(&synthesize_with(&big, an, &p, level, r).unwrap().window, &cold);
            prop_assert_eq!(&synthesize_with(&tiny, an, &p, level, r).unwrap().window, &cold);
        }
        prop_assert!(tiny.stats().bytes <= 40_000);
    }
}

#[test]
fn streams_do_not_mix() {
    let an = common::small();
    let pyr = Pyramid::new(64 << 20);
    let r = Rect::new(-30, 10, 64, 64);
    for seed in [1, 2, 1, 2] {
        for passes in [2, 1] {
            let p = SynthParams { seed, passes, ..SynthParams::default() };
            assert_eq!(synthesize_with(&pyr, an, &p, 6, r).unwrap().window, synthesize(an, &p, 6, r).unwrap());
        }
    }
}

#[test]
fn a_repeated_window_computes_nothing_and_a_pan_shares_its_padding() {
    let an = common::small();
    let p = SynthParams::default();
    let pyr = Pyramid::new(256 << 20);
    let tile = |i: i64, j: i64| Rect::new(64 * i, 64 * j, 64, 64);
    let cold_one = synthesis_cost(an, &p, 6, tile(0, 0));
    let first = synthesize_with(&pyr, an, &p, 6, tile(0, 0)).unwrap();
    assert_eq!(first.synthesized, cold_one, "a cold window computes its whole plan");
    assert_eq!(synthesize_with(&pyr, an, &p, 6, tile(0, 0)).unwrap().synthesized, 0);
    // Sweep 6×4 tiles: every pixel of every level is computed once, so the sweep costs what
    // one window over the whole area costs, far less than 24 cold tiles.
    let mut total = first.synthesized;
    for i in 0..6 {
        for j in 0..4 {
            if (i, j) != (0, 0) {
                total += synthesize_with(&pyr, an, &p, 6, tile(i, j)).unwrap().synthesized;
            }
        }
    }
    let whole = synthesis_cost(an, &p, 6, Rect::new(0, 0, 6 * 64, 4 * 64));
    assert!(total <= whole + whole / 50, "sweep {total} vs one window {whole}");
    assert!(total < 24 * cold_one * 3 / 4, "sweep {total} vs 24 cold tiles {}", 24 * cold_one);
    // Zooming out reuses the coarser levels the sweep computed.
    let zoomed = render_with(&pyr, an, &p, 1, Rect::new(0, 0, 3 * 32, 2 * 32)).unwrap();
    assert_eq!(zoomed.synthesized, 0);
    assert_eq!(zoomed.image, textile_core::modes::synth::render(an, &p, 1, Rect::new(0, 0, 96, 64)).unwrap());
}

#[test]
fn cached_windows_do_not_depend_on_thread_count() {
    let an = common::small();
    let p = SynthParams::default();
    let rects: Vec<Rect> = (0..5).map(|i| Rect::new(50 * i - 90, 37 * i - 60, 70, 50)).collect();
    let run = |threads: usize, order: &[usize]| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let pyr = Pyramid::new(64 << 20);
        let mut out = vec![None; rects.len()];
        pool.install(|| {
            for &i in order {
                out[i] = Some(synthesize_with(&pyr, an, &p, 6, rects[i]).unwrap().window);
            }
        });
        out
    };
    let a = run(1, &[0, 1, 2, 3, 4]);
    assert_eq!(a, run(3, &[4, 2, 0, 3, 1]));
    assert_eq!(a, run(2, &[3, 4, 1, 0, 2]));
}
