//! The correction kernel's paths agree: the AVX2 copy with the portable one, and the shortcut
//! for coherent pixels with the full candidate search — each checked on whole windows that
//! [`super::window::synthesize`] computes with the kernel as it is and then forced down the
//! other path. Kept beside the kernel, not in it, so that the kernel does not depend on the
//! window that drives it.

use std::sync::atomic::{AtomicBool, Ordering};

use super::kernel::tests::{FORCE_FULL_SEARCH, FORCE_PORTABLE};
use super::params::SynthParams;
use super::window::synthesize;
use crate::geom::Rect;
use crate::{Analysis, Exemplar, ExemplarOptions, NoProgress};

#[test]
fn simd_and_portable_kernels_agree() {
    if super::kernel::skip_without_avx2("simd_and_portable_kernels_agree") {
        return;
    }
    let pattern: Vec<[u8; 4]> = (0..64 * 64u32)
        .map(|i| {
            let (x, y) = (i % 64, i / 64);
            [((x * 7 + y * 3) % 256) as u8, ((x * y) % 251) as u8, ((x ^ y) * 5 % 256) as u8, 255]
        })
        .collect();
    // Black-and-white noise per channel: neighbourhoods of the largest energy, so features
    // and their differences near the i16 bound the SIMD kernel relies on.
    let noise = hashed_64(|z| {
        let bit = |k: u32| if (z >> (40 + k)) & 1 == 1 { 255 } else { 0 };
        [bit(0), bit(1), bit(2)]
    });
    let other = SynthParams { seed: 9, passes: 3, subpasses: 1, kappa: 1 << 16, ..SynthParams::default() };
    for (px, toroidal) in [(&pattern, None), (&noise, Some(false)), (&noise, Some(true))] {
        let opts = ExemplarOptions { toroidal, ..ExemplarOptions::default() };
        let an = Analysis::build(&Exemplar::from_rgba(64, 64, px, &opts), &NoProgress);
        for p in [SynthParams::default(), other.clone()] {
            let r = Rect::new(-70, 33, 150, 90);
            let (fast, portable) = as_is_and_forced(&FORCE_PORTABLE, || synthesize(&an, &p, 6, r).unwrap());
            assert_eq!(fast, portable, "{p:?} toroidal {toroidal:?}");
        }
    }
}

#[test]
fn coherent_pixels_keep_what_the_search_would_choose() {
    // A smooth pattern (large coherent patches) and noise; wrapping and edged; κ = 0 (ties
    // with second candidates at distance 0 possible) and the defaults; 1 and 4 subpasses.
    let smooth: Vec<[u8; 4]> = (0..64 * 64u32)
        .map(|i| {
            let (x, y) = (i % 64, i / 64);
            [(x * 4) as u8, (y * 4) as u8, ((x + y) * 2) as u8, 255]
        })
        .collect();
    let noise = hashed_64(|z| [(z >> 40) as u8, (z >> 48) as u8, (z >> 56) as u8]);
    let flat = SynthParams { seed: 3, kappa: 0, ..SynthParams::default() };
    let whole = SynthParams { seed: 4, passes: 3, subpasses: 1, ..SynthParams::default() };
    let mut skipped_somewhere = false;
    for (px, toroidal) in [(&smooth, Some(false)), (&smooth, Some(true)), (&noise, Some(false))] {
        let opts = ExemplarOptions { toroidal, ..ExemplarOptions::default() };
        let an = Analysis::build(&Exemplar::from_rgba(64, 64, px, &opts), &NoProgress);
        for p in [SynthParams::default(), flat.clone(), whole.clone()] {
            let r = Rect::new(-90, 17, 140, 120);
            let (fast, searched) = as_is_and_forced(&FORCE_FULL_SEARCH, || synthesize(&an, &p, 6, r).unwrap());
            assert_eq!(fast, searched, "{p:?} toroidal {toroidal:?}");
            skipped_somewhere |= coherent_share(&fast.coords, fast.rect.width() as usize, &an) > 0.05;
        }
    }
    assert!(skipped_somewhere, "no output had coherent neighbourhoods: the test checked nothing");
}

/// `run` as the kernel is, then with `flag` set.
fn as_is_and_forced<T>(flag: &AtomicBool, run: impl Fn() -> T) -> (T, T) {
    let as_is = run();
    flag.store(true, Ordering::Relaxed);
    let forced = run();
    flag.store(false, Ordering::Relaxed);
    (as_is, forced)
}

/// A 64² RGBA test exemplar whose texels are `colour` of a hash of their index.
fn hashed_64(colour: impl Fn(u64) -> [u8; 3]) -> Vec<[u8; 4]> {
    (0..64 * 64u64)
        .map(|i| {
            let [r, g, b] = colour((i + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
            [r, g, b, 255]
        })
        .collect()
}

/// The share of a finest-level window's pixels whose 5×5 neighbourhood is coherent.
fn coherent_share(s: &[u32], w: usize, an: &Analysis) -> f64 {
    let (ew, eh) = (an.width() as i64, an.height() as i64);
    let h = s.len() / w;
    let mut n = 0;
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            let v = s[y * w + x];
            let ok = (0..25).all(|t| {
                let (dx, dy) = (t % 5 - 2, t / 5 - 2);
                let q = s[(y as i64 + dy) as usize * w + (x as i64 + dx) as usize];
                let ex = ((v & 0xFFFF) as i64 + dx).rem_euclid(ew) as u32;
                let ey = ((v >> 16) as i64 + dy).rem_euclid(eh) as u32;
                q == ex | ey << 16
            });
            n += ok as usize;
        }
    }
    n as f64 / ((w - 4) * (h - 4)) as f64
}
