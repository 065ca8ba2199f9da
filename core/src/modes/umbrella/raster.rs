//! Coverage of a band of sub-samples by scanline fill: which umbrella each sub-sample sees and
//! how many umbrellas in front of that one shade it. Every umbrella of a list (front to back)
//! fills its star polygon into the samples not yet taken of the cells that list it, then counts
//! a shadow on the samples its polygon moved by `+ℓ` covers that are still free — the same rule
//! as walking each cell's list per point (the first umbrella containing the point is hit; those
//! before it containing the point moved by `−ℓ` shade it), at the cost of a few edge crossings
//! per sample row instead of a point-in-polygon test per umbrella and sample. A row of cells
//! is filled with the union of its cells' lists, each umbrella masked to the cells that list it
//! ([`Cells`]), so an umbrella that reaches several cells is filled once.
//!
//! Positions are relative to the origin of a fixed frame of cells, sample centres at
//! `(r + ½)·sp` for a sample spacing `sp` (a pixel's width over its sub-samples per side), so a
//! sample's coverage depends on its absolute position only: windows are the same samples cut
//! from larger ones.

use std::cell::Cell;

use super::arrange::{Arrangement, Placed};
use super::extract::RAYS;

/// No umbrella: the background shows.
pub const NONE: u32 = u32::MAX;

/// The rim of `u` in its cell's coordinates, moved by `(ox, oy)`.
pub fn polygon(arr: &Arrangement, u: &Placed, ox: f32, oy: f32) -> [[f32; 2]; RAYS] {
    let m = &arr.table[u.modified as usize];
    let s = 1.0 / u.inv_scale;
    let (c, sn) = (u.cos * s, u.sin * s);
    std::array::from_fn(|i| {
        let d = arr.rays[i];
        let (lx, ly) = (d[0] * m.radii[i], d[1] * m.radii[i]);
        [u.cx + ox + c * lx - sn * ly, u.cy + oy + sn * lx + c * ly]
    })
}

