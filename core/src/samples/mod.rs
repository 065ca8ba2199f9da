//! Per-sample queries (Wei & Levoy 2003): colours of scattered texels, in any order, for
//! renderers that ask for texture where their rasterizer or ray tracer needs it.
//!
//! A batch is answered by grouping its texels into windows per zoom — quadtree cells from
//! `MAX_GROUP` down to `GROUP` texels wide, merged wherever one window over their bounding box
//! costs less than its parts (padding and a fixed overhead counted) — rendering each window with
//! the mode, and reading the samples
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
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::geom::Rect;
use crate::modes::{ModeParams, Source, View};

pub use filter::Footprint;

/// Side of the smallest aligned cells a batch's texels are grouped by (pixels at their zoom):
/// one window per occupied cell, the bounding box of its texels.
pub const GROUP: i64 = 32;
/// Side of the largest cells: where texels are dense, cells up to this side are one window
/// (fewer windows, and no padding computed twice by windows running side by side).
pub const MAX_GROUP: i64 = 256;

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

/// Padding of a window at its finest level, as the cost model counts it.
const PAD: i64 = 10;
/// Fixed cost of a window (plans, cache lookups) in pixels' worth of work.
const WINDOW_OVERHEAD: i64 = 1024;

/// A window of texels: zoom, bounding box, members.
type Window = (u32, Rect, Vec<u32>);

/// The bounding box of some texels.
fn bbox(texels: &[Texel], members: &[u32]) -> Rect {
    let t0 = texels[members[0] as usize];
    members.iter().fold(Rect::new(t0.x, t0.y, 1, 1), |r, &i| {
        let t = texels[i as usize];
        r.union(&Rect::new(t.x, t.y, 1, 1))
    })
}

/// What rendering a window over `r` costs in the model: its padded area and a fixed overhead.
fn cost(r: Rect) -> i64 {
    (r.width() + 2 * PAD) * (r.height() + 2 * PAD) + WINDOW_OVERHEAD
}

/// The cheapest windows for `members`, all in one aligned cell of side `g` at one zoom: the
/// cell's bounding box as one window, or the best split into its four quadrants, whichever the
/// cost model prefers. Returns the cost and the windows.
fn split(texels: &[Texel], members: &mut [u32], g: i64) -> (i64, Vec<Window>) {
    let rect = bbox(texels, members);
    let whole = cost(rect);
    let one = |m: &[u32]| vec![(texels[m[0] as usize].zoom_out, rect, m.to_vec())];
    if g <= GROUP {
        return (whole, one(members));
    }
    let h = g / 2;
    let quad = |i: &u32| {
        let t = texels[*i as usize];
        (t.y.div_euclid(h), t.x.div_euclid(h))
    };
    members.sort_unstable_by_key(quad);
    let (mut total, mut parts) = (0, Vec::new());
    let mut rest = &mut *members;
    while !rest.is_empty() {
        let q = quad(&rest[0]);
        let n = rest.iter().position(|i| quad(i) != q).unwrap_or(rest.len());
        let (run, tail) = rest.split_at_mut(n);
        let (c, w) = split(texels, run, h);
        total += c;
        parts.extend(w);
        rest = tail;
    }
    if whole <= total {
        (whole, one(members))
    } else {
        (total, parts)
    }
}

/// Where a texel's planning cell comes in a batch: by zoom, then by blocks of 8 × 8 cells of
/// side [`MAX_GROUP`] (neighbours together, for the cache to share their cones), then by cell.
fn cell_order(t: &Texel) -> (u32, i64, i64, i64, i64) {
    let (cy, cx) = (t.y.div_euclid(MAX_GROUP), t.x.div_euclid(MAX_GROUP));
    (t.zoom_out, cy.div_euclid(8), cx.div_euclid(8), cy, cx)
}

/// The windows of a batch: per zoom and aligned cell of side [`MAX_GROUP`], the cheapest
/// split into windows over quadrants down to cells of side [`GROUP`] (dense texels make one
/// big window, sparse ones small windows around them). Windows are ordered so that neighbours
/// follow each other (cells of 8 × 8 big cells together), for the cache to share their cones.
fn plan(texels: &[Texel]) -> Vec<Window> {
    let cell = |i: &u32| cell_order(&texels[*i as usize]);
    let mut all: Vec<u32> = (0..texels.len() as u32).collect();
    all.sort_unstable_by_key(cell);
    let mut out = Vec::new();
    let mut rest = &mut all[..];
    while !rest.is_empty() {
        let c = cell(&rest[0]);
        let n = rest.iter().position(|i| cell(i) != c).unwrap_or(rest.len());
        let (run, tail) = rest.split_at_mut(n);
        out.extend(split(texels, run, MAX_GROUP).1);
        rest = tail;
    }
    out
}

