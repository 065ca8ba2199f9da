//! Window synthesis (design note §1.3): for each level of a window plan, upsample the parent
//! coordinates, jitter them by a hash of absolute coordinates, and correct them in Jacobi
//! subpasses with k-coherence candidates. Output: exemplar coordinates of any rectangle at any
//! level, bit-identical to the same pixels cut from any larger window.

use std::sync::Arc;

use rayon::prelude::*;

use crate::analysis::{Analysis, Candidate, CorrectionLevel};
use crate::error::{CoreError, Result};
use crate::features::{FEAT_SHIFT, RUNTIME_DIMS, TAPS5};
use crate::geom::{fl2, par, Rect};
use crate::hash::{hash, TAG_JITTER};
use crate::params::SynthParams;
use crate::plan::{correction_cone, pad_for_correction, plan_window, schedule, Class};
use crate::pyramid::{Block, BlockGrid, BlockKey, Pyramid, StreamId, BLOCK};

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
    params.validate_for(an)?;
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
    let ctx = Ctx::new(an, params, pyr);
    let mut synthesized = 0;
    let buf = ctx.level(level, rect, &mut synthesized);
    Ok(Synthesized { window: CoordWindow { level, rect, coords: buf.s }, synthesized })
}

/// Pixels a cold call to [`synthesize`] computes at all levels (padding included), from its plan.
pub fn synthesis_cost(an: &Analysis, params: &SynthParams, level: u32, rect: Rect) -> u64 {
    plan_window(level.min(an.levels()), rect, &schedule(params.passes, params.subpasses))
        .iter()
        .map(|lp| lp.padded.area() as u64)
        .sum()
}

/// Rows, first column and column step of a subpass class within a rectangle.
fn class_layout(class: Class, r: Rect) -> (Vec<usize>, usize, usize) {
    match class {
        Class::All => ((0..r.height() as usize).collect(), 0, 1),
        Class::Parity(px, py) => {
            let j0 = (py - r.y0).rem_euclid(2) as usize;
            ((j0..r.height() as usize).step_by(2).collect(), (px - r.x0).rem_euclid(2) as usize, 2)
        }
    }
}

/// Index of pixel `(x, y)` in the generation-`k ≥ 1` array of its block.
#[inline]
fn class_index(class: Class, x: i64, y: i64) -> usize {
    let (i, j) = (x.rem_euclid(BLOCK) as usize, y.rem_euclid(BLOCK) as usize);
    match class {
        Class::All => j * BLOCK as usize + i,
        Class::Parity(..) => (j / 2) * (BLOCK as usize / 2) + i / 2,
    }
}

/// A block this call learns about and will offer to the cache: its history so far.
struct Pending {
    rect: Rect,
    /// The part of the block inside the call's rectangle.
    inner: Rect,
    /// The highest generation this call knows of any of its pixels.
    top: i8,
    lo: Vec<i8>,
    data: Vec<u32>,
}

/// Index of pixel `(x, y)` within its block (row-major).
#[inline]
fn block_index(x: i64, y: i64) -> usize {
    class_index(Class::All, x, y)
}

/// Call `f(y, x0, x1)` for each row of `r`.
fn for_rows(r: Rect, mut f: impl FnMut(i64, i64, i64)) {
    for y in r.y0..r.y1 {
        f(y, r.x0, r.x1);
    }
}

/// The row-wise layout of a class within the part `r` of a block: the number of class pixels
/// per row, the buffer step between them, and for each row the buffer index of its first class
/// pixel in `ext` and its offset in the block's class array.
fn class_rows(ext: Rect, r: Rect, class: Class) -> (usize, usize, impl Iterator<Item = (usize, usize)>) {
    let w = ext.width() as usize;
    let (j0, c0, step) = match class {
        Class::All => (0, 0, 1),
        Class::Parity(px, py) => ((py - r.y0).rem_euclid(2) as usize, (px - r.x0).rem_euclid(2) as usize, 2),
    };
    let n = if r.width() as usize > c0 { (r.width() as usize - c0).div_ceil(step) } else { 0 };
    let rows = (j0..r.height().max(0) as usize).step_by(step).map(move |j| {
        let (x, y) = (r.x0 + c0 as i64, r.y0 + j as i64);
        ((y - ext.y0) as usize * w + (x - ext.x0) as usize, class_index(class, x, y))
    });
    (n, step, rows)
}

