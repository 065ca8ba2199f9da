//! Finding an exemplar's lattice from its pixels alone (after Liu, Lin & Hays 2004: the
//! lattice from the autocorrelation's peaks), decided in units of the autocorrelation's own
//! noise ([`super::acf`]).
//!
//! Two kinds of candidate are weighed, each as a prediction: shifted by a lattice translation,
//! the image must match itself clearly better than shifted by half of one.
//! - **Ridges** ([`super::ridge`]): a 1-D wave, scored by the comb of its first repeats against
//!   the half periods between them.
//! - **Cells** ([`super::cell`]): a 2-D lattice proposed by two of the autocorrelation's peaks,
//!   scored at every lattice point within reach against the worst of its three half-cell
//!   cosets, so that a second direction must be a repeat of its own (not the flat crest of a
//!   course) and the cell the fundamental one.
//!
//! **The rule.** A candidate's *margin* is the lesser of its score over [`MIN_Z`] noise units
//! and its contrast over a least effect ([`MIN_CONTRAST`]: the share of the high-passed
//! luma's variance the shift predicts beyond the half shift). The
//! best cell with a margin of at least 1 is the lattice; else the best ridge with one, made
//! its fundamental; else none. The score alone would pass weak, real but local periodicity
//! (a sand's wind ripples are many and significant); the contrast alone is what the old
//! absolute thresholds were, and depends on the image's size. The margins measured on the
//! development set, the materials and the lattices set are in `bench/README.md` ("Structure
//! on materials never seen").
//!
//! Deterministic on every machine: scalar (no SIMD) FFTs in `f64` and results rounded to the
//! fixed point of [`Wave`].

use rayon::prelude::*;

use super::acf::{halve, highpass, Autocorrelation};
use super::cell::Cell;
use super::exact::{self, Repeat};
use super::ridge::Ridge;
use super::{Lattice, Origin, Wave};

/// Least score of a detected lattice, in noise units.
pub const MIN_Z: f64 = 3.5;

/// Least contrast of a detected lattice (a ridge's comb, a cell's worst coset).
pub const MIN_CONTRAST: f64 = 0.075;

/// Longest period of a lattice inside a tile repeated, as a share of the tile's period along
/// it: twice the period must stay clear of the copy, which matches itself exactly.
const INSIDE_SHARE: f64 = 0.45;

/// Cells scored in full, of the best roughly scored.
const RESCORED: usize = 24;

/// Share of the best cell's margin a smaller cell needs to be taken instead.
const SMALLEST_SHARE: f64 = 0.5;

/// Largest side analysed at full resolution; larger exemplars are box-reduced first.
const DETECT_SIDE: usize = 256;

/// What detection found: the exemplar's class ([`Detection::class`]), its exact repeat if it is
/// a tile repeated, the lattice the modes keep (for a tiling, the structure found *inside* one
/// tile), and the best candidates it weighed with their scores (found or not).
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// The translations that map the image onto itself, if it is a tile repeated.
    pub repeat: Option<Repeat>,
    /// The lattice, or `None` for a stochastic exemplar (or a tiling of stochastic content).
    pub lattice: Option<Lattice>,
    /// The best 1-D candidate (period in exemplar texels).
    pub ridge: Option<Ridge>,
    /// The best 2-D candidate (vectors in exemplar texels).
    pub cell: Option<Cell>,
}

/// An exemplar's structure class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Class {
    /// A tile repeated pixel for pixel.
    Exact,
    /// A near-regular lattice (1-D or 2-D).
    Lattice,
    /// Stochastic.
    None,
}

impl Class {
    /// `exact`, `lattice` or `none`.
    pub fn name(self) -> &'static str {
        match self {
            Class::Exact => "exact",
            Class::Lattice => "lattice",
            Class::None => "none",
        }
    }
}

impl Detection {
    /// Exact if the image is a tile repeated, else lattice if one was found, else none.
    pub fn class(&self) -> Class {
        match (&self.repeat, &self.lattice) {
            (Some(_), _) => Class::Exact,
            (None, Some(_)) => Class::Lattice,
            (None, None) => Class::None,
        }
    }
}

/// Detect the structure of the `w × h` exemplar `pixels` (see the module comment): its exact
/// repeat first, then the lattice, inside one tile for a tiling. A non-square exemplar is
/// looked at through its largest centred square: a lattice or a repeat is the same
/// everywhere in the image, and the square keeps the autocorrelation's lags isotropic.
pub fn detect(pixels: &[[u8; 3]], w: u32, h: u32) -> Detection {
    let (square, side) = crate::geom::centred_square(pixels, (w as usize, h as usize));
    detect_square(&square, side as u32)
}

