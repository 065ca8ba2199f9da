//! Chaos mosaic (Xu, Guo & Shum; design note §4): the cheap mode. The exemplar is tiled; every
//! tile contributes one block of the exemplar (area between the paper's bounds) moved by the cat
//! map inside its super-tile and pasted over the tiling, higher priority on top; block and tile
//! edges are smoothed over three pixel layers. Everything is a function of absolute
//! coordinates, so any window equals the same pixels cut from any larger one.

use rayon::prelude::*;

use crate::analysis::Analysis;
use crate::error::{CoreError, Result};
use crate::geom::Rect;
use crate::hash::hash;
use crate::params::MAX_PERIOD;
use crate::render::RgbWindow;

/// Domain tag of block geometry.
pub const TAG_MOSAIC_BLOCK: u64 = 0x4D4F_5341_4943_0001;
/// Domain tag of block priority.
pub const TAG_MOSAIC_PRIO: u64 = 0x4D4F_5341_4943_0002;
/// Tiles per super-tile side (the cat map's torus is `SUPER·n` texels).
pub const SUPER: i64 = 16;
/// Largest number of cat-map iterations accepted.
pub const MAX_ITERATIONS: u32 = 64;
/// Smoothing layers at most (the tent filter is 7×7).
pub const MAX_SMOOTHING: u32 = 3;
/// Largest native window, in pixels, one call may evaluate (2^26).
pub const MAX_PIXELS: i64 = 1 << 26;

/// Validated mosaic parameters.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct MosaicParams {
    /// Selects another arrangement of blocks.
    pub seed: u64,
    /// Cat-map iterations (0 = blocks stay in place: the plain tiling).
    pub iterations: u32,
    /// Smallest block area, per mille of the exemplar area.
    pub area_min: u32,
    /// Largest block area, per mille of the exemplar area.
    pub area_max: u32,
    /// Pixel layers smoothed on each side of block and tile edges (0–3).
    pub smoothing: u32,
    /// Optional period in texels (power of two ≥ the exemplar side): a mosaic on a torus.
    pub period: Option<i64>,
}

impl Default for MosaicParams {
    fn default() -> Self {
        MosaicParams { seed: 0, iterations: 10, area_min: 500, area_max: 750, smoothing: 3, period: None }
    }
}

impl MosaicParams {
    /// Check ranges against an analysis.
    pub fn validate_for(&self, an: &Analysis) -> Result<()> {
        let bad = |name, message: String| Err(CoreError::Param { name, message });
        if self.iterations > MAX_ITERATIONS {
            return bad("iterations", format!("{} is outside 0..={MAX_ITERATIONS}", self.iterations));
        }
        if !(50..=1000).contains(&self.area_min) || !(self.area_min..=1000).contains(&self.area_max) {
            return bad(
                "block_area",
                format!(
                    "{},{} must be two fractions of the exemplar area with 0.05 <= min <= max <= 1",
                    self.area_min as f64 / 1000.0,
                    self.area_max as f64 / 1000.0
                ),
            );
        }
        if self.smoothing > MAX_SMOOTHING {
            return bad("smoothing", format!("{} is outside 0..={MAX_SMOOTHING}", self.smoothing));
        }
        if let Some(p) = self.period {
            let n = an.side() as i64;
            if p < n || p > MAX_PERIOD || p.count_ones() != 1 {
                return bad("period", format!("must be a power of two from {n} (the exemplar side) to 2^40 texels"));
            }
        }
        Ok(())
    }

    /// Canonical text form for cache keys and ETags.
    pub fn canonical(&self) -> String {
        format!(
            "seed={};it={};area={},{};smooth={};period={}",
            self.seed,
            self.iterations,
            self.area_min,
            self.area_max,
            self.smoothing,
            self.period.map(|p| p.to_string()).unwrap_or_else(|| "none".into())
        )
    }
}

/// One pasted block: source rect in the exemplar, absolute destination, priority.
#[derive(Debug, Clone, Copy)]
struct Block {
    sx: i64,
    sy: i64,
    w: i64,
    h: i64,
    dx: i64,
    dy: i64,
    prio: (u64, i64, i64),
}

/// Block geometry and placement for a plane of `n`-texel tiles.
struct Layout {
    n: i64,
    tiles: i64,    // tiles per super-tile side
    span: i64,     // texels per super-tile side
    cat: [u64; 4], // A^iterations mod span
    period_tiles: Option<i64>,
    p: MosaicParams,
}

