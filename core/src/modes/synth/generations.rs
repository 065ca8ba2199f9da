//! Which generation of which pixel a request needs (design note §1.5, per pixel): generation
//! `k` is a pixel's value after `k` correction subpasses. Given what the pyramidal cache already
//! holds, a request needs, for each pixel of its padded rectangle, every generation up to some
//! highest one; this module works that out — from the plan's cone when nothing is cached, by
//! dilation around what must be computed otherwise — with each subpass's bounding box.

use crate::geom::Rect;
use super::plan::{correction_cone, Class};

/// Where a subpass class lies in a rectangle: its first row and first column (relative to the
/// rectangle) and the step between its rows and between its columns.
pub(crate) fn class_origin(class: Class, r: Rect) -> (usize, usize, usize) {
    match class {
        Class::All => (0, 0, 1),
        Class::Parity(px, py) => ((py - r.y0).rem_euclid(2) as usize, (px - r.x0).rem_euclid(2) as usize, 2),
    }
}

/// How many class columns a row `width` wide holds, the first at `c0`, `step` apart.
pub(crate) fn class_cols(width: usize, c0: usize, step: usize) -> usize {
    if width > c0 {
        (width - c0).div_ceil(step)
    } else {
        0
    }
}

/// Rows, first column and column step of a subpass class within a rectangle.
pub(crate) fn class_layout(class: Class, r: Rect) -> (Vec<usize>, usize, usize) {
    let (j0, c0, step) = class_origin(class, r);
    ((j0..r.height().max(0) as usize).step_by(step).collect(), c0, step)
}

/// For each pixel of `ext`, the highest generation a call needing `need` at the last
/// generation must know (−1: none), given the generations the cache holds (`lo`); and for each
/// subpass, the bounding rectangle of the pixels it computes. A pixel computed at generation `k`
/// by a subpass of its class reads its 5×5 neighbourhood at `k − 1`; every other pixel just
/// keeps its own value. With nothing cached (`cached` false) this is the plan's cone, filled in
/// row intervals; otherwise it is dilated pixel by pixel around what must be computed.
pub(crate) fn needed_generations(
    ext: Rect,
    need: Rect,
    gens: &[Class],
    lo: &[i8],
    cached: bool,
) -> (Vec<i8>, Vec<Rect>) {
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
        let (j0, c0, step) = class_origin(class, ext);
        // Per row: the first and last computed column, if any. Sequential: these passes are
        // short, and forking for them cost more than they do.
        let mut spans: Vec<Option<(usize, usize)>> = vec![None; h];
        let mut src = vec![0u8; w + 4];
        for (j, d) in dil.chunks_mut(w).enumerate() {
            if j < j0 || (j - j0) % step != 0 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modes::synth::plan::{pad_for_correction, schedule};

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
}
