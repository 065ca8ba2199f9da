//! From a validated request to pixels: tiles and windows mapped onto the core's `render` at the
//! right zoom-out, and `@2x` tiles (one zoom-out less at twice the size; at native zoom, each
//! texel shown as 2×2 pixels until magnification lands).

use textile_core::{mosaic, render, CoreError, Rect, RgbWindow};

use crate::textures::Texture;
use crate::tile_request::{RenderParams, TileSpec, WindowSpec, TILE_SIZE};

/// Render `rect` viewed `zoom_out` steps coarser than native, with the request's engine.
pub fn view(tex: &Texture, p: &RenderParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow, CoreError> {
    match p {
        RenderParams::Synth(s) => render(&tex.analysis, s, zoom_out, rect),
        RenderParams::Mosaic(m) => mosaic::render(&tex.analysis, m, zoom_out, rect),
    }
}

/// Render a tile.
pub fn render_tile(tex: &Texture, p: &RenderParams, t: &TileSpec) -> Result<RgbWindow, CoreError> {
    let k = tex.native_zoom() - t.z;
    if t.scale == 1 {
        return view(tex, p, k, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE));
    }
    let big = 2 * TILE_SIZE;
    if k >= 1 {
        return view(tex, p, k - 1, Rect::new(big * t.x, big * t.y, big, big));
    }
    let img = view(tex, p, 0, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE))?;
    Ok(upscale2(&img))
}

/// Render a window.
pub fn render_window(tex: &Texture, p: &RenderParams, w: &WindowSpec) -> Result<RgbWindow, CoreError> {
    view(tex, p, tex.native_zoom() - w.z, Rect::new(w.x, w.y, w.w, w.h))
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