/// Put a cached block's generation-`k` values (`arr`, laid out for `class`) into `s` where this
/// call needs them and the block holds them; `changed(p, v)` is told of every changed pixel.
#[allow(clippy::too_many_arguments)]
fn overlay(
    s: &mut [u32],
    ext: Rect,
    r: Rect,
    class: Class,
    arr: &[u32],
    top: &[i8],
    lo: &[i8],
    k: i8,
    mut changed: impl FnMut(usize, u32),
) {
    let (n, step, rows) = class_rows(ext, r, class);
    for (p0, a0) in rows {
        for (c, &v) in arr[a0..a0 + n].iter().enumerate() {
            let p = p0 + c * step;
            if top[p] >= k && lo[p] >= k && s[p] != v {
                s[p] = v;
                changed(p, v);
            }
        }
    }
}

/// Record generation `k` (laid out for `class`, at `start` in the block data) of the pixels this
/// call knows into the pending blocks.
fn capture(pending: &mut [Pending], s: &[u32], ext: Rect, top: &[i8], class: Class, k: usize, start: usize) {
    let k = k as i8;
    pending.par_iter_mut().filter(|pb| pb.top >= k).for_each(|pb| {
        let (n, step, rows) = class_rows(ext, pb.inner, class);
        for (p0, a0) in rows {
            let dst = &mut pb.data[start + a0..start + a0 + n];
            let (sv, tv) = (&s[p0..], &top[p0..]);
            if step == 1 {
                for ((d, &v), &t) in dst.iter_mut().zip(sv).zip(tv) {
                    *d = if t >= k { v } else { *d };
                }
            } else {
                for (c, d) in dst.iter_mut().enumerate() {
                    if tv[2 * c] >= k {
                        *d = sv[2 * c];
                    }
                }
            }
        }
    });
}

struct Ctx<'a> {
    an: &'a Analysis,
    pyr: &'a Pyramid,
    stream: StreamId,
    sched: Vec<Class>,
    seed: u64,
    r: Vec<u32>,
    phi: [u64; 2],
    period: Option<i64>,
    m: i64,
    levels: u32,
}

impl<'a> Ctx<'a> {
    fn new(an: &'a Analysis, p: &SynthParams, pyr: &'a Pyramid) -> Self {
        Ctx {
            an,
            pyr,
            stream: StreamId::new(an, p),
            sched: schedule(p.passes, p.subpasses),
            seed: p.seed,
            r: p.randomness.resolve(an.levels()),
            phi: p.phi(),
            period: p.period,
            m: an.side() as i64,
            levels: an.levels(),
        }
    }

