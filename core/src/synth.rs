//! Window synthesis (design note §1.3): for each level of a window plan, upsample the parent
//! coordinates, jitter them by a hash of absolute coordinates, and correct them in Jacobi
//! subpasses with k-coherence candidates. Output: exemplar coordinates of any rectangle at any
//! level, bit-identical to the same pixels cut from any larger window.

use rayon::prelude::*;

use crate::analysis::{Analysis, Candidate, CorrectionLevel};
use crate::error::{CoreError, Result};
use crate::features::{FEAT_SHIFT, RUNTIME_DIMS, TAPS5};
use crate::geom::{fl2, par, Rect};
use crate::hash::{hash, TAG_JITTER};
use crate::params::SynthParams;
use crate::plan::{plan_window, schedule, Class, LevelPlan};

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

/// Synthesize the exemplar coordinates of `rect` at pyramid `level` (`0..=L`).
pub fn synthesize(an: &Analysis, params: &SynthParams, level: u32, rect: Rect) -> Result<CoordWindow> {
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
    let sched = schedule(params.passes, params.subpasses);
    let plans = plan_window(level, rect, &sched);
    let ctx = Ctx::new(an, params);
    let mut parent: Option<Buf> = None;
    for lp in &plans {
        let mut buf = ctx.upsample_jitter(lp, parent.as_ref());
        if let Some(cl) = an.correction_level(lp.level).filter(|_| !lp.subpasses.is_empty()) {
            ctx.correct(lp, cl, &mut buf);
        }
        parent = Some(buf.crop(lp.need));
    }
    let out = parent.unwrap_or(Buf { rect, s: Vec::new() });
    Ok(CoordWindow { level, rect, coords: out.s })
}

/// Pixels a call to [`synthesize`] computes at all levels (padding included), from its plan.
pub fn synthesis_cost(an: &Analysis, params: &SynthParams, level: u32, rect: Rect) -> u64 {
    plan_window(level.min(an.levels()), rect, &schedule(params.passes, params.subpasses))
        .iter()
        .map(|lp| lp.padded.area() as u64)
        .sum()
}

struct Ctx<'a> {
    an: &'a Analysis,
    seed: u64,
    r: Vec<u32>,
    phi: [u64; 2],
    period: Option<i64>,
    m: i64,
    levels: u32,
}

impl<'a> Ctx<'a> {
    fn new(an: &'a Analysis, p: &SynthParams) -> Self {
        Ctx {
            an,
            seed: p.seed,
            r: p.randomness.resolve(an.levels()),
            phi: p.phi(),
            period: p.period,
            m: an.side() as i64,
            levels: an.levels(),
        }
    }

    /// Upsample the parent buffer (or the constant level −1) over `lp.padded` and jitter.
    fn upsample_jitter(&self, lp: &LevelPlan, parent: Option<&Buf>) -> Buf {
        let l = lp.level;
        let h = 1i64 << (self.levels - l);
        let mask = self.m - 1;
        let rq = self.r[l as usize] as i64;
        let period_l = self.period.map(|n| n >> (self.levels - l));
        let rect = lp.padded;
        let w = rect.width() as usize;
        let mut s = vec![0u32; rect.area() as usize];
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
        s.par_chunks_mut(w).enumerate().with_min_len(8).for_each(|(j, row)| {
            let y = rect.y0 + j as i64;
            let oy = off(par(y));
            let prow = parent.map(|p| {
                let pw = p.rect.width() as usize;
                let py = (fl2(y) - p.rect.y0) as usize;
                (&p.s[py * pw..(py + 1) * pw], p.rect.x0)
            });
            for (i, out) in row.iter_mut().enumerate() {
                let x = rect.x0 + i as i64;
                let (mut sx, mut sy) = match prow {
                    Some((pr, px0)) => {
                        let v = pr[(fl2(x) - px0) as usize];
                        ((v & 0xFFFF) as i64, (v >> 16) as i64)
                    }
                    None => (0, 0),
                };
                sx += off(par(x));
                sy += oy;
                if rq != 0 {
                    let (hx_, hy_) = match period_l {
                        Some(n) => (x.rem_euclid(n), y.rem_euclid(n)),
                        None => (x, y),
                    };
                    let z = hash(TAG_JITTER, self.seed, l as i64, hx_, hy_);
                    let hx = ((z >> 40) as i64) - (1 << 23);
                    let hy = (((z >> 16) & 0xFF_FFFF) as i64) - (1 << 23);
                    sx += (h * hx * rq + (1 << 38)) >> 39;
                    sy += (h * hy * rq + (1 << 38)) >> 39;
                }
                *out = ((sx & mask) | ((sy & mask) << 16)) as u32;
            }
        });
        Buf { rect, s }
    }

    /// Run every correction subpass of the plan on `buf` (Jacobi: each subpass reads a snapshot).
    fn correct(&self, lp: &LevelPlan, cl: &CorrectionLevel, buf: &mut Buf) {
        let l = lp.level;
        let h = 1i64 << (self.levels - l);
        let m = self.m as usize;
        let pal: Vec<u32> =
            self.an.colours8(l).iter().map(|c| c[0] as u32 | (c[1] as u32) << 8 | (c[2] as u32) << 16).collect();
        let w = buf.rect.width() as usize;
        let colour = |v: u32| pal[(v >> 16) as usize * m + (v & 0xFFFF) as usize];
        let mut col: Vec<u32> = buf.s.iter().map(|&v| colour(v)).collect();
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
        let proj: Vec<i32> = cl.proj.iter().map(|&v| v as i32).collect();
        let k = Kernel {
            taps: taps.try_into().unwrap_or([0; TAPS5]),
            nb_off: nb_off.try_into().unwrap_or([(0, 0, 0); 9]),
            proj: &proj,
            cands: &cl.cands,
            m,
            mask: (m - 1) as u32,
            phi: self.phi,
        };
        for &(class, r) in &lp.subpasses {
            if r.is_empty() {
                continue;
            }
            let step = if class == Class::All { 1 } else { 2 };
            let cols = ((r.width() - 1) / step + 1) as usize;
            let rows = ((r.height() - 1) / step + 1) as usize;
            let mut out = vec![0u32; cols * rows];
            let (s, colr) = (&buf.s, &col);
            out.par_chunks_mut(cols).enumerate().with_min_len(4).for_each(|(j, row)| {
                let y = r.y0 + j as i64 * step;
                let start = (y - buf.rect.y0) as usize * w + (r.x0 - buf.rect.x0) as usize;
                k.row(s, colr, start, step as usize, row);
            });
            for (j, row) in out.chunks(cols).enumerate() {
                let by = (r.y0 - buf.rect.y0) as usize + j * step as usize;
                for (i, &v) in row.iter().enumerate() {
                    let idx = by * w + (r.x0 - buf.rect.x0) as usize + i * step as usize;
                    buf.s[idx] = v;
                    col[idx] = colour(v);
                }
            }
        }
    }
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
