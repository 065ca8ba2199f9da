//! Magnification beyond native zoom (design note §1.8, after LH05 §5): at zoom `native + k` a
//! pixel is `1/2^k` of a texel. Synthesized coordinates are a patch parametrisation — each
//! texel says which exemplar point it copies — so a point between texel centres is sampled in
//! each of its four nearest texels' patches, extrapolated to the point, from a detail image
//! (the exemplar itself, or a higher-resolution version of it), and the four colours are
//! blended by the point's position between the centres. Inside a patch the four agree and the
//! detail image is copied; at patch seams the blend feathers. Modes without coordinates
//! magnify their native pixels bilinearly instead.
//!
//! Everything is integer arithmetic on absolute coordinates in units of `1/2^(k+1)` texel, so
//! a magnified window equals the same pixels cut from any other magnified window.

use crate::error::{CoreError, Result};
use crate::geom::Rect;
use crate::image::RgbWindow;
use crate::maps::{UvWindow, UV_SCALE};

/// Most magnification steps: zooms up to `native + MAX_ZOOM_IN` (the server serves one step
/// fewer, so that its `@2x` tiles at the highest zoom stay within it).
pub const MAX_ZOOM_IN: u32 = 4;

/// The image magnified texels are sampled from: the exemplar, or a version 2, 4 … times
/// larger of the same content (a higher-resolution photograph the exemplar was reduced from).
#[derive(Debug, Clone, Copy)]
pub struct Detail<'a> {
    /// Row-major RGB texels, `width × height`.
    pub pixels: &'a [[u8; 3]],
    /// Width: the exemplar's times 1, 2, 4 …
    pub width: u32,
    /// Height: the exemplar's times the same factor.
    pub height: u32,
    /// Wrap around the edges (toroidal exemplar) or clamp to them.
    pub toroidal: bool,
}

/// Check a magnification step count.
pub fn check_steps(k: u32) -> Result<()> {
    if (1..=MAX_ZOOM_IN).contains(&k) {
        Ok(())
    } else {
        Err(CoreError::Param {
            name: "zoom",
            message: format!("magnification must be 1 to {MAX_ZOOM_IN} steps, not {k}"),
        })
    }
}

/// The native-zoom texels a window magnified `k` steps reads: each pixel's two nearest texel
/// centres per axis.
pub fn source_rect(rect: Rect, k: u32) -> Rect {
    let s = 1i64 << k;
    let (x0, y0) = (rect.x0.div_euclid(s) - 1, rect.y0.div_euclid(s) - 1);
    let (x1, y1) = ((rect.x1 - 1).div_euclid(s) + 2, (rect.y1 - 1).div_euclid(s) + 2);
    Rect::new(x0, y0, x1 - x0, y1 - y0)
}

/// Per axis, for every output pixel of `[a, b)` at `k` steps: the native texel `q0` left of
/// the pixel's centre (absolute) and the centre's distance past `q0`'s centre, in `1/2^(k+1)`
/// texel (`0..2^(k+1)`); plus `2^(k+1)·Pt`, the centre's absolute position in those units.
fn axis(a: i64, b: i64, k: u32) -> Vec<(i64, i64, i64)> {
    let (s, two_s) = (1i64 << k, 2i64 << k);
    (a..b)
        .map(|x| {
            let t = 2 * x + 1 - s;
            let q0 = t.div_euclid(two_s);
            (q0, t - two_s * q0, 2 * x + 1)
        })
        .collect()
}