    /// The final coordinates of `need` at level `l`, computing (after its parents) only what
    /// the cache does not hold. Generation `k` of a pixel is its value after `k` subpasses;
    /// per pixel, `top` is the highest generation this call needs and `lo` the highest the
    /// cache holds (−1: none), so the pixel is computed at generations `lo+1 ..= top`.
    fn level(&self, l: u32, need: Rect, count: &mut u64) -> Buf {
        let cl = self.an.correction_level(l).filter(|_| !self.sched.is_empty());
        let gens: &[Class] = if cl.is_some() { &self.sched } else { &[] };
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
            if self.pyr.is_on() { self.pending(&grid, &blocks, ext, &top, class_len) } else { Vec::new() };

        // Generation 0: upsample the parents and jitter, or take the cached values.
        let lc = self.level_consts(l);
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
                    *out = self.jitter(&lc, x, y, v);
                }
            }
        });
        for &(blk, r) in &cached {
            overlay(&mut s, ext, r, Class::All, blk.generation(0), &top, &lo, 0, |_, _| {});
        }
        capture(&mut pending, &s, ext, &top, Class::All, 0, 0);

        // Generations 1..: the correction subpasses (Jacobi: each reads the previous generation).
        if let Some(cl) = cl {
            let m = self.m as usize;
            let pal: Vec<u32> =
                self.an.colours8(l).iter().map(|c| c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16).collect();
            let colour = |v: u32| pal[(v >> 16) as usize * m + (v & 0xFFFF) as usize];
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
                let bw = bx.width().max(0) as usize;
                let cols = if bw > c0 { (bw - c0).div_ceil(step) } else { 0 };
                let mut out = vec![0u32; rows.len() * cols];
                let (sr, colr) = (&s, &col);
                out.par_chunks_mut(cols.max(1)).zip(rows.par_iter()).with_min_len(4).for_each(|(orow, &j)| {
                    let base = (oy + j) * w + ox + c0;
                    let todo = |c: usize| {
                        let p = base + c * step;
                        top[p] >= k8 && lo[p] < k8
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

    /// The blocks this call learns something about, each starting from its cached history.
    fn pending(
        &self,
        grid: &BlockGrid,
        blocks: &[Option<Arc<Block>>],
        ext: Rect,
        top: &[i8],
        class_len: usize,
    ) -> Vec<Pending> {
        let (w, bs) = (ext.width() as usize, BLOCK as usize);
        let mut out = Vec::new();
        // Never gather more than half the cache could keep (a huge window would otherwise
        // hold its whole history in memory only to see most of it evicted).
        let (mut bytes, budget) = (0u64, self.pyr.limit() / 2);
        for (n, old) in blocks.iter().enumerate() {
            let rect = grid.rect(n % grid.nbx, n / grid.nbx);
            let inner = rect.intersect(&ext);
            let mut most = -1i8;
            for_rows(inner, |y, x0, x1| {
                let at = (y - ext.y0) as usize * w + (x0 - ext.x0) as usize;
                most = most.max(top[at..at + (x1 - x0) as usize].iter().copied().max().unwrap_or(-1));
            });
            if most < 0 || old.as_ref().is_some_and(|b| b.min_lo >= most) {
                continue;
            }
            let mut lo = old.as_ref().map_or_else(|| vec![-1i8; bs * bs], |b| b.lo.to_vec());
            for_rows(inner, |y, x0, x1| {
                let at = (y - ext.y0) as usize * w + (x0 - ext.x0) as usize;
                let from = block_index(x0, y);
                for (d, &t) in lo[from..from + (x1 - x0) as usize].iter_mut().zip(&top[at..]) {
                    *d = (*d).max(t);
                }
            });
            let arrays = lo.iter().copied().max().unwrap_or(0).max(0) as usize;
            let mut data = vec![0u32; bs * bs + arrays * class_len];
            if let Some(b) = old {
                let n = b.data.len().min(data.len());
                data[..n].copy_from_slice(&b.data[..n]);
            }
            bytes += 4 * data.len() as u64 + lo.len() as u64;
            if bytes > budget {
                break;
            }
            out.push(Pending { rect, inner, top: most, lo, data });
        }
        out
    }

    fn level_consts(&self, l: u32) -> LevelConsts {
        LevelConsts {
            l,
            h: 1i64 << (self.levels - l),
            mask: self.m - 1,
            rq: self.r[l as usize] as i64,
            period: self.period.map(|n| n >> (self.levels - l)),
        }
    }

    /// Generation 0 of pixel `(x, y)`: its parent's coordinate `v` shifted to the child's
    /// position, plus the hash jitter of its absolute position.
    #[inline]
    fn jitter(&self, c: &LevelConsts, x: i64, y: i64, v: u32) -> u32 {
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
        if c.rq != 0 {
            let (hx_, hy_) = match c.period {
                Some(n) => (x.rem_euclid(n), y.rem_euclid(n)),
                None => (x, y),
            };
            let z = hash(TAG_JITTER, self.seed, c.l as i64, hx_, hy_);
            let hx = ((z >> 40) as i64) - (1 << 23);
            let hy = (((z >> 16) & 0xFF_FFFF) as i64) - (1 << 23);
            sx += (h * hx * c.rq + (1 << 38)) >> 39;
            sy += (h * hy * c.rq + (1 << 38)) >> 39;
        }
        ((sx & c.mask) | ((sy & c.mask) << 16)) as u32
    }

    /// The correction kernel of level `l` for buffers `w` pixels wide.
    fn kernel<'k>(&self, l: u32, w: usize, proj: &'k [i32], cl: &'k CorrectionLevel) -> Kernel<'k> {
        let h = 1i64 << (self.levels - l);
        let m = self.m as usize;
        let taps: Vec<isize> = (-2..=2).flat_map(|dy| (-2..=2).map(move |dx| dy * w as isize + dx)).collect::<Vec<_>>();
        // Candidate neighbours: (0,0) first, then the other 8 in raster order.
        let mut nb: Vec<(i64, i64)> = vec![(0, 0)];
        nb.extend((-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))).filter(|&d| d != (0, 0)));
        let nb_off: Vec<(isize, u32, u32)> = nb
            .iter()
            .map(|&(dx, dy)| {
                let sub = |d: i64| ((-(h * d)).rem_euclid(self.m)) as u32;
                (dy as isize * w as isize + dx as isize, sub(dx), sub(dy))
            })
            .collect();
        Kernel {
            taps: taps.try_into().unwrap_or([0; TAPS5]),
            nb_off: nb_off.try_into().unwrap_or([(0, 0, 0); 9]),
            proj,
            cands: &cl.cands,
            m,
            mask: (m - 1) as u32,
            phi: self.phi,
        }
    }
}

/// Per-level constants of generation 0.
struct LevelConsts {
    l: u32,
    h: i64,
    mask: i64,
    rq: i64,
    period: Option<i64>,
}

/// For each pixel of `ext`, the highest generation a call needing `need` at the last
/// generation must know (−1: none), given the generations the cache holds (`lo`); and for each
/// subpass, the bounding rectangle of the pixels it computes. A pixel computed at generation `k`
/// by a subpass of its class reads its 5×5 neighbourhood at `k − 1`; every other pixel just
/// keeps its own value. With nothing cached (`cached` false) this is the plan's cone, filled in
/// row intervals; otherwise it is dilated pixel by pixel around what must be computed.
fn needed_generations(ext: Rect, need: Rect, gens: &[Class], lo: &[i8], cached: bool) -> (Vec<i8>, Vec<Rect>) {
    if !cached {
        return cone_generations(ext, need, gens);
    }
    let (w, h) = (ext.width() as usize, ext.height() as usize);
    let mut top = vec![-1i8; w * h];
    let (ni, nj) = ((need.x0 - ext.x0) as usize, (need.y0 - ext.y0) as usize);
    for j in nj..nj + need.height() as usize {
        top[j * w + ni..j * w + ni + need.width() as usize].fill(gens.len() as i8);
    }
    let mut boxes = vec![Rect::new(0, 0, 0, 0); gens.len()];
    // `dil`: per class row, the class pixels computed at this generation, dilated by 2 columns
    // (valid for the rows whose flag is set).
    let mut dil = vec![0u8; w * h];
    let mut acc = vec![0u8; w];
    for (k, &class) in gens.iter().enumerate().rev().map(|(i, c)| (i as i8 + 1, c)) {
        let (rows, c0, step) = class_layout(class, ext);
        let row_step = if step == 1 { 1 } else { 2 };
        let j0 = rows.first().copied().unwrap_or(0);
        // Per row: the first and last computed column, if any. Sequential: these passes are
        // short, and forking for them cost more than they do.
        let mut spans: Vec<Option<(usize, usize)>> = vec![None; h];
        let mut src = vec![0u8; w + 4];
        for (j, d) in dil.chunks_mut(w).enumerate() {
            if j < j0 || (j - j0) % row_step != 0 {
                continue;
            }
            let (t, o) = (&top[j * w..(j + 1) * w], &lo[j * w..(j + 1) * w]);
            src.fill(0);
            let mut span: Option<(usize, usize)> = None;
            for i in (c0..w).step_by(step) {
                if t[i] >= k && o[i] < k {
                    src[i + 2] = 1;
                    span = Some(span.map_or((i, i), |(a, _)| (a, i)));
                }
            }
            if span.is_some() {
                for (i, dv) in d.iter_mut().enumerate() {
                    *dv = src[i] | src[i + 1] | src[i + 2] | src[i + 3] | src[i + 4];
                }
            }
            spans[j] = span;
        }
        let (Some(first), Some(last)) =
            (spans.iter().position(Option::is_some), spans.iter().rposition(Option::is_some))
        else {
            continue;
        };
        let (x0, x1) = spans.iter().flatten().fold((usize::MAX, 0), |(a, b), &(s, e)| (a.min(s), b.max(e)));
        boxes[k as usize - 1] = Rect {
            x0: ext.x0 + x0 as i64,
            y0: ext.y0 + first as i64,
            x1: ext.x0 + x1 as i64 + 1,
            y1: ext.y0 + last as i64 + 1,
        };
        // Columns the dilation can reach; rows likewise.
        let (ca, cb) = (x0.saturating_sub(2), (x1 + 3).min(w));
        for j in first.saturating_sub(2)..=(last + 2).min(h - 1) {
            let acc = &mut acc[ca..cb];
            acc.fill(0);
            let mut any = false;
            for jj in j.saturating_sub(2)..=(j + 2).min(h - 1) {
                if spans[jj].is_some() {
                    any = true;
                    for (a, &dv) in acc.iter_mut().zip(&dil[jj * w + ca..jj * w + cb]) {
                        *a |= dv;
                    }
                }
            }
            if any {
                for (t, &a) in top[j * w + ca..j * w + cb].iter_mut().zip(acc.iter()) {
                    *t = (*t).max(a as i8 * k - 1);
                }
            }
        }
    }
    (top, boxes)
}

/// [`needed_generations`] with nothing cached: the plan's cone, written row by row (each pixel
/// once: generation `k` fills what generation `k + 1` did not need).
fn cone_generations(ext: Rect, need: Rect, gens: &[Class]) -> (Vec<i8>, Vec<Rect>) {
    let (w, h) = (ext.width() as usize, ext.height() as usize);
    debug_assert!(h > 0);
    let cone = correction_cone(need, gens);
    let mut top = vec![-1i8; w * h];
    for (j, row) in top.chunks_mut(w).enumerate() {
        let y = ext.y0 + j as i64;
        for px in 0..2i64 {
            let c = (px + 2 * y.rem_euclid(2)) as usize;
            // Columns of this class in `row`, as a range over x, nested per generation.
            let mut inner: Option<(i64, i64)> = None;
            for k in (0..cone.needs.len()).rev() {
                let r = cone.needs[k][c];
                if y < r.y0 || y >= r.y1 || r.is_empty() {
                    continue;
                }
                let (a, b) = (r.x0.max(ext.x0), r.x1.min(ext.x1));
                let mut fill = |from: i64, to: i64| {
                    let start = from + (px - from).rem_euclid(2);
                    for x in (start..to).step_by(2) {
                        row[(x - ext.x0) as usize] = k as i8;
                    }
                };
                match inner {
                    None => fill(a, b),
                    Some((ia, ib)) => {
                        fill(a, ia);
                        fill(ib, b);
                    }
                }
                inner = Some((a, b));
            }
        }
    }
    let boxes = cone
        .subpasses
        .iter()
        .map(|&(_, r)| if r.is_empty() { Rect::new(0, 0, 0, 0) } else { r.intersect(&ext) })
        .collect();
    (top, boxes)
}

/// The correction kernel of one level: everything a pixel's correction reads besides the
/// snapshot buffers.
struct Kernel<'a> {
    /// Buffer offsets of the 5×5 neighbourhood, raster order.
    taps: [isize; TAPS5],
    /// Buffer offset and exemplar shift `−h·Δ mod m` (x, y) of the 9 candidate neighbours.
    nb_off: [(isize, u32, u32); 9],
    /// Projection widened to i32, `[tap][channel][dim]`.
    proj: &'a [i32],
    cands: &'a [[Candidate; 2]],
    m: usize,
    mask: u32,
    phi: [u64; 2],
}