impl Layout {
    fn new(n: i64, p: &MosaicParams) -> Layout {
        let period_tiles = p.period.map(|per| per / n);
        let tiles = period_tiles.map_or(SUPER, |t| t.min(SUPER));
        let span = tiles * n;
        let mask = span as u64 - 1;
        let mut cat = [1u64, 0, 0, 1];
        for _ in 0..p.iterations {
            // cat · [[1,1],[1,2]]
            let [a, b, c, d] = cat;
            cat = [(a + b) & mask, (a + 2 * b) & mask, (c + d) & mask, (c + 2 * d) & mask];
        }
        Layout { n, tiles, span, cat, period_tiles, p: p.clone() }
    }

    /// The block of absolute tile `(k1, k2)`.
    fn block(&self, k1: i64, k2: i64) -> Block {
        let (h1, h2) = match self.period_tiles {
            Some(t) => (k1.rem_euclid(t), k2.rem_euclid(t)),
            None => (k1, k2),
        };
        let z = hash(TAG_MOSAIC_BLOCK, self.p.seed, h1, h2, 0);
        let n = self.n;
        let rho = self.p.area_min as f64 + (((z & 0xFFFF) * (self.p.area_max - self.p.area_min) as u64) >> 16) as f64;
        let rho = rho / 1000.0;
        // Aspect in [2/3, 3/2], symmetric in log scale (α and 1/α equally likely).
        let u = ((z >> 16) & 0xFFFF) as f64 / 32768.0 - 1.0;
        let alpha = if u >= 0.0 { 1.0 + 0.5 * u } else { 1.0 / (1.0 - 0.5 * u) };
        let w = ((n as f64 * (rho * alpha).sqrt()).round() as i64).clamp(1, n);
        let h = ((n as f64 * (rho / alpha).sqrt()).round() as i64).clamp(1, n);
        let sx = (((z >> 32) & 0xFFFF) as i64 * (n - w + 1)) >> 16;
        let sy = (((z >> 48) & 0xFFFF) as i64 * (n - h + 1)) >> 16;
        let (s1, s2) = (k1.div_euclid(self.tiles), k2.div_euclid(self.tiles));
        let (a1, a2) = (k1.rem_euclid(self.tiles), k2.rem_euclid(self.tiles));
        let (x0, y0) = ((sx + a1 * n) as u64, (sy + a2 * n) as u64);
        let mask = self.span as u64 - 1;
        let [a, b, c, d] = self.cat;
        let s = (a.wrapping_mul(x0).wrapping_add(b.wrapping_mul(y0))) & mask;
        let t = (c.wrapping_mul(x0).wrapping_add(d.wrapping_mul(y0))) & mask;
        let prio = hash(TAG_MOSAIC_PRIO, self.p.seed, h1, h2, 0);
        Block { sx, sy, w, h, dx: s1 * self.span + s as i64, dy: s2 * self.span + t as i64, prio: (prio, k2, k1) }
    }

    /// Every block whose destination meets `r`, in ascending priority.
    fn blocks_meeting(&self, r: Rect) -> Vec<Block> {
        // A block lies within its super-tile or spills at most n−1 texels right/down.
        let lo = |v: i64| (v - self.n).div_euclid(self.span);
        let hi = |v: i64| (v - 1).div_euclid(self.span);
        let mut out = Vec::new();
        for s2 in lo(r.y0)..=hi(r.y1) {
            for s1 in lo(r.x0)..=hi(r.x1) {
                for a2 in 0..self.tiles {
                    for a1 in 0..self.tiles {
                        let b = self.block(s1 * self.tiles + a1, s2 * self.tiles + a2);
                        if b.dx < r.x1 && b.dx + b.w > r.x0 && b.dy < r.y1 && b.dy + b.h > r.y0 {
                            out.push(b);
                        }
                    }
                }
            }
        }
        out.sort_by_key(|b| b.prio);
        out
    }
}

/// Labels (which block or background tile shows) and source texels over a rect, on a grid of
/// sample points `step·(i, j) + offset`. Background labels have the top bit set and identify
/// the tiling tile (unique among neighbours); block labels are indices in priority order.
struct Paint {
    label: Vec<u32>,
    src: Vec<u32>,
}

