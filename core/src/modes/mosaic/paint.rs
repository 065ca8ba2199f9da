//! Painting the layout: for every sample point of a window, which block (or background tile)
//! shows there and which exemplar texel it shows.

use rayon::prelude::*;

use crate::geom::Rect;

use super::layout::{Block, Layout};

/// Labels (which block or background tile shows) and source texels over a rect, on a grid of
/// sample points `step·(i, j) + offset`. Background labels have the top bit set and identify
/// the tiling tile (unique among neighbours); block labels are indices in priority order.
pub(super) struct Paint {
    pub label: Vec<u32>,
    pub src: Vec<u32>,
}

pub(super) fn paint(layout: &Layout, rect: Rect, toroidal: bool, step: i64, offset: i64) -> Paint {
    let (mut label, mut src) = background(layout, rect, toroidal, step, offset);
    let w = rect.width() as usize;
    for (id, b) in layout.blocks_meeting(grid_extent(rect, step, offset)).iter().enumerate() {
        let (i0, i1, j0, j1) = samples_in(b, rect, step, offset);
        for j in j0..j1 {
            let row = (j - rect.y0) as usize * w;
            for i in i0..i1 {
                let k = row + (i - rect.x0) as usize;
                label[k] = id as u32;
                src[k] = source(b, i, j, step, offset);
            }
        }
    }
    Paint { label, src }
}

/// Rows of samples per parallel band of [`sources`].
const SOURCES_BAND: i64 = 32;

/// [`paint`]'s source texels alone, for grids much sparser than the blocks (far zoom-outs):
/// each sample shows the block of highest priority covering it — what painting in ascending
/// priority leaves there — found by keeping each sample's best priority instead of sorting
/// the blocks (most of which cover one sample or none). The blocks are enumerated once for the
/// whole rect, by rows of super-tiles, and each band of sample rows, painted in parallel,
/// picks those crossing it from the rows that reach it (enumerating per band made each band's
/// super-tiles over again: 1.8× the blocks).
pub(super) fn sources(layout: &Layout, rect: Rect, toroidal: bool, step: i64, offset: i64) -> Vec<u32> {
    let rows = layout.block_rows_meeting(grid_extent(rect, step, offset));
    let w = rect.width() as usize;
    let mut src = vec![0u32; w * rect.height() as usize];
    src.par_chunks_mut(w * SOURCES_BAND as usize).enumerate().for_each(|(t, out)| {
        let y0 = rect.y0 + t as i64 * SOURCES_BAND;
        let band = Rect { y0, y1: rect.y1.min(y0 + SOURCES_BAND), ..rect };
        out.copy_from_slice(&background(layout, band, toroidal, step, offset).1);
        let extent = grid_extent(band, step, offset);
        // Each sample's best priority so far; below every block's (whose tiles' rows are far
        // above i64::MIN) where only the background shows.
        let mut top = vec![(0u64, i64::MIN, i64::MIN); out.len()];
        let near = rows.iter().filter(|row| row.y0 < extent.y1 && row.y1 > extent.y0);
        for b in near.flat_map(|row| &row.blocks).filter(|b| b.dy < extent.y1 && b.dy + b.h > extent.y0) {
            let (i0, i1, j0, j1) = samples_in(b, band, step, offset);
            for j in j0..j1 {
                let row = (j - band.y0) as usize * w;
                for i in i0..i1 {
                    let k = row + (i - band.x0) as usize;
                    if top[k] < b.prio {
                        top[k] = b.prio;
                        out[k] = source(b, i, j, step, offset);
                    }
                }
            }
        }
    });
    src
}