impl Kernel<'_> {
    /// Correct the pixels `start, start + step, …` of one row (one per `out` entry). Runs a copy
    /// compiled for AVX2 when the processor has it; integer arithmetic makes both copies give
    /// identical results.
    fn row(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") && !tests::portable_forced() {
                // SAFETY: the processor supports AVX2 (checked just above).
                unsafe { self.row_avx2(s, col, start, step, out) };
                return;
            }
        }
        self.row_portable(s, col, start, step, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn row_avx2(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        self.row_portable(s, col, start, step, out);
    }

    #[inline(always)]
    fn row_portable(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.pixel(start + i * step, s, col);
        }
    }

    /// The best of the 18 k-coherence candidates for the pixel at buffer index `idx`.
    #[inline(always)]
    fn pixel(&self, idx: usize, s: &[u32], col: &[u32]) -> u32 {
        let mut acc = [0i32; RUNTIME_DIMS];
        for (t, &off) in self.taps.iter().enumerate() {
            let c = col[(idx as isize + off) as usize];
            let (r, g, b) = ((c & 255) as i32, ((c >> 8) & 255) as i32, ((c >> 16) & 255) as i32);
            let pr: &[i32; 3 * RUNTIME_DIMS] = self.proj[t * 3 * RUNTIME_DIMS..(t + 1) * 3 * RUNTIME_DIMS]
                .try_into()
                .unwrap_or(&[0; 3 * RUNTIME_DIMS]);
            for d in 0..RUNTIME_DIMS {
                acc[d] += pr[d] * r + pr[RUNTIME_DIMS + d] * g + pr[2 * RUNTIME_DIMS + d] * b;
            }
        }
        let ns = acc.map(|a| a >> FEAT_SHIFT);
        let mut best = (u64::MAX, s[idx]);
        for (k, &phi_k) in self.phi.iter().enumerate() {
            for &(off, subx, suby) in &self.nb_off {
                let v = s[(idx as isize + off) as usize];
                let vx = ((v & 0xFFFF) + subx) & self.mask;
                let vy = ((v >> 16) + suby) & self.mask;
                let cand = &self.cands[vy as usize * self.m + vx as usize][k];
                let mut d = 0u32;
                for (a, &b) in ns.iter().zip(&cand.feat) {
                    let e = a - b as i32;
                    d = d.wrapping_add((e * e) as u32);
                }
                let dd = d as u64 * phi_k;
                if dd < best.0 {
                    best = (dd, cand.coord);
                }
            }
        }
        best.1
    }
}

