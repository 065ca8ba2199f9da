//! One seamless, tileable texture by Wei & Levoy's 2000 algorithm (design note §3): Gaussian
//! pyramids of the exemplar and of a toroidal output, synthesized coarse to fine, each level in
//! scanline order: every output pixel takes the colour of the exemplar pixel whose
//! neighbourhood best matches its own — the causal L-shaped 5×5 half at its level (12 pixels)
//! and the full 3×3 around its parent one level coarser (9 pixels). Output neighbourhoods wrap
//! around the edges, so the result tiles; each level is swept three times: twice with the causal
//! neighbourhood (the second sweep sees synthesized pixels beyond the wrap where the first saw
//! the starting noise), then once with the whole 5×5 neighbourhood but the pixel itself, which
//! joins the last rows and columns to the first across the wrap. The best
//! match is found by a [`Tsvq`] with limited backtracking, or exhaustively. Deterministic for a
//! seed: the noise is a hash of the seed and the pixel, the search has no randomness.

use rayon::prelude::*;

use crate::analysis::Progress;
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::exemplar::Exemplar;
use crate::hash::hash;
use crate::image::RgbWindow;
use crate::tsvq::{distance, Tsvq};

/// How the best match is found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Search {
    /// A TSVQ scanning at most this many leaves per query (W&L's limited backtracking).
    Tsvq {
        /// Leaves scanned per query (≥ 1).
        backtrack: usize,
    },
    /// Every exemplar neighbourhood (W&L's exhaustive search; slow, for comparison).
    Exact,
}

/// What to synthesize.
#[derive(Debug, Clone, Copy)]
pub struct TileableOptions {
    /// Output side (a multiple of `2^(levels − 1)`, within [`MIN_SIZE`, `MAX_SIZE`]).
    pub size: u32,
    /// Seed of the starting noise.
    pub seed: u64,
    /// Search.
    pub search: Search,
}

/// Smallest output side.
pub const MIN_SIZE: u32 = 32;
/// Largest output side.
pub const MAX_SIZE: u32 = 4096;
/// Default leaves scanned per query.
pub const DEFAULT_BACKTRACK: usize = 8;
/// Vectors per TSVQ leaf.
const LEAF_CAP: usize = 16;
/// Sweeps per level: two with causal neighbourhoods, then one with full ones.
const SWEEPS: u32 = 3;
/// Causal half of the 5×5 neighbourhood at the pixel's own level.
const CAUSAL: [(i64, i64); 12] =
    [(-2, -2), (-2, -1), (-2, 0), (-2, 1), (-2, 2), (-1, -2), (-1, -1), (-1, 0), (-1, 1), (-1, 2), (0, -2), (0, -1)];
/// The whole 5×5 neighbourhood but its centre, for the last sweep.
const FULL: [(i64, i64); 24] = [
    (-2, -2),
    (-2, -1),
    (-2, 0),
    (-2, 1),
    (-2, 2),
    (-1, -2),
    (-1, -1),
    (-1, 0),
    (-1, 1),
    (-1, 2),
    (0, -2),
    (0, -1),
    (0, 1),
    (0, 2),
    (1, -2),
    (1, -1),
    (1, 0),
    (1, 1),
    (1, 2),
    (2, -2),
    (2, -1),
    (2, 0),
    (2, 1),
    (2, 2),
];
/// Full 3×3 around the parent one level coarser.
const PARENT: [(i64, i64); 9] = [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 0), (0, 1), (1, -1), (1, 0), (1, 1)];

/// Pyramid levels for an exemplar whose shorter side is `m`: coarsest exemplar level at least
/// 16 px, at most 4.
pub fn levels(m: u32) -> u32 {
    let log2 = 31 - m.max(1).leading_zeros();
    (log2.saturating_sub(3)).clamp(1, 4)
}

/// One level of an image pyramid, `f32` RGB.
struct Level {
    w: usize,
    h: usize,
    px: Vec<[f32; 3]>,
}

impl Level {
    fn at_wrapped(&self, x: i64, y: i64) -> [f32; 3] {
        self.px[(y.rem_euclid(self.h as i64) as usize) * self.w + x.rem_euclid(self.w as i64) as usize]
    }

    /// The next coarser level: 2×2 means.
    fn down(&self) -> Level {
        let (w, h) = (self.w / 2, self.h / 2);
        let mut px = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let mut s = [0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let p = self.px[(2 * y + dy) * self.w + 2 * x + dx];
                    for c in 0..3 {
                        s[c] += p[c];
                    }
                }
                px.push(s.map(|v| v * 0.25));
            }
        }
        Level { w, h, px }
    }
}

