//! From coordinates to colours (design note §1.4, §1.8): native windows copy exemplar texels;
//! zoomed-out windows average 2×2 blocks of the next finer level's stack colours (a faithful
//! reduced view: one zoom step out is exactly the 2×2 box average of the native pixels); beyond
//! the pyramid the view is the exemplar's mean colour.

use crate::analysis::Analysis;
use crate::error::Result;
use crate::geom::Rect;
use crate::params::SynthParams;
use crate::synth::{synthesis_cost, synthesize};

/// An RGB8 image of a window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbWindow {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB bytes (`3·width·height`).
    pub pixels: Vec<u8>,
}

impl RgbWindow {
    /// The pixel at `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }
}

/// Pixels [`render`] synthesizes at all levels for this view (for computation ratios).
pub fn render_cost(an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> u64 {
    let levels = an.levels();
    match zoom_out {
        0 => synthesis_cost(an, params, levels, rect),
        k if k <= levels => synthesis_cost(an, params, levels - k + 1, rect.children()),
        _ => 0,
    }
}

/// Render `rect` of the texture viewed `zoom_out` steps coarser than native (0 = native: one
/// pixel per exemplar texel; `k`: one pixel covers `2^k × 2^k` texels).
pub fn render(an: &Analysis, params: &SynthParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    let levels = an.levels();
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let m = an.side() as usize;
    let mut pixels = Vec::with_capacity(3 * w * h);
    if zoom_out == 0 {
        let cw = synthesize(an, params, levels, rect)?;
        for &v in &cw.coords {
            pixels.extend_from_slice(&an.exemplar[(v >> 16) as usize * m + (v & 0xFFFF) as usize]);
        }
    } else if zoom_out <= levels {
        let l = levels - zoom_out + 1;
        let cw = synthesize(an, params, l, rect.children())?;
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
        params.validate_for(an)?;
        let mean = an.mean_colour();
        for _ in 0..w * h {
            pixels.extend_from_slice(&mean);
        }
    }
    Ok(RgbWindow { width: w as u32, height: h as u32, pixels })
}
