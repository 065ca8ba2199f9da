//! Where blocks go (design note §4.2): each tile of the tiled exemplar contributes one block of
//! the exemplar, of hashed size and position, moved by the cat map inside its super-tile and
//! stacked by hashed priority. A pure function of absolute tile coordinates.

use rayon::prelude::*;

use crate::geom::Rect;
use crate::hash::{hash_keyed, key};
use crate::lattice::{Lattice, LevelLattice};

use super::params::MosaicParams;

/// Domain tag of block geometry.
pub const TAG_MOSAIC_BLOCK: u64 = 0x4D4F_5341_4943_0001;
/// Domain tag of block priority.
pub const TAG_MOSAIC_PRIO: u64 = 0x4D4F_5341_4943_0002;
/// Tiles per super-tile side (without a period; the cat map's torus is `SUPER·n` texels for
/// an `n × n` exemplar).
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

/// Block geometry and placement for a plane of `w × h`-texel tiles.
///
/// The cat map is a map of a square torus; a super-tile of a non-square exemplar is not square
/// (`SUPER` tiles each way). Its blocks are moved on the square torus of side `q` (the
/// smallest power of two at least as long as the super-tile's longer side, so a power-of-two
/// square exemplar's torus is its super-tile, as in the paper), their positions scaled to it
/// and back along each axis.
pub(super) struct Layout {
    /// The exemplar's width and height: the tiles.
    pub(super) ew: i64,
    pub(super) eh: i64,
    tiles: (i64, i64), // tiles per super-tile across and down (powers of two)
    span: (i64, i64),  // texels per super-tile across and down
    q: i64,            // the cat map's torus side (a power of two)
    cat: [u64; 4],     // A^iterations mod q
    keys: [u64; 2], // hash keys of block geometry and priority
    period_tiles: Option<(i64, i64)>,
    /// The exemplar's lattice: block offsets are snapped to its translations.
    lattice: LevelLattice,
    /// Where the background's tiles lie when they are laid on lattice translations.
    tiles_on_lattice: Option<LatticeTiles>,
    pub(super) p: MosaicParams,
}

/// The background of a near-regular exemplar whose sides are not lattice translations (brick's
/// columns every 17.97 texels across 256): its tiles are laid on the lattice translations `lx`
/// and `ly` nearest the sides (at most the sides), so the phase runs on across every tile
/// border instead of jumping by the side's remainder. A point's tile is the cell of the
/// `lx, ly` lattice holding it; the few texels of a sheared cell that fall outside the exemplar
/// wrap by its sides.
#[derive(Debug, Clone, Copy)]
struct LatticeTiles {
    lx: (i64, i64),
    ly: (i64, i64),
    /// `[lx ly]⁻¹`, for a sheared cell's tile.
    inv: [[f64; 2]; 2],
}

impl LatticeTiles {
    /// The tiles for an `ew × eh` exemplar of lattice `l`; `None` where the sides are lattice
    /// translations already (the plain tiling keeps the phase) or no translation near a side
    /// fits in it.
    fn new(l: &LevelLattice, ew: i64, eh: i64) -> Option<LatticeTiles> {
        // A side that is a translation (a free axis of stripes, or a whole number of cells)
        // stays; another is the translation nearest the side less half the longest period.
        let side = |v: (i64, i64), less: (i64, i64)| if l.translation(v) == v { v } else { l.translation(less) };
        let (lx, ly) = (side((ew, 0), (ew - l.reach, 0)), side((0, eh), (0, eh - l.reach)));
        if (lx, ly) == ((ew, 0), (0, eh)) {
            return None;
        }
        let fits = |(x, y): (i64, i64), along: i64, across: i64| x > along / 2 && x <= along && y.abs() < across / 4;
        let det = (lx.0 * ly.1 - lx.1 * ly.0) as f64;
        if !fits(lx, ew, eh) || !fits((ly.1, ly.0), eh, ew) || det <= 0.0 {
            return None;
        }
        let inv = [[ly.1 as f64 / det, -ly.0 as f64 / det], [-lx.1 as f64 / det, lx.0 as f64 / det]];
        Some(LatticeTiles { lx, ly, inv })
    }

    /// The tile holding texel `d` (its indices `a, b`: origin `a·lx + b·ly`) and `d`'s offset
    /// from its origin, not yet wrapped into the exemplar.
    #[inline]
    fn locate(&self, d: (i64, i64)) -> ((i64, i64), (i64, i64)) {
        let (a, b) = if self.lx.1 == 0 && self.ly.0 == 0 {
            (d.0.div_euclid(self.lx.0), d.1.div_euclid(self.ly.1))
        } else {
            let (x, y) = (d.0 as f64, d.1 as f64);
            (
                (self.inv[0][0] * x + self.inv[0][1] * y).floor() as i64,
                (self.inv[1][0] * x + self.inv[1][1] * y).floor() as i64,
            )
        };
        ((a, b), (d.0 - a * self.lx.0 - b * self.ly.0, d.1 - a * self.lx.1 - b * self.ly.1))
    }
}