/// [`detect`] on a `side × side` image.
fn detect_square(pixels: &[[u8; 3]], side: u32) -> Detection {
    let mut m = side as usize;
    let mut luma: Vec<f64> =
        pixels.iter().map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect();
    let mut scale = 1.0;
    while m > DETECT_SIDE {
        luma = halve(&luma, m);
        m /= 2;
        scale *= 2.0;
    }
    let [raw, a] = Autocorrelation::of_all([&luma, &highpass(&luma, m)], m);
    let lags = exact::Lags { m: raw.m, n: raw.n, a: &raw.a };
    let repeat = exact::find(pixels, side as usize, &lags, scale as usize);
    // A tiling's own period is no lattice: inside one tile, a wave must repeat more than twice.
    let inside = |period: f64, angle: f64| {
        repeat.as_ref().is_none_or(|rep| {
            let (s, c) = angle.to_radians().sin_cos();
            rep.period_along([c, s]).is_none_or(|p| period * scale <= INSIDE_SHARE * p)
        })
    };
    let (ridge, cell) = best_of(&a, &inside);
    if std::env::var_os("TEXTILE_LATTICE_DEBUG").is_some() {
        eprintln!("  sigma {:.4} r0 {}", a.sigma, a.r0);
    }
    let scaled_ridge = ridge.map(|r| Ridge { period: r.period * scale, ..r });
    let scaled_cell =
        cell.map(|c| Cell { t1: [c.t1[0] * scale, c.t1[1] * scale], t2: [c.t2[0] * scale, c.t2[1] * scale], ..c });
    let found = |waves: Vec<Wave>, margin: f64| {
        Some(Lattice { waves, origin: Origin::Detected, confidence: confidence(margin) })
    };
    let lattice = match (&scaled_cell, &scaled_ridge) {
        (Some(c), _) if cell_margin(c) >= 1.0 => found(waves_of_cell(c), cell_margin(c)),
        (_, Some(r)) if ridge_margin(r) >= 1.0 => found(vec![Wave::new(r.period, r.angle)], ridge_margin(r)),
        _ => None,
    };
    Detection { repeat, lattice, ridge: scaled_ridge, cell: scaled_cell }
}

/// The best ridge and cell of one view, each made its fundamental and refined if it passes.
fn best_of(a: &Autocorrelation, inside: &(dyn Fn(f64, f64) -> bool + Sync)) -> (Option<Ridge>, Option<Cell>) {
    let ridge = a
        .ridges()
        .into_iter()
        .filter(|r| inside(r.period, r.angle))
        .max_by(|x, y| ridge_margin(x).total_cmp(&ridge_margin(y)))
        .map(|r| {
            let passes = |s: &Ridge| ridge_margin(s) >= 1.0;
            if passes(&r) {
                a.refine(a.doubled(a.fundamental(r, passes), passes))
            } else {
                r
            }
        });
    let cell_inside = |c: &Cell| waves_of_cell(c).iter().all(|w| inside(w.period(), w.angle_deg()));
    let mut rough = a.cells();
    rough.sort_by(|x, y| cell_margin(y).total_cmp(&cell_margin(x)));
    rough.truncate(RESCORED);
    let cells: Vec<Cell> = rough.par_iter().filter_map(|c| a.cell_at(c.t1, c.t2)).filter(cell_inside).collect();
    let best = cells.iter().map(cell_margin).fold(f64::MIN, f64::max);
    // Of the cells nearly as good as the best, the smallest: an odd multiple of a cell (three
    // tread lugs across) passes the coset test too.
    let area = |c: &Cell| (c.t1[0] * c.t2[1] - c.t1[1] * c.t2[0]).abs();
    let cell = cells
        .iter()
        .filter(|c| cell_margin(c) >= (SMALLEST_SHARE * best).max(best.min(1.0)))
        .min_by(|x, y| area(x).total_cmp(&area(y)))
        .copied()
        .map(|c| if cell_margin(&c) >= 1.0 { a.fit(c) } else { c });
    (ridge, cell)
}

/// A cell's two waves.
fn waves_of_cell(c: &Cell) -> Vec<Wave> {
    let [t1, t2] = [c.t1, c.t2].map(|t| [t[1], t[0]]);
    super::choice::waves_of(&[t1, t2], u32::MAX).unwrap_or_default()
}

/// How far a ridge clears the rule: the lesser of its score over [`MIN_Z`] and its contrast
/// over [`MIN_CONTRAST`]; 1 on the rule.
pub fn ridge_margin(r: &Ridge) -> f64 {
    (r.z / MIN_Z).min(r.contrast / MIN_CONTRAST)
}

/// How far a cell clears the rule: the lesser of its score over [`MIN_Z`] and its contrast
/// over [`MIN_CONTRAST`]; 1 on the rule.
pub fn cell_margin(c: &Cell) -> f64 {
    (c.z / MIN_Z).min(c.contrast / MIN_CONTRAST)
}

