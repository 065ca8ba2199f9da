//! Window synthesis (design note §1.3): for each level of a window plan, upsample the parent
//! coordinates, jitter them by a hash of absolute coordinates, and correct them in Jacobi
//! subpasses with k-coherence candidates. Output: exemplar coordinates of any rectangle at any
//! level, bit-identical to the same pixels cut from any larger window.
//!
//! Per level, the work is shared through the [`crate::cache`] cache: `generations`
//! says which generation of which pixel is still needed, `history` lays cached blocks over the
//! buffer and gathers what this call computes, and `kernel` corrects one pixel.

use rayon::prelude::*;

use crate::analysis::{Analysis, CorrectionLevel};
use crate::error::{CoreError, Result};
use crate::analysis::features::TAPS5;
use super::generations::{class_cols, class_layout, needed_generations};
use crate::geom::{fl2, pack_wrapped, par, wrap, Rect};
use crate::hash::{hash_tail, head, key, TAG_JITTER};
use crate::lattice::LevelLattice;
use crate::mask::RandomnessMask;
use crate::modes::params::ONE_Q16;
use crate::modes::Declared;
use super::controls::Controls;
use super::history::{block_index, capture, for_rows, overlay, pending};
use super::kernel::{projection_pairs, projection_run_pairs, tap_shifts, tap_spans, Kernel};
use super::params::SynthParams;
use super::Synth;
use crate::modes::Mode;
use super::plan::{pad_for_correction, plan_window, Class, Schedules};
use crate::cache::{Block, BlockGrid, BlockKey, Pyramid, StreamId, BLOCK};

/// Largest number of pixels synthesized at the finest requested level in one call (2^26).
pub const MAX_WINDOW_PIXELS: i64 = 1 << 26;

/// Exemplar coordinates of a window at one level.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CoordWindow {
    /// Pyramid level of the coordinates.
    pub level: u32,
    /// The window.
    pub rect: Rect,
    /// Row-major packed coordinates `x | y << 16`.
    pub coords: Vec<u32>,
}

impl CoordWindow {
    /// The coordinate at window-relative `(i, j)` as `(x, y)`.
    pub fn get(&self, i: usize, j: usize) -> (u32, u32) {
        let v = self.coords[j * self.rect.width() as usize + i];
        (v & 0xFFFF, v >> 16)
    }
}

/// A level's buffer: packed coordinates over a rectangle.
struct Buf {
    rect: Rect,
    s: Vec<u32>,
}

impl Buf {
    fn crop(&self, r: Rect) -> Buf {
        let w = self.rect.width() as usize;
        let (ox, oy) = ((r.x0 - self.rect.x0) as usize, (r.y0 - self.rect.y0) as usize);
        let rw = r.width() as usize;
        let mut s = Vec::with_capacity(r.area() as usize);
        for j in 0..r.height() as usize {
            let start = (oy + j) * w + ox;
            s.extend_from_slice(&self.s[start..start + rw]);
        }
        Buf { rect: r, s }
    }
}

/// Synthesize the exemplar coordinates of `rect` at pyramid `level` (`0..=L`), computing
/// everything (no cache).
pub fn synthesize(an: &Analysis, params: &SynthParams, level: u32, rect: Rect) -> Result<CoordWindow> {
    synthesize_with(&Pyramid::off(), an, params, level, rect).map(|s| s.window)
}

/// A synthesized window and the work it took.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Synthesized {
    /// The coordinates.
    pub window: CoordWindow,
    /// Pixels computed at all levels, padding included (a pixel counts once however many
    /// subpasses touched it); what came from the pyramid cache is not counted.
    pub synthesized: u64,
}

