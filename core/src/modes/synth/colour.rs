//! From coordinates to colours (design note §1.4, §1.8): native windows copy exemplar texels;
//! zoomed-out windows average 2×2 blocks of the next finer level's stack colours (a faithful
//! reduced view: one zoom step out is exactly the 2×2 box average of the native pixels); beyond
//! the pyramid the view is the exemplar's mean colour.

use crate::analysis::Analysis;
use crate::image::{Rendered, RgbWindow};
use crate::error::Result;
use crate::geom::Rect;
use super::params::SynthParams;
use crate::cache::Pyramid;
use super::window::synthesize_with;

/// Render `rect` of the texture viewed `zoom_out` steps coarser than native (0 = native: one
/// pixel per exemplar texel; `k`: one pixel covers `2^k × 2^k` texels).
pub fn render(an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    render_with(&Pyramid::off(), an, params, zoom_out, rect).map(|r| r.image)
}

/// [`render`] through a pyramidal cache (same pixels, shared work).
pub fn render_with(pyr: &Pyramid, an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<Rendered> {
    let levels = an.levels();
    let mut synthesized = 0;
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let m = an.side() as usize;
    let mut pixels = Vec::with_capacity(3 * w * h);
    if zoom_out == 0 {
        let sw = synthesize_with(pyr, an, params, levels, rect)?;
        synthesized = sw.synthesized;
        let cw = sw.window;
        for &v in &cw.coords {
            pixels.extend_from_slice(&an.exemplar[(v >> 16) as usize * m + (v & 0xFFFF) as usize]);
        }
    } else if zoom_out <= levels {
        let l = levels - zoom_out + 1;
        let sw = synthesize_with(pyr, an, params, l, rect.children())?;
        synthesized = sw.synthesized;
        let cw = sw.window;
        let stack = &an.stack[l as usize];
        let cwid = 2 * w;
        let at = |i: usize, j: usize| {
            let v = cw.coords[j * cwid + i];
            stack[(v >> 16) as usize * m + (v & 0xFFFF) as usize]
        };
        for j in 0..h {
            for i in 0..w {
                let q = [at(2 * i, 2 * j), at(2 * i + 1, 2 * j), at(2 * i, 2 * j + 1), at(2 * i + 1, 2 * j + 1)];
                for c in 0..3 {
                    let s: u32 = q.iter().map(|p| p[c] as u32).sum();
                    pixels.push(((s + 512) >> 10).min(255) as u8);
                }
            }
        }
    } else {
        params.validate(an.side())?;
        let mean = an.mean_colour();
        for _ in 0..w * h {
            pixels.extend_from_slice(&mean);
        }
    }
    Ok(Rendered { image: RgbWindow { width: w as u32, height: h as u32, pixels }, synthesized })
}
