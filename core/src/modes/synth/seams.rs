//! Seam-aware blending of native pixels (issue 40). Native pixels copy exemplar texels by
//! coordinate; where correction put side by side two places of the exemplar that do not
//! continue each other and whose low frequencies differ (a bright region against a dark one on
//! a smooth texture), the jump shows as an edge the exemplar never has. Here each pixel's low
//! frequencies are replaced by a tent-weighted mean of what its neighbours' coordinates predict
//! for it (neighbour `q` predicts `S(q) − (q − p)`), keeping the pixel's own detail:
//!
//! `out(p) = E[S(p)] + fade(Σ_d w(d)·Ē[S(p+d) − d] / Σ w − Ē[S(p)])`
//!
//! with `Ē` the exemplar low-passed at stride 4 (stack level `L − 2`; a smooth exemplar's
//! whole colours, [`Style`]). Wherever the neighbourhood is coherent every prediction is `S(p)`
//! and the pixel stays exactly the texel; a jump between places of similar low frequencies
//! changes little (`fade` scales corrections smaller than the texture's [`Style::fade`] down),
//! so sharp detail stays sharp. Integer arithmetic over a window grown by [`RADIUS`]:
//! deterministic, and a window equals the same pixels cut from any larger one.

use rayon::prelude::*;

use crate::geom::wrap;

use crate::analysis::FineDetail;

/// Radius of the blend, texels: a pixel reads the coordinates within this Chebyshev distance.
/// 3 (a 7-texel ramp) against 2 and 4 on the development set: slime's `edges` 1.31 (2: 1.34,
/// 4: 1.27) at less cost in `hist` than 4 (bench/README.md).
pub const RADIUS: usize = 3;
/// Stack levels below the finest of the low-pass `Ē` of a detailed texture (stride 4): the
/// ramp is 7 texels, so frequencies finer than it stay the pixel's own.
pub const LOW_STEPS: u32 = crate::analysis::FINE_DETAIL_STEPS;
/// The largest fade (8-bit units): corrections whose largest channel is below the fade are
/// scaled by `largest / fade`, so jumps between places of similar brightness stay almost
/// untouched, which keeps the colour histogram and gradients of busy textures (gravel `hist`
/// 0.0042 with no fade, 0.0033 with 16), while visible steps are ramped fully.
pub const MAX_FADE: i32 = 16;

/// How a texture's seams are blended, chosen from its exemplar's fine detail
/// ([`crate::analysis::Analysis::fine_detail`]): what a visible step is depends on the texture.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Style {
    /// Stack levels below the finest of the low-pass that is cross-faded: [`LOW_STEPS`], or 0
    /// (whole colours) for a smooth exemplar, whose detail is under 1/16 of its variance —
    /// there a seam is a step in every frequency, and cross-fading loses no detail (texq
    /// `edges` of fractal clouds: 6.0 unblended, 3.6 with the low-pass, 2.2 whole).
    pub low_steps: u32,
    /// The fade: the exemplar's RMS fine detail, within `2..=MAX_FADE` (a step that large is
    /// visible against the texture's own detail).
    pub fade: i32,
}

impl Style {
    /// The style for an exemplar with fine detail `d`.
    pub fn of(d: FineDetail) -> Style {
        let rms = (d.fine / d.samples.max(1)).isqrt() as i32;
        let low_steps = if 16 * d.fine < d.total { 0 } else { LOW_STEPS };
        Style { low_steps, fade: rms.clamp(2, MAX_FADE) }
    }
}

/// What native pixels show: the texels at exemplar coordinates and their low-pass.
pub(crate) struct Texels<'a> {
    /// The `m × m` texels (the exemplar's colours or a material map's).
    pub texels: &'a [[u8; 3]],
    /// Their low-pass `Ē`, same layout.
    pub low: &'a [[u8; 3]],
    /// The exemplar's size `(width, height)`.
    pub dims: (usize, usize),
    /// Whether the exemplar wraps (else its edge repeats).
    pub toroidal: bool,
}