/// The neighbourhood vector of pixel (x, y) of `level` over `shape` (with `parent` one level
/// coarser, if any), read with wrap-around, into `out`.
fn neighbourhood(shape: &[(i64, i64)], level: &Level, parent: Option<&Level>, x: i64, y: i64, out: &mut Vec<f32>) {
    out.clear();
    for &(dy, dx) in shape {
        out.extend_from_slice(&level.at_wrapped(x + dx, y + dy));
    }
    if let Some(p) = parent {
        for (dy, dx) in PARENT {
            out.extend_from_slice(&p.at_wrapped(x.div_euclid(2) + dx, y.div_euclid(2) + dy));
        }
    }
}

/// The exemplar's neighbourhoods at one level: positions whose neighbourhood lies inside the
/// exemplar (every position, for a toroidal one) and their vectors.
struct Candidates {
    dim: usize,
    positions: Vec<(u32, u32)>,
    vectors: Vec<f32>,
}

fn candidates(shape: &[(i64, i64)], level: &Level, parent: Option<&Level>, toroidal: bool) -> Candidates {
    let mut positions = Vec::new();
    for y in 0..level.h as u32 {
        for x in 0..level.w as u32 {
            let inside = toroidal || {
                let (w, h) = (level.w as i64, level.h as i64);
                let (x, y) = (x as i64, y as i64);
                let below = shape.iter().map(|o| o.0).max().unwrap_or(0);
                let own = x >= 2 && x + 2 < w && y >= 2 && y + below < h;
                let up = parent.is_none_or(|_| x / 2 >= 1 && x / 2 + 1 < w / 2 && y / 2 >= 1 && y / 2 + 1 < h / 2);
                own && up
            };
            if inside {
                positions.push((x, y));
            }
        }
    }
    let dim = 3 * (shape.len() + if parent.is_some() { PARENT.len() } else { 0 });
    let mut vectors = Vec::with_capacity(positions.len() * dim);
    let mut v = Vec::with_capacity(dim);
    for &(x, y) in &positions {
        neighbourhood(shape, level, parent, x as i64, y as i64, &mut v);
        vectors.extend_from_slice(&v);
    }
    Candidates { dim, positions, vectors }
}

/// Brute-force nearest vector (ties to the smallest index), in parallel over chunks.
fn exact_nearest(c: &Candidates, q: &[f32]) -> u32 {
    let n = c.positions.len();
    (0..n)
        .into_par_iter()
        .with_min_len(1024)
        .map(|i| (distance(&c.vectors[i * c.dim..(i + 1) * c.dim], q), i as u32))
        .reduce(|| (f32::INFINITY, u32::MAX), |a, b| if b.0 < a.0 || (b.0 == a.0 && b.1 < a.1) { b } else { a })
        .1
}

/// Check the options against the exemplar; the number of pyramid levels.
pub fn check(ex: &Exemplar, opts: &TileableOptions) -> Result<u32> {
    let bad = |message: String| CoreError::Param { name: "size", message };
    let levels = levels(ex.width.min(ex.height));
    let step = 1u32 << (levels - 1);
    if !(MIN_SIZE..=MAX_SIZE).contains(&opts.size) {
        return Err(bad(format!("{} is outside {MIN_SIZE}..={MAX_SIZE}", opts.size)));
    }
    if !opts.size.is_multiple_of(step) {
        return Err(bad(format!(
            "{} is not a multiple of {step}: a {0}² exemplar gives a pyramid of {levels} levels",
            opts.size
        )));
    }
    if matches!(opts.search, Search::Tsvq { backtrack: 0 }) {
        return Err(CoreError::Param { name: "backtrack", message: "must be at least 1".into() });
    }
    Ok(levels)
}