/// Magnify `rect` (pixels at zoom `native + k`) from synthesized coordinates: `coords` holds
/// the packed level-`L` coordinates (`x | y << 16`, exemplar width `m`) of
/// [`source_rect`]`(rect, k)`, row-major.
pub fn patches(coords: &[u32], m: u32, detail: Detail, k: u32, rect: Rect) -> RgbWindow {
    let src = source_rect(rect, k);
    let sw = src.width() as usize;
    let two_s = 2i64 << k;
    let r = (detail.width / m.max(1)).max(1) as i64;
    let (n, nh) = (detail.width as i64, detail.height as i64);
    let (ax, ay) = (axis(rect.x0, rect.x1, k), axis(rect.y0, rect.y1, k));
    // Detail texel index along an axis of `n` texels: wrapped or clamped.
    let index = |i: i64, n: i64| if detail.toroidal { i.rem_euclid(n) } else { i.clamp(0, n - 1) } as usize;
    // Bilinear sample of the detail image at `V / 2s` texels past the first texel centre.
    let sample = |vx: i64, vy: i64| -> [u32; 3] {
        let (ix, gx) = (vx.div_euclid(two_s), vx.rem_euclid(two_s));
        let (iy, gy) = (vy.div_euclid(two_s), vy.rem_euclid(two_s));
        let (x0, x1, y0, y1) = (index(ix, n), index(ix + 1, n), index(iy, nh), index(iy + 1, nh));
        let w = [(two_s - gx) * (two_s - gy), gx * (two_s - gy), (two_s - gx) * gy, gx * gy];
        let t = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
        let mut c = [0u32; 3];
        for (&(x, y), &w) in t.iter().zip(&w) {
            let p = detail.pixels[y * n as usize + x];
            for (c, &v) in c.iter_mut().zip(&p) {
                *c += w as u32 * v as u32;
            }
        }
        c
    };
    let shift = 4 * (k + 1);
    let mut pixels = Vec::with_capacity(3 * rect.area() as usize);
    for &(qy, fy, py) in &ay {
        for &(qx, fx, px) in &ax {
            let mut acc = [0u32; 3];
            for (b, wy) in [(0, two_s - fy), (1, fy)] {
                for (a, wx) in [(0, two_s - fx), (1, fx)] {
                    let w = (wx * wy) as u32;
                    if w == 0 {
                        continue;
                    }
                    let (q_x, q_y) = (qx + a, qy + b);
                    let v = coords[(q_y - src.y0) as usize * sw + (q_x - src.x0) as usize];
                    let (sx, sy) = ((v & 0xFFFF) as i64, (v >> 16) as i64);
                    // The point in q's patch, in 1/2s texel: 2s·(S[q] + Pt − q); scaled to the
                    // detail image and measured from its first texel centre.
                    let (ux, uy) = (two_s * sx + px - two_s * q_x, two_s * sy + py - two_s * q_y);
                    let c = sample(ux * r - two_s / 2, uy * r - two_s / 2);
                    for (a, v) in acc.iter_mut().zip(c) {
                        *a += w * v;
                    }
                }
            }
            pixels.extend(acc.map(|v| ((v + (1 << (shift - 1))) >> shift) as u8));
        }
    }
    RgbWindow { width: rect.width() as u32, height: rect.height() as u32, pixels }
}

/// The exemplar point each pixel of `rect` (zoom `native + k`) shows, for `map=uv`: the
/// pixel's centre in the patch of the texel it lies in (`coords` as for [`patches`]), in
/// `1/UV_SCALE` texel. Where neighbouring patches disagree [`patches`] blends them; this
/// names the one the pixel belongs to.
pub fn patch_points(coords: &[u32], (w, h): (u32, u32), k: u32, rect: Rect) -> UvWindow {
    let src = source_rect(rect, k);
    let sw = src.width() as usize;
    let unit = (UV_SCALE >> 1 >> k) as i64;
    let mut uv = Vec::with_capacity(rect.area() as usize);
    for y in rect.y0..rect.y1 {
        let qy = y >> k;
        let fy = 2 * y + 1 - ((2 * qy) << k);
        for x in rect.x0..rect.x1 {
            let qx = x >> k;
            let fx = 2 * x + 1 - ((2 * qx) << k);
            let v = coords[(qy - src.y0) as usize * sw + (qx - src.x0) as usize];
            let (sx, sy) = ((v & 0xFFFF) as i64, (v >> 16) as i64);
            let at =
                |s: i64, f: i64, m: u32| (s * UV_SCALE as i64 + f * unit).clamp(0, (m * UV_SCALE) as i64 - 1) as u16;
            uv.push([at(sx, fx, w), at(sy, fy, h)]);
        }
    }
    UvWindow { width: rect.width() as u32, height: rect.height() as u32, uv }
}

