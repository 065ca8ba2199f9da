//! An exact k-d tree for the candidate search (design note §1.2d, §3): nearest neighbour under a
//! predicate, so the 5 % separation rule is applied during the search instead of by retrying
//! ever larger k-nearest queries (which degrades to brute force on blurred coarse levels, where
//! every near match is a spatial neighbour). Deterministic: ties go to the smallest item.

/// Points per leaf.
const LEAF: usize = 16;

enum Node {
    Leaf { start: usize, end: usize },
    Split { dim: usize, value: f64, left: usize, right: usize },
}

/// A static k-d tree over `D`-dimensional points, each tagged with an item number.
pub struct KdTree<const D: usize> {
    points: Vec<[f64; D]>,
    items: Vec<u32>,
    nodes: Vec<Node>,
}

impl<const D: usize> KdTree<D> {
    /// Build over `(point, item)` pairs. Median splits on the widest dimension.
    pub fn new(mut entries: Vec<([f64; D], u32)>) -> Self {
        let mut nodes = Vec::new();
        let n = entries.len();
        build(&mut entries, 0, n, &mut nodes);
        let (points, items) = entries.into_iter().unzip();
        KdTree { points, items, nodes }
    }

    /// The item nearest to `q` (squared Euclidean distance) among those `keep` accepts, with its
    /// distance; ties go to the smallest item. `None` if no item is accepted.
    pub fn nearest(&self, q: &[f64; D], keep: impl Fn(u32) -> bool) -> Option<(f64, u32)> {
        self.nearest_k(q, 1, keep).first().copied()
    }

    /// The `k` items nearest to `q` among those `keep` accepts, nearest first (ties to the
    /// smallest item).
    pub fn nearest_k(&self, q: &[f64; D], k: usize, keep: impl Fn(u32) -> bool) -> Vec<(f64, u32)> {
        let mut best = Vec::with_capacity(k + 1);
        if !self.nodes.is_empty() && k > 0 {
            let mut gap = [0.0; D];
            self.search(0, q, k, &keep, &mut best, &mut gap);
        }
        best
    }

    /// Search the subtree `node`; `gap` holds `q`'s distance to the subtree's cell along each
    /// dimension (0 where `q` lies within its extent).
    fn search(
        &self,
        node: usize,
        q: &[f64; D],
        k: usize,
        keep: &impl Fn(u32) -> bool,
        best: &mut Vec<(f64, u32)>,
        gap: &mut [f64; D],
    ) {
        // The k-th best so far: what a new item must beat.
        let worst = |best: &Vec<(f64, u32)>| if best.len() < k { (f64::INFINITY, u32::MAX) } else { best[k - 1] };
        match self.nodes[node] {
            Node::Leaf { start, end } => {
                let mut w = worst(best);
                for (p, &item) in self.points[start..end].iter().zip(&self.items[start..end]) {
                    let mut d = 0.0;
                    for j in 0..D {
                        let e = p[j] - q[j];
                        d += e * e;
                    }
                    if (d < w.0 || (d == w.0 && item < w.1)) && keep(item) {
                        let at = best.partition_point(|b| b.0 < d || (b.0 == d && b.1 < item));
                        best.insert(at, (d, item));
                        best.truncate(k);
                        w = worst(best);
                    }
                }
            }
            Node::Split { dim, value, left, right } => {
                let diff = q[dim] - value;
                let (near, far) = if diff < 0.0 { (left, right) } else { (right, left) };
                self.search(near, q, k, keep, best, gap);
                // Every point of the far cell is at least `gap` (with `diff` on this dimension)
                // from `q` along each dimension, and its distance is summed in the same order
                // from terms at least as large: in floating point too, it is at least `reach`.
                // Beyond the k-th best, no point there could be accepted.
                let old = gap[dim];
                gap[dim] = diff;
                let mut reach = 0.0;
                for g in gap.iter() {
                    reach += g * g;
                }
                if reach <= worst(best).0 {
                    self.search(far, q, k, keep, best, gap);
                }
                gap[dim] = old;
            }
        }
    }
}

fn build<const D: usize>(e: &mut [([f64; D], u32)], start: usize, end: usize, nodes: &mut Vec<Node>) -> usize {
    let id = nodes.len();
    if end - start <= LEAF {
        nodes.push(Node::Leaf { start, end });
        return id;
    }
    let slice = &mut e[start..end];
    let mut dim = 0;
    let mut widest = -1.0;
    for k in 0..D {
        let (lo, hi) =
            slice.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.0[k]), hi.max(p.0[k])));
        if hi - lo > widest {
            widest = hi - lo;
            dim = k;
        }
    }
    let mid = slice.len() / 2;
    slice.select_nth_unstable_by(mid, |a, b| a.0[dim].total_cmp(&b.0[dim]).then(a.1.cmp(&b.1)));
    let value = slice[mid].0[dim];
    nodes.push(Node::Split { dim, value, left: 0, right: 0 });
    // Left: points ordered before the median (coordinate ≤ value); right: the rest (≥ value).
    let left = build(e, start, start + mid, nodes);
    let right = build(e, start + mid, end, nodes);
    nodes[id] = Node::Split { dim, value, left, right };
    id
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_and_k_nearest_match_brute_force_with_a_predicate() {
        let pts: Vec<[f64; 3]> =
            (0..500u32).map(|i| [((i * 37) % 101) as f64, ((i * 53) % 97) as f64, ((i * 11) % 7) as f64]).collect();
        let tree = KdTree::new(pts.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect());
        for qi in 0..60u32 {
            let q = [(qi * 13 % 100) as f64 + 0.5, (qi * 29 % 90) as f64, (qi % 7) as f64];
            let keep = |i: u32| i % 3 != qi % 3;
            let brute = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(*i as u32))
                .map(|(i, p)| (p.iter().zip(&q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>(), i as u32))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(tree.nearest(&q, keep), brute);
            let mut all: Vec<(f64, u32)> = pts
                .iter()
                .enumerate()
                .filter(|(i, _)| keep(*i as u32))
                .map(|(i, p)| (p.iter().zip(&q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>(), i as u32))
                .collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(tree.nearest_k(&q, 7, keep), all[..7]);
        }
    }

    #[test]
    fn cell_pruning_keeps_the_exact_result_in_eight_dimensions() {
        // Clustered points with repeated coordinates (many equal distances) and fractional
        // ones (rounding), as blurred coarse levels give.
        let mut z = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            z = z.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (z >> 33) as f64 / (1u64 << 31) as f64
        };
        let pts: Vec<[f64; 8]> = (0..3000)
            .map(|i| {
                std::array::from_fn(|j| {
                    if (i + j) % 3 == 0 {
                        (i % 5) as f64
                    } else {
                        (i % 7) as f64 * 0.1 + next() * 1e-3
                    }
                })
            })
            .collect();
        let tree = KdTree::new(pts.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect());
        let dist = |a: &[f64; 8], b: &[f64; 8]| {
            let mut d = 0.0;
            for j in 0..8 {
                let e = a[j] - b[j];
                d += e * e;
            }
            d
        };
        for qi in (0..3000).step_by(97) {
            let q = pts[qi];
            let keep = |i: u32| (i as usize).abs_diff(qi) > 40;
            let mut all: Vec<(f64, u32)> =
                pts.iter().enumerate().filter(|(i, _)| keep(*i as u32)).map(|(i, p)| (dist(p, &q), i as u32)).collect();
            all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(tree.nearest_k(&q, 8, keep), all[..8], "query {qi}");
        }
    }
}
