//! Block histories on the move between a synthesis buffer and the pyramidal cache: laying a
//! cached block's generation over the buffer, choosing the blocks a call learns something about
//! (merged with what the cache held), and recording each generation the call computes into them.

use std::sync::Arc;

use rayon::prelude::*;

use super::generations::{class_cols, class_origin};
use crate::geom::Rect;
use super::plan::Class;
use crate::cache::{Block, BlockGrid, Pyramid, BLOCK};

/// Index of pixel `(x, y)` in the generation-`k ≥ 1` array of its block.
#[inline]
pub(crate) fn class_index(class: Class, x: i64, y: i64) -> usize {
    let (i, j) = (x.rem_euclid(BLOCK) as usize, y.rem_euclid(BLOCK) as usize);
    match class {
        Class::All => j * BLOCK as usize + i,
        Class::Parity(..) => (j / 2) * (BLOCK as usize / 2) + i / 2,
    }
}

/// A block this call learns about and will offer to the cache: its history so far.
pub(crate) struct Pending {
    /// The block.
    pub rect: Rect,
    /// The part of the block inside the call's rectangle.
    pub inner: Rect,
    /// The highest generation this call knows of any of its pixels.
    pub top: i8,
    /// Per pixel, the highest generation known (cached or this call's).
    pub lo: Vec<i8>,
    /// The history being gathered, laid out as in [`Block`].
    pub data: Vec<u32>,
}

/// Index of pixel `(x, y)` within its block (row-major).
#[inline]
pub(crate) fn block_index(x: i64, y: i64) -> usize {
    class_index(Class::All, x, y)
}

/// Call `f(y, x0, x1)` for each row of `r`.
pub(crate) fn for_rows(r: Rect, mut f: impl FnMut(i64, i64, i64)) {
    for y in r.y0..r.y1 {
        f(y, r.x0, r.x1);
    }
}

/// The row-wise layout of a class within the part `r` of a block: the number of class pixels
/// per row, the buffer step between them, and for each row the buffer index of its first class
/// pixel in `ext` and its offset in the block's class array.
fn class_rows(ext: Rect, r: Rect, class: Class) -> (usize, usize, impl Iterator<Item = (usize, usize)>) {
    let w = ext.width() as usize;
    let (j0, c0, step) = class_origin(class, r);
    let n = class_cols(r.width() as usize, c0, step);
    let rows = (j0..r.height().max(0) as usize).step_by(step).map(move |j| {
        let (x, y) = (r.x0 + c0 as i64, r.y0 + j as i64);
        ((y - ext.y0) as usize * w + (x - ext.x0) as usize, class_index(class, x, y))
    });
    (n, step, rows)
}

/// Put a cached block's generation-`k` values (`arr`, laid out for `class`) into `s` where this
/// call needs them and the block holds them; `changed(p, v)` is told of every changed pixel.
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlay(
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
pub(crate) fn capture(pending: &mut [Pending], s: &[u32], ext: Rect, top: &[i8], class: Class, k: usize, start: usize) {
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

/// The blocks this call learns something about, each starting from its cached history.
pub(crate) fn pending(
    pyr: &Pyramid,
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
    let (mut bytes, budget) = (0u64, pyr.limit() / 2);
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