/// [`synthesize`] sharing work through a pyramidal cache: blocks it holds are reused, blocks
/// this call completes are offered to it. The coordinates do not depend on the cache.
pub fn synthesize_with(
    pyr: &Pyramid,
    an: &Analysis,
    params: &SynthParams,
    level: u32,
    rect: Rect,
) -> Result<Synthesized> {
    params.validate(an.dims())?;
    if level > an.levels() {
        return Err(CoreError::Param { name: "level", message: format!("must be 0 to {}", an.levels()) });
    }
    if rect.is_empty() || rect.area() > MAX_WINDOW_PIXELS {
        return Err(CoreError::Window {
            width: rect.width(),
            height: rect.height(),
            message: format!("must be non-empty with at most {MAX_WINDOW_PIXELS} pixels"),
        });
    }
    let ctx = Ctx::new(an, params, pyr, an.randomness_mask()?);
    // The same window again (another map of a tile just rendered): its coordinates, as kept.
    let key = (ctx.stream, level, rect);
    if let Some(coords) = pyr.window(&key) {
        return Ok(Synthesized { window: CoordWindow { level, rect, coords: coords.to_vec() }, synthesized: 0 });
    }
    let mut synthesized = 0;
    let buf = ctx.level(level, rect, &mut synthesized);
    pyr.keep_window(key, buf.s.as_slice().into());
    Ok(Synthesized { window: CoordWindow { level, rect, coords: buf.s }, synthesized })
}

/// Pixels a cold call to [`synthesize`] computes at all levels (padding included), from its plan.
pub fn synthesis_cost(an: &Analysis, params: &SynthParams, level: u32, rect: Rect) -> u64 {
    plan_window(level.min(an.levels()), rect, &Schedules::new(params.passes, params.subpasses, an.levels()))
        .iter()
        .map(|lp| lp.padded.area() as u64)
        .sum()
}

struct Ctx<'a> {
    an: &'a Analysis,
    pyr: &'a Pyramid,
    stream: StreamId,
    scheds: Schedules,
    seed: u64,
    r: Vec<u32>,
    phi: [u64; 2],
    period: Option<i64>,
    /// The exemplar's width and height: coordinates wrap at them.
    dims: (i64, i64),
    levels: u32,
    /// The randomness mask over the exemplar (`R_E`), scaling jitter.
    mask: Option<&'a RandomnessMask>,
    /// The request's modulation over the output (`R_S`), scaling jitter.
    controls: Controls,
}

impl<'a> Ctx<'a> {
    fn new(an: &'a Analysis, p: &SynthParams, pyr: &'a Pyramid, mask: Option<&'a RandomnessMask>) -> Self {
        Ctx {
            mask,
            controls: p.controls.clone(),
            an,
            pyr,
            stream: StreamId::new(&format!("{}|v{}|{}|{}", Synth::NAME, Synth::VERSION, an.header.id, p.canonical())),
            scheds: Schedules::new(p.passes, p.subpasses, an.levels()),
            seed: p.seed,
            r: p.randomness.resolve(an.levels()),
            phi: p.phi(),
            period: p.period,
            dims: (an.width() as i64, an.height() as i64),
            levels: an.levels(),
        }
    }

