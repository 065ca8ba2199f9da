//! Merged levels of detail (design note §5.5). Level `j ≥ 1` has cells of `2^j·G` texels; a
//! cell's umbrellas — those its `2^j × 2^j` spawn cells place — are clustered by deterministic
//! k-means on their centres into at most `k`; each cluster becomes one *merged* umbrella —
//! centre the mean of its members', rim the convex hull of their rims simplified to
//! [`MERGED_VERTICES`] by deleting the flattest vertex and shrunk to the area its members are
//! expected to cover (the hull grows a cluster over the gaps between its members, the note's
//! stated limit; shrunk, a merged level keeps the share of gaps and so the mean colour and
//! contrast of what it summarises), depth the front-most member's — coloured
//! only at its centre and vertices, by sampling its members along each spoke. A cluster of one
//! stays the umbrella it is (its rim, its mipmapped base texture). Merged cells are memoised.
//! A zoom draws the level whose cells are about [`LOD_PIXELS`] pixels wide: tile zooms are
//! powers of two, so each falls exactly on one level and there is nothing to blend between
//! two. Everything is computed from absolute positions in a fixed order, so a cell is the same
//! whichever window asks for it.
//!
//! Deviation from the note: it builds level `j + 1` from level `j`'s merged umbrellas; here
//! every level clusters the level-0 umbrellas directly. Building the levels between would cost
//! as much as what they summarise (measured: 4.6 thousand level-1 cells under one tile at
//! level 2, 0.2 s), while clustering the placed umbrellas needs only the spawn cells.

use std::sync::Arc;


use super::arrange::{Arrangement, Placed};
pub use super::caches::Merged;
use super::extract::{Elements, RAYS};
use super::raster::{disc_reaches, Poly};
use super::shape::{self, SectorTable};

/// Deepest merged level drawn; further out the background takes over (building a level-`j`
/// cell places `4^j` spawn cells, so deeper levels cost more per tile than they save).
pub const MAX_LEVEL: u32 = 2;
/// A level's cells are drawn at least this many pixels wide (the design note's `ρ ≤ 1/8`).
pub const LOD_PIXELS: i64 = 8;
/// Rim vertices of a merged umbrella at most.
pub const MERGED_VERTICES: usize = 12;
const KMEANS_ITERATIONS: usize = 10;


/// The level drawn `zoom_out` steps out: 0 while a grid cell is at least [`LOD_PIXELS`]
/// pixels wide, else the least `j` whose cells are; `None` past [`MAX_LEVEL`].
pub fn level(arr: &Arrangement, zoom_out: u32) -> Option<u32> {
    let step = 1i64 << zoom_out.min(40);
    let mut j = 0;
    while (arr.g << j) < LOD_PIXELS * step {
        j += 1;
        if j > MAX_LEVEL {
            return None;
        }
    }
    Some(j)
}

/// A member of a cluster: an umbrella of level 0, centred at absolute `(x, y)`.
struct Member {
    x: f64,
    y: f64,
    u: Placed,
}

impl Member {
    fn centre(&self) -> [f64; 2] {
        [self.x, self.y]
    }
    fn key(&self) -> (u64, (i64, i64, u32)) {
        (self.u.depth, self.u.id)
    }
}

/// What colouring needs besides the members.
struct Palette<'a> {
    el: &'a Elements,
    arr: &'a Arrangement,
    sectors: &'a SectorTable,
    rays: [[f32; 2]; RAYS],
    /// Texels of a level-0 base a lookup spans (before the umbrella's scale).
    footprint: f32,
}

impl Palette<'_> {
    /// The colour member `m` shows at absolute `q`, if it covers it.
    fn colour(&self, m: &Member, q: [f64; 2]) -> Option<[f32; 3]> {
        let u = &m.u;
        let (dx, dy) = ((q[0] - m.x) as f32, (q[1] - m.y) as f32);
        // Beyond its reach (with a margin far above rounding) no umbrella covers a point: the
        // same answer as the rim test, without it for most members a point is tested against.
        if dx * dx + dy * dy > u.reach2 * 1.01 + 1e-3 {
            return None;
        }
        let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
        let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
        let t = &self.arr.table[u.modified as usize];
        let hit = t.rim.locate(self.sectors, lx, ly)?;
        let c = shape::colour(&self.el.bases[t.base], &self.rays, &t.colour, hit, self.footprint * u.inv_scale);
        Some(self.el.oriented(c, u.cos, u.sin, u.inv_scale))
    }
}