/// Magnify `rect` bilinearly from `native`, the native-zoom pixels of
/// [`source_rect`]`(rect, k)` (for modes without a patch parametrisation).
pub fn bilinear(native: &RgbWindow, k: u32, rect: Rect) -> RgbWindow {
    let src = source_rect(rect, k);
    let sw = native.width as usize;
    let two_s = 2i64 << k;
    let shift = 2 * (k + 1);
    let (ax, ay) = (axis(rect.x0, rect.x1, k), axis(rect.y0, rect.y1, k));
    let mut pixels = Vec::with_capacity(3 * rect.area() as usize);
    for &(qy, fy, _) in &ay {
        for &(qx, fx, _) in &ax {
            let mut acc = [0u32; 3];
            for (b, wy) in [(0, two_s - fy), (1, fy)] {
                for (a, wx) in [(0, two_s - fx), (1, fx)] {
                    let i = 3 * ((qy + b - src.y0) as usize * sw + (qx + a - src.x0) as usize);
                    for (a, &v) in acc.iter_mut().zip(&native.pixels[i..i + 3]) {
                        *a += (wx * wy) as u32 * v as u32;
                    }
                }
            }
            pixels.extend(acc.map(|v| ((v + (1 << (shift - 1))) >> shift) as u8));
        }
    }
    RgbWindow { width: rect.width() as u32, height: rect.height() as u32, pixels }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_source_rect_holds_every_pixels_two_nearest_centres() {
        for k in 1..=MAX_ZOOM_IN {
            for (x0, w) in [(0i64, 1i64), (-37, 100), (1 << 30, 513), (-5, 3)] {
                let rect = Rect::new(x0, x0, w, w);
                let src = source_rect(rect, k);
                for (q0, f, _) in axis(rect.x0, rect.x1, k) {
                    assert!(q0 >= src.x0 && q0 + 1 < src.x1, "k {k}, x0 {x0}: {q0} outside {src:?}");
                    assert!((0..2 << k).contains(&f));
                }
            }
        }
    }

    #[test]
    fn identity_coordinates_magnify_like_bilinear_interpolation_of_the_exemplar() {
        // A toroidal 8×8 exemplar, coordinates S[q] = q mod 8: every patch agrees, so the
        // result is the bilinear magnification of the tiled exemplar.
        let m = 8u32;
        let ex: Vec<[u8; 3]> =
            (0..64u32).map(|i| [(i * 37 % 251) as u8, (i * 11) as u8, (255 - i * 3) as u8]).collect();
        let detail = Detail { pixels: &ex, width: m, height: m, toroidal: true };
        for k in 1..=3 {
            let rect = Rect::new(-13, 5, 40, 24);
            let src = source_rect(rect, k);
            let coords: Vec<u32> = (src.y0..src.y1)
                .flat_map(|y| (src.x0..src.x1).map(move |x| x.rem_euclid(8) as u32 | (y.rem_euclid(8) as u32) << 16))
                .collect();
            let native: Vec<u8> = coords.iter().flat_map(|&v| ex[((v >> 16) * m + (v & 0xFFFF)) as usize]).collect();
            let native = RgbWindow { width: src.width() as u32, height: src.height() as u32, pixels: native };
            let a = patches(&coords, m, detail, k, rect);
            let b = bilinear(&native, k, rect);
            assert_eq!(a, b, "k = {k}");
        }
    }
}
