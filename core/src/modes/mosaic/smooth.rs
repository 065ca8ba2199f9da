//! Native-scale mosaic pixels: the painted labels and texels, with block and tile edges smoothed
//! over up to three pixel layers by a 7×7 tent filter blended by the distance to the nearest
//! edge (Xu, Guo & Shum's edge smoothing).

use rayon::prelude::*;

use crate::exemplar::Exemplar;
use crate::geom::Rect;
use crate::image::RgbWindow;

use super::layout::Layout;
use super::paint::paint;

/// Rows per parallel piece of a native render, and pixels per piece of the colour lookup: a
/// tile (264 rows with its margin) splits in two, not sixteen. Under load every pool thread is
/// busy with its own tiles and finer pieces only cost splitting and stealing (mosaic pan
/// +7–10 % in alternating runs); a lone 256² window is as fast as with finer pieces (0.45 ms).
const PAR_ROWS: usize = 128;
const PAR_PIXELS: usize = 1 << 15;

pub(super) fn native(ex: &Exemplar, texels: &[[u8; 3]], layout: &Layout, rect: Rect) -> RgbWindow {
    let ew = layout.ew as usize;
    let s = layout.p.smoothing;
    // Labels and unsmoothed colours M0 on rect ⊕ 4 (edges on rect ⊕ 3 need 4-neighbours).
    let g = rect.grow(4);
    let pt = paint(layout, g, ex.toroidal, 1, 0);
    let gw = g.width() as usize;
    let m0: Vec<[u8; 3]> = pt
        .src
        .par_iter()
        .with_min_len(PAR_PIXELS)
        .map(|&v| texels[(v >> 16) as usize * ew + (v & 0xFFFF) as usize])
        .collect();
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let mut pixels = Vec::with_capacity(3 * w * h);
    if s == 0 {
        for j in 0..h {
            for c in &m0[(j + 4) * gw + 4..(j + 4) * gw + 4 + w] {
                pixels.extend_from_slice(c);
            }
        }
        return RgbWindow { width: w as u32, height: h as u32, pixels };
    }
    // Edge pixels (a 4-neighbour with another label) on e = rect ⊕ 3, and each pixel's
    // horizontal distance to the nearest edge pixel in its row (capped at 4).
    let (ew, eh) = (w + 6, h + 6);
    let mut hd = vec![4u8; ew * eh];
    hd.par_chunks_mut(ew).enumerate().with_min_len(PAR_ROWS).for_each(|(j, row)| {
        let mut last = 4u8;
        for (i, d) in row.iter_mut().enumerate() {
            let k = (j + 1) * gw + i + 1;
            let l = pt.label[k];
            let edge = pt.label[k - 1] != l || pt.label[k + 1] != l || pt.label[k - gw] != l || pt.label[k + gw] != l;
            last = if edge { 0 } else { (last + 1).min(4) };
            *d = last;
        }
        let mut last = 4u8;
        for d in row.iter_mut().rev() {
            last = if *d == 0 { 0 } else { (last + 1).min(4) };
            *d = (*d).min(last);
        }
    });
    // Horizontal tent (1,2,3,4,3,2,1) = two 4-wide boxes, as running sums, over e's rows and
    // rect's columns (at most 16 · 255 = 4 080: u16).
    let mut th = vec![[0u16; 3]; w * eh];
    th.par_chunks_mut(w).enumerate().with_min_len(PAR_ROWS).for_each_init(
        || vec![[0u32; 3]; w + 3],
        |bx, (j, out)| {
            let row = &m0[(j + 1) * gw + 1..(j + 1) * gw + 1 + ew];
            // bx[t] = row[t] + … + row[t+3], t = 0..w+3
            let mut acc = [0u32; 3];
            for p in &row[..4] {
                for c in 0..3 {
                    acc[c] += p[c] as u32;
                }
            }
            bx[0] = acc;
            for t in 1..w + 3 {
                for c in 0..3 {
                    acc[c] = acc[c] + row[t + 3][c] as u32 - row[t - 1][c] as u32;
                }
                bx[t] = acc;
            }
            let mut acc = [0u32; 3];
            for b in &bx[..4] {
                for c in 0..3 {
                    acc[c] += b[c];
                }
            }
            out[0] = acc.map(|v| v as u16);
            for i in 1..w {
                for c in 0..3 {
                    acc[c] = acc[c] + bx[i + 3][c] - bx[i - 1][c];
                }
                out[i] = acc.map(|v| v as u16);
            }
        },
    );
    const TENT: [u32; 7] = [1, 2, 3, 4, 3, 2, 1];
    pixels.resize(3 * w * h, 0);
    pixels.par_chunks_mut(3 * w).enumerate().with_min_len(PAR_ROWS).for_each_init(
        || vec![4u8; w],
        |dist, (j, out)| {
            // Chebyshev distance to the nearest edge pixel, from the row distances (dy outer
            // so the inner loop vectorises).
            dist.fill(4);
            for dy in 0..7usize {
                let ady = (dy as i32 - 3).unsigned_abs() as u8;
                let row = &hd[(j + dy) * ew + 3..(j + dy) * ew + 3 + w];
                for (d, &r) in dist.iter_mut().zip(row) {
                    *d = (*d).min(ady.max(r));
                }
            }
            let m0row = &m0[(j + 4) * gw + 4..(j + 4) * gw + 4 + w];
            for (i, (o, (&c0, &d))) in out.chunks_exact_mut(3).zip(m0row.iter().zip(dist.iter())).enumerate() {
                let d = d as u32;
                if d >= s {
                    o.copy_from_slice(&c0);
                    continue;
                }
                let mut t = [0u32; 3];
                for (k, &wt) in TENT.iter().enumerate() {
                    let r = th[(j + k) * w + i];
                    for (acc, v) in t.iter_mut().zip(r) {
                        *acc += wt * v as u32;
                    }
                }
                for ((o, c), &tc) in o.iter_mut().zip(&c0).zip(&t) {
                    let v = (*c as u32 * 256 * d + tc * (s - d) + 128 * s) / (256 * s);
                    *o = v.min(255) as u8;
                }
            }
        },
    );
    RgbWindow { width: w as u32, height: h as u32, pixels }
}
