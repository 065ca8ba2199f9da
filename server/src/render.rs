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

/// The view a tile is rendered from: zoom-out, rectangle, and whether it is upscaled 2×
/// (`@2x` at native zoom).
fn tile_view(tex: &Texture, t: &TileSpec) -> (u32, Rect, bool) {
    let k = tex.native_zoom() - t.z;
    let big = 2 * TILE_SIZE;
    match (t.scale, k) {
        (1, _) => (k, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE), false),
        (_, k) if k >= 1 => (k - 1, Rect::new(big * t.x, big * t.y, big, big), false),
        _ => (0, Rect::new(TILE_SIZE * t.x, TILE_SIZE * t.y, TILE_SIZE, TILE_SIZE), true),
    }
}

/// Render a tile.
pub fn render_tile(tex: &Texture, p: &RenderParams, t: &TileSpec) -> Result<RgbWindow, CoreError> {
    let (k, rect, upscale) = tile_view(tex, t);
    let img = view(tex, p, k, rect)?;
    Ok(if upscale { upscale2(&img) } else { img })
}

/// Render a window.
pub fn render_window(tex: &Texture, p: &RenderParams, w: &WindowSpec) -> Result<RgbWindow, CoreError> {
    view(tex, p, tex.native_zoom() - w.z, window_rect(w))
}

fn window_rect(w: &WindowSpec) -> Rect {
    Rect::new(w.x, w.y, w.w, w.h)
}

/// Pixels synthesized (at all levels) and delivered by one render: the computation ratio's parts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cost {
    /// Pixels the engine computes, padding and coarser levels included.
    pub synthesized: u64,
    /// Pixels of the answer.
    pub delivered: u64,
}

fn view_cost(tex: &Texture, p: &RenderParams, k: u32, rect: Rect) -> u64 {
    match p {
        RenderParams::Synth(s) => textile_core::render_cost(&tex.analysis, s, k, rect),
        RenderParams::Mosaic(_) => mosaic::render_cost(k, rect),
    }
}

/// The cost of rendering a tile.
pub fn tile_cost(tex: &Texture, p: &RenderParams, t: &TileSpec) -> Cost {
    let (k, rect, _) = tile_view(tex, t);
    let side = (TILE_SIZE * t.scale as i64) as u64;
    Cost { synthesized: view_cost(tex, p, k, rect), delivered: side * side }
}

/// The cost of rendering a window.
pub fn window_cost(tex: &Texture, p: &RenderParams, w: &WindowSpec) -> Cost {
    Cost { synthesized: view_cost(tex, p, tex.native_zoom() - w.z, window_rect(w)), delivered: (w.w * w.h) as u64 }
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
