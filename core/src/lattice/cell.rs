//! 2-D lattices: cells proposed by the autocorrelation's peaks and tested as predictions. A
//! lattice `L` of basis `t1, t2` predicts that the image matches itself at every `p ∈ L`
//! better than at the points half a cell away: the three cosets `c` of `L` in `L/2` (`t1/2`,
//! `t2/2`, `(t1 + t2)/2`). A cell's *contrast* is, for the worst coset, the mean over the
//! lattice points `p` within reach of `A(p) − ½(A(p + c) + A(p − c))`, `c` the higher of the
//! coset's two shortest representatives (each read as the highest
//! `A` within 4 % of its length, the lattice's drift), and its score `z` that contrast in noise
//! units (`K` points of three reads each).
//!
//! The worst coset is what makes this a test of the *lattice* and not of its peaks:
//! - a 2-D lattice that only refines a 1-D one (the long bed joints of an irregular wall make
//!   `A` high all along each course, so any shift along a course is a "peak") always has a
//!   coset on the courses, where `A` is as high as on the lattice, and fails;
//! - a cell twice too big has the true lattice's points among its cosets, and fails;
//! - a cell too small has its own points at the true lattice's half-way points, and fails.

use rayon::prelude::*;

use super::acf::{parabola_peak, Autocorrelation};
use super::ridge::MIN_PERIOD;
use super::MIN_ANGLE;

/// Peaks proposed as basis vectors: the highest, and the shortest of the strong ones.
const PROPOSED: usize = 16;

/// Share of the highest peak a short peak must reach to be proposed.
const SHORT_SHARE: f64 = 0.3;

/// A 2-D lattice cell and how well it predicts the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Basis vectors `(x, y)` in lags, Gauss-reduced (shortest first).
    pub t1: [f64; 2],
    /// The second basis vector.
    pub t2: [f64; 2],
    /// The worst coset's mean contrast (module comment).
    pub contrast: f64,
    /// The contrast in noise units.
    pub z: f64,
}

impl Autocorrelation {
    /// Where lattice points are read: within 0.45 of the side.
    fn reach(&self) -> f64 {
        0.45 * self.m as f64
    }

    /// Every cell the peaks propose, roughly scored (each point read where the basis puts it,
    /// not at the peak near it): [`Autocorrelation::cell_at`] scores the best of them.
    pub(super) fn cells(&self) -> Vec<Cell> {
        let reach = self.reach() as i64;
        let mut peaks: Vec<(f64, i64, i64)> = Vec::new();
        for y in 0..=reach {
            for x in -reach..=reach {
                let r2 = x * x + y * y;
                if (y == 0 && x <= 0) || (r2 as f64) < MIN_PERIOD * MIN_PERIOD || r2 > reach * reach {
                    continue;
                }
                let v = self.grid(x, y);
                if v <= 0.0 || !self.usable([x as f64, y as f64]) {
                    continue;
                }
                let top = (-2..=2).all(|dy| (-2..=2).all(|dx| (dx == 0 && dy == 0) || self.grid(x + dx, y + dy) <= v));
                if top {
                    peaks.push((v, x, y));
                }
            }
        }
        peaks.sort_by(|a, b| b.0.total_cmp(&a.0).then((a.1, a.2).cmp(&(b.1, b.2))));
        let Some(vmax) = peaks.first().map(|p| p.0) else { return Vec::new() };
        let mut short: Vec<(f64, i64, i64)> = peaks.iter().copied().filter(|p| p.0 >= SHORT_SHARE * vmax).collect();
        short.sort_by_key(|p| (p.1 * p.1 + p.2 * p.2, p.1, p.2));
        let mut proposed: Vec<[f64; 2]> = Vec::new();
        for p in peaks.iter().take(PROPOSED).chain(short.iter().take(PROPOSED)) {
            let v = [p.1 as f64, p.2 as f64];
            if !proposed.contains(&v) {
                proposed.push(v);
            }
        }
        let mut seen: Vec<([f64; 2], [f64; 2])> = Vec::new();
        for i in 0..proposed.len() {
            for j in i + 1..proposed.len() {
                let (p, q) = (proposed[i], proposed[j]);
                let sin = cross(p, q).abs() / (p[0].hypot(p[1]) * q[0].hypot(q[1]));
                if sin < MIN_ANGLE.to_radians().sin() {
                    continue;
                }
                let [t1, t2] = super::reduce(p, q);
                let (t1, t2) = canonical((t1, t2));
                if seen.contains(&(t1, t2)) {
                    continue;
                }
                seen.push((t1, t2));
            }
        }
        seen.par_iter().filter_map(|&(t1, t2)| self.score(t1, t2, false)).collect()
    }