/// Runs of samples inside polygon `poly` (even–odd rule, half-open crossings): calls
/// `span(r, c0, c1)` for samples `c0..c1` of sample row `r`, rows within `rows` and columns
/// within `cols` (sample indices relative to the list's origin, centres at `(i + ½)·sp`); rows
/// for which `skip(r)` holds are passed over. `crossings` is scratch space, reused from call to
/// call.
#[allow(clippy::too_many_arguments)]
pub fn fill(
    poly: &[[f32; 2]],
    sp: f32,
    rows: (i64, i64),
    cols: (i64, i64),
    crossings: &mut Crossings,
    skip: impl Fn(i64) -> bool,
    mut span: impl FnMut(i64, i64, i64),
) {
    // The edges that reach the rows asked for (a crossing is computed from the edge alone, so
    // leaving the others out changes nothing).
    let (top, bottom) = ((rows.0 as f32 + 0.5) * sp, (rows.1 as f32 - 0.5) * sp);
    // Per edge: its ends' y, and x at the first end with the slope dx/dy.
    let mut edges = [[0f32; 4]; RAYS];
    let (mut ne, mut ymin, mut ymax) = (0, f32::MAX, f32::MIN);
    for i in 0..poly.len().min(RAYS) {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (lo, hi) = (a[1].min(b[1]), a[1].max(b[1]));
        if hi >= top && lo <= bottom && a[1] != b[1] {
            edges[ne] = [a[1], b[1], a[0], (b[0] - a[0]) / (b[1] - a[1])];
            ne += 1;
            ymin = ymin.min(lo);
            ymax = ymax.max(hi);
        }
    }
    // No edge reaches the rows: no crossing (and `ymin`, `ymax` are still their sentinels).
    if ne == 0 {
        return;
    }
    // Multiplying by the inverse: exactly dividing when `sp` is a power of two (2 or 4
    // sub-samples per pixel side), rounded when it is not (3), but the same f32 operations on
    // the same frame-relative values whichever window asks.
    debug_assert!(sp > 0.0 && sp.is_finite(), "a sample spacing");
    let inv = 1.0 / sp;
    let first = ceil(ymin * inv - 0.5).max(rows.0);
    let last = ceil(ymax * inv - 0.5).min(rows.1);
    if first >= last {
        return;
    }
    let height = (last - first) as usize;
    {
        let Crossings { xs, counts } = crossings;
        // Each edge's crossings in the rows it spans (found from its ends, with a row of margin
        // either side for rounding, then tested exactly), into its rows in edge order — the
        // crossings of a row in the order a walk over all edges per row meets them.
        // Only grown: every slot read is written first.
        if xs.len() < height * RAYS {
            xs.resize(height * RAYS, 0.0);
        }
        counts.clear();
        counts.resize(height, 0);
        for &[ay, by, ax, slope] in &edges[..ne] {
            let (lo, hi) = (ay.min(by), ay.max(by));
            let r0 = (ceil(lo * inv - 0.5) - 1).max(first);
            let r1 = (ceil(hi * inv - 0.5) + 1).min(last);
            for r in r0..r1 {
                let y = (r as f32 + 0.5) * sp;
                if (ay <= y) != (by <= y) {
                    let k = (r - first) as usize;
                    xs[k * RAYS + counts[k] as usize] = ax + (y - ay) * slope;
                    counts[k] += 1;
                }
            }
        }
        for (k, &n) in counts.iter().enumerate() {
            let r = first + k as i64;
            if n < 2 || skip(r) {
                continue;
            }
            let xs = &mut xs[k * RAYS..][..n as usize];
            // Insertion sort: a handful of crossings.
            for i in 1..xs.len() {
                let mut j = i;
                while j > 0 && xs[j - 1] > xs[j] {
                    xs.swap(j - 1, j);
                    j -= 1;
                }
            }
            for pair in xs.chunks_exact(2) {
                let c0 = ceil(pair[0] * inv - 0.5).max(cols.0);
                let c1 = ceil(pair[1] * inv - 0.5).min(cols.1);
                if c0 < c1 {
                    span(r, c0, c1);
                }
            }
        }
    }
}

/// [`fill`]'s scratch space: the crossings of each row (at most [`RAYS`]) and their counts.
#[derive(Debug, Default)]
pub struct Crossings {
    xs: Vec<f32>,
    counts: Vec<u8>,
}

/// `⌈v⌉` for the sample indices at hand (|v| < 2^23; without SSE4.1, `f32::ceil` is a call).
#[inline]
fn ceil(v: f32) -> i64 {
    let t = v as i64;
    t + ((t as f32) < v) as i64
}

/// Sub-samples of a band of pixel rows: per sample the index of the umbrella it sees (into
/// the band's list of umbrellas, or [`NONE`]) and the number of shadows on it.
pub struct Coverage {
    /// Samples per row.
    pub width: usize,
    /// Umbrella index per sample.
    pub hit: Vec<u32>,
    /// Shadows per sample (saturating).
    pub shade: Vec<u8>,
    /// The scanline fill's scratch space.
    crossings: Crossings,
}

impl Coverage {
    /// An uncovered band of `width × rows` samples.
    pub fn new(width: usize, rows: usize) -> Coverage {
        Coverage { width, hit: vec![NONE; width * rows], shade: vec![0; width * rows], crossings: Crossings::default() }
    }

