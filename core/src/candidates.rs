//! k-coherence candidate sets, k = 2 (design note §1.2d): for every exemplar texel, itself (or,
//! near a non-toroidal border, its best match away from the border) and its best match at least
//! 5 % of the exemplar away. Exact nearest neighbours in the 7×7 PCA space with a k-d tree.

use std::num::NonZeroUsize;

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use rayon::prelude::*;

use crate::features::SEARCH_DIMS;

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

/// Compute `[C_1(u), C_2(u)]` (texel indices `y·m + x`) for every texel `u`.
pub fn candidate_sets(feats: &[[f64; SEARCH_DIMS]], rules: &CandidateRules) -> Vec<[u32; 2]> {
    let inner: Vec<usize> = (0..feats.len()).filter(|&i| !rules.is_border(i)).collect();
    let points: Vec<[f64; SEARCH_DIMS]> = inner.iter().map(|&i| feats[i]).collect();
    let tree: ImmutableKdTree<f64, u64, SEARCH_DIMS, 32> = ImmutableKdTree::new_from_slice(&points);
    let dist = |a: &[f64; SEARCH_DIMS], b: &[f64; SEARCH_DIMS]| -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
    };
    (0..feats.len())
        .into_par_iter()
        .map(|u| {
            let q = &feats[u];
            let mut tries = [48usize, 1024];
            let c1 = if rules.is_border(u) {
                let n = tree.nearest_one::<SquaredEuclidean>(q);
                inner[n.item as usize]
            } else {
                u
            };
            let mut c2 = None;
            for n in tries.iter_mut() {
                let n = (*n).min(points.len()).max(1);
                let mut found =
                    tree.nearest_n::<SquaredEuclidean>(q, NonZeroUsize::new(n).unwrap_or(NonZeroUsize::MIN));
                found.sort_by(|a, b| {
                    a.distance.total_cmp(&b.distance).then(inner[a.item as usize].cmp(&inner[b.item as usize]))
                });
                if let Some(f) = found.iter().find(|f| rules.far_enough(inner[f.item as usize], c1)) {
                    c2 = Some(inner[f.item as usize]);
                    break;
                }
                if n == points.len() {
                    break;
                }
            }
            let c2 = c2.unwrap_or_else(|| {
                // Exhaustive fallback (tiny exemplars): best far-enough texel, ties by index.
                let mut best: Option<(f64, usize)> = None;
                for &v in &inner {
                    if rules.far_enough(v, c1) {
                        let d = dist(q, &feats[v]);
                        if best.is_none_or(|(bd, _)| d < bd) {
                            best = Some((d, v));
                        }
                    }
                }
                best.map(|b| b.1).unwrap_or(c1)
            });
            [c1 as u32, c2 as u32]
        })
        .collect()
}