/// The colour of merged umbrella `m` at absolute `q`: the centre's and two vertices' colours
/// interpolated over the fan triangle that holds `q`, or `None` outside.
pub fn merged_colour(m: &Merged, q: [f64; 2]) -> Option<[f32; 3]> {
    let n = m.rim.len();
    let (px, py) = (q[0] - m.o[0], q[1] - m.o[1]);
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b) = ([m.rim[i][0] - m.o[0], m.rim[i][1] - m.o[1]], [m.rim[j][0] - m.o[0], m.rim[j][1] - m.o[1]]);
        let det = a[0] * b[1] - a[1] * b[0];
        if det <= 0.0 {
            continue;
        }
        let beta = (px * b[1] - py * b[0]) / det;
        let gamma = (a[0] * py - a[1] * px) / det;
        if beta >= -1e-9 && gamma >= -1e-9 && beta + gamma <= 1.0 + 1e-9 {
            let (beta, gamma) = (beta.max(0.0) as f32, gamma.max(0.0) as f32);
            let alpha = (1.0 - beta - gamma).max(0.0);
            return Some([0, 1, 2].map(|k| alpha * m.centre[k] + beta * m.colour[i][k] + gamma * m.colour[j][k]));
        }
    }
    None
}

/// The convex hull of `points` (monotone chain), counter-clockwise in the y-up sense
/// (positive `cross`), without collinear points.
fn hull(points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    // Points well inside the quadrilateral of the extreme points in x and y cannot be hull
    // vertices: left out before sorting (Akl–Toussaint). The margin keeps any point that
    // rounding could put on the hull.
    // The first point of least x, of least y, of greatest x and of greatest y, in one pass.
    let mut quad = [points.first().copied().unwrap_or([0.0; 2]); 4];
    for &p in points.iter().skip(1) {
        if p[0] < quad[0][0] {
            quad[0] = p;
        }
        if p[1] < quad[1][1] {
            quad[1] = p;
        }
        if p[0] > quad[2][0] {
            quad[2] = p;
        }
        if p[1] > quad[3][1] {
            quad[3] = p;
        }
    }
    let span = (quad[2][0] - quad[0][0]).max(quad[3][1] - quad[1][1]);
    let margin = 1e-9 * span * span;
    let inside = |p: &[f64; 2]| (0..4).all(|i| cross(quad[i], quad[(i + 1) % 4], *p) > margin);
    // Sorted lexicographically, (x, y), as one integer per point: each coordinate's bits
    // mapped to an unsigned integer of the same order (−0 taken as +0, the same point).
    let key = |v: f64| {
        let b = (v + 0.0).to_bits();
        if b >> 63 == 1 { !b } else { b | 1 << 63 }
    };
    let value = |k: u64| f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k });
    let mut keys: Vec<u128> = Vec::with_capacity(points.len());
    keys.extend(points.iter().filter(|p| !inside(p)).map(|p| (key(p[0]) as u128) << 64 | key(p[1]) as u128));
    keys.sort_unstable();
    keys.dedup();
    let points: Vec<[f64; 2]> = keys.iter().map(|&k| [value((k >> 64) as u64), value(k as u64)]).collect();
    chain(&points)
}

/// `(a − o) × (b − o)`: positive when `o, a, b` turn counter-clockwise (y up).
fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The monotone chain over distinct points sorted by `(x, y)`: their convex hull.
fn chain(points: &[[f64; 2]]) -> Vec<[f64; 2]> {
    if points.len() < 3 {
        return points.to_vec();
    }
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * points.len());
    // The lower chain left to right, then the upper right to left.
    fn half(h: &mut Vec<[f64; 2]>, it: impl Iterator<Item = [f64; 2]>) {
        let start = h.len();
        for p in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], p) <= 0.0 {
                h.pop();
            }
            h.push(p);
        }
        h.pop();
    }
    half(&mut h, points.iter().copied());
    half(&mut h, points.iter().rev().copied());
    h
}