#[cfg(not(test))]
mod tests {
    pub(super) fn portable_forced() -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicBool, Ordering};

    use super::*;
    use crate::{Exemplar, ExemplarOptions, NoProgress};

    static FORCE_PORTABLE: AtomicBool = AtomicBool::new(false);

    pub(super) fn portable_forced() -> bool {
        FORCE_PORTABLE.load(Ordering::Relaxed)
    }

    /// With nothing cached, the plan's cone (filled by rows) and the pixel-by-pixel dilation
    /// agree on every pixel's needed generation and every subpass's box.
    #[test]
    fn cone_and_dilation_agree_without_cache() {
        for (x, y, w, h) in [(0, 0, 256, 256), (-7, 13, 33, 20), (5, -3, 1, 1), (-100, -101, 64, 3)] {
            let need = Rect::new(x, y, w, h);
            for sched in [schedule(2, 4), schedule(1, 1), schedule(3, 4)] {
                let ext = pad_for_correction(need, &sched).0;
                let lo = vec![-1i8; ext.area() as usize];
                let (a, ab) = needed_generations(ext, need, &sched, &lo, false);
                let (b, bb) = needed_generations(ext, need, &sched, &lo, true);
                assert_eq!(a, b, "{need:?} {sched:?}");
                assert_eq!(ab, bb, "{need:?} {sched:?}");
            }
        }
    }

    #[test]
    fn simd_and_portable_kernels_agree() {
        let px: Vec<[u8; 4]> = (0..64 * 64u32)
            .map(|i| {
                let (x, y) = (i % 64, i / 64);
                [((x * 7 + y * 3) % 256) as u8, ((x * y) % 251) as u8, ((x ^ y) * 5 % 256) as u8, 255]
            })
            .collect();
        let an = Analysis::build(&Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default()), &NoProgress);
        let p = SynthParams::default();
        let r = Rect::new(-70, 33, 150, 90);
        let fast = synthesize(&an, &p, 6, r).unwrap();
        FORCE_PORTABLE.store(true, Ordering::Relaxed);
        let portable = synthesize(&an, &p, 6, r).unwrap();
        FORCE_PORTABLE.store(false, Ordering::Relaxed);
        assert_eq!(fast, portable);
    }
}