/// Synthesize a seamless `size × size` texture from `ex`. `progress` hears of every row swept.
pub fn synthesize(
    ex: &Exemplar,
    opts: &TileableOptions,
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<RgbWindow> {
    let levels = check(ex, opts)? as usize;
    synthesize_sized(ex, levels, (opts.size as usize, opts.size as usize), opts, progress, cancel)
}

/// [`synthesize`] of a `width × height` texture over `levels` pyramid levels (sizes unchecked:
/// a level of an odd size is the floor of half the finer one's, wrapping all the same).
fn synthesize_sized(
    ex: &Exemplar,
    levels: usize,
    (width, height): (usize, usize),
    opts: &TileableOptions,
    progress: &dyn Progress,
    cancel: &Cancel,
) -> Result<RgbWindow> {
    let (ew, eh) = ex.dims();
    let mut pyr = vec![Level { w: ew, h: eh, px: ex.pixels.iter().map(|p| p.map(|c| c as f32)).collect() }];
    for _ in 1..levels {
        let next = pyr[pyr.len() - 1].down();
        pyr.push(next);
    }
    let total: u32 = (0..levels).map(|l| SWEEPS * (height >> l) as u32).sum();
    let mut done = 0;
    progress.step(0, total, "starting");
    let mut out: Vec<Level> = Vec::with_capacity(levels);
    for l in (0..levels).rev() {
        let ex_level = &pyr[l];
        let ex_parent = pyr.get(l + 1);
        let searches: Vec<(Candidates, Option<Tsvq>)> = [&CAUSAL[..], &FULL[..]]
            .into_iter()
            .map(|shape| {
                let c = candidates(shape, ex_level, ex_parent, ex.toroidal);
                let tree = match opts.search {
                    Search::Tsvq { .. } => Some(Tsvq::new(c.dim, &c.vectors, LEAF_CAP)),
                    Search::Exact => None,
                };
                (c, tree)
            })
            .collect();
        let (s, sh) = ((width >> l).max(1), (height >> l).max(1));
        // Starting noise: exemplar pixels picked by a hash of the seed and the pixel.
        let px = (0..s * sh)
            .map(|i| {
                let h = hash(0x7117, opts.seed, (i % s) as i64, (i / s) as i64, l as i64);
                ex_level.px[(h % ex_level.px.len() as u64) as usize]
            })
            .collect();
        let mut level = Level { w: s, h: sh, px };
        let parent = out.last();
        let mut q = Vec::new();
        for sweep in 0..SWEEPS {
            // The last sweep sees both sides of every pixel, across the wrap too.
            let (shape, (cands, tree)) =
                if sweep + 1 < SWEEPS { (&CAUSAL[..], &searches[0]) } else { (&FULL[..], &searches[1]) };
            for y in 0..sh {
                cancel.check()?;
                for x in 0..s {
                    neighbourhood(shape, &level, parent, x as i64, y as i64, &mut q);
                    let best = match (tree, opts.search) {
                        (Some(t), Search::Tsvq { backtrack }) => {
                            t.nearest(&q, backtrack, |_| true).map(|b| b.1).unwrap_or(0)
                        }
                        _ => exact_nearest(cands, &q),
                    };
                    let (bx, by) = cands.positions[best as usize];
                    level.px[y * s + x] = ex_level.px[by as usize * ex_level.w + bx as usize];
                }
                done += 1;
                progress.step(done, total, &format!("level {l} of {levels}, sweep {} of {SWEEPS}", sweep + 1));
            }
        }
        out.push(level);
    }
    let finest = out.pop().ok_or_else(|| CoreError::Param { name: "size", message: "no level".into() })?;
    let pixels = finest.px.iter().flat_map(|p| p.map(|c| c.round().clamp(0.0, 255.0) as u8)).collect();
    Ok(RgbWindow { width: width as u32, height: height as u32, pixels })
}

/// A toroidal exemplar made from a non-toroidal one: a seamless texture of the same size
/// synthesized from it (TSVQ, [`DEFAULT_BACKTRACK`] leaves), so that the main engine can wrap
/// around it with no border rule. Deterministic for a seed.
pub fn make_toroidal(ex: &Exemplar, seed: u64) -> Result<Exemplar> {
    let opts = TileableOptions { size: ex.width, seed, search: Search::Tsvq { backtrack: DEFAULT_BACKTRACK } };
    let levels = levels(ex.width.min(ex.height)) as usize;
    let img = synthesize_sized(ex, levels, ex.dims(), &opts, &crate::analysis::NoProgress, &Cancel::new())?;
    let pixels: Vec<[u8; 3]> = img.pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let seam_ratio = crate::exemplar::seam_ratio(&pixels, ex.width as usize, ex.height as usize);
    let preparation = crate::exemplar::Intake {
        toroidal_forced: true,
        seam_ratio,
        toroidal_synthesized: true,
        ..ex.preparation.clone()
    };
    Ok(Exemplar {
        width: ex.width,
        height: ex.height,
        pixels,
        toroidal: true,
        preparation,
        hires: None,
        randomness_mask: None,
        input_spread: ex.input_spread,
        lattice: None,
        repeat: None,
        structure: None,
        maps: Vec::new(),
    })
}
