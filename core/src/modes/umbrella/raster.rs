//! Coverage of a band of sub-samples by scanline fill: which umbrella each sub-sample sees and
//! how many umbrellas in front of that one shade it. Every umbrella of a cell's list (front to
//! back) fills its star polygon into the samples of that cell not yet taken, then counts a
//! shadow on the samples its polygon moved by `+ℓ` covers that are still free — the same rule as
//! walking the list per point (the first umbrella containing the point is hit; those before it
//! containing the point moved by `−ℓ` shade it), at the cost of a few edge crossings per sample
//! row instead of a point-in-polygon test per umbrella and sample.
//!
//! Positions are relative to the cell, sample centres at `(r + ½)·sp` for a sample spacing
//! `sp` that is a power of two, so a sample's coverage depends on its absolute position only:
//! windows are the same samples cut from larger ones.

use std::cell::Cell;

use super::arrange::{Arrangement, Placed};
use super::extract::{ray, RAYS};

/// No umbrella: the background shows.
pub const NONE: u32 = u32::MAX;

/// The rim of `u` in its cell's coordinates, moved by `(ox, oy)`.
pub fn polygon(arr: &Arrangement, u: &Placed, ox: f32, oy: f32) -> [[f32; 2]; RAYS] {
    let m = &arr.table[u.modified as usize];
    let s = 1.0 / u.inv_scale;
    let (c, sn) = (u.cos * s, u.sin * s);
    std::array::from_fn(|i| {
        let d = ray(i);
        let (lx, ly) = (d[0] * m.radii[i], d[1] * m.radii[i]);
        [u.cx + ox + c * lx - sn * ly, u.cy + oy + sn * lx + c * ly]
    })
}

/// Runs of samples inside polygon `poly` (even–odd rule, half-open crossings): calls
/// `span(r, c0, c1)` for samples `c0..c1` of sample row `r`, rows within `rows` and columns
/// within `cols` (sample indices relative to the cell, centres at `(i + ½)·sp`); rows for which
/// `skip(r)` holds are passed over.
pub fn fill(
    poly: &[[f32; 2]; RAYS],
    sp: f32,
    rows: (i64, i64),
    cols: (i64, i64),
    skip: impl Fn(i64) -> bool,
    mut span: impl FnMut(i64, i64, i64),
) {
    // The edges that reach the rows asked for (a crossing is computed from the edge alone, so
    // leaving the others out changes nothing).
    let (top, bottom) = ((rows.0 as f32 + 0.5) * sp, (rows.1 as f32 - 0.5) * sp);
    // Per edge: its ends' y, and x at the first end with the slope dx/dy.
    let mut edges = [[0f32; 4]; RAYS];
    let (mut ne, mut ymin, mut ymax) = (0, f32::MAX, f32::MIN);
    for i in 0..RAYS {
        let (a, b) = (poly[i], poly[(i + 1) % RAYS]);
        let (lo, hi) = (a[1].min(b[1]), a[1].max(b[1]));
        if hi >= top && lo <= bottom && a[1] != b[1] {
            edges[ne] = [a[1], b[1], a[0], (b[0] - a[0]) / (b[1] - a[1])];
            ne += 1;
            ymin = ymin.min(lo);
            ymax = ymax.max(hi);
        }
    }
    let first = ceil(ymin / sp - 0.5).max(rows.0);
    let last = ceil(ymax / sp - 0.5).min(rows.1);
    let mut xs = [0f32; RAYS];
    for r in first..last {
        if skip(r) {
            continue;
        }
        let y = (r as f32 + 0.5) * sp;
        let mut n = 0;
        // Branch-free: whether an edge crosses the row is a coin toss from row to row.
        for &[ay, by, ax, slope] in &edges[..ne] {
            xs[n] = ax + (y - ay) * slope;
            n += ((ay <= y) != (by <= y)) as usize;
        }
        let xs = &mut xs[..n];
        // Insertion sort: a handful of crossings.
        for i in 1..xs.len() {
            let mut j = i;
            while j > 0 && xs[j - 1] > xs[j] {
                xs.swap(j - 1, j);
                j -= 1;
            }
        }
        for pair in xs.chunks_exact(2) {
            let c0 = ceil(pair[0] / sp - 0.5).max(cols.0);
            let c1 = ceil(pair[1] / sp - 0.5).min(cols.1);
            if c0 < c1 {
                span(r, c0, c1);
            }
        }
    }
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
}

