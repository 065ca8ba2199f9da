//! The infinite arrangement (design note §5.2–5.3): a table of modified umbrellas (base,
//! variant, morph amount) drawn from the seed, and spawn cells of `G × G` texels that each place
//! a hash-drawn number of them (position, rotation, scale, depth); every cell's list holds, front
//! to back, the umbrellas that cover part of it (an exact polygon–square test) up to the `k`-th,
//! with those in front of it that may shade the cell, positions relative to the cell so that
//! far-away cells lose no precision. Lists are built a window at a time and kept in the
//! texture's caches ([`super::caches::Caches`]), shared by its requests.

use std::cell::OnceCell;
use std::sync::Arc;

use rayon::prelude::*;

use super::extract::{ray, Elements, RAYS};
pub use super::caches::Placed;
use super::caches::Caches;
use super::shape::{fold_free, Rim};
use super::UmbrellaParams;
use crate::hash::hash;
use crate::modes::params::ONE_Q16;
use crate::modes::Declared;

const TAG_TABLE: u64 = 0x554D_4252_0001;
const TAG_COUNT: u64 = 0x554D_4252_0002;
const TAG_PLACE: u64 = 0x554D_4252_0003;
const TAG_DEPTH: u64 = 0x554D_4252_0004;

/// Modified umbrellas in the table, per base.
pub const MODIFIED_PER_BASE: usize = 16;
/// Least and most of the plane umbrellas cover at density 100 %, whatever the exemplar's
/// foreground share.
pub const MIN_COVER: f64 = 0.3;
/// See [`MIN_COVER`].
pub const MAX_COVER: f64 = 0.9;
/// Most umbrellas one spawn cell places.
pub const MAX_PER_SPAWN: u64 = 48;

/// A modified umbrella (§5.2): a base with a variant's colour offsets and a morph towards its
/// shape.
#[derive(Debug, Clone, PartialEq)]
pub struct Modified {
    /// Base index.
    pub base: usize,
    /// Rim radii after the morph `V(t) = (1 − t)·V + t·V′` (fold-free).
    pub radii: [f32; RAYS],
    /// Colour offset per vertex, scaled by the colour strength.
    pub colour: [[f32; 3]; RAYS + 1],
    /// Largest radius.
    pub reach: f32,
    /// Smallest radius: a disc certainly inside (the rim's chords stay outside
    /// `min·cos(π/RAYS)`).
    pub inner: f32,
    /// The rim prepared for lookups.
    pub rim: Rim,
}


/// Everything needed to place umbrellas for one texture and parameter set.
pub struct Arrangement {
    /// Cell side `G` (texels, a power of two).
    pub g: i64,
    /// Mean umbrellas per spawn cell.
    pub mean_per_cell: f64,
    /// Modified umbrellas.
    pub table: Vec<Modified>,
    /// Scale range.
    pub scale: (f64, f64),
    /// Shadow offset (texels, along the diagonal).
    pub shadow_offset: f32,
    /// At most this many umbrellas per cell list.
    pub k: usize,
    /// Rotations are drawn within ± this (radians): the exemplar's orientation spread.
    pub spread: f64,
    /// Largest placed radius of any umbrella (texels).
    pub max_reach: f64,
    seed: u64,
    period_cells: Option<i64>,
    /// Identity of this arrangement in the caches.
    key: u64,
    /// Where its cell lists (and merged levels of detail) are kept.
    caches: Arc<Caches>,
    /// Spawn cells to look at around a cell.
    spawn_reach: i64,
    /// The rays' directions ([`ray`], computed once).
    pub rays: [[f32; 2]; RAYS],
    angles: [f32; RAYS],
}

impl Arrangement {
    /// The arrangement of `el` with parameters `p`; `ident` names the texture (its content
    /// hash). It keeps what it builds in caches of its own.
    pub fn new(el: &Elements, p: &UmbrellaParams, ident: &str) -> Arrangement {
        Self::cached(el, p, ident, Arc::new(Caches::default()))
    }