/// Labels and source texels of the background (the tiled exemplar) at every sample.
fn background(layout: &Layout, rect: Rect, toroidal: bool, step: i64, offset: i64) -> (Vec<u32>, Vec<u32>) {
    let (ew, eh) = (layout.ew, layout.eh);
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let mut label = vec![0u32; w * h];
    let mut src = vec![0u32; w * h];
    // Tile and texel within it along an axis of `n`-texel tiles.
    let split = |v: i64, n: i64| ((v.div_euclid(n) & 0x7FFF) as u32, v.rem_euclid(n) as u32);
    if layout.tiles_on_lattice() {
        for j in 0..h {
            let y = (rect.y0 + j as i64) * step + offset;
            for i in 0..w {
                let ((tx, ty), (sx, sy)) = layout.background(((rect.x0 + i as i64) * step + offset, y));
                label[j * w + i] = (1 << 31) | ((ty & 0x7FFF) as u32) << 15 | (tx & 0x7FFF) as u32;
                src[j * w + i] = (sy as u32) << 16 | sx as u32;
            }
        }
        return (label, src);
    }
    let cols: Vec<(u32, u32)> = (rect.x0..rect.x1).map(|i| split(i * step + offset, ew)).collect();
    for j in 0..h {
        let (ty, sy) = split((rect.y0 + j as i64) * step + offset, eh);
        let (ty, sy) = (ty << 15, sy << 16);
        let (lrow, srow) = (&mut label[j * w..(j + 1) * w], &mut src[j * w..(j + 1) * w]);
        for ((l, s), &(tx, sx)) in lrow.iter_mut().zip(srow.iter_mut()).zip(&cols) {
            *l = if toroidal { 1 << 31 } else { (1 << 31) | ty | tx };
            *s = sy | sx;
        }
    }
    (label, src)
}

/// Texel extent of the sample grid over `rect`.
fn grid_extent(rect: Rect, step: i64, offset: i64) -> Rect {
    Rect {
        x0: rect.x0 * step + offset,
        y0: rect.y0 * step + offset,
        x1: (rect.x1 - 1) * step + offset + 1,
        y1: (rect.y1 - 1) * step + offset + 1,
    }
}

/// The samples of `rect` inside block `b`: columns `i0..i1`, rows `j0..j1`. Sample `i` shows
/// texel `i·step + offset`: the first index at or after texel `d` is `⌈(d − offset)/step⌉`, and
/// one past the last before texel `e` is `⌊(e − 1 − offset)/step⌋ + 1` (power-of-two steps —
/// every zoom — by shifts: a division per block was a third of a far zoom-out's painting).
#[inline]
fn samples_in(b: &Block, rect: Rect, step: i64, offset: i64) -> (i64, i64, i64, i64) {
    let sh = step.trailing_zeros();
    let floor_div = |v: i64| if step == 1 << sh { v >> sh } else { v.div_euclid(step) };
    let first = |d: i64| -floor_div(offset - d);
    let end = |e: i64| floor_div(e - 1 - offset) + 1;
    (first(b.dx).max(rect.x0), end(b.dx + b.w).min(rect.x1), first(b.dy).max(rect.y0), end(b.dy + b.h).min(rect.y1))
}

/// The packed exemplar texel block `b` shows at sample `(i, j)`.
#[inline]
fn source(b: &Block, i: i64, j: i64, step: i64, offset: i64) -> u32 {
    ((b.sy + j * step + offset - b.dy) as u32) << 16 | (b.sx + i * step + offset - b.dx) as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modes::mosaic::MosaicParams;

    /// Keeping each sample's best priority gives what painting in priority order gives, on
    /// dense and sparse grids, toroidal or not, with and without a period.
    #[test]
    fn sources_equal_the_painted_sources() {
        for (seed, period) in [(0, None), (7, Some(512)), (3, Some(4096))] {
            let layout = Layout::new((128, 128), &MosaicParams { seed, period, ..MosaicParams::default() }, None);
            for (step, rect) in [
                (1, Rect::new(-300, 70, 96, 64)),
                (4, Rect::new(1000, -2000, 64, 48)),
                (32, Rect::new(-9, -13, 40, 40)),
                (128, Rect::new(5_000, 77, 33, 20)),
                (3, Rect::new(-50, -50, 30, 30)),
            ] {
                for toroidal in [false, true] {
                    let painted = paint(&layout, rect, toroidal, step, step / 2).src;
                    assert_eq!(sources(&layout, rect, toroidal, step, step / 2), painted, "{seed} {period:?} {step} {rect:?}");
                }
            }
        }
    }
}
