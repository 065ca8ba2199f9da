//! From coordinates to colours (design note §1.4, §1.8): native windows copy exemplar texels;
//! a window `k` steps out is synthesis level `L − k` one pixel per pixel — the texture's mipmap,
//! as Lefebvre & Hoppe note, at the cost of a native window — each pixel the exact box mean of
//! the `2^k × 2^k` exemplar block its coordinate's descendants cover when the finer levels keep
//! coherence (where their correction moves texels, close to the box filter of the native
//! pixels, not equal; `core/tests/zoom_consistency.rs` bounds it); beyond the pyramid the view
//! is the exemplar's mean colour.

use crate::analysis::Analysis;
use crate::maps::{UvWindow, MaterialMap, UV_SCALE};
use crate::image::{Rendered, RgbWindow};
use crate::error::Result;
use crate::geom::Rect;
use super::params::SynthParams;
use crate::cache::Pyramid;
use super::seams;
use super::window::synthesize_with;

/// Render `rect` of the texture viewed `zoom_out` steps coarser than native (0 = native: one
/// pixel per exemplar texel; `k`: one pixel covers `2^k × 2^k` texels).
pub fn render(an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    render_with(&Pyramid::off(), an, params, zoom_out, rect).map(|r| r.image)
}

/// [`render`] through a pyramidal cache (same pixels, shared work).
pub fn render_with(pyr: &Pyramid, an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<Rendered> {
    render_map(pyr, an, None, params, zoom_out, rect)
}

/// [`render_with`] showing material `map` (none: the colour) at the same coordinates.
pub fn render_map(
    pyr: &Pyramid,
    an: &Analysis,
    map: Option<&MaterialMap>,
    params: &SynthParams,
    zoom_out: u32,
    rect: Rect,
) -> Result<Rendered> {
    let levels = an.levels();
    let mut synthesized = 0;
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let (ew, eh) = an.dims();
    let mut pixels = Vec::with_capacity(3 * w * h);
    if zoom_out == 0 {
        // The window grown by the blend's reach, blended back to `rect` (super::seams).
        let sw = synthesize_with(pyr, an, params, levels, rect.grow(seams::RADIUS as i64))?;
        synthesized = sw.synthesized;
        let toroidal = an.header.toroidal;
        let style = seams::Style::of(an.fine_detail());
        let map_low;
        let (texels, low) = match map {
            None => (&an.exemplar[..], an.colours8(levels.saturating_sub(style.low_steps))),
            Some(mp) => {
                map_low = mp.low_pass(pyr, toroidal, style.low_steps);
                (&mp.texels[..], &map_low[0][..])
            }
        };
        seams::blend(&sw.window.coords, (w, h), &seams::Texels { texels, low, dims: (ew, eh), toroidal }, style.fade, &mut pixels);
    } else if zoom_out <= levels {
        // Level `L − k`, one pixel per pixel: coherent upsampling would give each of them the
        // `2^k × 2^k` exemplar block centred on its coordinate at the finest level, so it shows
        // that block's mean (exact wherever finer levels keep coherence; close where their
        // jitter or correction moved texels).
        let sw = synthesize_with(pyr, an, params, levels - zoom_out, rect)?;
        synthesized = sw.synthesized;
        let stack = map.map_or_else(|| an.box_stack(pyr), |m| m.box_stack(pyr));
        let boxes = &stack[zoom_out as usize];
        for &v in &sw.window.coords {
            pixels.extend_from_slice(&boxes[(v >> 16) as usize * ew + (v & 0xFFFF) as usize]);
        }
    } else {
        params.validate(an.dims())?;
        let mean = map.map_or_else(|| an.mean_colour(), MaterialMap::mean);
        for _ in 0..w * h {
            pixels.extend_from_slice(&mean);
        }
    }
    Ok(Rendered { image: RgbWindow { width: w as u32, height: h as u32, pixels }, synthesized })
}

/// The exemplar point each pixel of `rect` shows, `zoom_out` steps coarser than native (see
/// [`crate::maps::UV_SCALE`]): a native pixel's texel centre; zoomed out, the centre of the
/// block whose mean it shows; beyond the pyramid, the exemplar's centre.
pub fn coordinates(pyr: &Pyramid, an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<UvWindow> {
    let levels = an.levels();
    let (w, h) = (rect.width() as u32, rect.height() as u32);
    let s = UV_SCALE;
    let uv = if zoom_out <= levels {
        let sw = synthesize_with(pyr, an, params, levels - zoom_out, rect)?;
        // Native: the texel's centre; zoomed out: the centred block's centre, a texel corner.
        let half = if zoom_out == 0 { s / 2 } else { 0 };
        sw.window.coords.iter().map(|&v| [(v & 0xFFFF) * s + half, (v >> 16) * s + half].map(|c| c as u16)).collect()
    } else {
        params.validate(an.dims())?;
        let centre = [an.width() * s / 2, an.height() * s / 2].map(|c| c as u16);
        vec![centre; (w * h) as usize]
    };
    Ok(UvWindow { width: w, height: h, uv })
}
