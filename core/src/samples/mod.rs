//! Per-sample queries (Wei & Levoy 2003): colours of scattered texels, in any order, for
//! renderers that ask for texture where their rasterizer or ray tracer needs it.
//!
//! A batch is answered by grouping its texels into aligned `GROUP × GROUP` cells per zoom,
//! rendering each occupied cell's bounding box as a window of the mode, and reading the samples
//! from it. A sample therefore equals the pixel of any tile that contains it, byte for byte (a
//! window equals the same pixels cut from any larger one), whatever the batch around it. The
//! windows of a batch run through one pyramidal cache, so the dependency cones of neighbouring
//! samples — and of tiles seen before — are computed once: a pixel's value at a generation is
//! cached per pixel ([`crate::cache`]), whichever window computed it.
//!
//! - [`filter`] — continuous samples `(u, v, lod)` filtered like a GPU texture unit (bilinear
//!   within a level, linear between levels) in fixed point, as weighted integer texels;
//! - [`camera`] — a perspective camera over the infinite ground plane: per-pixel footprints with
//!   their level of detail (Wei & Levoy's Figure 6).

pub mod camera;
pub mod filter;

use rayon::prelude::*;

use crate::cache::Pyramid;
use crate::error::{CoreError, Result};
use crate::geom::Rect;
use crate::modes::{ModeParams, Source, View};

pub use filter::Footprint;

/// Side of the aligned cells a batch's texels are grouped by (pixels at their zoom): one window
/// per occupied cell, the bounding box of its texels.
pub const GROUP: i64 = 32;

/// One texel of the texture viewed `zoom_out` steps coarser than native (0: native texels;
/// `k`: one texel covers `2^k × 2^k` native texels) — a pixel of a tile at zoom `N − k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Texel {
    /// Column at that zoom.
    pub x: i64,
    /// Row at that zoom.
    pub y: i64,
    /// Steps coarser than native.
    pub zoom_out: u32,
}

/// Colours of a batch and the work it took.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sampled {
    /// One RGB colour per requested sample, in request order.
    pub colors: Vec<[u8; 3]>,
    /// Pixels computed at all levels and generations (what a cache supplied is not counted):
    /// the numerator of the computation ratio.
    pub synthesized: u64,
    /// Windows rendered (occupied cells).
    pub windows: u64,
}

/// The samples read from one window (index in the request, colour) and the pixels it computed.
type WindowSamples = (Vec<(u32, [u8; 3])>, u64);

/// The cell of a texel, and a sort key that keeps neighbouring cells together (cells ordered
/// in 8 × 8 super-cells), so that consecutive windows share their cones through the cache.
fn cell(t: &Texel) -> (u32, i64, i64, i64, i64) {
    let (cx, cy) = (t.x.div_euclid(GROUP), t.y.div_euclid(GROUP));
    (t.zoom_out, cy.div_euclid(8), cx.div_euclid(8), cy, cx)
}

/// The colours of `texels` (any order, duplicates allowed) for a mode with its parameters,
/// through `cache` (for a batch's cones to be shared, it must be on).
pub fn texels(params: &ModeParams, src: &Source, cache: &Pyramid, texels: &[Texel]) -> Result<Sampled> {
    texels_until(params, src, cache, texels, &|| false)
}

/// [`texels`], giving up with [`CoreError::Cancelled`] between windows once `cancelled`
/// answers true (the client went away).
pub fn texels_until(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    texels: &[Texel],
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Sampled> {
    let mut order: Vec<u32> = (0..texels.len() as u32).collect();
    order.sort_unstable_by_key(|&i| cell(&texels[i as usize]));
    // Runs of the order with the same cell: one window each.
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut start = 0;
    for i in 1..=order.len() {
        let key = |k: usize| {
            let c = cell(&texels[order[k] as usize]);
            (c.0, c.3, c.4)
        };
        if i == order.len() || key(i) != key(start) {
            runs.push((start, i));
            start = i;
        }
    }
    let rendered: Vec<Result<WindowSamples>> = runs
        .par_iter()
        .with_max_len(4)
        .map(|&(a, b)| {
            if cancelled() {
                return Err(CoreError::Cancelled);
            }
            let members = &order[a..b];
            let first = texels[members[0] as usize];
            let mut rect = Rect::new(first.x, first.y, 1, 1);
            for &i in members {
                let t = texels[i as usize];
                rect = rect.union(&Rect::new(t.x, t.y, 1, 1));
            }
            let r = params.render(src, cache, View { zoom_out: first.zoom_out, rect })?;
            let out = members
                .iter()
                .map(|&i| {
                    let t = texels[i as usize];
                    (i, r.image.pixel((t.x - rect.x0) as u32, (t.y - rect.y0) as u32))
                })
                .collect();
            Ok((out, r.synthesized))
        })
        .collect();
    let mut colors = vec![[0u8; 3]; texels.len()];
    let mut synthesized = 0;
    for r in rendered {
        let (out, n) = r?;
        synthesized += n;
        for (i, c) in out {
            colors[i as usize] = c;
        }
    }
    Ok(Sampled { colors, synthesized, windows: runs.len() as u64 })
}

/// The colours of continuous samples, filtered trilinearly (see [`filter`]); levels of detail
/// are clamped to `0 ..= max_zoom_out`.
pub fn footprints(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    points: &[Footprint],
    max_zoom_out: u32,
) -> Result<Sampled> {
    footprints_until(params, src, cache, points, max_zoom_out, &|| false)
}

/// [`footprints`] with cancellation (see [`texels_until`]).
pub fn footprints_until(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    points: &[Footprint],
    max_zoom_out: u32,
    cancelled: &(dyn Fn() -> bool + Sync),
) -> Result<Sampled> {
    let taps = filter::taps(points, max_zoom_out)?;
    let wanted: Vec<Texel> = taps.iter().flat_map(|t| t.iter().map(|&(texel, _)| texel)).collect();
    let got = texels_until(params, src, cache, &wanted, cancelled)?;
    let mut at = 0;
    let colors = taps
        .iter()
        .map(|t| {
            let c = filter::blend(t.iter().map(|&(_, w)| w).zip(&got.colors[at..at + t.len()]));
            at += t.len();
            c
        })
        .collect();
    Ok(Sampled { colors, synthesized: got.synthesized, windows: got.windows })
}
