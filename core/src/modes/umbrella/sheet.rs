//! Inspection pictures of an extraction (`textile render --mode umbrella --debug-umbrellas`):
//! each base umbrella's crop magnified with its rim (red) and centre (yellow), and below it
//! modified umbrellas of that base — colour offsets and shape morphs — as the arrangement
//! places them (unrotated, unscaled).

use super::arrange::Arrangement;
use super::extract::{ray, Elements, RAYS};
use super::shape;
use crate::image::RgbWindow;

/// Magnification of the sheet.
const ZOOM: usize = 4;
/// Modified umbrellas shown per base.
const SHOWN: usize = 3;

/// The sheet: one column per base, the base on top, [`SHOWN`] modified umbrellas below.
pub fn debug_sheet(el: &Elements, arr: &Arrangement) -> RgbWindow {
    let cell = el.bases.iter().map(|b| b.w.max(b.h) as usize).max().unwrap_or(8) * ZOOM + 8;
    let (w, h) = (cell * el.bases.len().max(1), cell * (1 + SHOWN));
    let mut px = vec![40u8; 3 * w * h];
    let rays: [[f32; 2]; RAYS] = std::array::from_fn(ray);
    let angles = shape::ray_angles();
    let put = |px: &mut Vec<u8>, x: i64, y: i64, c: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h {
            let i = 3 * (y as usize * w + x as usize);
            px[i..i + 3].copy_from_slice(&c);
        }
    };
    for (b, base) in el.bases.iter().enumerate() {
        let (ox, oy) = ((b * cell + 4) as i64, 4i64);
        for y in 0..base.h as usize * ZOOM {
            for x in 0..base.w as usize * ZOOM {
                let t = base.texture[(y / ZOOM) * base.w as usize + x / ZOOM];
                let c = t.map(|v| (v * 255.0).round() as u8);
                put(&mut px, ox + x as i64, oy + y as i64, c);
            }
        }
        // Rim and centre.
        let vertex = |i: usize| {
            let d = rays[i % RAYS];
            (
                (base.centre[0] + d[0] * base.radii[i % RAYS]) * ZOOM as f32,
                (base.centre[1] + d[1] * base.radii[i % RAYS]) * ZOOM as f32,
            )
        };
        for i in 0..RAYS {
            let ((ax, ay), (bx, by)) = (vertex(i), vertex(i + 1));
            let steps = ((bx - ax).abs().max((by - ay).abs()).ceil() as usize).max(1);
            for s in 0..=steps {
                let t = s as f32 / steps as f32;
                put(&mut px, ox + (ax + (bx - ax) * t) as i64, oy + (ay + (by - ay) * t) as i64, [255, 40, 40]);
            }
        }
        let (cx, cy) = ((base.centre[0] * ZOOM as f32) as i64, (base.centre[1] * ZOOM as f32) as i64);
        for d in -2..=2 {
            put(&mut px, ox + cx + d, oy + cy, [255, 230, 0]);
            put(&mut px, ox + cx, oy + cy + d, [255, 230, 0]);
        }
        // Modified umbrellas of this base, centred in their cells.
        let modified: Vec<_> = arr.table.iter().filter(|m| m.base == b).take(SHOWN).collect();
        for (r, m) in modified.iter().enumerate() {
            let (oy, half) = (((r + 1) * cell) as i64, (cell / 2) as f32);
            for y in 0..cell - 2 {
                for x in 0..cell - 2 {
                    let (lx, ly) = ((x as f32 - half) / ZOOM as f32, (y as f32 - half) / ZOOM as f32);
                    if let Some(hit) = shape::locate(&angles, &rays, &m.radii, lx, ly) {
                        let c = shape::colour(base, &rays, &m.colour, hit, 1.0);
                        put(&mut px, (b * cell) as i64 + x as i64, oy + y as i64, c.map(|v| (v * 255.0).round() as u8));
                    }
                }
            }
        }
    }
    RgbWindow { width: w as u32, height: h as u32, pixels: px }
}
