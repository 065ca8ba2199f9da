//! k-coherence candidate sets, k = 2 (design note §1.2d): for every exemplar texel, itself (or,
//! near a non-toroidal border, its best match away from the border) and its best match at least
//! 5 % of the exemplar away. Exact nearest neighbours in the 7×7 PCA space with a k-d tree.

use rayon::prelude::*;

use crate::analysis::features::SEARCH_DIMS;
use crate::analysis::kdtree::KdTree;

/// Geometry of one level's candidate problem.
pub struct CandidateRules {
    /// Exemplar side.
    pub m: usize,
    /// Whether the exemplar wraps (no border zone, toroidal distances).
    pub toroidal: bool,
    /// Width of the border zone (texels within it are never candidates).
    pub border: usize,
    /// Minimum distance between the two candidates.
    pub separation: usize,
}

impl CandidateRules {
    /// Rules at a level with stride `h` (`b_l = min(2h, m/4)`, separation `⌈0.05·m⌉`).
    pub fn for_level(m: usize, toroidal: bool, h: usize) -> Self {
        CandidateRules { m, toroidal, border: (2 * h).min(m / 4), separation: (m * 5).div_ceil(100) }
    }

    fn is_border(&self, i: usize) -> bool {
        if self.toroidal {
            return false;
        }
        let (x, y) = (i % self.m, i / self.m);
        let d = x.min(self.m - 1 - x).min(y).min(self.m - 1 - y);
        d < self.border
    }

    /// Texel `c` moved by `(dx, dy)` (wrapping when toroidal), unless that leaves the exemplar or
    /// lands in the border zone.
    fn shifted(&self, c: u32, dx: i64, dy: i64) -> Option<u32> {
        let m = self.m as i64;
        let (mut x, mut y) = ((c as i64) % m + dx, (c as i64) / m + dy);
        if self.toroidal {
            (x, y) = (x.rem_euclid(m), y.rem_euclid(m));
        } else if x < 0 || y < 0 || x >= m || y >= m {
            return None;
        }
        let v = (y * m + x) as usize;
        (!self.is_border(v)).then_some(v as u32)
    }

    fn far_enough(&self, a: usize, b: usize) -> bool {
        let m = self.m as i64;
        let (ax, ay, bx, by) = ((a % self.m) as i64, (a / self.m) as i64, (b % self.m) as i64, (b / self.m) as i64);
        let (mut dx, mut dy) = ((ax - bx).abs(), (ay - by).abs());
        if self.toroidal {
            dx = dx.min(m - dx);
            dy = dy.min(m - dy);
        }
        let s = self.separation as i64;
        dx * dx + dy * dy >= s * s
    }
}

/// Offsets of the local refinement around each proposal.
const AROUND: [(i64, i64); 9] = [(-1, -1), (0, -1), (1, -1), (-1, 0), (0, 0), (1, 0), (-1, 1), (0, 1), (1, 1)];

/// Nearest matches kept per grid texel by [`candidate_sets`].
pub const GRID_MATCHES: usize = 8;

/// The grid step of the coherent search at a level of stride `h`: exact (1) at the two finest
/// levels, whose exact search is cheap, 2 for `h = 4, 8`, 4 above, where blurred features make
/// the exact search slow and the coherence strong (recall per level in bench/README.md).
pub fn grid_step(h: usize) -> usize {
    match h {
        0..=2 => 1,
        3..=8 => 2,
        _ => 4,
    }
}

