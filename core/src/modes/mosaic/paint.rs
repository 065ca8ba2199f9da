//! Painting the layout: for every sample point of a window, which block (or background tile)
//! shows there and which exemplar texel it shows.

use crate::geom::Rect;

use super::layout::Layout;

/// Labels (which block or background tile shows) and source texels over a rect, on a grid of
/// sample points `step·(i, j) + offset`. Background labels have the top bit set and identify
/// the tiling tile (unique among neighbours); block labels are indices in priority order.
pub(super) struct Paint {
    pub label: Vec<u32>,
    pub src: Vec<u32>,
}

pub(super) fn paint(layout: &Layout, rect: Rect, toroidal: bool, step: i64, offset: i64) -> Paint {
    let n = layout.n;
    let (shift, mask) = (n.trailing_zeros(), n - 1);
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let mut label = vec![0u32; w * h];
    let mut src = vec![0u32; w * h];
    let cols: Vec<(u32, u32)> = (rect.x0..rect.x1)
        .map(|i| {
            let x = i * step + offset;
            (((x >> shift) & 0x7FFF) as u32, (x & mask) as u32)
        })
        .collect();
    for j in 0..h {
        let y = (rect.y0 + j as i64) * step + offset;
        let (ty, sy) = ((((y >> shift) & 0x7FFF) as u32) << 15, ((y & mask) as u32) << 16);
        let (lrow, srow) = (&mut label[j * w..(j + 1) * w], &mut src[j * w..(j + 1) * w]);
        for ((l, s), &(tx, sx)) in lrow.iter_mut().zip(srow.iter_mut()).zip(&cols) {
            *l = if toroidal { 1 << 31 } else { (1 << 31) | ty | tx };
            *s = sy | sx;
        }
    }
    // Texel extent of the sample grid.
    let tex = Rect {
        x0: rect.x0 * step + offset,
        y0: rect.y0 * step + offset,
        x1: (rect.x1 - 1) * step + offset + 1,
        y1: (rect.y1 - 1) * step + offset + 1,
    };
    for (id, b) in layout.blocks_meeting(tex).iter().enumerate() {
        // Sample i shows texel i·step + offset: the first index at or after texel d, and one
        // past the last index before texel e.
        let first = |d: i64| (d - offset).div_euclid(step) + i64::from((d - offset).rem_euclid(step) != 0);
        let end = |e: i64| (e - 1 - offset).div_euclid(step) + 1;
        let (i0, i1) = (first(b.dx).max(rect.x0), end(b.dx + b.w).min(rect.x1));
        let (j0, j1) = (first(b.dy).max(rect.y0), end(b.dy + b.h).min(rect.y1));
        for j in j0..j1 {
            let sy = ((b.sy + j * step + offset - b.dy) as u32) << 16;
            let row = (j - rect.y0) as usize * w;
            for i in i0..i1 {
                let k = row + (i - rect.x0) as usize;
                label[k] = id as u32;
                src[k] = sy | (b.sx + i * step + offset - b.dx) as u32;
            }
        }
    }
    Paint { label, src }
}