/// The area of a polygon (shoelace, positive for either orientation).
fn area(poly: &[[f64; 2]]) -> f64 {
    let n = poly.len();
    let twice: f64 = (0..n).map(|i| {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        a[0] * b[1] - a[1] * b[0]
    }).sum();
    (twice / 2.0).abs()
}

/// Delete the flattest vertex (interior angle closest to 180°: the largest cosine between
/// its two edges' directions) until at most `n` are left; ties: the first.
fn simplify(mut rim: Vec<[f64; 2]>, n: usize) -> Vec<[f64; 2]> {
    while rim.len() > n.max(3) {
        let len = rim.len();
        let mut best = (f64::MIN, 0);
        for i in 0..len {
            let (p, v, q) = (rim[(i + len - 1) % len], rim[i], rim[(i + 1) % len]);
            let (a, b) = ([v[0] - p[0], v[1] - p[1]], [q[0] - v[0], q[1] - v[1]]);
            let norm = ((a[0] * a[0] + a[1] * a[1]) * (b[0] * b[0] + b[1] * b[1])).sqrt();
            let straight = if norm > 0.0 { (a[0] * b[0] + a[1] * b[1]) / norm } else { 1.0 };
            if straight > best.0 {
                best = (straight, i);
            }
        }
        rim.remove(best.1);
    }
    rim
}

/// Cluster `members` (sorted front to back) into at most `k` groups by k-means on their
/// centres: the first centre the front-most member's, then each the member farthest from
/// those chosen; at most [`KMEANS_ITERATIONS`] iterations, stopping once an assignment repeats
/// (every further one would repeat it too); ties to the lower index.
fn kmeans(members: &[Member], k: usize) -> Vec<Vec<usize>> {
    let pts: Vec<[f64; 2]> = members.iter().map(Member::centre).collect();
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let k = k.min(pts.len()).max(1);
    let mut centres = vec![pts[0]];
    // Each point's distance to the nearest centre chosen so far.
    let mut near: Vec<f64> = pts.iter().map(|&p| d2(p, pts[0])).collect();
    while centres.len() < k {
        let far = near.iter().enumerate().fold((f64::MIN, 0), |best, (i, &d)| if d > best.0 { (d, i) } else { best });
        let c = pts[far.1];
        centres.push(c);
        for (n, &p) in near.iter_mut().zip(&pts) {
            *n = n.min(d2(p, c));
        }
    }
    let mut assign = vec![usize::MAX; pts.len()];
    let mut sums = vec![([0f64; 2], 0f64); k];
    for _ in 0..KMEANS_ITERATIONS {
        let mut changed = false;
        for (a, &p) in assign.iter_mut().zip(&pts) {
            let mut best = (d2(p, centres[0]), 0);
            for (c, &centre) in centres.iter().enumerate().skip(1) {
                let d = d2(p, centre);
                if d < best.0 {
                    best = (d, c);
                }
            }
            changed |= *a != best.1;
            *a = best.1;
        }
        // The same assignment twice: the same means, so every further iteration repeats it.
        if !changed {
            break;
        }
        // Means, each summed in point order.
        sums.fill(([0f64; 2], 0f64));
        for (&a, p) in assign.iter().zip(&pts) {
            let (s, n) = &mut sums[a];
            *s = [s[0] + p[0], s[1] + p[1]];
            *n += 1.0;
        }
        for (centre, &(s, n)) in centres.iter_mut().zip(&sums) {
            if n > 0.0 {
                *centre = [s[0] / n, s[1] / n];
            }
        }
    }
    let mut groups = vec![Vec::new(); k];
    for (i, &a) in assign.iter().enumerate() {
        groups[a].push(i);
    }
    groups.into_iter().filter(|g| !g.is_empty()).collect()
}