    /// Fill a list of `count` shapes, front to back, into the band: the samples are rows
    /// `rows` and columns `cols` relative to the list's origin, which start at band row `row0`
    /// and band column `col0`; shape `n` is recorded as `first + n`. `shape(n, o, extent)` is
    /// the polygon of shape `n` moved by `(o, o)` in those coordinates with the mask of
    /// `cells` it may take samples in, or `None` when its disc does not reach `extent` (the
    /// samples: `x0, x1, y0, y1`). `shadow`: the offset ℓ at which shapes shade what is behind
    /// them, if they do. Rows whose samples are all taken are passed over, and the list is left
    /// once all are.
    #[allow(clippy::too_many_arguments)]
    pub fn fill_list(
        &mut self,
        count: usize,
        shape: impl Fn(usize, f32, [f32; 4]) -> Option<(Poly, u64)>,
        cells: Cells,
        first: u32,
        sp: f32,
        rows: (i64, i64),
        cols: (i64, i64),
        (row0, col0): (i64, i64),
        shadow: Option<f32>,
    ) {
        let width = self.width as i64;
        let at = |r: i64, c: i64| ((r - rows.0 + row0) * width + (c - cols.0 + col0)) as usize;
        // Samples still free per row of the cell, and in all.
        let free: Vec<Cell<u32>> = (rows.0..rows.1).map(|_| Cell::new((cols.1 - cols.0) as u32)).collect();
        let full = |r: i64| free[(r - rows.0) as usize].get() == 0;
        let mut left: u64 = free.iter().map(|f| f.get() as u64).sum();
        let (hit, shade, crossings) = (&mut self.hit, &mut self.shade, &mut self.crossings);
        let extent = [cols.0 as f32 * sp, cols.1 as f32 * sp, rows.0 as f32 * sp, rows.1 as f32 * sp];
        for n in 0..count {
            if left == 0 {
                break;
            }
            let id = first + n as u32;
            // (A shape listed only for its shadow takes no sample here.)
            if let Some((p, mask)) = shape(n, 0.0, extent) {
                fill(p.vertices(), sp, rows, cols, crossings, full, |r, c0, c1| {
                    cells.clip(mask, c0, c1, |c0, c1| {
                        let k = at(r, c0);
                        let mut taken = 0;
                        // Branch-free (vectorised): free samples take `id`.
                        for h in &mut hit[k..k + (c1 - c0) as usize] {
                            let free = (*h == NONE) as u32;
                            taken += free;
                            let mask = free.wrapping_neg();
                            *h = (*h & !mask) | (id & mask);
                        }
                        let f = &free[(r - rows.0) as usize];
                        f.set(f.get() - taken);
                        left -= taken as u64;
                    });
                });
            }
            if let Some((p, mask)) = shadow.and_then(|l| shape(n, l, extent)) {
                fill(p.vertices(), sp, rows, cols, crossings, full, |r, c0, c1| {
                    cells.clip(mask, c0, c1, |c0, c1| {
                        let k = at(r, c0);
                        let n = (c1 - c0) as usize;
                        for (h, s) in hit[k..k + n].iter().zip(&mut shade[k..k + n]) {
                            *s = s.saturating_add((*h == NONE) as u8);
                        }
                    });
                });
            }
        }
    }
}

/// The cells of a list's row that its shapes may take samples in, by a mask per shape: bit
/// `i` stands for sample columns `base + i·width .. base + (i + 1)·width`; all bits set, for
/// every column.
#[derive(Debug, Clone, Copy)]
pub struct Cells {
    /// First column of the cell of bit 0.
    pub base: i64,
    /// Sample columns per cell.
    pub width: i64,
}

impl Cells {
    /// Every column to every shape (masks of all bits set).
    pub const ALL: Cells = Cells { base: 0, width: 1 };

    /// Calls `f(s0, s1)` for the parts of columns `c0..c1` in the cells of `mask`, in order.
    #[inline]
    fn clip(&self, mask: u64, c0: i64, c1: i64, mut f: impl FnMut(i64, i64)) {
        if mask == u64::MAX {
            return f(c0, c1);
        }
        let mut m = mask;
        while m != 0 {
            // A run of set bits: cells `b0..b1`.
            let b0 = m.trailing_zeros();
            let b1 = b0 + (!(m >> b0)).trailing_zeros().min(64 - b0);
            let (s0, s1) = (c0.max(self.base + b0 as i64 * self.width), c1.min(self.base + b1 as i64 * self.width));
            if s0 < s1 {
                f(s0, s1);
            }
            m = if b1 >= 64 { 0 } else { m & (u64::MAX << b1) };
        }
    }
}