    /// [`Arrangement::new`], keeping what it builds in `caches` (a texture's, shared by its
    /// requests).
    pub fn cached(el: &Elements, p: &UmbrellaParams, ident: &str, caches: Arc<Caches>) -> Arrangement {
        let rays: [[f32; 2]; RAYS] = std::array::from_fn(ray);
        let shape = p.shape as f32 / ONE_Q16 as f32;
        let strength = p.colour as f32 / ONE_Q16 as f32;
        let mut table = Vec::new();
        for (b, base) in el.bases.iter().enumerate() {
            for j in 0..MODIFIED_PER_BASE {
                let z = hash(TAG_TABLE, p.seed, b as i64, j as i64, 0);
                let variant = &base.variants[(z % base.variants.len() as u64) as usize];
                let mut t = shape * ((z >> 32) & 0xFFFF) as f32 / 65535.0;
                let mut radii = base.radii;
                // Reduce the morph until no sector folds (radii along fixed rays never do, but
                // the check keeps the rule whatever the targets).
                for _ in 0..8 {
                    radii = std::array::from_fn(|i| (1.0 - t) * base.radii[i] + t * variant.radii[i]);
                    if fold_free(&rays, &radii) {
                        break;
                    }
                    t *= 0.5;
                }
                if !fold_free(&rays, &radii) {
                    radii = base.radii;
                }
                let colour = variant.colour.map(|c| c.map(|v| v * strength));
                let reach = radii.iter().copied().fold(0.0f32, f32::max);
                let inner = radii.iter().copied().fold(f32::MAX, f32::min) * (std::f32::consts::PI / RAYS as f32).cos();
                table.push(Modified { base: b, rim: Rim::new(&rays, &radii), radii, colour, reach, inner });
            }
        }
        let scale = (p.scale.0 as f64 / 1000.0, p.scale.1 as f64 / 1000.0);
        // The umbrellas' own area (a star polygon is smaller than its element when the
        // element is not star-shaped from its centre).
        let wedge = (std::f64::consts::TAU / RAYS as f64).sin() / 2.0;
        let poly_area = table
            .iter()
            .map(|m| (0..RAYS).map(|i| wedge * m.radii[i] as f64 * m.radii[(i + 1) % RAYS] as f64).sum::<f64>())
            .sum::<f64>()
            / table.len().max(1) as f64;
        let mean_r = (poly_area / std::f64::consts::PI).sqrt();
        // Cells about as wide as an element: then about `k` umbrellas meet a cell at density 1
        // (λ·(G + 2R)² with λ = 1.6 / πR² and G = 2R: 8), so truncating lists to `k` rarely
        // drops a visible one, and each lookup tests few.
        let g = (1u64 << ((2.0 * mean_r * scale.1).max(4.0).log2().floor() as u32)).clamp(4, 64) as i64;
        let mean_scale2 = (scale.0 * scale.0 + scale.0 * scale.1 + scale.1 * scale.1) / 3.0;
        // As many umbrellas as cover the exemplar's share of foreground at density 100 %
        // (§5.6 step 7): a Boolean model covers `1 − e^(−c)` of the plane when its shapes' areas
        // sum to `c` times it; the background shows through the rest, as the gaps between the
        // exemplar's elements do.
        let phi = el.foreground.clamp(MIN_COVER, MAX_COVER);
        let lambda = -(1.0 - phi).ln() / (poly_area.max(1.0) * mean_scale2);
        let mean_per_cell = (lambda * (g * g) as f64 * p.density as f64 / 100.0).min(MAX_PER_SPAWN as f64);
        let max_reach = table.iter().map(|m| m.reach).fold(0.0f32, f32::max) as f64 * scale.1;
        let shadow_offset = p.shadow_offset as f32;
        let spawn_reach = ((max_reach + 1.5 * shadow_offset as f64) / g as f64).ceil() as i64 + 1;
        let key = {
            let mut h = blake3::Hasher::new();
            h.update(ident.as_bytes());
            h.update(p.canonical().as_bytes());
            u64::from_le_bytes(h.finalize().as_bytes()[..8].try_into().unwrap_or_default())
        };
        Arrangement {
            g,
            mean_per_cell,
            table,
            scale,
            shadow_offset,
            k: p.k as usize,
            spread: (el.orientation_spread as f64).to_radians(),
            max_reach,
            seed: p.seed,
            period_cells: p.period.map(|n| (n / g).max(1)),
            key,
            caches,
            spawn_reach,
            rays,
            angles: super::shape::ray_angles(),
        }
    }

