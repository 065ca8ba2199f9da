//! The background of the umbrella mode — another mode's pixels, or the exemplar's mean colour
//! (of the colour or of the map shown) —
//! and the colour calibrations that shift it: so that the gaps between umbrellas keep the
//! exemplar's mean colour, and zooming out past the last drawn zoom changes the detail, not
//! the colour (memoised in the texture's caches).

use super::*;

/// `image` with `shift` added to each channel, rounded and clamped (a table per channel, not a
/// rounding per pixel).
pub(super) fn shifted(mut image: RgbWindow, shift: [f32; 3]) -> RgbWindow {
    let table: [[u8; 256]; 3] =
        std::array::from_fn(|c| std::array::from_fn(|v| (v as f32 + shift[c]).round().clamp(0.0, 255.0) as u8));
    for px in image.pixels.chunks_exact_mut(3) {
        for (v, t) in px.iter_mut().zip(&table) {
            *v = t[*v as usize];
        }
    }
    image
}

/// A colour calibration of texture `ident` with parameters `p`, memoised in `memo` (one of
/// the texture's caches, beside `arr`'s): `f` is given the parameters it is measured with —
/// `p` with seed 0, since a calibration is a statistic of the arrangement that another seed
/// changes only by chance, and a new seed should not pay for it again — and their arrangement.
pub(super) fn calibrated(
    memo: &Memo<String, [f32; 3]>,
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    f: impl FnOnce(&UmbrellaParams, &Arrangement) -> Result<[f32; 3]>,
) -> Result<[f32; 3]> {
    let p = UmbrellaParams { seed: 0, ..p.clone() };
    let key = format!("{ident};{}", p.canonical());
    if let Some(s) = memo.get(&key) {
        return Ok(s);
    }
    let caches = arr.caches_arc();
    let s = f(&p, &Arrangement::cached(el, &p, ident, caches))?;
    memo.put(key.clone(), s, key.len() as u64 + 64);
    Ok(s)
}

/// Largest shift of the background's colour for the gaps ([`gap_shift`]), per channel.
pub(super) const MAX_GAP_SHIFT: f32 = 48.0;

/// What the background is shifted by, per channel, where it shows between umbrellas: so that
/// the native view's mean colour is the exemplar's. The background stands for the gaps between
/// elements, but it is another mode's view of the whole exemplar — elements included — so
/// with light elements on dark gaps (leaves, smallstone, gravel) the output came out brighter
/// than the exemplar, and darker for dark ones (granite). Measured over a fixed 256² native
/// window at the origin: the mean colour, and the background's weight in it (the view with a
/// white background less the view with a black one); the difference to the exemplar's mean
/// over that weight, at most [`MAX_GAP_SHIFT`]. Elements keep their colours. Measured with
/// seed 0 and memoised ([`calibrated`]).
pub(super) fn gap_shift(
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    src: &Source,
    cache: &Pyramid,
) -> Result<[f32; 3]> {
    calibrated(&arr.caches().gaps, arr, el, p, ident, |p, arr| {
        let Some(level) = lod::level(arr, 0) else {
            return Ok([0.0; 3]);
        };
        let view = View::out(0, crate::geom::Rect::new(0, 0, 256, 256));
        let flat = |v: u8| move || Ok(RgbWindow { width: 256, height: 256, pixels: vec![v; 3 * 256 * 256] });
        let image = paint(el, arr, p, view, level, || background(p, src, cache, view))?;
        let black = paint(el, arr, p, view, level, flat(0))?;
        let white = paint(el, arr, p, view, level, flat(255))?;
        let mut sums = [[0f64; 3]; 2];
        for (i, ((&v, &b), &w)) in image.pixels.iter().zip(&black.pixels).zip(&white.pixels).enumerate() {
            sums[0][i % 3] += v as f64;
            sums[1][i % 3] += w as f64 - b as f64;
        }
        let n = (image.pixels.len() / 3).max(1) as f64;
        // The exemplar's mean (for a hand-made set too, whose elements' mean it is not).
        let target = mean_colour(src.exemplar);
        Ok(std::array::from_fn(|c| {
            let (mean, weight) = (sums[0][c] / n, sums[1][c] / n / 255.0);
            let target = target[c];
            if weight < 0.05 {
                0.0
            } else {
                ((target - mean) / weight).clamp(-MAX_GAP_SHIFT as f64, MAX_GAP_SHIFT as f64) as f32
            }
        }))
    })
}

/// Mean colour of the umbrellas' view (its gaps shifted, [`gap_shift`]) minus the background's,
/// per channel, at the last zoom where umbrellas are drawn, over a fixed 128² window at the
/// origin (measured with seed 0 and memoised, [`calibrated`]): what the background is shifted
/// by further out.
pub(super) fn colour_shift(
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    src: &Source,
    cache: &Pyramid,
    zooms: u32,
) -> Result<[f32; 3]> {
    let gaps = gap_shift(arr, el, p, ident, src, cache)?;
    calibrated(&arr.caches().colours, arr, el, p, ident, |p, arr| {
        let view = View::out(zooms, crate::geom::Rect::new(0, 0, 128, 128));
        let level = lod::level(arr, zooms).unwrap_or(0);
        let raw = background(p, src, cache, view)?;
        let gapped = shifted(raw.clone(), gaps);
        let umb = paint(el, arr, p, view, level, || Ok(gapped))?;
        let mut shift = [0f32; 3];
        for (i, (a, b)) in umb.pixels.iter().zip(&raw.pixels).enumerate() {
            shift[i % 3] += *a as f32 - *b as f32;
        }
        let n = (umb.pixels.len() / 3).max(1) as f32;
        Ok(shift.map(|v| v / n))
    })
}

/// The background of a view: another mode's pixels (or the mean colour), at the view's zoom.
pub(super) fn background(p: &UmbrellaParams, src: &Source, cache: &Pyramid, view: View) -> Result<RgbWindow> {
    let ex = src.exemplar;
    Ok(match p.background {
        Background::Mosaic => {
            let mp = MosaicParams { seed: p.seed, period: p.period, ..MosaicParams::default() };
            mosaic::render_texels(src, cache, &mp, view.zoom_out, view.rect)?
        }
        Background::Synth => {
            let sp = SynthParams { seed: p.seed, period: p.period, ..SynthParams::default() };
            <Synth as Mode>::render(&sp, &(), src, cache, view)?.image
        }
        Background::Tiling => {
            let tp = TilingParams { seed: p.seed, period: p.period };
            <Tiling as Mode>::render(&tp, &(), src, cache, view)?.image
        }
        Background::Mean => {
            let (w, h) = (view.rect.width() as usize, view.rect.height() as usize);
            // Rounded half up, as the exact integer means were.
            let mean = match src.map {
                Some(map) => map.mean(),
                None => mean_colour(ex).map(|v| v.round() as u8),
            };
            RgbWindow { width: w as u32, height: h as u32, pixels: mean.repeat(w * h) }
        }
    })
}

/// The exemplar's mean colour, RGB in `[0, 255]` (exact sums).
pub(super) fn mean_colour(ex: &Exemplar) -> [f64; 3] {
    let n = ex.pixels.len().max(1) as u64;
    let mut s = [0u64; 3];
    for p in &ex.pixels {
        for k in 0..3 {
            s[k] += p[k] as u64;
        }
    }
    s.map(|v| v as f64 / n as f64)
}
