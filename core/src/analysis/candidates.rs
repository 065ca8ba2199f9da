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
    let inner: Vec<([f64; SEARCH_DIMS], u32)> =
        (0..feats.len()).filter(|&i| !rules.is_border(i)).map(|i| (feats[i], i as u32)).collect();
    let tree = KdTree::new(inner);
    (0..feats.len())
        .into_par_iter()
        .map(|u| {
            let q = &feats[u];
            let c1 =
                if rules.is_border(u) { tree.nearest(q, |_| true).map(|b| b.1).unwrap_or(u as u32) } else { u as u32 };
            let c2 = tree.nearest(q, |v| rules.far_enough(v as usize, c1 as usize)).map(|b| b.1).unwrap_or(c1);
            [c1, c2]
        })
        .collect()
}