    /// The identity of this arrangement (texture and canonical parameters), which keys what is
    /// cached of it.
    pub fn key(&self) -> u64 {
        self.key
    }

    /// Where what is built of it is kept.
    pub fn caches(&self) -> &Caches {
        &self.caches
    }

    /// The same, shared.
    pub fn caches_arc(&self) -> Arc<Caches> {
        self.caches.clone()
    }

    /// The umbrellas spawn cell `(sx, sy)` places: centres `(x, y)` in 1/256 texels (absolute),
    /// and the umbrella (its centre not yet relative to a cell).
    pub fn spawn(&self, sx: i64, sy: i64) -> Vec<(i64, i64, Placed)> {
        let (hx, hy) = match self.period_cells {
            Some(n) => (sx.rem_euclid(n), sy.rem_euclid(n)),
            None => (sx, sy),
        };
        // Poisson count by inversion of a hashed uniform.
        let u = (hash(TAG_COUNT, self.seed, hx, hy, 0) >> 11) as f64 / (1u64 << 53) as f64;
        let (mut n, mut p, mut cdf) = (0u64, (-self.mean_per_cell).exp(), 0.0);
        cdf += p;
        while u > cdf && n < MAX_PER_SPAWN {
            n += 1;
            p *= self.mean_per_cell / n as f64;
            cdf += p;
        }
        let g256 = self.g * 256;
        (0..n as u32)
            .map(|i| {
                let z = hash(TAG_PLACE, self.seed, hx, hy, i as i64);
                let z2 = hash(TAG_PLACE, self.seed, hx, hy, i as i64 + (1 << 32));
                let px = sx * g256 + (z & 0xFFFF) as i64 * g256 / 65536;
                let py = sy * g256 + ((z >> 16) & 0xFFFF) as i64 * g256 / 65536;
                let angle = self.spread * (2.0 * ((z >> 32) & 0xFFFF) as f64 / 65536.0 - 1.0);
                let s = self.scale.0 + (self.scale.1 - self.scale.0) * ((z >> 48) & 0xFFFF) as f64 / 65535.0;
                let modified = (z2 % self.table.len() as u64) as u32;
                let reach = self.table[modified as usize].reach * s as f32;
                let inner = self.table[modified as usize].inner * s as f32 * 0.999;
                let depth = hash(TAG_DEPTH, self.seed, hx, hy, i as i64);
                let placed = Placed {
                    cx: 0.0,
                    cy: 0.0,
                    cos: angle.cos() as f32,
                    sin: angle.sin() as f32,
                    inv_scale: (1.0 / s) as f32,
                    reach,
                    reach2: reach * reach,
                    inner2: inner * inner,
                    modified,
                    depth,
                    id: (sx, sy, i),
                };
                (px, py, placed)
            })
            .collect()
    }

    /// The rim of umbrella `u` centred at `(x, y)` (texels): its vertices in absolute texels.
    pub fn rim(&self, u: &Placed, x: f64, y: f64) -> [(f64, f64); RAYS] {
        let m = &self.table[u.modified as usize];
        let s = 1.0 / u.inv_scale as f64;
        let (c, sn) = (u.cos as f64, u.sin as f64);
        std::array::from_fn(|i| {
            let d = self.rays[i];
            let (lx, ly) = (d[0] as f64 * m.radii[i] as f64 * s, d[1] as f64 * m.radii[i] as f64 * s);
            (x + c * lx - sn * ly, y + sn * lx + c * ly)
        })
    }