/// Appends to `out` (RGB8) the blended colours of the `w × h` pixels at the centre of
/// `coords`, a `(w + 2·RADIUS) × (h + 2·RADIUS)` window of packed exemplar coordinates
/// `x | y << 16`, from `src`, with the texture's `fade`. Rows run in parallel; each pixel
/// depends on its neighbourhood only.
pub(crate) fn blend(coords: &[u32], (w, h): (usize, usize), src: &Texels, fade: i32, out: &mut Vec<u8>) {
    let Texels { texels, low, dims: (ew, eh), toroidal } = *src;
    const R: usize = RADIUS;
    const SIDE: usize = 2 * R + 1;
    let (bw, bh) = (w + 2 * R, h + 2 * R);
    debug_assert_eq!(coords.len(), bw * bh);
    if w == 0 || h == 0 {
        return;
    }
    let (ewi, ehi) = (ew as i64, eh as i64);
    // The low-pass padded by `R` on every side (wrapped on a torus, else its edge repeated):
    // every prediction `S(q) − d` is then a plain index into it.
    let (pm, ph) = (ew + 2 * R, eh + 2 * R);
    // Channels packed 21 bits apart, so one multiply-add weighs all three: a weighted sum
    // stays below 255 · 256 < 2^21 per channel.
    let pack = |c: [u8; 3]| c[0] as u64 | (c[1] as u64) << 21 | (c[2] as u64) << 42;
    let mut padded = vec![0u64; pm * ph];
    padded.par_chunks_exact_mut(pm).enumerate().for_each(|(py, row)| {
        let y = py as i64 - R as i64;
        let y = if toroidal { wrap(y, ehi) } else { y.clamp(0, ehi - 1) } as usize;
        for (px, out) in row.iter_mut().enumerate() {
            let x = px as i64 - R as i64;
            let x = if toroidal { wrap(x, ewi) } else { x.clamp(0, ewi - 1) } as usize;
            *out = pack(low[y * ew + x]);
        }
    });
    // Each buffer pixel's translation `t(q)`: its coordinate as an index into `padded` less its
    // own position `lin(q)` at `padded`'s stride, so that what `q` predicts for `p` (`S(q) −
    // (q − p)`) is `padded[t(q) + lin(p)]`. Coordinates are inside the exemplar and wrapped
    // all the same, so that every such index, `(S_y(q) + R − dy)·pm + S_x(q) + R − dx`
    // with `|dx|, |dy| ≤ R`, provably lies in `padded`: the sum below reads it unchecked.
    let lin = |x: usize, y: usize| (y * pm + x) as isize;
    let mut trans = vec![0isize; bw * bh];
    trans.par_chunks_exact_mut(bw).zip(coords.par_chunks_exact(bw)).enumerate().for_each(|(y, (row_t, row_c))| {
        for (x, (t, &v)) in row_t.iter_mut().zip(row_c).enumerate() {
            let (sx, sy) = (wrap((v & 0xFFFF) as i64, ewi), wrap((v >> 16) as i64, ehi));
            *t = ((sy as usize + R) * pm + sx as usize + R) as isize - lin(x, y);
        }
    });
    let index = |v: u32| (v >> 16) as usize * ew + (v & 0xFFFF) as usize;
    // Pixels whose right or lower neighbour does not continue them, then whether one lies
    // within `R` along each row: a pixel with none in its window is its texel.
    let next = |v: u32, dx: i64, dy: i64| -> u32 {
        let (x, y) = ((v & 0xFFFF) as i64 + dx, (v >> 16) as i64 + dy);
        if toroidal {
            crate::geom::pack_wrapped(x, y, (ewi, ehi))
        } else {
            (x | y << 16) as u32
        }
    };
    let mut seam = vec![false; bw * bh];
    seam.par_chunks_exact_mut(bw).enumerate().for_each(|(y, row)| {
        let (here, below) = (&coords[y * bw..(y + 1) * bw], coords.get((y + 1) * bw..(y + 2) * bw));
        for (x, out) in row.iter_mut().enumerate() {
            let v = here[x];
            *out = (x + 1 < bw && here[x + 1] != next(v, 1, 0)) || below.is_some_and(|b| b[x] != next(v, 0, 1));
        }
    });
    let mut near_row = vec![false; bw * bh];
    near_row.par_chunks_exact_mut(bw).zip(seam.par_chunks_exact(bw)).for_each(|(row, s)| {
        for x in R..bw.saturating_sub(R) {
            row[x] = s[x - R..=x + R].iter().any(|&s| s);
        }
    });
    // The tent weights along one axis.
    const WEIGHTS: [u64; SIDE] = {
        let mut w = [0; SIDE];
        let mut d = 0;
        while d < SIDE {
            w[d] = (R + 1 - d.abs_diff(R)) as u64;
            d += 1;
        }
        w
    };
    // The weights sum to 2^8: the mean is a rounding shift.
    const SHIFT: u32 = 8;
    let total = 1i32 << SHIFT;
    debug_assert_eq!(WEIGHTS.iter().sum::<u64>().pow(2), total as u64);
    // `c · size / fade` for every correction `|c| ≤ size < fade` (indexed `[size][c + fade]`):
    // a lookup instead of a division per channel.
    let faded: Vec<Vec<i32>> = (0..fade).map(|size| (-fade..=fade).map(|c| c * size / fade).collect()).collect();
    let start = out.len();
    out.resize(start + 3 * w * h, 0);
    out[start..].par_chunks_mut(3 * w).enumerate().for_each(|(y, line)| {
        let cy = y + R;
        for (x, px) in line.chunks_exact_mut(3).enumerate() {
            let cx = x + R;
            let v = coords[cy * bw + cx];
            let own = texels[index(v)];
            if !(cy - R..=cy + R).any(|yy| near_row[yy * bw + cx]) {
                px.copy_from_slice(&own);
                continue;
            }
            // The tent-weighted sum of the neighbours' predictions, less `v`'s own low-pass
            // colour at full weight (neighbours that continue `v` predict it: they add nothing
            // to the correction). Every tap is read: a fixed, branch-free sum.
            let mine = low[index(v)].map(i32::from);
            let here = lin(cx, cy);
            // The taps' translations: rows `bw` apart from the window's corner (one bounds
            // check for all of them).
            let corner = (cy - R) * bw + cx - R;
            let taps = &trans[corner..corner + (SIDE - 1) * bw + SIDE];
            let mut sum = 0u64;
            for (dy, &wy) in WEIGHTS.iter().enumerate() {
                let mut along = 0u64;
                for (dx, &wx) in WEIGHTS.iter().enumerate() {
                    // SAFETY: `dy·bw + dx < taps.len()`; `t + here` indexes `padded` (see
                    // `trans`). Checked, these reads cost a third more instructions.
                    let t = unsafe { *taps.get_unchecked(dy * bw + dx) };
                    debug_assert!(((t + here) as usize) < padded.len());
                    along += wx * unsafe { *padded.get_unchecked((t + here) as usize) };
                }
                sum += wy * along;
            }
            let acc: [i32; 3] = std::array::from_fn(|k| ((sum >> (21 * k)) & 0x1F_FFFF) as i32);
            let acc: [i32; 3] = std::array::from_fn(|k| acc[k] - total * mine[k]);
            let corr = acc.map(|a| (a + total / 2) >> SHIFT);
            let size = corr.iter().map(|c| c.abs()).max().unwrap_or(0);
            for k in 0..3 {
                let c = if size >= fade { corr[k] } else { faded[size as usize][(corr[k] + fade) as usize] };
                px[k] = (own[k] as i32 + c).clamp(0, 255) as u8;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stack::low_pass;

    fn texels(m: usize) -> Vec<[u8; 3]> {
        (0..m * m).map(|i| [(i * 37 % 251) as u8, (i % m * 255 / m) as u8, (i / m * 255 / m) as u8]).collect()
    }

    #[test]
    fn smooth_exemplars_cross_fade_whole_colours_and_busy_ones_low_frequencies() {
        // Fine detail 2% of the variance, RMS 2: whole colours, the smallest fade.
        let smooth = FineDetail { fine: 4 * 300, total: 200 * 300, samples: 300 };
        assert_eq!(Style::of(smooth), Style { low_steps: 0, fade: 2 });
        // Half the variance, RMS 27 (gravel): the low-pass, the largest fade.
        let busy = FineDetail { fine: 729 * 300, total: 1458 * 300, samples: 300 };
        assert_eq!(Style::of(busy), Style { low_steps: LOW_STEPS, fade: MAX_FADE });
        // In between (slime: a ninth of the variance, RMS 10).
        let soft = FineDetail { fine: 100 * 300, total: 900 * 300, samples: 300 };
        assert_eq!(Style::of(soft), Style { low_steps: LOW_STEPS, fade: 10 });
    }

    #[test]
    fn coherent_windows_are_exemplar_texels() {
        let m = 32;
        let ex = texels(m);
        let low = low_pass(&ex, (m, m), true, LOW_STEPS);
        let (w, h) = (20, 9);
        let (bw, bh) = (w + 2 * RADIUS, h + 2 * RADIUS);
        // A coherent window that wraps around the torus.
        let coords: Vec<u32> = (0..bw * bh).map(|i| ((i % bw + 25) % m) as u32 | ((((i / bw) + 7) % m) as u32) << 16).collect();
        let mut out = Vec::new();
        blend(&coords, (w, h), &Texels { texels: &ex, low: &low, dims: (m, m), toroidal: true }, MAX_FADE, &mut out);
        let want: Vec<u8> = (0..w * h)
            .flat_map(|i| ex[((i / w + RADIUS + 7) % m) * m + (i % w + RADIUS + 25) % m])
            .collect();
        assert_eq!(out, want);
    }

    #[test]
    fn a_jump_between_bright_and_dark_becomes_a_ramp() {
        // Left half of the exemplar black, right half white; the window puts a black texel's
        // continuation next to a white one.
        let m = 32;
        let ex: Vec<[u8; 3]> = (0..m * m).map(|i| if i % m < m / 2 { [0; 3] } else { [255; 3] }).collect();
        let low = low_pass(&ex, (m, m), false, LOW_STEPS);
        let (w, h) = (16, 1);
        let (bw, bh) = (w + 2 * RADIUS, h + 2 * RADIUS);
        let coords: Vec<u32> = (0..bw * bh)
            .map(|i| {
                let (x, y) = (i % bw, i / bw);
                let sx = if x < bw / 2 { 2 + x } else { 20 + x - bw / 2 };
                sx as u32 | ((8 + y) as u32) << 16
            })
            .collect();
        let mut out = Vec::new();
        blend(&coords, (w, h), &Texels { texels: &ex, low: &low, dims: (m, m), toroidal: false }, 2, &mut out);
        let row: Vec<i32> = out.chunks(3).map(|c| c[0] as i32).collect();
        let steps: Vec<i32> = row.windows(2).map(|p| p[1] - p[0]).collect();
        assert!(steps.iter().all(|&s| s >= 0), "monotone: {row:?}");
        assert!(steps.iter().all(|&s| s < 128), "no hard step left: {row:?}");
        assert_eq!((row[0], row[w - 1]), (0, 255), "far from the jump, texels: {row:?}");
    }
}