/// A margin as a confidence in thousandths: `1 − 2^−margin`, ½ on the rule, ¾ at twice it,
/// under ½ for a weak find.
fn confidence(margin: f64) -> u32 {
    ((1.0 - 0.5f64.powf(margin.max(0.0))) * 1000.0).round() as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic near-regular image: `f(x, y)` sampled on `side²`.
    fn image(side: u32, f: impl Fn(f64, f64) -> f64) -> Vec<[u8; 3]> {
        (0..side * side)
            .map(|i| {
                let v = f((i % side) as f64, (i / side) as f64).clamp(0.0, 255.0) as u8;
                [v, v, v]
            })
            .collect()
    }

    /// A little hashed noise, so that no image is exactly periodic.
    fn noise(x: f64, y: f64) -> f64 {
        let h = crate::hash::hash_keyed(7, x as i64, y as i64, 0);
        (h % 41) as f64 - 20.0
    }

    fn angle_gap(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(180.0);
        d.min(180.0 - d)
    }

    #[test]
    fn stripes_with_a_fractional_period() {
        let px = image(256, |x, y| if (x / 23.4).fract() < 0.15 { 40.0 } else { 170.0 + noise(x, y) });
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("stripes detected");
        assert_eq!(lat.waves.len(), 1, "{d:?}");
        let w = lat.waves[0];
        assert!((w.period() - 23.4).abs() < 0.1, "{d:?}");
        assert!(angle_gap(w.angle_deg(), 0.0) < 0.5, "{d:?}");
    }

    #[test]
    fn oblique_stripes() {
        let (c, s) = 33f64.to_radians().sin_cos();
        let px = image(256, |x, y| if ((x * s + y * c) / 19.3).fract() < 0.2 { 40.0 } else { 170.0 + noise(x, y) });
        let d = detect(&px, 256, 256);
        let w = d.lattice.clone().expect("stripes detected").waves[0];
        assert!((w.period() - 19.3).abs() < 0.1 && angle_gap(w.angle_deg(), 33.0) < 0.3, "{d:?}");
    }

    /// The wave of `lat` nearest `angle`, as (period, angle).
    fn wave_near(lat: &Lattice, angle: f64) -> (f64, f64) {
        let w =
            lat.waves.iter().min_by(|a, b| angle_gap(a.angle_deg(), angle).total_cmp(&angle_gap(b.angle_deg(), angle)));
        w.map_or((f64::NAN, f64::NAN), |w| (w.period(), w.angle_deg()))
    }

    #[test]
    fn square_tiles_with_a_fractional_pitch() {
        let p = 21.5;
        let px = image(
            256,
            |x, y| {
                if (x / p).fract() < 0.12 || (y / p).fract() < 0.12 {
                    50.0
                } else {
                    160.0 + noise(x, y)
                }
            },
        );
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("tiles detected");
        assert_eq!(lat.waves.len(), 2, "{d:?}");
        for a in [0.0, 90.0] {
            let (period, angle) = wave_near(&lat, a);
            assert!((period - p).abs() < 0.5 && angle_gap(angle, a) < 1.0, "{a}: {d:?}");
        }
    }

    #[test]
    fn running_bond() {
        // Courses 16 texels high, bricks 32 long, each course shifted by half a brick: the
        // lattice of (32, 0) and (16, 16).
        let px = image(256, |x, y| {
            let course = (y / 16.0).floor();
            let along = x + 16.0 * course.rem_euclid(2.0);
            if (y / 16.0).fract() < 0.15 || (along / 32.0).fract() < 0.08 {
                45.0
            } else {
                165.0 + noise(x, y)
            }
        });
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("bond detected");
        let (period, angle) = wave_near(&lat, 90.0);
        assert!((period - 16.0).abs() < 0.5 && angle_gap(angle, 90.0) < 1.0, "{d:?}");
        assert_eq!(lat.waves.len(), 2, "the bond's second wave: {d:?}");
        // Whichever second wave was found, the half-brick shift is a translation of the lattice.
        let k: Vec<[f64; 2]> = lat.waves.iter().map(|w| w.vector()).collect();
        for t in [[32.0, 0.0], [16.0, 16.0]] {
            for kv in &k {
                let phase = kv[0] * t[0] + kv[1] * t[1];
                assert!((phase - phase.round()).abs() < 0.05, "{t:?} is off the lattice {kv:?}: {d:?}");
            }
        }
    }

    #[test]
    fn noise_has_no_lattice() {
        let px = image(128, |x, y| 128.0 + 3.0 * noise(x, y));
        assert_eq!(detect(&px, 128, 128).lattice, None);
    }
}