/// One merged umbrella from a cluster (members front to back).
fn merge(members: &[&Member], palette: &Palette, background: [f32; 3]) -> Option<Merged> {
    let reach_of = |o: [f64; 2], rim: &[[f64; 2]]| rim.iter().map(|v| ((v[0] - o[0]).powi(2) + (v[1] - o[1]).powi(2)).sqrt()).fold(0.0, f64::max);
    if let [one] = members {
        // A cluster of one keeps its umbrella: its own (star-shaped) rim, coloured from its
        // base texture when drawn (no vertex colours).
        let (depth, id) = one.key();
        let rim: Vec<[f64; 2]> = palette.arr.rim(&one.u, one.x, one.y).iter().map(|&(a, b)| [a, b]).collect();
        let o = one.centre();
        // (Its `centre` colour is never read: [`colour_at`] colours a single from its texture.)
        let single = Some(one.u);
        return Some(Merged { reach: reach_of(o, &rim), o, rim, colour: Vec::new(), centre: background, depth, id, single });
    }
    let n = members.len() as f64;
    let mut o = [0f64; 2];
    let mut points = Vec::with_capacity(members.len() * RAYS);
    let mut covered = 0f64;
    for m in members {
        let c = m.centre();
        o = [o[0] + c[0] / n, o[1] + c[1] / n];
        let from = points.len();
        points.extend(palette.arr.rim(&m.u, m.x, m.y).iter().map(|&(a, b)| [a, b]));
        covered += area(&points[from..]);
    }
    let rim = simplify(hull(points), MERGED_VERTICES);
    if rim.len() < 3 {
        return None;
    }
    // The hull also covers the gaps between the members: shrunk about the members' mean centre
    // to the area they are expected to cover (their areas scattered over the hull at random:
    // `1 − e^(−Σ/hull)` of it), so that a merged level keeps the share of gaps it stands for.
    let hull_area = area(&rim);
    let shrink = if hull_area > 0.0 { (1.0 - (-covered / hull_area).exp()).sqrt() } else { 1.0 };
    let rim: Vec<[f64; 2]> = rim.iter().map(|v| [o[0] + shrink * (v[0] - o[0]), o[1] + shrink * (v[1] - o[1])]).collect();
    // The centre must stay inside the simplified rim (it may not, for a sliver): else the
    // rim's vertex mean, which is.
    let inside = |o: [f64; 2]| {
        (0..rim.len()).all(|i| {
            let (a, b) = (rim[i], rim[(i + 1) % rim.len()]);
            (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > 0.0
        })
    };
    if !inside(o) {
        let c = rim.len() as f64;
        o = rim.iter().fold([0.0, 0.0], |s, v| [s[0] + v[0] / c, s[1] + v[1] / c]);
    }
    // What the level below shows at `q`: the front-most member covering it, else the
    // background's mean.
    let below = |q: [f64; 2]| members.iter().find_map(|m| palette.colour(m, q)).unwrap_or(background);
    let at = |v: [f64; 2], t: f64| [o[0] + t * (v[0] - o[0]), o[1] + t * (v[1] - o[1])];
    let colour = rim.iter().map(|&v| below(at(v, 0.6))).collect();
    let spokes: Vec<[f64; 2]> = std::iter::once(o).chain(rim.iter().step_by(3).map(|&v| at(v, 0.3))).collect();
    let sum = spokes.iter().map(|&q| below(q)).fold([0f32; 3], |s, c| [s[0] + c[0], s[1] + c[1], s[2] + c[2]]);
    let centre = sum.map(|v| v / spokes.len() as f32);
    let (depth, id) = members[0].key();
    Some(Merged { reach: reach_of(o, &rim), o, rim, colour, centre, depth, id, single: None })
}

/// Bytes charged for a cached cell besides its merged umbrellas' own (key, slot, allocations).
const CELL_OVERHEAD: u64 = 96;

/// The merged umbrellas of level-`j` cell `(cx, cy)` (`j ≥ 1`), front to back: the umbrellas
/// its `2^j × 2^j` spawn cells place, clustered.
pub fn cell(el: &Elements, arr: &Arrangement, sectors: &SectorTable, j: u32, cx: i64, cy: i64) -> Arc<Vec<Merged>> {
    let key = (arr.key(), j, cx, cy);
    if let Some(c) = arr.caches().cells.get(&key) {
        return c;
    }
    let n = 1i64 << j;
    let mut members: Vec<Member> = (0..n * n)
        .flat_map(|i| arr.spawn(n * cx + i % n, n * cy + i / n))
        .map(|(px, py, u)| Member { x: px as f64 / 256.0, y: py as f64 / 256.0, u })
        .collect();
    members.sort_by(|a, b| b.key().0.cmp(&a.key().0).then(a.key().1.cmp(&b.key().1)));
    let palette = Palette {
        el,
        arr,
        sectors,
        rays: arr.rays,
        footprint: ((arr.g << j) / LOD_PIXELS).max(1) as f32,
    };
    let merged: Vec<Merged> = if members.is_empty() {
        Vec::new()
    } else {
        let mut out: Vec<Merged> = kmeans(&members, arr.k)
            .iter()
            .filter_map(|g| merge(&g.iter().map(|&i| &members[i]).collect::<Vec<_>>(), &palette, el.mean_colour))
            .collect();
        out.sort_by(|a, b| b.depth.cmp(&a.depth).then(a.id.cmp(&b.id)));
        out
    };
    let bytes = merged.iter().map(|m| (std::mem::size_of::<Merged>() + m.rim.len() * 16 + m.colour.len() * 12) as u64).sum::<u64>()
        + CELL_OVERHEAD;
    let merged = Arc::new(merged);
    arr.caches().cells.put(key, merged.clone(), bytes);
    merged
}

/// Cells per frame: a row of cells is rasterised a frame at a time, with positions relative to
/// the frame's origin (cell `FRAME·n`), so that they are the same f32s whichever window asks.
pub const FRAME: i64 = 64;

/// The first cell of the frame holding cell `cx`.
pub fn frame_of(cx: i64) -> i64 {
    cx.div_euclid(FRAME) * FRAME
}

/// A merged umbrella relative to the origin of a frame of cells, for rasterising and colouring.
pub struct Local<'a> {
    /// The umbrella.
    pub m: &'a Merged,
    /// Centre relative to the frame's origin.
    pub o: [f32; 2],
    /// Squared reach.
    pub reach2: f32,
    /// Rim relative to the frame's origin.
    pub rim: Poly,
    /// The frame's origin (absolute texels), to take a point back.
    pub origin: [f64; 2],
}

