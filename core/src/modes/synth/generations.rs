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
/// row intervals; otherwise it is dilated around what must be computed, 64 pixels a word.
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
    // Pixel sets as bit rows, 64 columns a word, bits beyond `w` clear. The sets are nested:
    // `needs` holds the pixels whose highest needed generation is at least the current `k`, and
    // generation `k`'s computed pixels, dilated by 2 (their 5×5 neighbourhoods), join it at
    // `k − 1`; a pixel's highest generation is the `k` at which it joined.
    let ww = w.div_ceil(64);
    let tail = if w % 64 == 0 { !0u64 } else { (1u64 << (w % 64)) - 1 };
    let mut top = vec![-1i8; w * h];
    let mut needs = vec![0u64; ww * h];
    let (ni, nj) = ((need.x0 - ext.x0) as usize, (need.y0 - ext.y0) as usize);
    for j in nj..nj + need.height() as usize {
        top[j * w + ni..j * w + ni + need.width() as usize].fill(gens.len() as i8);
        for i in ni..ni + need.width() as usize {
            needs[j * ww + i / 64] |= 1 << (i % 64);
        }
    }
    let mut boxes = vec![Rect::new(0, 0, 0, 0); gens.len()];
    // Per row, the computed pixels dilated along the row (valid where `computed_rows` says so).
    let mut along = vec![0u64; ww * h];
    let mut computed_rows = vec![false; h];
    // One class row's computed pixels.
    let mut row = vec![0u64; ww];
    for (k, &class) in gens.iter().enumerate().rev().map(|(i, c)| (i as i8 + 1, c)) {
        let (j0, c0, step) = class_origin(class, ext);
        let columns = match (step, c0 % 2) {
            (1, _) => !0u64,
            (_, 0) => 0x5555_5555_5555_5555,
            _ => 0xAAAA_AAAA_AAAA_AAAA,
        };
        computed_rows.fill(false);
        let (mut x0, mut x1) = (usize::MAX, 0);
        for j in (j0..h).step_by(step) {
            // This class's pixels that need generation `k` and whose cached generations stop below it.
            let mut any = false;
            for (i, out) in row.iter_mut().enumerate() {
                let keep = set_bits(needs[j * ww + i] & columns)
                    .filter(|&b| lo[j * w + 64 * i + b] < k)
                    .fold(0u64, |acc, b| acc | 1 << b);
                *out = keep;
                any |= keep != 0;
            }
            if !any {
                continue;
            }
            computed_rows[j] = true;
            let first = row.iter().position(|&v| v != 0).unwrap_or(0);
            let last = row.iter().rposition(|&v| v != 0).unwrap_or(0);
            x0 = x0.min(64 * first + row[first].trailing_zeros() as usize);
            x1 = x1.max(64 * last + 63 - row[last].leading_zeros() as usize);
            // Dilate by two columns, carrying across words.
            for i in 0..ww {
                let (prev, next) = (if i > 0 { row[i - 1] } else { 0 }, row.get(i + 1).copied().unwrap_or(0));
                let v = row[i];
                let d = v | v << 1 | prev >> 63 | v << 2 | prev >> 62 | v >> 1 | next << 63 | v >> 2 | next << 62;
                along[j * ww + i] = if i + 1 == ww { d & tail } else { d };
            }
        }
        let (Some(first), Some(last)) =
            (computed_rows.iter().position(|&c| c), computed_rows.iter().rposition(|&c| c))
        else {
            continue;
        };
        boxes[k as usize - 1] = Rect {
            x0: ext.x0 + x0 as i64,
            y0: ext.y0 + first as i64,
            x1: ext.x0 + x1 as i64 + 1,
            y1: ext.y0 + last as i64 + 1,
        };
        // Dilate by two rows; pixels new to the set need generation `k − 1` at most.
        for j in first.saturating_sub(2)..=(last + 2).min(h - 1) {
            let rows = j.saturating_sub(2)..=(j + 2).min(h - 1);
            for i in 0..ww {
                let d = rows.clone().filter(|&jj| computed_rows[jj]).fold(0, |a, jj| a | along[jj * ww + i]);
                for b in set_bits(d & !needs[j * ww + i]) {
                    top[j * w + 64 * i + b] = k - 1;
                }
                needs[j * ww + i] |= d;
            }
        }
    }
    (top, boxes)
}