    /// Whether umbrella `u`, centred at `(x, y)`, covers part of the square of side `g` at
    /// `(x0, y0)`: its centre or a rim vertex ([`Arrangement::rim`]) inside the square, a rim
    /// edge crossing it, or the square inside the umbrella.
    pub fn meets(&self, u: &Placed, x: f64, y: f64, x0: f64, y0: f64, g: f64) -> bool {
        self.meets_with(u, x, y, x0, y0, g, &OnceCell::new())
    }

    /// The rim of `u` centred at `(x, y)` ([`Arrangement::rim`]) and its bounding box
    /// (`x0, x1, y0, y1`).
    fn rim_and_box(&self, u: &Placed, x: f64, y: f64) -> Outline {
        let rim = self.rim(u, x, y);
        let b = rim.iter().fold([f64::MAX, f64::MIN, f64::MAX, f64::MIN], |b, &(px, py)| {
            [b[0].min(px), b[1].max(px), b[2].min(py), b[3].max(py)]
        });
        (rim, b)
    }

    /// [`Arrangement::meets`], with `u`'s rim and its box computed at most once over the calls
    /// that share `rim`.
    #[allow(clippy::too_many_arguments)]
    fn meets_with(&self, u: &Placed, x: f64, y: f64, x0: f64, y0: f64, g: f64, rim: &OnceCell<Outline>) -> bool {
        // The discs first: the square's nearest point to the centre beyond the reach (with a
        // margin for rounding) → apart; within the inner disc, which the rim encloses → met.
        let (dx, dy) = (x - x.clamp(x0, x0 + g), y - y.clamp(y0, y0 + g));
        let d2 = dx * dx + dy * dy;
        let reach = u.reach as f64 * (1.0 + 1e-5) + 1e-6;
        if d2 > reach * reach {
            return false;
        }
        if d2 < u.inner2 as f64 {
            return true;
        }
        let (rim, b) = rim.get_or_init(|| self.rim_and_box(u, x, y));
        // The rim's box apart from the square: so are the centre, every vertex and edge, and
        // the square's centre (outside the rim by half a cell at least).
        if b[1] < x0 || b[0] > x0 + g || b[3] < y0 || b[2] > y0 + g {
            return false;
        }
        let inside_sq = |(px, py): (f64, f64)| px >= x0 && px <= x0 + g && py >= y0 && py <= y0 + g;
        if inside_sq((x, y)) || rim.iter().any(|&v| inside_sq(v)) {
            return true;
        }
        // A rim edge crossing the square: Liang–Barsky clipping of each edge.
        let crosses = |(ax, ay): (f64, f64), (bx, by): (f64, f64)| {
            // An edge whose box misses the square cannot cross it.
            if ax.max(bx) < x0 || ax.min(bx) > x0 + g || ay.max(by) < y0 || ay.min(by) > y0 + g {
                return false;
            }
            let (dx, dy) = (bx - ax, by - ay);
            let (mut t0, mut t1) = (0.0f64, 1.0f64);
            for (p, q) in [(-dx, ax - x0), (dx, x0 + g - ax), (-dy, ay - y0), (dy, y0 + g - ay)] {
                if p == 0.0 {
                    if q < 0.0 {
                        return false;
                    }
                } else {
                    let r = q / p;
                    if p < 0.0 {
                        t0 = t0.max(r);
                    } else {
                        t1 = t1.min(r);
                    }
                }
            }
            t0 <= t1
        };
        if (0..RAYS).any(|i| crosses(rim[i], rim[(i + 1) % RAYS])) {
            return true;
        }
        // No vertex in it and no edge across it: the square is either wholly inside the
        // umbrella or wholly outside; its centre says which.
        let m = &self.table[u.modified as usize];
        let (c, sn, inv) = (u.cos as f64, u.sin as f64, u.inv_scale as f64);
        let (qx, qy) = (x0 + g / 2.0 - x, y0 + g / 2.0 - y);
        let (lx, ly) = ((c * qx + sn * qy) * inv, (-sn * qx + c * qy) * inv);
        super::shape::locate(&self.angles, &self.rays, &m.radii, lx as f32, ly as f32).is_some()
    }

