//! From a validated request to pixels: tiles and windows mapped onto the core's `render` at the
//! right zoom-out, and `@2x` tiles (one zoom-out less at twice the size; at native zoom, each
//! texel shown as 2×2 pixels until magnification lands).

use textile_core::{render, CoreError, Rect, RgbWindow};

use crate::textures::Texture;
use crate::tile_request::{RenderParams, TileSpec, WindowSpec, TILE_SIZE};

/// Render a tile.
pub fn render_tile(tex: &Texture, p: &RenderParams, t: &TileSpec) -> Result<RgbWindow, CoreError> {
    let k = tex.native_zoom() - t.z;
    let an = &tex.analysis;
    if t.scale == 1 {
        return render(an, &p.synth, k, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE));
    }
    let big = 2 * TILE_SIZE;
    if k >= 1 {
        return render(an, &p.synth, k - 1, Rect::new(big * t.x, big * t.y, big, big));
    }
    let img = render(an, &p.synth, 0, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE))?;
    Ok(upscale2(&img))
}

/// Render a window.
pub fn render_window(tex: &Texture, p: &RenderParams, w: &WindowSpec) -> Result<RgbWindow, CoreError> {
    render(&tex.analysis, &p.synth, tex.native_zoom() - w.z, Rect::new(w.x, w.y, w.w, w.h))
}

fn upscale2(img: &RgbWindow) -> RgbWindow {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut px = Vec::with_capacity(12 * w * h);
    for j in 0..2 * h {
        for i in 0..2 * w {
            let s = 3 * ((j / 2) * w + i / 2);
            px.extend_from_slice(&img.pixels[s..s + 3]);
        }
    }
    RgbWindow { width: 2 * img.width, height: 2 * img.height, pixels: px }
}
