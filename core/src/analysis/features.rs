//! Neighbourhood vectors and their PCA projections (design note §1.2b–c): the 5×5 runtime
//! neighbourhood projected to [`RUNTIME_DIMS`] integer dimensions, and the 7×7 similarity
//! neighbourhood projected to [`SEARCH_DIMS`] for the candidate search.

use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;

use crate::stack::addr;

/// Dimensions of the runtime (correction) feature vectors.
pub const RUNTIME_DIMS: usize = 8;
/// Dimensions of the candidate-search feature vectors.
pub const SEARCH_DIMS: usize = 8;
/// Fixed-point scale of projection matrices (unit vectors × 2^12).
pub const PROJ_ONE: f64 = 4096.0;
/// Right shift from `P · N` to a stored feature: features are in quarter colour units and
/// fit i16; squared 8-D distances fit u32.
pub const FEAT_SHIFT: u32 = 10;
/// Number of texels in the 5×5 runtime neighbourhood.
pub const TAPS5: usize = 25;

/// The 8-bit stack colours of one level, for neighbourhood gathering.
pub struct LevelColours<'a> {
    /// Row-major `width × height` colours.
    pub px: &'a [[u8; 3]],
    /// Exemplar width.
    pub width: i64,
    /// Exemplar height.
    pub height: i64,
    /// Wrap (true) or mirror (false) addressing.
    pub toroidal: bool,
    /// Sampling stride `h_l`.
    pub h: i64,
}

impl LevelColours<'_> {
    /// The `(2r+1)²` neighbourhood of texel `(x, y)` at stride `h`, raster order, RGB.
    pub fn neighbourhood(&self, x: i64, y: i64, r: i64, out: &mut Vec<i32>) {
        out.clear();
        for dy in -r..=r {
            let sy = addr(y + dy * self.h, self.height, self.toroidal);
            for dx in -r..=r {
                let sx = addr(x + dx * self.h, self.width, self.toroidal);
                let p = self.px[sy * self.width as usize + sx];
                out.extend(p.iter().map(|&v| v as i32));
            }
        }
    }
}

/// The taps of a 5×5 neighbourhood that lie inside a non-toroidal exemplar: rows `r0..r1` and
/// columns `c0..c1` of the 5×5 grid (design note §1.2b: near an edge only real texels are
/// compared, never the mirror image the stack's addressing would supply).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InnerTaps {
    /// First row inside.
    pub r0: u8,
    /// One past the last row inside.
    pub r1: u8,
    /// First column inside.
    pub c0: u8,
    /// One past the last column inside.
    pub c1: u8,
}

impl InnerTaps {
    /// The taps inside a `w × ht` exemplar of the 5×5 neighbourhood at stride `h` around
    /// `(x, y)`, or `None` when all are (the usual case: `2h ≤ x < w − 2h`, and so for `y`).
    #[inline]
    pub fn at(x: i64, y: i64, h: i64, (w, ht): (i64, i64)) -> Option<InnerTaps> {
        let t = Self::around(x as u32, y as u32, h as u32, (w as u32, ht as u32));
        (t != InnerTaps { r0: 0, r1: 5, c0: 0, c1: 5 }).then_some(t)
    }

    /// [`InnerTaps::at`] without the test for the usual case (branch-free).
    #[inline(always)]
    pub fn around(x: u32, y: u32, h: u32, (w, ht): (u32, u32)) -> InnerTaps {
        let lo = |v: u32| (v < 2 * h) as u8 + (v < h) as u8;
        let hi = |v: u32, m: u32| 5 - (v + 2 * h >= m) as u8 - (v + h >= m) as u8;
        InnerTaps { r0: lo(y), r1: hi(y, ht), c0: lo(x), c1: hi(x, w) }
    }

    /// Number of taps inside.
    #[inline]
    pub fn count(&self) -> u32 {
        (self.r1 - self.r0) as u32 * (self.c1 - self.c0) as u32
    }

    /// Whether tap `t` (raster order) is inside.
    #[inline]
    pub fn contains(&self, t: usize) -> bool {
        let (r, c) = ((t / 5) as u8, (t % 5) as u8);
        r >= self.r0 && r < self.r1 && c >= self.c0 && c < self.c1
    }
}