    /// The final coordinates of `need` at level `l`, computing (after its parents) only what
    /// the cache does not hold. Generation `k` of a pixel is its value after `k` subpasses;
    /// per pixel, `top` is the highest generation this call needs and `lo` the highest the
    /// cache holds (−1: none), so the pixel is computed at generations `lo+1 ..= top`.
    fn level(&self, l: u32, need: Rect, count: &mut u64) -> Buf {
        let cl = self.an.correction_level(l).filter(|_| !self.scheds.level(l).is_empty());
        let gens: &[Class] = if cl.is_some() { self.scheds.level(l) } else { &[] };
        let kk = gens.len();
        let ext = if kk > 0 { pad_for_correction(need, gens).0 } else { need };
        let w = ext.width() as usize;
        let grid = BlockGrid::covering(ext);
        let blocks = self.pyr.lookup(self.stream, l, &grid);
        // The cached blocks, with the part of each inside `ext`.
        let cached: Vec<(&Block, Rect)> = blocks
            .iter()
            .enumerate()
            .filter_map(|(n, b)| b.as_deref().map(|b| (b, grid.rect(n % grid.nbx, n / grid.nbx).intersect(&ext))))
            .collect();

        let mut lo = vec![-1i8; w * ext.height() as usize];
        for &(b, r) in &cached {
            for_rows(r, |y, x0, x1| {
                let at = (y - ext.y0) as usize * w + (x0 - ext.x0) as usize;
                let from = block_index(x0, y);
                lo[at..at + (x1 - x0) as usize].copy_from_slice(&b.lo[from..from + (x1 - x0) as usize]);
            });
        }
        let (top, boxes) = needed_generations(ext, need, gens, &lo, !cached.is_empty());

        // Pixels computed from scratch (generation 0): counted, and their parents are needed.
        let (mut fresh, mut b) = (0u64, (i64::MAX, i64::MAX, i64::MIN, i64::MIN));
        for (j, (trow, lrow)) in top.chunks(w).zip(lo.chunks(w)).enumerate() {
            let n = trow.iter().zip(lrow).filter(|(&t, &o)| t >= 0 && o < 0).count();
            if n > 0 {
                let first = trow.iter().zip(lrow).position(|(&t, &o)| t >= 0 && o < 0).unwrap_or(0);
                let last = w - 1 - trow.iter().zip(lrow).rev().position(|(&t, &o)| t >= 0 && o < 0).unwrap_or(0);
                let y = ext.y0 + j as i64;
                b = (b.0.min(ext.x0 + first as i64), b.1.min(y), b.2.max(ext.x0 + last as i64), b.3.max(y));
                fresh += n as u64;
            }
        }
        let fresh_rect = Rect { x0: b.0, y0: b.1, x1: b.2.wrapping_add(1), y1: b.3.wrapping_add(1) };
        let parent = (!fresh_rect.is_empty() && l > 0).then(|| self.level(l - 1, fresh_rect.parents(), count));
        *count += fresh;

        let class_len = match gens.first() {
            Some(Class::Parity(..)) => (BLOCK * BLOCK / 4) as usize,
            _ => (BLOCK * BLOCK) as usize,
        };
        let mut pending =
            if self.pyr.is_on() { pending(self.pyr, &grid, &blocks, ext, &top, class_len) } else { Vec::new() };

        // Generation 0: upsample the parents and jitter, or take the cached values.
        let lc = self.level_consts(l);
        let rs = Modulation::over(&self.controls, ext, lc.h, self.period);
        // What features impose on this level's pixels, drawn once (usually nothing).
        let imposed = Imposed::draw(&self.controls, l, self.levels, ext, lc.h, self.dims, self.period);
        let mut s = vec![0u32; lo.len()];
        s.par_chunks_mut(w).enumerate().with_min_len(8).for_each(|(j, row)| {
            let y = ext.y0 + j as i64;
            let prow = parent.as_ref().and_then(|p| {
                let (py, pw) = (fl2(y) - p.rect.y0, p.rect.width() as usize);
                (py >= 0 && py < p.rect.height()).then(|| (&p.s[py as usize * pw..(py as usize + 1) * pw], p.rect.x0))
            });
            let (trow, lrow) = (&top[j * w..(j + 1) * w], &lo[j * w..(j + 1) * w]);
            for (i, out) in row.iter_mut().enumerate() {
                if trow[i] >= 0 && lrow[i] < 0 {
                    let x = ext.x0 + i as i64;
                    let v = prow.map_or(0, |(pr, px0)| pr[(fl2(x) - px0) as usize]);
                    *out = match imposed.at(j * w + i) {
                        Some(v) => v,
                        None => self.jitter(&lc, x, y, v, rs.at(x, y)),
                    };
                }
            }
        });
        for &(blk, r) in &cached {
            overlay(&mut s, ext, r, Class::All, blk.generation(0), &top, &lo, 0, |_, _| {});
        }
        capture(&mut pending, &s, ext, &top, Class::All, 0, 0);

        // Generations 1..: the correction subpasses (Jacobi: each reads the previous generation).
        if let Some(cl) = cl {
            let ew = self.dims.0 as usize;
            let pal: Vec<u32> =
                self.an.colours8(l).iter().map(|c| c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16).collect();
            let colour = |v: u32| pal[(v >> 16) as usize * ew + (v & 0xFFFF) as usize];
            let mut col: Vec<u32> = Vec::with_capacity(s.len());
            s.par_iter().map(|&v| colour(v)).collect_into_vec(&mut col);
            let proj: Vec<i32> = cl.proj.iter().map(|&v| v as i32).collect();
            let kern = self.kernel(l, w, &proj, cl);
            for (k, &class) in gens.iter().enumerate().map(|(i, c)| (i + 1, c)) {
                let k8 = k as i8;
                // Only the box of the pixels this subpass computes (inside `ext`, or empty).
                let bx = boxes[k - 1].intersect(&ext);
                let (rows, c0, step) = class_layout(class, bx);
                let (ox, oy) = ((bx.x0 - ext.x0).max(0) as usize, (bx.y0 - ext.y0).max(0) as usize);
                let cols = class_cols(bx.width() as usize, c0, step);
                let mut out = vec![0u32; rows.len() * cols];
                let (sr, colr) = (&s, &col);
                out.par_chunks_mut(cols.max(1)).zip(rows.par_iter()).with_min_len(4).for_each(|(orow, &j)| {
                    let base = (oy + j) * w + ox + c0;
                    // R_E: a pixel showing a kept (black) part of the exemplar stays as it is.
                    let kept = |v: u32| self.mask.is_some_and(|mk| mk.at(l, v & 0xFFFF, v >> 16) == 0);
                    // Pixels a feature imposes are not corrected either.
                    let todo = |c: usize| {
                        let p = base + c * step;
                        top[p] >= k8 && lo[p] < k8 && !kept(sr[p]) && imposed.at(p).is_none()
                    };
                    let mut c = 0;
                    while c < cols {
                        if !todo(c) {
                            orow[c] = sr[base + c * step];
                            c += 1;
                            continue;
                        }
                        let start = c;
                        while c < cols && todo(c) {
                            c += 1;
                        }
                        kern.row(sr, colr, base + start * step, step, &mut orow[start..c]);
                    }
                    // Nor is any other pixel corrected into one: kept parts arrive whole, by
                    // upsampling, never texel by texel.
                    if self.mask.is_some() {
                        for (c, o) in orow.iter_mut().enumerate() {
                            let v = sr[base + c * step];
                            if *o != v && kept(*o) {
                                *o = v;
                            }
                        }
                    }
                });
                for (orow, &j) in out.chunks(cols.max(1)).zip(&rows) {
                    let base = (oy + j) * w + ox + c0;
                    for (c, &v) in orow.iter().enumerate() {
                        let p = base + c * step;
                        if s[p] != v {
                            s[p] = v;
                            col[p] = colour(v);
                        }
                    }
                }
                for &(blk, r) in cached.iter().filter(|(b, _)| b.max_lo >= k8) {
                    overlay(&mut s, ext, r, class, blk.generation(k), &top, &lo, k8, |p, v| col[p] = colour(v));
                }
                capture(&mut pending, &s, ext, &top, class, k, BLOCK as usize * BLOCK as usize + (k - 1) * class_len);
            }
        }

        if !pending.is_empty() {
            let store = pending
                .into_iter()
                .map(|pb| {
                    let key =
                        BlockKey { stream: self.stream, level: l, bx: pb.rect.x0 / BLOCK, by: pb.rect.y0 / BLOCK };
                    (key, Block::new(pb.lo, class_len, pb.data))
                })
                .collect();
            self.pyr.store(store);
        }
        Buf { rect: ext, s }.crop(need)
    }

