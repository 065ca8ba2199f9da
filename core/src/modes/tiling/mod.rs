//! `mode=tiling`: the exemplar repeated, as it is — the reference every synthesis is compared
//! with (quality tables, "better-looking than tiling"). Native pixels are exemplar texels at
//! `(x mod w, y mod h)`: the tiling repeats at the exemplar's own width and height. A
//! zoomed-out pixel is the exact box average of the `2^k × 2^k` texels it covers: a box on
//! the exemplar's torus (for a power-of-two square, its box mip; the mean once a pixel covers
//! a whole period). Needs only the exemplar; seed and world change nothing (a world's period
//! is a multiple of a power-of-two exemplar's; any other exemplar repeats at its own size).

use crate::cache::Pyramid;
use crate::error::Result;
use crate::image::{Integral, Rendered, RgbWindow};
use crate::maps::{UvWindow, UV_SCALE};
use crate::modes::params::check_period;
use crate::modes::{check_window, Cost, Mode, Needs, Source, View};

/// Largest window, in pixels, one call may render (2^26).
pub const MAX_PIXELS: i64 = 1 << 26;

/// The tiling mode.
pub struct Tiling;

crate::declare_params! {
    /// Tiling parameters: only the common ones, kept so that requests stay canonical; neither
    /// changes the pixels, so neither is part of the canonical text.
    pub struct TilingParams {
        /// Accepted like every mode's; the tiling does not depend on it.
        pub seed: u64 { default: 0, canonical: none, seed }
        /// Accepted like every mode's; the tiling repeats at the exemplar's own size.
        pub period: Option<i64> { default: None, canonical: none, period }
    }
    check(p, src) { check_period(p.period, src.exemplar.size().longer()) }
}

impl Mode for Tiling {
    const NAME: &'static str = "tiling";
    const VERSION: u32 = 1;
    const SUMMARY: &'static str = "the exemplar repeated as it is: the reference that synthesis improves on";
    const NEEDS: Needs = Needs::Exemplar;
    const COST: Cost = Cost::Light;
    const HAS_UV: bool = true;
    type Params = TilingParams;
    type State = ();

    fn render(_: &TilingParams, _: &(), src: &Source, _: &Pyramid, view: View) -> Result<Rendered> {
        let rect = view.rect;
        check_window(rect, MAX_PIXELS)?;
        let texels = src.texels();
        let (ew, eh) = src.dims();
        let lvl = view.zoom_out.min(src.levels());
        let (w, h) = (rect.width() as usize, rect.height() as usize);
        let mut pixels = Vec::with_capacity(3 * w * h);
        if lvl == 0 {
            for y in rect.y0..rect.y1 {
                let row = y.rem_euclid(eh as i64) as usize * ew;
                for x in rect.x0..rect.x1 {
                    pixels.extend_from_slice(&texels[row + x.rem_euclid(ew as i64) as usize]);
                }
            }
        } else {
            // Pixel `x` covers texels `[x·f, (x + 1)·f)` of the tiled plane: the box centred on
            // `x·f + f/2`, on the exemplar's torus.
            let f = 1i64 << lvl;
            let sums = Integral::new(texels, (ew, eh), f as usize);
            let centre = |v: i64, n: usize| (v * f + f / 2).rem_euclid(n as i64) as usize;
            let xs: Vec<usize> = (rect.x0..rect.x1).map(|x| centre(x, ew)).collect();
            for y in rect.y0..rect.y1 {
                let cy = centre(y, eh);
                for &cx in &xs {
                    pixels.extend_from_slice(&sums.mean_around(cx, cy));
                }
            }
        }
        let image = RgbWindow { width: w as u32, height: h as u32, pixels };
        Ok(Rendered { image, synthesized: rect.area() as u64 })
    }

    /// Native and magnified: the pixel centre's place in the exemplar; zoomed out, the centre
    /// of the block it averages (the exemplar's centre once it covers the whole exemplar).
    fn coordinates(_: &TilingParams, _: &(), src: &Source, _: &Pyramid, view: View) -> Result<UvWindow> {
        let rect = view.rect;
        check_window(rect, MAX_PIXELS)?;
        let (ew, eh) = src.dims();
        let lvl = view.zoom_out.min(src.levels());
        // A pixel's centre along an axis of `n` texels, in 1/UV_SCALE texel, on the exemplar.
        let at = |x: i64, n: usize| -> u16 {
            let period = (n as u32 * UV_SCALE) as i64;
            let c = if view.zoom_in > 0 {
                ((2 * x + 1) * (UV_SCALE as i64 / 2)) >> view.zoom_in
            } else if lvl < src.levels() {
                ((2 * x + 1) * (UV_SCALE as i64 / 2)) << lvl
            } else {
                period / 2
            };
            c.rem_euclid(period) as u16
        };
        let xs: Vec<u16> = (rect.x0..rect.x1).map(|x| at(x, ew)).collect();
        let uv = (rect.y0..rect.y1).flat_map(|y| xs.iter().map(move |&u| [u, at(y, eh)])).collect();
        Ok(UvWindow { width: rect.width() as u32, height: rect.height() as u32, uv })
    }
}