/// A polygon of at most [`RAYS`] vertices.
#[derive(Debug, Clone, Copy)]
pub struct Poly {
    v: [[f32; 2]; RAYS],
    n: usize,
}

impl Poly {
    /// The first `n` (≤ [`RAYS`]) of `v`.
    pub fn new(v: [[f32; 2]; RAYS], n: usize) -> Poly {
        Poly { v, n: n.min(RAYS) }
    }

    /// Its vertices.
    pub fn vertices(&self) -> &[[f32; 2]] {
        &self.v[..self.n]
    }

    /// Moved by `(o, o)`.
    pub fn shifted(&self, o: f32) -> Poly {
        Poly { v: self.v.map(|p| [p[0] + o, p[1] + o]), n: self.n }
    }
}

/// Whether a disc at `(cx, cy)` of squared radius `r2` reaches `extent` (`x0, x1, y0, y1`),
/// with a margin for rounding.
pub fn disc_reaches(cx: f32, cy: f32, r2: f32, extent: [f32; 4]) -> bool {
    let (dx, dy) = (cx - cx.clamp(extent[0], extent[1]), cy - cy.clamp(extent[2], extent[3]));
    dx * dx + dy * dy <= r2 * 1.001 + 1e-3
}

/// The shapes of a level-0 list for [`Coverage::fill_list`]: each umbrella's rim, with the mask
/// of the cells it is listed in.
pub fn placed_shape<'a>(arr: &'a Arrangement, list: &'a [(Placed, u64)]) -> impl Fn(usize, f32, [f32; 4]) -> Option<(Poly, u64)> + 'a {
    move |n, o, extent| {
        let (u, mask) = &list[n];
        disc_reaches(u.cx + o, u.cy + o, u.reach2, extent).then(|| (Poly::new(polygon(arr, u, o, o), RAYS), *mask))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_fills_the_samples_whose_centres_it_contains() {
        let mut sq = [[0f32; 2]; RAYS];
        // A square 1..3 × 1..3 drawn with RAYS vertices (repeated corners).
        let corners = [[1.0, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]];
        for (i, v) in sq.iter_mut().enumerate() {
            *v = corners[i * 4 / RAYS];
        }
        let mut seen = Vec::new();
        fill(&sq, 0.5, (0, 100), (0, 100), &mut Crossings::default(), |_| false, |r, c0, c1| seen.extend((c0..c1).map(|c| (r, c))));
        // Centres at (i + ½)/2: 1.25, 1.75, 2.25, 2.75 → indices 2..6 both ways.
        let want: Vec<_> = (2..6).flat_map(|r| (2..6).map(move |c| (r, c))).collect();
        assert_eq!(seen, want);
        seen.clear();
        fill(&sq, 0.5, (3, 4), (0, 3), &mut Crossings::default(), |_| false, |r, c0, c1| seen.extend((c0..c1).map(|c| (r, c))));
        assert_eq!(seen, vec![(3, 2)], "clipped to the rows and columns asked for");
    }

    #[test]
    fn a_polygon_beside_the_rows_asked_for_fills_nothing() {
        // No edge reaches the rows (a shape listed for a band it misses, or a flat one): the
        // row range is never computed from the empty extent (whose `⌈·⌉` overflowed in debug
        // builds on the first umbrella tile served), and nothing is filled, at a spacing
        // that is a power of two or not (3 sub-samples per pixel side).
        let square = [[1.0f32, 1.0], [3.0, 1.0], [3.0, 3.0], [1.0, 3.0]];
        let flat = [[1.0f32, 2.0], [3.0, 2.0], [2.0, 2.0]];
        for sp in [0.5, 4.0 / 3.0] {
            for (poly, rows) in [(&square[..], (40, 60)), (&square[..], (-9, -4)), (&flat[..], (0, 10))] {
                let mut seen = 0;
                fill(poly, sp, rows, (0, 100), &mut Crossings::default(), |_| false, |_, c0, c1| seen += c1 - c0);
                assert_eq!(seen, 0, "spacing {sp}, rows {rows:?}");
            }
        }
    }
}