impl Layout {
    pub(super) fn new((ew, eh): (i64, i64), p: &MosaicParams, lattice: Option<&Lattice>) -> Layout {
        // A period is a multiple of both sides (checked: `MosaicParams::validate`).
        let period_tiles = p.period.map(|per| (per / ew, per / eh));
        let tiles = period_tiles.map_or((SUPER, SUPER), |(tx, ty)| (tx.min(SUPER), ty.min(SUPER)));
        let span = (tiles.0 * ew, tiles.1 * eh);
        let q = (span.0.max(span.1) as u64).next_power_of_two() as i64;
        let mask = q as u64 - 1;
        let mut cat = [1u64, 0, 0, 1];
        for _ in 0..p.iterations {
            // cat · [[1,1],[1,2]]
            let [a, b, c, d] = cat;
            cat = [(a + b) & mask, (a + 2 * b) & mask, (c + d) & mask, (c + 2 * d) & mask];
        }
        let keys = [key(TAG_MOSAIC_BLOCK, p.seed), key(TAG_MOSAIC_PRIO, p.seed)];
        let lattice = lattice.map_or(LevelLattice::FREE, Lattice::whole);
        // A periodic world keeps the plain tiling, which its period repeats.
        let tiles_on_lattice = match (lattice.is_free(), period_tiles) {
            (false, None) => LatticeTiles::new(&lattice, ew, eh),
            _ => None,
        };
        Layout { ew, eh, tiles, span, q, cat, keys, period_tiles, lattice, tiles_on_lattice, p: p.clone() }
    }

    /// Whether the background's tiles lie on lattice translations rather than at the sides.
    pub(super) fn tiles_on_lattice(&self) -> bool {
        self.tiles_on_lattice.is_some()
    }

    /// The background at texel `d`: its tile's indices and the exemplar texel it shows, not
    /// yet wrapped into the exemplar (in phase with `d`'s neighbours on the lattice).
    #[inline]
    fn background_unwrapped(&self, d: (i64, i64)) -> ((i64, i64), (i64, i64)) {
        match &self.tiles_on_lattice {
            Some(t) => t.locate(d),
            None => ((d.0.div_euclid(self.ew), d.1.div_euclid(self.eh)), (d.0.rem_euclid(self.ew), d.1.rem_euclid(self.eh))),
        }
    }

    /// The background at texel `d`: its tile's indices and the exemplar texel it shows.
    #[inline]
    pub(super) fn background(&self, d: (i64, i64)) -> ((i64, i64), (i64, i64)) {
        let (tile, (x, y)) = self.background_unwrapped(d);
        (tile, (x.rem_euclid(self.ew), y.rem_euclid(self.eh)))
    }

    /// The block of tile `(a1, a2)` of super-tile `(s1, s2)`: absolute tile
    /// `(s1·tiles + a1, s2·tiles + a2)` (the reference for [`Layout::super_tile`]).
    #[cfg(test)]
    fn block(&self, s1: i64, s2: i64, a1: i64, a2: i64) -> Block {
        let (z, prio) = self.hashes(s1, s2, a1, a2);
        self.place(s1, s2, a1, a2, z, prio, self.sides(z))
    }

    /// The geometry and priority hashes of a tile.
    #[inline]
    fn hashes(&self, s1: i64, s2: i64, a1: i64, a2: i64) -> (u64, u64) {
        let (k1, k2) = (s1 * self.tiles.0 + a1, s2 * self.tiles.1 + a2);
        let (h1, h2) = match self.period_tiles {
            Some((tx, ty)) => (k1.rem_euclid(tx), k2.rem_euclid(ty)),
            None => (k1, k2),
        };
        (hash_keyed(self.keys[0], h1, h2, 0), hash_keyed(self.keys[1], h1, h2, 0))
    }

    /// Width and height of the block whose geometry hash is `z`.
    #[inline]
    fn sides(&self, z: u64) -> (i64, i64) {
        let (ew, eh) = (self.ew, self.eh);
        // Integers below 2^48 convert to f64 exactly, and from i64 in one instruction.
        let rho = self.p.block_area.0 as f64
            + ((((z & 0xFFFF) * (self.p.block_area.1 - self.p.block_area.0) as u64) >> 16) as i64) as f64;
        let rho = rho / 1000.0;
        // Aspect in [2/3, 3/2], symmetric in log scale (α and 1/α equally likely).
        let u = (((z >> 16) & 0xFFFF) as i64) as f64 / 32768.0 - 1.0;
        let alpha = if u >= 0.0 { 1.0 + 0.5 * u } else { 1.0 / (1.0 - 0.5 * u) };
        let w = round(ew as f64 * (rho * alpha).sqrt()).clamp(1, ew);
        let h = round(eh as f64 * (rho / alpha).sqrt()).clamp(1, eh);
        (w, h)
    }