    /// The lattice points of `t1, t2` in the upper half plane within reach whose cosets can be
    /// read, with their indices.
    fn points(&self, t1: [f64; 2], t2: [f64; 2]) -> Vec<(i64, i64, [f64; 2])> {
        let reach = self.reach();
        let cosets: Vec<[f64; 2]> = cosets(t1, t2).iter().flatten().copied().collect();
        let len1 = t1[0].hypot(t1[1]).max(1.0);
        let len2 = t2[0].hypot(t2[1]).max(1.0);
        // Enough indices to cover the reach: the basis is reduced, so |i·t1 + j·t2| ≥ ~|i|·|t1|·sin.
        let ni = (2.0 * reach / len1).ceil() as i64 + 1;
        let nj = (2.0 * reach / len2).ceil() as i64 + 1;
        let mut out = Vec::new();
        for j in -nj..=nj {
            for i in -ni..=ni {
                let p = [i as f64 * t1[0] + j as f64 * t2[0], i as f64 * t1[1] + j as f64 * t2[1]];
                let upper = p[1] > 0.0 || (p[1] == 0.0 && p[0] > 0.0);
                if !upper || p[0].hypot(p[1]) > reach || !self.usable(p) {
                    continue;
                }
                let readable = cosets
                    .iter()
                    .all(|c| self.usable([p[0] + c[0], p[1] + c[1]]) && self.usable([p[0] - c[0], p[1] - c[1]]));
                if readable {
                    out.push((i, j, p));
                }
            }
        }
        out
    }

    /// The cell of `t1, t2`, scored (module comment) on its lattice points other than the
    /// two that proposed it (held out: a chance pair of peaks predicts nothing beyond itself);
    /// `None` with fewer than two such points, or a basis vector longer than a quarter of the
    /// side (a repeat seen fewer than four times).
    pub(super) fn cell_at(&self, t1: [f64; 2], t2: [f64; 2]) -> Option<Cell> {
        self.score(t1, t2, true)
    }

    /// [`Autocorrelation::cell_at`], reading each point at the highest `A` near it (`near`) or
    /// where the basis puts it.
    fn score(&self, t1: [f64; 2], t2: [f64; 2], near: bool) -> Option<Cell> {
        let longest = t1[0].hypot(t1[1]).max(t2[0].hypot(t2[1]));
        if longest > 0.25 * self.m as f64 + 0.5 {
            return None;
        }
        let proposed = |i: i64, j: i64| (i.abs() == 1 && j == 0) || (i == 0 && j.abs() == 1);
        let points: Vec<[f64; 2]> =
            self.points(t1, t2).into_iter().filter(|(i, j, _)| !proposed(*i, *j)).map(|(_, _, p)| p).collect();
        if points.len() < 2 {
            return None;
        }
        let read = |p: [f64; 2]| {
            if near {
                self.near(p, (0.04 * p[0].hypot(p[1])).max(1.0))
            } else {
                self.at(p[0], p[1])
            }
        };
        let on: Vec<f64> = points.iter().map(|p| read(*p)).collect();
        let contrast = cosets(t1, t2)
            .iter()
            .map(|reps| {
                let sum: f64 = points
                    .iter()
                    .zip(&on)
                    .map(|(p, a)| {
                        let side =
                            |c: &[f64; 2]| 0.5 * (read([p[0] + c[0], p[1] + c[1]]) + read([p[0] - c[0], p[1] - c[1]]));
                        a - side(&reps[0]).max(side(&reps[1]))
                    })
                    .sum();
                sum / points.len() as f64
            })
            .fold(f64::INFINITY, f64::min);
        let z = contrast / (self.sigma * (1.5 / points.len() as f64).sqrt());
        Some(Cell { t1, t2, contrast, z })
    }