/// The merged umbrellas that may cover level-`j` cells `cx0..cx1` of row `cy` or shade them,
/// front to back, relative to the origin of cell `(frame, cy)`, appended to `out`: those of the
/// cells around them whose disc, grown by the shadow offset, meets them. (Merged levels keep
/// every umbrella of a cell, not the first `k`, so the list of a stretch of cells is the union
/// of its cells' lists: each umbrella is rasterised once per stretch, not once per cell it
/// reaches.) The umbrellas are ordered by reference (their depth and id, unique), and their
/// rims built in that order, so no rim is moved.
pub fn list_into<'a>(
    cells: impl Iterator<Item = &'a Vec<Merged>>,
    arr: &Arrangement,
    j: u32,
    frame: i64,
    (cx0, cx1): (i64, i64),
    cy: i64,
    out: &mut Vec<Local<'a>>,
) {
    let side = (arr.g << j) as f64;
    let origin = [frame as f64 * side, cy as f64 * side];
    let grow = 1.5 * arr.shadow_offset as f64;
    let extent = [((cx0 - frame) as f64 * side) as f32, ((cx1 - frame) as f64 * side) as f32, 0.0, side as f32];
    let centre = |m: &Merged| [(m.o[0] - origin[0]) as f32, (m.o[1] - origin[1]) as f32];
    let mut near: Vec<&Merged> = cells
        .flat_map(|ms| ms.iter())
        .filter(|m| {
            let o = centre(m);
            let r = (m.reach + grow) as f32;
            disc_reaches(o[0], o[1], r * r, extent) || disc_reaches(o[0] + grow as f32, o[1] + grow as f32, r * r, extent)
        })
        .collect();
    near.sort_unstable_by(|a, b| b.depth.cmp(&a.depth).then(a.id.cmp(&b.id)));
    out.extend(near.into_iter().map(|m| {
        let mut v = [[0f32; 2]; RAYS];
        for (d, s) in v.iter_mut().zip(&m.rim) {
            *d = [(s[0] - origin[0]) as f32, (s[1] - origin[1]) as f32];
        }
        let reach2 = (m.reach * m.reach) as f32;
        Local { m, o: centre(m), reach2, rim: Poly::new(v, m.rim.len()), origin }
    }));
}

