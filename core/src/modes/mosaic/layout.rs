//! Where blocks go (design note §4.2): each tile of the tiled exemplar contributes one block of
//! the exemplar, of hashed size and position, moved by the cat map inside its super-tile and
//! stacked by hashed priority. A pure function of absolute tile coordinates.

use crate::geom::Rect;
use crate::hash::hash;

use super::params::MosaicParams;

/// Domain tag of block geometry.
pub const TAG_MOSAIC_BLOCK: u64 = 0x4D4F_5341_4943_0001;
/// Domain tag of block priority.
pub const TAG_MOSAIC_PRIO: u64 = 0x4D4F_5341_4943_0002;
/// Tiles per super-tile side (the cat map's torus is `SUPER·n` texels).
pub const SUPER: i64 = 16;

/// One pasted block: source rect in the exemplar, absolute destination, priority.
#[derive(Debug, Clone, Copy)]
pub(super) struct Block {
    pub(super) sx: i64,
    pub(super) sy: i64,
    pub(super) w: i64,
    pub(super) h: i64,
    pub(super) dx: i64,
    pub(super) dy: i64,
    pub(super) prio: (u64, i64, i64),
}

/// Block geometry and placement for a plane of `n`-texel tiles.
pub(super) struct Layout {
    pub(super) n: i64,
    tiles: i64,    // tiles per super-tile side
    span: i64,     // texels per super-tile side
    cat: [u64; 4], // A^iterations mod span
    period_tiles: Option<i64>,
    pub(super) p: MosaicParams,
}

impl Layout {
    pub(super) fn new(n: i64, p: &MosaicParams) -> Layout {
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
    pub(super) fn blocks_meeting(&self, r: Rect) -> Vec<Block> {
        let mut out = self.blocks_meeting_unordered(r);
        // Priorities are distinct (they end with the block's tile), so an unstable sort gives
        // the one order there is.
        out.sort_unstable_by_key(|b| b.prio);
        out
    }

    /// Every block whose destination meets `r`, in no particular order.
    pub(super) fn blocks_meeting_unordered(&self, r: Rect) -> Vec<Block> {
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
        out
    }
}