    /// A cell's basis to a fraction of a texel: the peaks near its lattice points (parabolic
    /// in each axis), fitted by least squares as `i·t1 + j·t2`, weighted by their height.
    pub(super) fn fit(&self, c: Cell) -> Cell {
        let (mut sii, mut sij, mut sjj) = (0.0, 0.0, 0.0);
        let (mut si, mut sj) = ([0.0; 2], [0.0; 2]);
        for (i, j, p) in self.points(c.t1, c.t2) {
            let radius = (0.04 * p[0].hypot(p[1])).max(1.0);
            let ri = radius.ceil() as i64;
            let (cx, cy) = (p[0].round() as i64, p[1].round() as i64);
            let mut best = (f64::MIN, cx, cy);
            for dy in -ri..=ri {
                for dx in -ri..=ri {
                    let (x, y) = (cx + dx, cy + dy);
                    let v = self.grid(x, y);
                    if (x as f64 - p[0]).hypot(y as f64 - p[1]) <= radius && v > best.0 {
                        best = (v, x, y);
                    }
                }
            }
            let (v, x, y) = best;
            if v <= 0.0 {
                continue;
            }
            let q = [
                parabola_peak(x as f64, 1.0, |t| self.at(t, y as f64)),
                parabola_peak(y as f64, 1.0, |t| self.at(x as f64, t)),
            ];
            let (fi, fj) = (i as f64, j as f64);
            (sii, sij, sjj) = (sii + v * fi * fi, sij + v * fi * fj, sjj + v * fj * fj);
            for d in 0..2 {
                si[d] += v * fi * q[d];
                sj[d] += v * fj * q[d];
            }
        }
        let det = sii * sjj - sij * sij;
        if det.abs() < 1e-9 {
            return c;
        }
        let t1 = [(sjj * si[0] - sij * sj[0]) / det, (sjj * si[1] - sij * sj[1]) / det];
        let t2 = [(sii * sj[0] - sij * si[0]) / det, (sii * sj[1] - sij * si[1]) / det];
        // A fit that moved a vector by more than a texel and a half found other peaks: keep
        // the proposal.
        let moved = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]) > 1.5;
        if moved(t1, c.t1) || moved(t2, c.t2) {
            return c;
        }
        Cell { t1, t2, ..c }
    }
}

/// The three half-cell cosets of the lattice of `t1, t2`, each by its two shortest
/// representatives (up to sign): for a staggered cell, `(t1 + t2)/2` and `(t2 − t1)/2` are the
/// same coset, one on the next course and one half way along the lattice point's own course.
fn cosets(t1: [f64; 2], t2: [f64; 2]) -> [[[f64; 2]; 2]; 3] {
    [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)].map(|(i, j)| {
        let mut reps: Vec<[f64; 2]> = Vec::new();
        for a in -1..=1 {
            for b in -1..=1 {
                let c = half(t1, t2, i + 2.0 * a as f64, j + 2.0 * b as f64);
                if !reps.iter().any(|r| (r[0] + c[0]).abs() < 1e-9 && (r[1] + c[1]).abs() < 1e-9) {
                    reps.push(c);
                }
            }
        }
        reps.sort_by(|x, y| x[0].hypot(x[1]).total_cmp(&y[0].hypot(y[1])));
        [reps[0], reps[1]]
    })
}

/// `(i·t1 + j·t2) / 2`.
fn half(t1: [f64; 2], t2: [f64; 2], i: f64, j: f64) -> [f64; 2] {
    [0.5 * (i * t1[0] + j * t2[0]), 0.5 * (i * t1[1] + j * t2[1])]
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// A reduced basis in one spelling: each vector in the upper half plane, so that the same
/// lattice proposed by different peaks is scored once.
fn canonical((a, b): ([f64; 2], [f64; 2])) -> ([f64; 2], [f64; 2]) {
    let up = |v: [f64; 2]| if v[1] < 0.0 || (v[1] == 0.0 && v[0] < 0.0) { [-v[0], -v[1]] } else { v };
    let (a, b) = (up(a), up(b));
    // Equal lengths: the one nearer +x first.
    if (a[0] * a[0] + a[1] * a[1] - b[0] * b[0] - b[1] * b[1]).abs() < 1e-9 && b[0] > a[0] {
        (b, a)
    } else {
        (a, b)
    }
}