/// How many level-`j` cells away a merged umbrella may still cover or shade a cell: a rim
/// reaches beyond its own cell by at most the largest umbrella's reach, and its shadow by the
/// shadow offset more.
pub fn around(arr: &Arrangement, j: u32) -> i64 {
    let side = (arr.g << j) as f64;
    ((arr.max_reach + 1.5 * arr.shadow_offset as f64) / side).ceil() as i64
}

/// The colour of `l` at `q` relative to its frame's origin, for a lookup spanning `footprint`
/// texels: a single umbrella's from its base texture, a merged one's from its vertex colours
/// (its centre's for a point the coverage put inside but the fan test, by rounding, just
/// outside).
#[allow(clippy::too_many_arguments)]
pub fn colour_at(
    l: &Local,
    q: [f32; 2],
    el: &Elements,
    arr: &Arrangement,
    sectors: &SectorTable,
    rays: &[[f32; 2]; RAYS],
    footprint: f32,
) -> [f32; 3] {
    if let Some(u) = &l.m.single {
        let (dx, dy) = (q[0] - l.o[0], q[1] - l.o[1]);
        let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
        let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
        let t = &arr.table[u.modified as usize];
        let hit = t.rim.locate_clamped(sectors, lx, ly);
        let c = shape::colour(&el.bases[t.base], rays, &t.colour, hit, footprint * u.inv_scale);
        return el.oriented(c, u.cos, u.sin, u.inv_scale);
    }
    merged_colour(l.m, [l.origin[0] + q[0] as f64, l.origin[1] + q[1] as f64]).unwrap_or(l.m.centre)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hash::hash;

    /// The monotone chain over every point, sorted by `f64::total_cmp`: what [`hull`] must equal.
    fn reference(mut points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
        points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        points.dedup();
        chain(&points)
    }

    #[test]
    fn the_hull_with_interior_points_left_out_equals_the_hull_of_all_points() {
        let unit = |n: u64, k: i64| (hash(0x4855, n, k, 0, 0) >> 11) as f64 / (1u64 << 53) as f64;
        for n in 0..2000u64 {
            // Rims of a few star-shaped umbrellas far from the origin, on a grid or not, with
            // repeated and collinear points now and then.
            let (cx, cy) = (1e5 * (unit(n, 0) - 0.5), -3e4 * unit(n, 1));
            let count = 1 + (n % 5) as i64;
            let mut points = Vec::new();
            for m in 0..count {
                let (ox, oy) = (cx + 30.0 * unit(n, 10 + m), cy + 30.0 * unit(n, 20 + m));
                for i in 0..RAYS as i64 {
                    let a = i as f64 * std::f64::consts::TAU / RAYS as f64;
                    let r = if n % 7 == 0 { 8.0 } else { 4.0 + 8.0 * unit(n, 100 * m + i) };
                    let p = [ox + r * a.cos(), oy + r * a.sin()];
                    points.push(if n % 3 == 0 { [p[0].round(), p[1].round()] } else { p });
                }
            }
            assert_eq!(hull(points.clone()), reference(points), "case {n}");
        }
    }
}