    /// The block of tile `(a1, a2)` of super-tile `(s1, s2)` from its hashes and sides: source
    /// position, and destination moved by the cat map inside the super-tile.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn place(&self, s1: i64, s2: i64, a1: i64, a2: i64, z: u64, prio: u64, (w, h): (i64, i64)) -> Block {
        let (ew, eh) = (self.ew, self.eh);
        let sx = (((z >> 32) & 0xFFFF) as i64 * (ew - w + 1)) >> 16;
        let sy = (((z >> 48) & 0xFFFF) as i64 * (eh - h + 1)) >> 16;
        // The source in the super-tile, on the cat map's torus.
        let (span_x, span_y, q) = (self.span.0, self.span.1, self.q);
        let to_q = |v: i64, span: i64| if span == q { v } else { v * q / span };
        let from_q = |v: i64, span: i64| if span == q { v } else { v * span / q };
        let (x0, y0) = (to_q(sx + a1 * ew, span_x) as u64, to_q(sy + a2 * eh, span_y) as u64);
        let mask = q as u64 - 1;
        let [a, b, c, d] = self.cat;
        let s = (a.wrapping_mul(x0).wrapping_add(b.wrapping_mul(y0))) & mask;
        let t = (c.wrapping_mul(x0).wrapping_add(d.wrapping_mul(y0))) & mask;
        let (k1, k2) = (s1 * self.tiles.0 + a1, s2 * self.tiles.1 + a2);
        let (mut dx, mut dy) = (s1 * span_x + from_q(s as i64, span_x), s2 * span_y + from_q(t as i64, span_y));
        if !self.lattice.is_free() {
            // A near-regular exemplar's block moves to the nearest place where the background
            // shows texels of its source's phase, so rows and gaps continue across its border
            // (the background repeats with the world's period: a periodic world stays periodic).
            let (mx, my) = self.lattice.snap(self.background_unwrapped((dx, dy)).1, (sx, sy));
            (dx, dy) = (dx + mx, dy + my);
        }
        Block { sx, sy, w, h, dx, dy, prio: (prio, k2, k1) }
    }

    /// The blocks of super-tile `(s1, s2)` that meet `r`, appended to `out`. Hashes, sides and
    /// placement are separate passes over the super-tile's tiles: one block's chain of
    /// divisions and square roots is longer than the processor's window, so computed one
    /// block at a time they ran back to back (43 ns a block); in passes they overlap. No
    /// coordinate is divided (tiles across is a power of two).
    fn super_tile(&self, s1: i64, s2: i64, r: Rect, out: &mut Vec<Block>) {
        let (t, count) = (self.tiles.0, (self.tiles.0 * self.tiles.1) as usize);
        let (shift, mask) = (t.trailing_zeros(), t - 1);
        let tile = |a: usize| (a as i64 & mask, a as i64 >> shift);
        let mut hashes = [(0u64, 0u64); (SUPER * SUPER) as usize];
        for (a, hs) in hashes[..count].iter_mut().enumerate() {
            let (a1, a2) = tile(a);
            *hs = self.hashes(s1, s2, a1, a2);
        }
        let mut sides = [(0i64, 0i64); (SUPER * SUPER) as usize];
        for (sd, &(z, _)) in sides[..count].iter_mut().zip(&hashes[..count]) {
            *sd = self.sides(z);
        }
        for (a, (&(z, prio), &sd)) in hashes[..count].iter().zip(&sides[..count]).enumerate() {
            let (a1, a2) = tile(a);
            let b = self.place(s1, s2, a1, a2, z, prio, sd);
            if b.dx < r.x1 && b.dx + b.w > r.x0 && b.dy < r.y1 && b.dy + b.h > r.y0 {
                out.push(b);
            }
        }
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
        self.block_rows_meeting(r).into_iter().flat_map(|row| row.blocks).collect()
    }

    /// Every block whose destination meets `r`, by rows of super-tiles, rows in parallel (a
    /// far zoom-out meets 9 rows of 9 super-tiles: 20 000 blocks). A caller painting bands
    /// of rows reads only the rows whose blocks reach its band.
    pub(super) fn block_rows_meeting(&self, r: Rect) -> Vec<BlockRow> {
        // A block lies within its super-tile or spills at most n−1 texels right/down, and a
        // lattice's snap moves it at most `reach` texels either way.
        let reach = self.lattice.reach;
        let lo = |v: i64, n: i64, span: i64| (v - n - reach).div_euclid(span);
        let hi = |v: i64, span: i64| (v - 1 + reach).div_euclid(span);
        let (s1s, s2s) = (
            lo(r.x0, self.ew, self.span.0)..=hi(r.x1, self.span.0),
            lo(r.y0, self.eh, self.span.1)..=hi(r.y1, self.span.1),
        );
        s2s.into_par_iter()
            .map(|s2| {
                let mut blocks = Vec::with_capacity(s1s.clone().count() * (self.tiles.0 * self.tiles.1) as usize);
                for s1 in s1s.clone() {
                    self.super_tile(s1, s2, r, &mut blocks);
                }
                let y0 = blocks.iter().map(|b| b.dy).min().unwrap_or(0);
                let y1 = blocks.iter().map(|b| b.dy + b.h).max().unwrap_or(0);
                BlockRow { y0, y1, blocks }
            })
            .collect()
    }
}

