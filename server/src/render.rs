//! From a validated request to pixels: tiles and windows mapped onto the core's `render` at the
//! right zoom-out (through the shared pyramidal cache), and `@2x` tiles (one zoom-out less at
//! twice the size; at native zoom, each texel shown as 2×2 pixels until magnification lands).
//! Every render reports the pixels it synthesized, for the computation ratio.

use textile_core::{mosaic, render_with, CoreError, Pyramid, Rect, Rendered, RgbWindow};

use crate::textures::Texture;
use crate::tile_request::{RenderParams, TileSpec, WindowSpec, TILE_SIZE};

/// Render `rect` viewed `zoom_out` steps coarser than native, with the request's engine.
pub fn view(pyr: &Pyramid, tex: &Texture, p: &RenderParams, zoom_out: u32, rect: Rect) -> Result<Rendered, CoreError> {
    match p {
        RenderParams::Synth(s) => render_with(pyr, &tex.analysis, s, zoom_out, rect),
        RenderParams::Mosaic(m) => Ok(Rendered {
            image: mosaic::render(&tex.analysis, m, zoom_out, rect)?,
            synthesized: mosaic::render_cost(zoom_out, rect),
        }),
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
pub fn render_tile(pyr: &Pyramid, tex: &Texture, p: &RenderParams, t: &TileSpec) -> Result<Rendered, CoreError> {
    let (k, rect, upscale) = tile_view(tex, t);
    let mut r = view(pyr, tex, p, k, rect)?;
    if upscale {
        r.image = upscale2(&r.image);
    }
    Ok(r)
}

/// Render a window.
pub fn render_window(pyr: &Pyramid, tex: &Texture, p: &RenderParams, w: &WindowSpec) -> Result<Rendered, CoreError> {
    view(pyr, tex, p, tex.native_zoom() - w.z, window_rect(w))
}

fn window_rect(w: &WindowSpec) -> Rect {
    Rect::new(w.x, w.y, w.w, w.h)
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