/// The positions of the set bits of `word`, lowest first.
fn set_bits(mut word: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (word != 0).then(|| {
            let b = word.trailing_zeros() as usize;
            word &= word - 1;
            b
        })
    })
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

    /// The definition, pixel by pixel: generation `k`'s computed pixels are its class's pixels
    /// that need `k` and hold less, and each of their 5×5 neighbourhoods needs `k − 1`.
    fn reference(ext: Rect, need: Rect, gens: &[Class], lo: &[i8]) -> (Vec<i8>, Vec<Rect>) {
        let (w, h) = (ext.width() as usize, ext.height() as usize);
        let mut top = vec![-1i8; w * h];
        for j in 0..h {
            for i in 0..w {
                if need.contains_rect(&Rect::new(ext.x0 + i as i64, ext.y0 + j as i64, 1, 1)) {
                    top[j * w + i] = gens.len() as i8;
                }
            }
        }
        let mut boxes = vec![Rect::new(0, 0, 0, 0); gens.len()];
        for k in (1..=gens.len()).rev() {
            let (j0, c0, step) = class_origin(gens[k - 1], ext);
            let computed: Vec<(usize, usize)> = (j0..h)
                .step_by(step)
                .flat_map(|j| (c0..w).step_by(step).map(move |i| (i, j)))
                .filter(|&(i, j)| top[j * w + i] >= k as i8 && lo[j * w + i] < k as i8)
                .collect();
            for &(i, j) in &computed {
                let pixel = Rect::new(ext.x0 + i as i64, ext.y0 + j as i64, 1, 1);
                boxes[k - 1] = if boxes[k - 1].is_empty() { pixel } else { boxes[k - 1].union(&pixel) };
                for jj in j.saturating_sub(2)..(j + 3).min(h) {
                    for ii in i.saturating_sub(2)..(i + 3).min(w) {
                        top[jj * w + ii] = top[jj * w + ii].max(k as i8 - 1);
                    }
                }
            }
        }
        (top, boxes)
    }

    /// With parts of the rectangle cached at assorted generations (blocks, as the pyramidal
    /// cache holds them, and scattered pixels), the bit-set dilation is the definition.
    #[test]
    fn dilation_follows_the_definition_around_cached_pixels() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        for (x, y, w, h) in [(0, 0, 256, 256), (-7, 13, 33, 20), (5, -3, 1, 1), (-100, -101, 130, 3), (3, 3, 64, 65)] {
            let need = Rect::new(x, y, w, h);
            for sched in [schedule(2, 4), schedule(1, 1), schedule(3, 4)] {
                let ext = pad_for_correction(need, &sched).0;
                let (ew, eh) = (ext.width() as usize, ext.height() as usize);
                for trial in 0..4 {
                    let g = sched.len() as u64 + 1;
                    let mut lo = vec![-1i8; ew * eh];
                    for _ in 0..trial * 3 {
                        let (bx, by) = (next(ew as u64) as usize, next(eh as u64) as usize);
                        let (bw, bh) = (1 + next(40) as usize, 1 + next(40) as usize);
                        let v = next(g + 1) as i8 - 1;
                        for j in by..(by + bh).min(eh) {
                            lo[j * ew + bx..j * ew + (bx + bw).min(ew)].fill(v);
                        }
                    }
                    for _ in 0..trial * 50 {
                        let i = next((ew * eh) as u64) as usize;
                        lo[i] = next(g + 1) as i8 - 1;
                    }
                    let got = needed_generations(ext, need, &sched, &lo, true);
                    assert_eq!(got, reference(ext, need, &sched, &lo), "{need:?} {sched:?} trial {trial}");
                }
            }
        }
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
}