/// The blocks of one row of super-tiles meeting a rect, and the texel rows `y0..y1` their
/// destinations span.
pub(super) struct BlockRow {
    pub(super) y0: i64,
    pub(super) y1: i64,
    pub(super) blocks: Vec<Block>,
}

/// `x.round()` for `0 ≤ x < 2^52`, without the libm call the baseline x86-64 target makes of
/// it (7 % of a far zoom-out): truncation and the fraction are exact there.
#[inline]
fn round(x: f64) -> i64 {
    let t = x as i64;
    t + (x - t as f64 >= 0.5) as i64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::modes::mosaic::MosaicParams;

    /// A super-tile's passes give the blocks [`Layout::block`] gives one at a time, with and
    /// without a period (fewer tiles per super-tile).
    #[test]
    fn super_tile_passes_equal_single_blocks() {
        for period in [None, Some(512), Some(1 << 20)] {
            let l = Layout::new((128, 128), &MosaicParams { seed: 3, period, ..MosaicParams::default() }, None);
            for (s1, s2) in [(0, 0), (-3, 7), (1 << 30, -(1 << 29))] {
                let mut out = Vec::new();
                l.super_tile(s1, s2, Rect::new(i64::MIN / 4, i64::MIN / 4, i64::MAX / 2, i64::MAX / 2), &mut out);
                assert_eq!(out.len() as i64, l.tiles.0 * l.tiles.1);
                for (a, b) in out.iter().enumerate() {
                    let r = l.block(s1, s2, a as i64 % l.tiles.0, a as i64 / l.tiles.0);
                    assert_eq!((b.sx, b.sy, b.w, b.h, b.dx, b.dy, b.prio), (r.sx, r.sy, r.w, r.h, r.dx, r.dy, r.prio));
                }
            }
        }
    }

    /// A near-regular exemplar whose side is no multiple of its period (stripes every 17.97
    /// texels across 256, and a bond 61.3 × 28.4 at half a brick's stagger): across every
    /// border of the background's tiles the texels shown keep their lattice phase within half a
    /// texel, where the plain tiling jumps by the side's remainder (4.4 texels for the stripes).
    #[test]
    fn background_tiles_keep_the_phase_across_their_borders() {
        use crate::lattice::Wave;
        // The bond's translations (61.3, 0) and (30.65, 28.4): courses, and the wave whose
        // vector (1/61.3, −0.5/28.4) is whole on both.
        let (kx, ky): (f64, f64) = (1.0 / 61.3, -0.5 / 28.4);
        let bond = [Wave::new(28.4, 90.0), Wave::new(1.0 / kx.hypot(ky), ky.atan2(kx).to_degrees())];
        for waves in [vec![Wave::new(17.97, 0.0)], bond.to_vec()] {
            let lattice = Lattice::given(waves, 256).unwrap();
            let l = Layout::new((256, 256), &MosaicParams::default(), Some(&lattice));
            assert!(l.tiles_on_lattice());
            let whole = lattice.whole();
            let off_phase = |d: (i64, i64)| {
                let (m, n) = whole.snap(d, (0, 0));
                m.abs().max(n.abs())
            };
            let mut borders = 0;
            for y in (-3000..3000).step_by(37) {
                for x in -3000..3000 {
                    let (ta, a) = l.background((x, y));
                    let (tb, b) = l.background((x + 1, y));
                    if ta != tb {
                        borders += 1;
                        assert!(off_phase((b.0 - a.0 - 1, b.1 - a.1)) <= 1, "{x},{y}: {a:?} → {b:?}");
                    }
                }
            }
            assert!(borders > 1000, "{borders}");
        }
    }

    #[test]
    fn round_is_f64_round_on_block_sides() {
        let mut x = 0.0f64;
        while x < 600.0 {
            for v in [x, x + 0.5, f64::from_bits((x + 0.5).to_bits() - 1), f64::from_bits((x + 0.5).to_bits() + 1)] {
                assert_eq!(round(v), v.round() as i64, "{v}");
            }
            x += 0.25;
        }
    }
}