    fn level_consts(&self, l: u32) -> LevelConsts {
        let h = 1i64 << (self.levels - l);
        LevelConsts {
            l,
            h,
            dims: self.dims,
            rq: self.r[l as usize] as i64,
            period: self.period.map(|n| n >> (self.levels - l)),
            jitter_head: head(key(TAG_JITTER, self.seed), l as i64),
            lattice: self
                .an
                .lattice()
                .map_or(LevelLattice::FREE, |lat| lat.level(h, self.an.size().longer())),
        }
    }

    /// Generation 0 of pixel `(x, y)`: its parent's coordinate `v` shifted to the child's
    /// position, plus the hash jitter of its absolute position.
    #[inline]
    fn jitter(&self, c: &LevelConsts, x: i64, y: i64, v: u32, rs: i64) -> u32 {
        let h = c.h;
        let off = |d: i64| -> i64 {
            if h >= 2 {
                if d == 0 {
                    -h / 2
                } else {
                    h / 2
                }
            } else {
                d - 1
            }
        };
        let mut sx = (v & 0xFFFF) as i64 + off(par(x));
        let mut sy = (v >> 16) as i64 + off(par(y));
        if c.still() && c.lattice.is_free() {
            // Every jitter below rounds to 0 (`|hx| ≤ 2²³`, effective `r ≤ c.rq`).
            return pack_wrapped(sx, sy, c.dims);
        }
        let (hx_, hy_) = match c.period {
            Some(n) => (x.rem_euclid(n), y.rem_euclid(n)),
            None => (x, y),
        };
        // Nor does a jump land inside a kept part (it would show it cut).
        let (ew, eh) = c.dims;
        let kept = |jx: i64, jy: i64| self.mask.is_some_and(|mk| mk.at(c.l, wrap(jx, ew) as u32, wrap(jy, eh) as u32) == 0);
        if !c.still() {
            // R_E (design note §1.9): the mask's minimum around the upsampled coordinate scales
            // this level's randomness (0 keeps the exemplar there).
            let rq = match self.mask {
                Some(mk) if c.rq != 0 => {
                    (c.rq * mk.at(c.l, wrap(sx, ew) as u32, wrap(sy, eh) as u32) as i64 + 127) / 255
                }
                _ => c.rq,
            };
            // R_S: the request's modulation around the pixel (see `Modulation`).
            let rq = rq * rs / ONE_Q16 as i64;
            if rq != 0 {
                let z = hash_tail(c.jitter_head, hx_, hy_);
                let hx = ((z >> 40) as i64) - (1 << 23);
                let hy = (((z >> 16) & 0xFF_FFFF) as i64) - (1 << 23);
                let (dx, dy) = ((h * hx * rq + (1 << 38)) >> 39, (h * hy * rq + (1 << 38)) >> 39);
                if !kept(sx + dx, sy + dy) {
                    (sx, sy) = (sx + dx, sy + dy);
                }
            }
        }
        // A lattice's coarse levels put every coordinate on its position's phase (§1.9):
        // content moves by whole periods, whatever wrapping the exemplar did to it.
        let (mx, my) = c.lattice.snap((sx, sy), (hx_ * h, hy_ * h));
        if (mx, my) != (0, 0) && !kept(sx + mx, sy + my) {
            (sx, sy) = (sx + mx, sy + my);
        }

        pack_wrapped(sx, sy, c.dims)
    }