impl Coverage {
    /// An uncovered band of `width × rows` samples.
    pub fn new(width: usize, rows: usize) -> Coverage {
        Coverage { width, hit: vec![NONE; width * rows], shade: vec![0; width * rows] }
    }

    /// Fill one cell's list into the band: the cell's samples are rows `rows` and columns
    /// `cols` relative to the cell, which start at band row `row0` and band column `col0`;
    /// umbrella `n` of `list` is recorded as `first + n`. `shadows`: whether to count them.
    /// Rows whose samples are all taken are passed over, and the list is left once all are.
    #[allow(clippy::too_many_arguments)]
    pub fn cell(&mut self, arr: &Arrangement, list: &[Placed], first: u32, sp: f32, rows: (i64, i64), cols: (i64, i64), row0: i64, col0: i64, shadows: bool) {
        let l = arr.shadow_offset;
        let width = self.width as i64;
        let at = |r: i64, c: i64| ((r - rows.0 + row0) * width + (c - cols.0 + col0)) as usize;
        // Samples still free per row of the cell, and in all.
        let free: Vec<Cell<u32>> = (rows.0..rows.1).map(|_| Cell::new((cols.1 - cols.0) as u32)).collect();
        let full = |r: i64| free[(r - rows.0) as usize].get() == 0;
        let mut left: u64 = free.iter().map(|f| f.get() as u64).sum();
        let (hit, shade) = (&mut self.hit, &mut self.shade);
        // Whether the disc of `u` moved by `o` reaches the cell's samples.
        let (x0, x1) = (cols.0 as f32 * sp, cols.1 as f32 * sp);
        let (y0, y1) = (rows.0 as f32 * sp, rows.1 as f32 * sp);
        let reaches = |u: &Placed, o: f32| {
            let (dx, dy) = (u.cx + o - (u.cx + o).clamp(x0, x1), u.cy + o - (u.cy + o).clamp(y0, y1));
            dx * dx + dy * dy <= u.reach2 * 1.001 + 1e-3
        };
        for (n, u) in list.iter().enumerate() {
            if left == 0 {
                break;
            }
            let id = first + n as u32;
            // (An umbrella listed only for its shadow takes no sample here.)
            if reaches(u, 0.0) {
                fill(&polygon(arr, u, 0.0, 0.0), sp, rows, cols, full, |r, c0, c1| {
                    let k = at(r, c0);
                    let mut taken = 0;
                    for h in &mut hit[k..k + (c1 - c0) as usize] {
                        let free = *h == NONE;
                        taken += free as u32;
                        *h = if free { id } else { *h };
                    }
                    let f = &free[(r - rows.0) as usize];
                    f.set(f.get() - taken);
                    left -= taken as u64;
                });
            }
            if shadows && l > 0.0 && reaches(u, l) {
                fill(&polygon(arr, u, l, l), sp, rows, cols, full, |r, c0, c1| {
                    let k = at(r, c0);
                    let n = (c1 - c0) as usize;
                    for (h, s) in hit[k..k + n].iter().zip(&mut shade[k..k + n]) {
                        *s = s.saturating_add((*h == NONE) as u8);
                    }
                });
            }
        }
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
        fill(&sq, 0.5, (0, 100), (0, 100), |_| false, |r, c0, c1| seen.extend((c0..c1).map(|c| (r, c))));
        // Centres at (i + ½)/2: 1.25, 1.75, 2.25, 2.75 → indices 2..6 both ways.
        let want: Vec<_> = (2..6).flat_map(|r| (2..6).map(move |c| (r, c))).collect();
        assert_eq!(seen, want);
        seen.clear();
        fill(&sq, 0.5, (3, 4), (0, 3), |_| false, |r, c0, c1| seen.extend((c0..c1).map(|c| (r, c))));
        assert_eq!(seen, vec![(3, 2)], "clipped to the rows and columns asked for");
    }
}