/// The colours of `texels` (any order, duplicates allowed) for a mode with its parameters,
/// through `cache` (for a batch's cones to be shared, it must be on).
pub fn texels(params: &ModeParams, src: &Source, cache: &Pyramid, texels: &[Texel]) -> Result<Sampled> {
    texels_until(params, src, cache, texels, &Cancel::new())
}

/// Texels planned and rendered together at most: a bigger batch is cut into spatially sorted
/// chunks of this many (the cache shares what neighbouring chunks have in common), which bounds
/// the plan's memory whatever the batch size.
const CHUNK_TEXELS: usize = 1 << 16;

/// Footprints filtered together at most (each has up to 8 taps).
const CHUNK_FOOTPRINTS: usize = CHUNK_TEXELS / 8;

/// [`texels`], giving up with [`CoreError::Cancelled`] between windows once `cancel` is set
/// (the client went away).
pub fn texels_until(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    texels: &[Texel],
    cancel: &Cancel,
) -> Result<Sampled> {
    if texels.len() <= CHUNK_TEXELS {
        return texels_together(params, src, cache, texels, cancel);
    }
    let mut order: Vec<u32> = (0..texels.len() as u32).collect();
    order.sort_unstable_by_key(|&i| cell_order(&texels[i as usize]));
    let mut colors = vec![[0u8; 3]; texels.len()];
    let (mut synthesized, mut windows) = (0, 0);
    for chunk in order.chunks(CHUNK_TEXELS) {
        let part: Vec<Texel> = chunk.iter().map(|&i| texels[i as usize]).collect();
        let got = texels_together(params, src, cache, &part, cancel)?;
        for (&i, c) in chunk.iter().zip(got.colors) {
            colors[i as usize] = c;
        }
        synthesized += got.synthesized;
        windows += got.windows;
    }
    Ok(Sampled { colors, synthesized, windows })
}

/// The texels of one chunk, planned into windows together.
fn texels_together(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    texels: &[Texel],
    cancel: &Cancel,
) -> Result<Sampled> {
    let windows = plan(texels);
    let rendered: Vec<Result<WindowSamples>> = windows
        .par_iter()
        .with_max_len(1)
        .map(|(zoom_out, rect, members)| {
            if cancel.is_set() {
                return Err(CoreError::Cancelled);
            }
            let r = params.render(src, cache, View::out(*zoom_out, *rect))?;
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
    Ok(Sampled { colors, synthesized, windows: windows.len() as u64 })
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
    footprints_until(params, src, cache, points, max_zoom_out, &Cancel::new())
}

/// [`footprints`] with cancellation (see [`texels_until`]).
pub fn footprints_until(
    params: &ModeParams,
    src: &Source,
    cache: &Pyramid,
    points: &[Footprint],
    max_zoom_out: u32,
    cancel: &Cancel,
) -> Result<Sampled> {
    let mut colors = Vec::with_capacity(points.len());
    let (mut synthesized, mut windows) = (0, 0);
    for (k, chunk) in points.chunks(CHUNK_FOOTPRINTS).enumerate() {
        let taps = filter::taps(chunk, max_zoom_out).map_err(|e| match e {
            CoreError::Sample { index, message } => CoreError::Sample { index: index + k * CHUNK_FOOTPRINTS, message },
            other => other,
        })?;
        let wanted: Vec<Texel> = taps.iter().flat_map(|t| t.iter().map(|&(texel, _)| texel)).collect();
        let got = texels_until(params, src, cache, &wanted, cancel)?;
        let mut at = 0;
        colors.extend(taps.iter().map(|t| {
            let c = filter::blend(t.iter().map(|&(_, w)| w).zip(&got.colors[at..at + t.len()]));
            at += t.len();
            c
        }));
        synthesized += got.synthesized;
        windows += got.windows;
    }
    Ok(Sampled { colors, synthesized, windows })
}