/// Compute `[C_1(u), C_2(u)]` (texel indices `y·m + x`) for every texel, searching exactly only the texels of a grid of
/// the given `step` (their `C_1`, and their [`GRID_MATCHES`] nearest matches far enough from it,
/// the first of which is `C_2`) and taking every other texel's candidates from the four grid
/// texels around it: each of their matches shifted by the texel's offset from the grid texel
/// (the coherence of a smooth level) and every texel within one of those, the best by the same
/// rules (border, separation); an exact search where no proposal qualifies. `step = 1` is the
/// exact search of every texel.
pub fn candidate_sets(feats: &[[f64; SEARCH_DIMS]], rules: &CandidateRules, step: usize) -> Vec<[u32; 2]> {
    let m = rules.m;
    let inner: Vec<([f64; SEARCH_DIMS], u32)> =
        (0..feats.len()).filter(|&i| !rules.is_border(i)).map(|i| (feats[i], i as u32)).collect();
    let tree = KdTree::new(inner);
    let first = |u: usize| {
        if rules.is_border(u) {
            tree.nearest(&feats[u], |_| true).map(|b| b.1).unwrap_or(u as u32)
        } else {
            u as u32
        }
    };
    let exact = |u: usize| {
        let c1 = first(u);
        let c2 = tree.nearest(&feats[u], |v| rules.far_enough(v as usize, c1 as usize)).map(|b| b.1).unwrap_or(c1);
        [c1, c2]
    };
    let step = step.clamp(1, m.max(1));
    if step == 1 {
        return (0..feats.len()).into_par_iter().map(exact).collect();
    }
    // Per grid texel: C_1, then its nearest matches far enough from C_1 (C_2 first).
    let gm = m.div_ceil(step);
    let grid: Vec<Vec<u32>> = (0..gm * gm)
        .into_par_iter()
        .map(|g| {
            let u = (g / gm) * step * m + (g % gm) * step;
            let c1 = first(u);
            let mut v = vec![c1];
            v.extend(
                tree.nearest_k(&feats[u], GRID_MATCHES, |x| rules.far_enough(x as usize, c1 as usize))
                    .into_iter()
                    .map(|b| b.1),
            );
            v
        })
        .collect();
    (0..feats.len())
        .into_par_iter()
        .map_init(Vec::new, |props, u| {
            let (x, y) = (u % m, u / m);
            if x % step == 0 && y % step == 0 {
                let g = &grid[(y / step) * gm + x / step];
                return [g[0], g.get(1).copied().unwrap_or(g[0])];
            }
            proposals(rules, &grid, gm, step, x, y, props);
            let q = &feats[u];
            let best = |keep: &dyn Fn(usize) -> bool| {
                props
                    .iter()
                    .filter(|&&v| keep(v as usize))
                    .map(|&v| (distance(q, &feats[v as usize]), v))
                    .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                    .map(|b| b.1)
            };
            let c1 = if rules.is_border(u) {
                match best(&|_| true) {
                    Some(c) => c,
                    None => return exact(u),
                }
            } else {
                u as u32
            };
            match best(&|v| rules.far_enough(v, c1 as usize)) {
                Some(c2) => [c1, c2],
                None => exact(u),
            }
        })
        .collect()
}

/// The candidates of the grid texels around `(x, y)`, shifted by its offset from each, and every
/// texel within one of those; never a border texel (duplicates possible).
fn proposals(
    rules: &CandidateRules,
    grid: &[Vec<u32>],
    gm: usize,
    step: usize,
    x: usize,
    y: usize,
    out: &mut Vec<u32>,
) {
    out.clear();
    let (gx0, gy0) = ((x / step) as i64, (y / step) as i64);
    let gmi = gm as i64;
    for gy in gy0..=gy0 + 1 {
        for gx in gx0..=gx0 + 1 {
            let (tx, ty) = (gx * step as i64, gy * step as i64);
            let (gx, gy) = if rules.toroidal { (gx.rem_euclid(gmi), gy.rem_euclid(gmi)) } else { (gx, gy) };
            if gx < 0 || gy < 0 || gx >= gmi || gy >= gmi {
                continue;
            }
            let (gx, gy) = (gx as usize, gy as usize);
            let (dx, dy) = (x as i64 - tx, y as i64 - ty);
            for &c in &grid[gy * gm + gx] {
                for (ex, ey) in AROUND {
                    if let Some(v) = rules.shifted(c, dx + ex, dy + ey) {
                        out.push(v);
                    }
                }
            }
        }
    }
}

fn distance(a: &[f64; SEARCH_DIMS], b: &[f64; SEARCH_DIMS]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum()
}