    /// The correction kernel of level `l` for buffers `w` pixels wide.
    fn kernel<'k>(&self, l: u32, w: usize, proj: &'k [i32], cl: &'k CorrectionLevel) -> Kernel<'k> {
        let h = 1i64 << (self.levels - l);
        let (ew, eh) = (self.dims.0 as u32, self.dims.1 as u32);
        let taps: Vec<isize> = (-2..=2).flat_map(|dy| (-2..=2).map(move |dx| dy * w as isize + dx)).collect::<Vec<_>>();
        // Candidate neighbours: (0,0) first, then the other 8 in raster order.
        let mut nb: Vec<(i64, i64)> = vec![(0, 0)];
        nb.extend((-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))).filter(|&d| d != (0, 0)));
        let nb_off: Vec<(isize, u32, u32)> = nb
            .iter()
            .map(|&(dx, dy)| {
                let sub = |d: i64, n: u32| ((-(h * d)).rem_euclid(n as i64)) as u32;
                (dy as isize * w as isize + dx as isize, sub(dx, ew), sub(dy, eh))
            })
            .collect();
        Kernel {
            taps: taps.try_into().unwrap_or([0; TAPS5]),
            nb_off: nb_off.try_into().unwrap_or([(0, 0, 0); 9]),
            proj,
            pairs: projection_pairs(&cl.proj),
            run_pairs: projection_run_pairs(&cl.proj),
            cands: &cl.cands,
            ew,
            eh,
            phi: self.phi,
            h: h as u32,
            edged: !self.an.header.toroidal,
            span_x: tap_spans(ew, h as u32),
            span_y: tap_spans(eh, h as u32),
            shift: tap_shifts((ew, eh), h as u32),
        }
    }
}

/// Per-level constants of generation 0.
/// The request's modulation `R_S` over a level's rectangle: one value per block of
/// [`MOD_BLOCK`]² pixels (blocks aligned to absolute multiples), taken at the block's centre —
/// a pure function of absolute coordinates, evaluated once per block instead of per pixel.
struct Modulation {
    /// Blocks covered, in block units; empty without controls.
    blocks: Rect,
    values: Vec<i64>,
}