fn paint(layout: &Layout, rect: Rect, toroidal: bool, step: i64, offset: i64) -> Paint {
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

/// Texels [`render`] evaluates for this view (with the smoothing margin), for computation ratios.
pub fn render_cost(zoom_out: u32, rect: Rect) -> u64 {
    match zoom_out {
        0 => rect.grow(4).area() as u64,
        k if k <= 3 => {
            let f = 1i64 << k;
            Rect { x0: rect.x0 * f, y0: rect.y0 * f, x1: rect.x1 * f, y1: rect.y1 * f }.grow(4).area() as u64
        }
        _ => rect.area() as u64,
    }
}

/// Render `rect` of the mosaic viewed `zoom_out` steps coarser than native.
pub fn render(an: &Analysis, p: &MosaicParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    p.validate_for(an)?;
    let scale = 1i64.checked_shl(zoom_out.min(62)).unwrap_or(i64::MAX);
    if rect.is_empty() || rect.area() > MAX_PIXELS || (zoom_out <= 3 && rect.area() * scale * scale > MAX_PIXELS) {
        return Err(CoreError::Window {
            width: rect.width(),
            height: rect.height(),
            message: format!("must be non-empty with at most {MAX_PIXELS} pixels at native scale"),
        });
    }
    let layout = Layout::new(an.side() as i64, p);
    if zoom_out == 0 {
        return Ok(native(an, &layout, rect));
    }
    if zoom_out <= 3 {
        // Exact: the box average of the native pixels.
        let big = native(
            an,
            &layout,
            Rect { x0: rect.x0 * scale, y0: rect.y0 * scale, x1: rect.x1 * scale, y1: rect.y1 * scale },
        );
        return Ok(box_down(&big, scale as usize));
    }
    Ok(sampled(an, &layout, zoom_out, rect))
}

/// Rows per parallel piece of a native render, and pixels per piece of the colour lookup: a
/// tile (264 rows with its margin) splits in two, not sixteen. Under load every pool thread is
/// busy with its own tiles and finer pieces only cost splitting and stealing (mosaic pan
/// +7–10 % in alternating runs); a lone 256² window is as fast as with finer pieces (0.45 ms).
const PAR_ROWS: usize = 128;
const PAR_PIXELS: usize = 1 << 15;

fn native(an: &Analysis, layout: &Layout, rect: Rect) -> RgbWindow {
    let n = layout.n as usize;
    let s = layout.p.smoothing;
    // Labels and unsmoothed colours M0 on rect ⊕ 4 (edges on rect ⊕ 3 need 4-neighbours).
    let g = rect.grow(4);
    let pt = paint(layout, g, an.header.toroidal, 1, 0);
    let gw = g.width() as usize;
    let m0: Vec<[u8; 3]> = pt
        .src
        .par_iter()
        .with_min_len(PAR_PIXELS)
        .map(|&v| an.exemplar[(v >> 16) as usize * n + (v & 0xFFFF) as usize])
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

fn box_down(img: &RgbWindow, f: usize) -> RgbWindow {
    let (w, h) = (img.width as usize / f, img.height as usize / f);
    let iw = img.width as usize;
    let area = (f * f) as u32;
    let mut pixels = Vec::with_capacity(3 * w * h);
    for j in 0..h {
        for i in 0..w {
            let mut s = [0u32; 3];
            for y in j * f..(j + 1) * f {
                let row = &img.pixels[3 * (y * iw + i * f)..3 * (y * iw + (i + 1) * f)];
                for px in row.chunks_exact(3) {
                    for (acc, &v) in s.iter_mut().zip(px) {
                        *acc += v as u32;
                    }
                }
            }
            pixels.extend(s.map(|v| ((v + area / 2) / area) as u8));
        }
    }
    RgbWindow { width: w as u32, height: h as u32, pixels }
}

/// Far zoom-out (`2^k` texels per pixel, k > 3): label each pixel by its centre texel and colour
/// it from the box-filtered exemplar at that scale (the mean colour once a pixel covers the
/// whole exemplar). Approximate, like the paper's reduced-scale rendering.
fn sampled(an: &Analysis, layout: &Layout, k: u32, rect: Rect) -> RgbWindow {
    let n = layout.n as usize;
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let lvl = k.min(an.levels()) as usize;
    let side = n >> lvl;
    let mip = box_mip(&an.exemplar, n, lvl);
    let mut pixels = Vec::with_capacity(3 * w * h);
    let step = 1i64 << k.min(40);
    let pt = paint(layout, rect, an.header.toroidal, step, step / 2);
    for v in &pt.src {
        let (x, y) = ((v & 0xFFFF) as usize >> lvl, (v >> 16) as usize >> lvl);
        pixels.extend_from_slice(&mip[y.min(side - 1) * side + x.min(side - 1)]);
    }
    RgbWindow { width: w as u32, height: h as u32, pixels }
}

/// The exemplar box-filtered `lvl` times (side `n >> lvl`).
fn box_mip(px: &[[u8; 3]], n: usize, lvl: usize) -> Vec<[u8; 3]> {
    let full = RgbWindow { width: n as u32, height: n as u32, pixels: px.iter().flatten().copied().collect() };
    box_down(&full, 1 << lvl).pixels.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}