    /// The list of cell `(cx, cy)`: umbrellas whose disc, grown by the shadow offset, meets
    /// the cell, front to back (depth, then id), up to the `k`-th whose disc itself meets it
    /// (the design note truncates to `k` with the grown discs; then umbrellas that only shade
    /// a cell crowd out those that cover it, leaving holes — 88 % of points missed every
    /// umbrella with a 4-texel shadow offset on gravel's 8-texel cells).
    pub fn list(&self, cx: i64, cy: i64) -> Arc<Vec<Placed>> {
        self.lists(cx, cy, cx + 1, cy + 1).pop().unwrap_or_default()
    }

    /// The union of the lists of cells `(cx, list)` of one row (consecutive, at most 64, from
    /// frame `frame` on), front to back, each umbrella with the mask of the cells that list it
    /// (bit `cx − first cx`) and its position moved from its cell's origin to the frame's.
    /// Lists stop at their `k`-th covering umbrella, so an umbrella may be in one cell's list
    /// and not its neighbour's: filling the union masked so is filling each list in its cell.
    pub fn union<'a>(&self, cells: impl Iterator<Item = (i64, &'a [Placed])>, frame: i64) -> Vec<(Placed, u64)> {
        let mut items: Vec<(&Placed, i64)> = Vec::new();
        let mut first = None;
        for (cx, list) in cells {
            first.get_or_insert(cx);
            items.extend(list.iter().map(|u| (u, cx)));
        }
        items.sort_unstable_by(|(a, ca), (b, cb)| b.depth.cmp(&a.depth).then(a.id.cmp(&b.id)).then(ca.cmp(cb)));
        let first = first.unwrap_or(0);
        let mut union: Vec<(Placed, u64)> = Vec::new();
        for (u, cx) in items {
            let bit = 1u64 << (cx - first).clamp(0, 63);
            match union.last_mut() {
                Some((v, mask)) if v.id == u.id => *mask |= bit,
                _ => {
                    // Exact: multiples of 1/256 texel well within f32's precision.
                    let mut v = *u;
                    v.cx += ((cx - frame) * self.g) as f32;
                    union.push((v, bit));
                }
            }
        }
        union
    }

    /// The lists of cells `cx0..cx1 × cy0..cy1`, row by row: from the LRU where it has them,
    /// the others computed in bands of rows, in parallel — each band places the spawn cells
    /// around it once and bins their umbrellas into the cells they meet.
    pub fn lists(&self, cx0: i64, cy0: i64, cx1: i64, cy1: i64) -> Vec<Arc<Vec<Placed>>> {
        let (w, h) = ((cx1 - cx0).max(0) as usize, (cy1 - cy0).max(0) as usize);
        let mut out: Vec<Option<Arc<Vec<Placed>>>> = vec![None; w * h];
        for (n, slot) in out.iter_mut().enumerate() {
            *slot = self.caches.lists.get(&(self.key, cx0 + (n % w.max(1)) as i64, cy0 + (n / w.max(1)) as i64));
        }
        if out.iter().all(Option::is_some) {
            return out.into_iter().flatten().collect();
        }
        // Bands tall enough that placing the spawn cells around each (`spawn_reach` rows above
        // and below) adds little, and enough of them to share out.
        let band = h.div_ceil(2 * rayon::current_num_threads()).max(4 * self.spawn_reach as usize).max(1);
        let built: Vec<Vec<Arc<Vec<Placed>>>> = out
            .par_chunks(band * w.max(1))
            .enumerate()
            .map(|(b, have)| {
                let y0 = cy0 + (b * band) as i64;
                self.build(cx0, y0, cx1, y0 + (have.len() / w.max(1)) as i64, have)
            })
            .collect();
        out.into_iter()
            .zip(built.into_iter().flatten())
            .enumerate()
            .map(|(n, (have, new))| {
                have.unwrap_or_else(|| {
                    let bytes = (new.len() * std::mem::size_of::<Placed>()) as u64 + LIST_OVERHEAD;
                    self.caches.lists.put((self.key, cx0 + (n % w) as i64, cy0 + (n / w) as i64), new.clone(), bytes);
                    new
                })
            })
            .collect()
    }

    /// The lists of cells `cx0..cx1 × cy0..cy1` not in `have` (those are returned empty).
    fn build(&self, cx0: i64, cy0: i64, cx1: i64, cy1: i64, have: &[Option<Arc<Vec<Placed>>>]) -> Vec<Arc<Vec<Placed>>> {
        let (w, h) = ((cx1 - cx0).max(0) as usize, (cy1 - cy0).max(0) as usize);
        let g = self.g as f64;
        let grow = 1.5 * self.shadow_offset as f64;
        let mut bins: Vec<Vec<(Placed, bool)>> = vec![Vec::new(); w * h];
        for sy in cy0 - self.spawn_reach..cy1 + self.spawn_reach {
            for sx in cx0 - self.spawn_reach..cx1 + self.spawn_reach {
                for (px, py, u) in self.spawn(sx, sy) {
                    let (x, y) = (px as f64 / 256.0, py as f64 / 256.0);
                    let r = u.reach as f64 + grow;
                    let (ax0, ax1) = (((x - r) / g).floor() as i64, ((x + r) / g).floor() as i64);
                    let (ay0, ay1) = (((y - r) / g).floor() as i64, ((y + r) / g).floor() as i64);
                    let ur = u.reach as f64;
                    let (bx0, bx1) = (((x - ur) / g).floor() as i64, ((x + ur) / g).floor() as i64);
                    let (by0, by1) = (((y - ur) / g).floor() as i64, ((y + ur) / g).floor() as i64);
                    let rim = OnceCell::new();
                    for cy in ay0.max(cy0)..=ay1.min(cy1 - 1) {
                        for cx in ax0.max(cx0)..=ax1.min(cx1 - 1) {
                            let n = (cy - cy0) as usize * w + (cx - cx0) as usize;
                            if have[n].is_some() {
                                continue;
                            }
                            let g256 = self.g * 256;
                            let mut v = u;
                            v.cx = ((px - cx * g256) as f64 / 256.0) as f32;
                            v.cy = ((py - cy * g256) as f64 / 256.0) as f32;
                            let (x0, y0) = (cx as f64 * g, cy as f64 * g);
                            let covers = (bx0..=bx1).contains(&cx)
                                && (by0..=by1).contains(&cy)
                                && self.meets_with(&u, x, y, x0, y0, g, &rim);
                            // Or it may shade the cell: it covers part of the cell moved by −ℓ.
                            let l = self.shadow_offset as f64;
                            if covers || (l > 0.0 && self.meets_with(&u, x, y, x0 - l, y0 - l, g, &rim)) {
                                bins[n].push((v, covers));
                            }
                        }
                    }
                }
            }
        }
        bins.into_iter()
            .map(|mut bin| {
                bin.sort_by(|a, b| b.0.depth.cmp(&a.0.depth).then(a.0.id.cmp(&b.0.id)));
                // Up to the k-th umbrella that covers part of the cell; those in front of it
                // that only cast shadows into it stay too.
                let mut covering = 0;
                let end = bin
                    .iter()
                    .position(|(_, covers)| {
                        covering += *covers as usize;
                        covering == self.k
                    })
                    .map_or(bin.len(), |i| i + 1);
                Arc::new(bin[..end].iter().map(|(u, _)| *u).collect::<Vec<_>>())
            })
            .collect()
    }
}

/// Bytes charged for a cached list besides its umbrellas (key, slot, allocation).
const LIST_OVERHEAD: u64 = 96;

/// An umbrella's rim in absolute texels and its bounding box (`x0, x1, y0, y1`).
type Outline = ([(f64, f64); RAYS], [f64; 4]);
