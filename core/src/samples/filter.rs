//! Continuous samples filtered like a GPU texture unit, in fixed point so that every machine
//! gets the same bytes: a sample at `(u, v)` in native texels with level of detail `lod` is
//! bilinear within each of the two levels bracketing `lod` and linear between them. Level `k`
//! is the texture viewed `k` steps coarser than native; its texel `(x, y)` has its centre at
//! `((x + ½)·2^k, (y + ½)·2^k)`. Fractions are quantised to 1/256 (GPUs use 8 bits of
//! sub-texel precision too), so a sample at a texel centre with `lod = 0` is that texel exactly.

use super::Texel;
use crate::error::{CoreError, Result};

/// A continuous sample: position in native texels (texel `(x, y)` spans `[x, x+1) × [y, y+1)`)
/// and level of detail (`log2` of the footprint in native texels; clamped to the levels that
/// exist).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Horizontal position in native texels.
    pub u: f64,
    /// Vertical position in native texels.
    pub v: f64,
    /// Level of detail.
    pub lod: f32,
}

/// Largest `|u|` and `|v|` accepted (far beyond any tile coordinate; keeps the arithmetic
/// exact).
pub const MAX_POSITION: f64 = (1u64 << 50) as f64;

/// Fixed-point one of a weight factor.
const ONE: u32 = 256;

/// The texels a sample reads and their weights (summing to `2^24`): at most 4 per level, at
/// most 2 levels; texels of zero weight are left out.
#[derive(Debug, Clone, Copy)]
pub struct Taps {
    n: u8,
    taps: [(Texel, u32); 8],
}

impl Taps {
    /// Number of taps.
    pub fn len(&self) -> usize {
        self.n as usize
    }

    /// True when there is none (never, for a valid sample).
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The taps.
    pub fn iter(&self) -> impl Iterator<Item = &(Texel, u32)> {
        self.taps[..self.n as usize].iter()
    }

    fn push(&mut self, t: Texel, w: u32) {
        if w > 0 {
            self.taps[self.n as usize] = (t, w);
            self.n += 1;
        }
    }
}

/// Split a position at level `k` into its first texel and the 8-bit fraction towards the next.
fn split(p: f64, k: u32) -> (i64, u32) {
    let s = p / (1u64 << k) as f64 - 0.5;
    let base = s.floor();
    let f = ((s - base) * ONE as f64).round() as u32;
    if f >= ONE {
        (base as i64 + 1, 0)
    } else {
        (base as i64, f)
    }
}

/// The taps of each sample; levels of detail are clamped to `0 ..= max_zoom_out`. A position or
/// level of detail that is not a finite number, or a position beyond [`MAX_POSITION`], is an
/// error naming the sample.
pub fn taps(points: &[Footprint], max_zoom_out: u32) -> Result<Vec<Taps>> {
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let bad = |message: &str| CoreError::Sample { index: i, message: message.to_string() };
            if !p.u.is_finite() || !p.v.is_finite() {
                return Err(bad("u and v must be finite numbers"));
            }
            if p.u.abs() > MAX_POSITION || p.v.abs() > MAX_POSITION {
                return Err(bad("u and v must be within ±2^50 texels"));
            }
            if p.lod.is_nan() {
                return Err(bad("lod must be a number"));
            }
            let lod = (p.lod as f64).clamp(0.0, max_zoom_out as f64);
            let q = (lod * ONE as f64).round() as u32;
            let (k0, t) = if q >> 8 >= max_zoom_out { (max_zoom_out, 0) } else { (q >> 8, q & (ONE - 1)) };
            let mut out = Taps { n: 0, taps: [(Texel { x: 0, y: 0, zoom_out: 0 }, 0); 8] };
            for (k, wl) in [(k0, ONE - t), (k0 + 1, t)] {
                if wl == 0 {
                    continue;
                }
                let ((x, fx), (y, fy)) = (split(p.u, k), split(p.v, k));
                let at = |dx: i64, dy: i64| Texel { x: x + dx, y: y + dy, zoom_out: k };
                out.push(at(0, 0), wl * (ONE - fx) * (ONE - fy));
                out.push(at(1, 0), wl * fx * (ONE - fy));
                out.push(at(0, 1), wl * (ONE - fx) * fy);
                out.push(at(1, 1), wl * fx * fy);
            }
            Ok(out)
        })
        .collect()
}

/// The weighted average of colours (weights summing to `2^24`), rounded to nearest.
pub fn blend<'a>(taps: impl Iterator<Item = (u32, &'a [u8; 3])>) -> [u8; 3] {
    let mut s = [0u64; 3];
    for (w, c) in taps {
        for (acc, &v) in s.iter_mut().zip(c) {
            *acc += w as u64 * v as u64;
        }
    }
    s.map(|v| ((v + (1 << 23)) >> 24).min(255) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(u: f64, v: f64, lod: f32) -> Footprint {
        Footprint { u, v, lod }
    }

    #[test]
    fn a_texel_centre_at_lod_zero_is_that_texel_alone() {
        for (x, y) in [(0i64, 0i64), (-1, 5), (-(1 << 39), (1 << 39) - 1)] {
            let t = taps(&[fp(x as f64 + 0.5, y as f64 + 0.5, 0.0)], 7).unwrap();
            let got: Vec<_> = t[0].iter().copied().collect();
            assert_eq!(got, vec![(Texel { x, y, zoom_out: 0 }, 1 << 24)]);
        }
    }

    #[test]
    fn weights_sum_to_one_and_lods_are_clamped() {
        for p in [fp(3.25, -7.9, 0.0), fp(100.3, 2.7, 1.5), fp(-5.0, 5.0, -3.0), fp(0.1, 0.2, 99.0)] {
            let t = taps(&[p], 7).unwrap();
            assert_eq!(t[0].iter().map(|&(_, w)| w as u64).sum::<u64>(), 1 << 24, "{p:?}");
            assert!(t[0].iter().all(|(t, _)| t.zoom_out <= 7));
        }
        // Between levels 1 and 2, a quarter of the way.
        let t = taps(&[fp(2.0, 2.0, 1.25)], 7).unwrap();
        let per_level = |k| t[0].iter().filter(|(t, _)| t.zoom_out == k).map(|&(_, w)| w).sum::<u32>();
        assert_eq!((per_level(1), per_level(2)), (3 << 22, 1 << 22));
        // Texel centres of level 1: (2, 2) is the corner between texels 0 and 1 of level 1.
        assert_eq!(t[0].iter().filter(|(t, _)| t.zoom_out == 1).count(), 4);
    }

    #[test]
    fn bad_numbers_name_the_sample() {
        for p in [fp(f64::NAN, 0.0, 0.0), fp(0.0, f64::INFINITY, 0.0), fp(0.0, 0.0, f32::NAN), fp(1e300, 0.0, 0.0)] {
            match taps(&[fp(0.5, 0.5, 0.0), p], 7) {
                Err(CoreError::Sample { index: 1, .. }) => {}
                other => panic!("{p:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn blend_of_one_colour_is_that_colour() {
        let c = [17u8, 200, 255];
        let w = [(1u32 << 23, &c), (1 << 22, &c), (1 << 22, &c)];
        assert_eq!(blend(w.into_iter()), c);
    }
}