/// What the request's features impose on a level's rectangle (design note §1.9): per pixel,
/// the exemplar coordinate of the feature whose disc holds the pixel's footprint centre (the
/// later feature where discs overlap), drawn feature by feature over their bounding boxes.
struct Imposed {
    /// Packed coordinates, `NONE` where no feature reaches; empty without features.
    cells: Vec<u32>,
}

impl Imposed {
    const NONE: u32 = u32::MAX;

    fn draw(controls: &Controls, l: u32, levels: u32, rect: Rect, h: i64, dims: (i64, i64), period: Option<i64>) -> Imposed {
        if controls.features.is_empty() {
            return Imposed { cells: Vec::new() };
        }
        let w = rect.width();
        let mut cells = vec![Self::NONE; rect.area() as usize];
        for f in &controls.features {
            // The feature's box in this level's pixels (the whole rectangle when the output
            // repeats, whose discs wrap).
            let area = match period {
                Some(_) => rect,
                None => {
                    let r = f.outer + h;
                    let (x0, y0) = ((f.x - r).div_euclid(h), (f.y - r).div_euclid(h));
                    let (x1, y1) = ((f.x + r).div_euclid(h) + 1, (f.y + r).div_euclid(h) + 1);
                    Rect::new(x0, y0, x1 - x0, y1 - y0).intersect(&rect)
                }
            };
            for y in area.y0..area.y1 {
                for x in area.x0..area.x1 {
                    if let Some((u, v)) = f.imposes(l, levels, x * h + h / 2, y * h + h / 2, period) {
                        cells[((y - rect.y0) * w + (x - rect.x0)) as usize] = pack_wrapped(u, v, dims);
                    }
                }
            }
        }
        Imposed { cells }
    }

    /// The coordinate imposed on pixel `p` of the rectangle (row-major), if any.
    #[inline]
    fn at(&self, p: usize) -> Option<u32> {
        self.cells.get(p).copied().filter(|&v| v != Self::NONE)
    }
}

/// Side of the blocks `R_S` is evaluated on, in pixels of a level.
const MOD_BLOCK: i64 = 4;

impl Modulation {
    fn over(controls: &Controls, rect: Rect, h: i64, period: Option<i64>) -> Modulation {
        if controls.is_unmodulated() {
            return Modulation { blocks: Rect::new(0, 0, 0, 0), values: Vec::new() };
        }
        let (bx0, by0) = (rect.x0.div_euclid(MOD_BLOCK), rect.y0.div_euclid(MOD_BLOCK));
        let (bx1, by1) = ((rect.x1 - 1).div_euclid(MOD_BLOCK) + 1, (rect.y1 - 1).div_euclid(MOD_BLOCK) + 1);
        let blocks = Rect::new(bx0, by0, bx1 - bx0, by1 - by0);
        // The block's centre in native texels.
        let centre = |b: i64| (b * MOD_BLOCK + MOD_BLOCK / 2) * h;
        let values = (by0..by1)
            .flat_map(|by| (bx0..bx1).map(move |bx| (bx, by)))
            .map(|(bx, by)| controls.at(centre(bx), centre(by), period))
            .collect();
        Modulation { blocks, values }
    }

    /// `R_S` (fixed point) for level pixel `(x, y)` inside the rectangle; 1 without controls.
    #[inline]
    fn at(&self, x: i64, y: i64) -> i64 {
        if self.values.is_empty() {
            return ONE_Q16 as i64;
        }
        let (bx, by) = (x.div_euclid(MOD_BLOCK) - self.blocks.x0, y.div_euclid(MOD_BLOCK) - self.blocks.y0);
        self.values[(by * self.blocks.width() + bx) as usize]
    }
}

struct LevelConsts {
    l: u32,
    h: i64,
    /// The exemplar's width and height.
    dims: (i64, i64),
    rq: i64,
    period: Option<i64>,
    /// The jitter hash with its tag, seed and level applied ([`crate::hash::head`]).
    jitter_head: u64,
    /// The lattice at this level: coordinates are snapped to their position's phase.
    lattice: LevelLattice,
}

impl LevelConsts {
    /// Whether no pixel of this level can move: the largest jitter, `h·r` texels, rounds to 0
    /// (`h·r ≤ ½`; the mask and `R_S` only scale `r` down). The finest levels of the default
    /// schedule, which then skip the hash.
    fn still(&self) -> bool {
        self.h * self.rq <= ONE_Q16 as i64 / 2
    }
}