/// The top `k` principal directions of the `(2r+1)²·3`-dimensional neighbourhoods of a level,
/// estimated from a regular grid of at most 64×64 texels (exact integer sums, f64 eigen-solve).
/// Each vector has its largest-magnitude component positive.
pub fn principal_directions(cols: &LevelColours, r: i64, k: usize) -> Vec<Vec<f64>> {
    let dim = ((2 * r + 1) * (2 * r + 1) * 3) as usize;
    let step = (cols.width.max(cols.height) / 64).max(1);
    // Integer sums per sampled row, added up: exact, so the same whatever the thread count.
    let rows: Vec<i64> = (0..cols.height).step_by(step as usize).collect();
    let (sum, cross, n) = rows
        .par_iter()
        .map(|&y| {
            let mut sum = vec![0i64; dim];
            let mut cross = vec![0i64; dim * dim];
            let mut n = 0i64;
            let mut v = Vec::with_capacity(dim);
            for x in (0..cols.width).step_by(step as usize) {
                cols.neighbourhood(x, y, r, &mut v);
                for i in 0..dim {
                    let vi = v[i] as i64;
                    sum[i] += vi;
                    let row = &mut cross[i * dim..i * dim + i + 1];
                    for (j, c) in row.iter_mut().enumerate() {
                        *c += vi * v[j] as i64;
                    }
                }
                n += 1;
            }
            (sum, cross, n)
        })
        .reduce(
            || (vec![0i64; dim], vec![0i64; dim * dim], 0),
            |mut a, b| {
                a.0.iter_mut().zip(&b.0).for_each(|(x, y)| *x += y);
                a.1.iter_mut().zip(&b.1).for_each(|(x, y)| *x += y);
                (a.0, a.1, a.2 + b.2)
            },
        );
    let nf = n as f64;
    let cov = DMatrix::from_fn(dim, dim, |i, j| {
        let (a, b) = if j <= i { (i, j) } else { (j, i) };
        (cross[a * dim + b] as f64 - sum[a] as f64 * sum[b] as f64 / nf) / nf
    });
    let eig = SymmetricEigen::new(cov);
    let mut order: Vec<usize> = (0..dim).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]).then(a.cmp(&b)));
    order
        .into_iter()
        .take(k)
        .map(|i| {
            let mut e: Vec<f64> = eig.eigenvectors.column(i).iter().copied().collect();
            let mut big = 0;
            for (j, x) in e.iter().enumerate() {
                if x.abs() > e[big].abs() {
                    big = j;
                }
            }
            if e[big] < 0.0 {
                e.iter_mut().for_each(|x| *x = -*x);
            }
            e
        })
        .collect()
}

/// Quantise runtime projection directions to the fixed-point layout used by correction:
/// `[tap (25)][channel (3)][dim (RUNTIME_DIMS)]` as i16 (unit vectors × 2^12).
pub fn quantise_projection(dirs: &[Vec<f64>]) -> Vec<i16> {
    let mut p = vec![0i16; TAPS5 * 3 * RUNTIME_DIMS];
    for (d, dir) in dirs.iter().enumerate().take(RUNTIME_DIMS) {
        for (i, &x) in dir.iter().enumerate() {
            let (tap, c) = (i / 3, i % 3);
            p[(tap * 3 + c) * RUNTIME_DIMS + d] = (x * PROJ_ONE).round() as i16;
        }
    }
    p
}

/// Project a 5×5 RGB neighbourhood with a quantised projection to a stored feature vector.
#[inline]
pub fn project_runtime(proj: &[i16], n: &[i32]) -> [i16; RUNTIME_DIMS] {
    let mut acc = [0i32; RUNTIME_DIMS];
    for (i, &v) in n.iter().enumerate() {
        let row = &proj[i * RUNTIME_DIMS..(i + 1) * RUNTIME_DIMS];
        for d in 0..RUNTIME_DIMS {
            acc[d] += row[d] as i32 * v;
        }
    }
    acc.map(|a| (a >> FEAT_SHIFT) as i16)
}

/// The candidate search's projection: directions stored tap-major (`[component][direction]`),
/// so one neighbourhood value feeds every direction at once.
pub struct SearchProjection {
    rows: Vec<[f64; SEARCH_DIMS]>,
}

impl SearchProjection {
    /// The projection onto (up to [`SEARCH_DIMS`]) `dirs`, all of one length.
    pub fn new(dirs: &[Vec<f64>]) -> SearchProjection {
        let len = dirs.first().map_or(0, Vec::len);
        let rows = (0..len)
            .map(|i| std::array::from_fn(|d| dirs.get(d).and_then(|v| v.get(i)).copied().unwrap_or(0.0)))
            .collect();
        SearchProjection { rows }
    }

    /// Project a neighbourhood: each output the sum, in component order, of direction ×
    /// value (no fused multiply-add: the same bits on every machine).
    pub fn project(&self, n: &[i32]) -> [f64; SEARCH_DIMS] {
        let mut out = [0.0; SEARCH_DIMS];
        for (row, &v) in self.rows.iter().zip(n) {
            let v = v as f64;
            for d in 0..SEARCH_DIMS {
                out[d] += row[d] * v;
            }
        }
        out
    }
}
