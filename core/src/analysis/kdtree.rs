//! A k-d tree for the candidate search (design note §1.2d, §3): nearest neighbours under a
//! predicate, exact or within a factor `1 + ε` (a cell is skipped when it cannot hold a match
//! much nearer than the one found), so the 5 % separation rule is applied during the search instead of by retrying
//! ever larger k-nearest queries (which degrades to brute force on blurred coarse levels, where
//! every near match is a spatial neighbour). Deterministic: ties go to the smallest item.
//!
//! A leaf's points are stored in groups of [`LANES`], dimension by dimension, so that their
//! distances to a query are computed [`LANES`] at a time (with AVX where the processor has it);
//! each distance is still summed in dimension order, so the results are the same bits as one
//! point at a time.
//!
//! Identical points are stored once, with all their items (sorted): degenerate exemplars (flat,
//! periodic, binary) give thousands of equal neighbourhoods, and a search that had to visit
//! each of them to break its ties by item was quadratic (minutes for a flat 256² exemplar).
//! Where no two points are equal, the tree is the one built over the points as given.

/// Most points per leaf.
const LEAF: usize = 16;
/// Points whose distances are computed together.
const LANES: usize = 4;

/// A node; the left child of a split is the next node.
#[derive(Clone, Copy)]
enum Node {
    /// Points `slot..slot + len` (`slot` a multiple of [`LANES`]).
    Leaf { slot: u32, len: u32 },
    /// Points with coordinate `dim` below `value` on the left, above it on the right.
    Split { value: f64, dim: u32, right: u32 },
}

/// A static k-d tree over `D`-dimensional points, each tagged with an item number.
pub struct KdTree<const D: usize> {
    /// Per group of [`LANES`] slots, `D` lane vectors (one per dimension); padding slots are
    /// at infinity.
    lanes: Vec<[f64; LANES]>,
    /// Smallest item of every slot's point (padding: `u32::MAX`).
    items: Vec<u32>,
    /// Per slot, where its point's other items start in `more` (one more entry at the end:
    /// slot `s` has `more[more_at[s]..more_at[s + 1]]`, ascending).
    more_at: Vec<u32>,
    /// The items of repeated points beyond their smallest.
    more: Vec<u32>,
    nodes: Vec<Node>,
    /// Whether the processor runs AVX (the leaf distances use it).
    avx: bool,
}

impl<const D: usize> KdTree<D> {
    /// Build over `(point, item)` pairs. Median splits on the widest dimension; equal points
    /// share one slot.
    pub fn new(entries: Vec<([f64; D], u32)>) -> Self {
        #[cfg(target_arch = "x86_64")]
        let avx = std::arch::is_x86_feature_detected!("avx");
        #[cfg(not(target_arch = "x86_64"))]
        let avx = false;
        let (mut unique, repeats) = collapse_equal(entries);
        let mut tree = KdTree {
            lanes: Vec::new(),
            items: Vec::new(),
            more_at: Vec::new(),
            more: Vec::new(),
            nodes: Vec::new(),
            avx,
        };
        if !unique.is_empty() {
            tree.build(&mut unique);
        }
        // Each slot's other items, in slot order.
        tree.more_at.reserve(tree.items.len() + 1);
        for &item in &tree.items {
            tree.more_at.push(tree.more.len() as u32);
            if let Some(others) = repeats.get(&item) {
                tree.more.extend_from_slice(others);
            }
        }
        tree.more_at.push(tree.more.len() as u32);
        tree
    }

    /// The items of slot `s`'s point beyond its smallest, ascending.
    fn more_items(&self, s: usize) -> &[u32] {
        &self.more[self.more_at[s] as usize..self.more_at[s + 1] as usize]
    }

    /// The item nearest to `q` (squared Euclidean distance) among those `keep` accepts, with its
    /// distance; ties go to the smallest item. `None` if no item is accepted.
    pub fn nearest(&self, q: &[f64; D], keep: impl Fn(u32) -> bool) -> Option<(f64, u32)> {
        self.nearest_k(q, 1, keep).first().copied()
    }

    /// The `k` items nearest to `q` among those `keep` accepts, nearest first (ties to the
    /// smallest item).
    pub fn nearest_k(&self, q: &[f64; D], k: usize, keep: impl Fn(u32) -> bool) -> Vec<(f64, u32)> {
        self.nearest_k_approx(q, k, 1.0, keep)
    }

    /// [`KdTree::nearest_k`], approximate: a cell is skipped unless `slack` times its squared
    /// distance to `q` is within the k-th best so far (`slack = (1 + ε)²`: every match returned
    /// is within `1 + ε` of the true one of its rank; `slack = 1`: exact). Deterministic.
    pub fn nearest_k_approx(&self, q: &[f64; D], k: usize, slack: f64, keep: impl Fn(u32) -> bool) -> Vec<(f64, u32)> {
        self.nearest_k_counted(q, k, slack, keep).0
    }

    /// [`KdTree::nearest_k_approx`], with the number of leaves it opened: the work of the query.
    pub fn nearest_k_counted(
        &self,
        q: &[f64; D],
        k: usize,
        slack: f64,
        keep: impl Fn(u32) -> bool,
    ) -> (Vec<(f64, u32)>, u64) {
        let mut best: Vec<(f64, u32)> = Vec::with_capacity(k + 1);
        let query = Query { k, slack, keep, leaves: std::cell::Cell::new(0) };
        if k > 0 && !self.nodes.is_empty() {
            let mut gap = [0.0; D];
            self.search(0, q, &query, &mut best, &mut gap);
        }
        (best, query.leaves.get())
    }

    /// Search the subtree `node`; `gap` holds `q`'s distance to the subtree's cell along each
    /// dimension (0 where `q` lies within its extent).
    fn search(
        &self,
        node: usize,
        q: &[f64; D],
        query: &Query<impl Fn(u32) -> bool>,
        best: &mut Vec<(f64, u32)>,
        gap: &mut [f64; D],
    ) {
        let (k, keep) = (query.k, &query.keep);
        // The k-th best so far: what a new item must beat.
        let worst = |best: &Vec<(f64, u32)>| if best.len() < k { (f64::INFINITY, u32::MAX) } else { best[k - 1] };
        match self.nodes[node] {
            Node::Leaf { slot, len } => {
                query.leaves.set(query.leaves.get() + 1);
                let (slot, len) = (slot as usize, len as usize);
                let mut dist = [[0.0; LANES]; LEAF / LANES];
                let mut w = worst(best);
                // Only points within the k-th best distance can enter (it only shrinks below).
                let mut hits = self.leaf_distances(slot, len, q, w.0, &mut dist);
                let dist = dist.as_flattened();
                while hits != 0 {
                    let i = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    let (d, item) = (dist[i], self.items[slot + i]);
                    if !(d < w.0 || (d == w.0 && item < w.1)) {
                        continue;
                    }
                    if keep(item) {
                        offer(best, k, d, item);
                        w = worst(best);
                    }
                    // The same point's other items, ascending: until one could not enter.
                    if self.more.is_empty() {
                        continue;
                    }
                    for &other in self.more_items(slot + i) {
                        if !(d < w.0 || (d == w.0 && other < w.1)) {
                            break;
                        }
                        if keep(other) {
                            offer(best, k, d, other);
                            w = worst(best);
                        }
                    }
                }
            }
            Node::Split { value, dim, right } => {
                let dim = dim as usize;
                let diff = q[dim] - value;
                let (near, far) = if diff < 0.0 { (node + 1, right as usize) } else { (right as usize, node + 1) };
                self.search(near, q, query, best, gap);
                // Every point of the far cell is at least `gap` (with `diff` on this dimension)
                // from `q` along each dimension, and its distance is summed in the same order
                // from terms at least as large: in floating point too, it is at least `reach`.
                // Beyond the k-th best, no point there could be accepted (with `slack` > 1,
                // none much nearer than the k-th best). Once the k best are all at distance 0
                // they are items of the one slot equal to `q`, and nothing can be better.
                let old = gap[dim];
                gap[dim] = diff;
                let mut reach = 0.0;
                for g in gap.iter() {
                    reach += g * g;
                }
                let w = worst(best).0;
                if reach * query.slack <= w && w > 0.0 {
                    self.search(far, q, query, best, gap);
                }
                gap[dim] = old;
            }
        }
    }

    /// Distances from `q` of the `len` points from `slot`, into `out` (flattened order); returns
    /// the mask of those at most `bound` (bit `i`: point `i`).
    #[inline]
    fn leaf_distances(
        &self,
        slot: usize,
        len: usize,
        q: &[f64; D],
        bound: f64,
        out: &mut [[f64; LANES]; LEAF / LANES],
    ) -> u32 {
        let groups = len.div_ceil(LANES);
        let lanes = &self.lanes[slot / LANES * D..(slot / LANES + groups) * D];
        #[cfg(target_arch = "x86_64")]
        let within = if self.avx {
            // SAFETY: the processor runs AVX (checked when the tree was built).
            unsafe { group_distances_avx(lanes, q, bound, out) }
        } else {
            group_distances(lanes, q, bound, out)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let within = group_distances(lanes, q, bound, out);
        within & ((1u32 << len) - 1)
    }

    /// Build the subtree of `e` at the end of the node list; returns its node.
    fn build(&mut self, e: &mut [([f64; D], u32)]) -> usize {
        let id = self.nodes.len();
        if e.len() <= LEAF {
            let slot = self.items.len();
            self.nodes.push(Node::Leaf { slot: slot as u32, len: e.len() as u32 });
            for group in e.chunks(LANES) {
                let mut lanes = [[f64::INFINITY; LANES]; D];
                for (l, (p, item)) in group.iter().enumerate() {
                    for j in 0..D {
                        lanes[j][l] = p[j];
                    }
                    self.items.push(*item);
                }
                self.items.resize(self.items.len().next_multiple_of(LANES), u32::MAX);
                self.lanes.extend_from_slice(&lanes);
            }
            return id;
        }
        let mut dim = 0;
        let mut widest = -1.0;
        for k in 0..D {
            let (lo, hi) =
                e.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.0[k]), hi.max(p.0[k])));
            if hi - lo > widest {
                widest = hi - lo;
                dim = k;
            }
        }
        let mid = e.len() / 2;
        e.select_nth_unstable_by(mid, |a, b| a.0[dim].total_cmp(&b.0[dim]).then(a.1.cmp(&b.1)));
        let value = e[mid].0[dim];
        self.nodes.push(Node::Split { value, dim: dim as u32, right: 0 });
        // Left: points ordered before the median (coordinate ≤ value); right: the rest (≥ value).
        let (left, rest) = e.split_at_mut(mid);
        self.build(left);
        let right = self.build(rest);
        self.nodes[id] = Node::Split { value, dim: dim as u32, right: right as u32 };
        id
    }
}

/// Equal points (`-0.0` taken as `0.0`) collapsed to one entry with their smallest item, in the
/// order of the entries given; and, per smallest item of a repeated point, its other items
/// (ascending).
#[allow(clippy::type_complexity)]
fn collapse_equal<const D: usize>(
    entries: Vec<([f64; D], u32)>,
) -> (Vec<([f64; D], u32)>, std::collections::HashMap<u32, Vec<u32>>) {
    let key = |p: &[f64; D]| p.map(|v| if v == 0.0 { 0 } else { v.to_bits() });
    let mut order: Vec<usize> = (0..entries.len()).collect();
    order.sort_unstable_by(|&a, &b| key(&entries[a].0).cmp(&key(&entries[b].0)).then(entries[a].1.cmp(&entries[b].1)));
    let mut repeats = std::collections::HashMap::new();
    let mut dropped = vec![false; entries.len()];
    for run in order.chunk_by(|&a, &b| key(&entries[a].0) == key(&entries[b].0)) {
        if let [first, rest @ ..] = run {
            if !rest.is_empty() {
                repeats.insert(entries[*first].1, rest.iter().map(|&r| entries[r].1).collect::<Vec<_>>());
                for &r in rest {
                    dropped[r] = true;
                }
            }
        }
    }
    if repeats.is_empty() {
        return (entries, repeats);
    }
    let unique = entries.into_iter().zip(dropped).filter(|(_, d)| !d).map(|(e, _)| e).collect();
    (unique, repeats)
}

/// What a search looks for.
struct Query<F> {
    k: usize,
    slack: f64,
    keep: F,
    /// Leaves opened so far.
    leaves: std::cell::Cell<u64>,
}

/// Insert `(d, item)` into the sorted `best` (ties by item), keeping at most `k`.
fn offer(best: &mut Vec<(f64, u32)>, k: usize, d: f64, item: u32) {
    let at = best.partition_point(|b| b.0 < d || (b.0 == d && b.1 < item));
    best.insert(at, (d, item));
    best.truncate(k);
}

/// The squared Euclidean distance from `q` of every point of consecutive lane groups (`D` lane
/// vectors each), summed in dimension order; returns the mask of those at most `bound`.
#[inline]
fn group_distances<const D: usize>(
    lanes: &[[f64; LANES]],
    q: &[f64; D],
    bound: f64,
    out: &mut [[f64; LANES]; LEAF / LANES],
) -> u32 {
    let mut within = 0;
    for (g, (group, o)) in lanes.chunks_exact(D).zip(out.iter_mut()).enumerate() {
        let mut d = [0.0; LANES];
        for (p, &qj) in group.iter().zip(q) {
            for l in 0..LANES {
                let e = p[l] - qj;
                d[l] += e * e;
            }
        }
        for (l, &dl) in d.iter().enumerate() {
            within |= ((dl <= bound) as u32) << (g * LANES + l);
        }
        *o = d;
    }
    within
}

/// [`group_distances`] with AVX: one group's four points per instruction, each distance still
/// summed in dimension order with separate multiplies and adds, so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn group_distances_avx<const D: usize>(
    lanes: &[[f64; LANES]],
    q: &[f64; D],
    bound: f64,
    out: &mut [[f64; LANES]; LEAF / LANES],
) -> u32 {
    use std::arch::x86_64::*;
    let qv: [__m256d; D] = std::array::from_fn(|j| _mm256_set1_pd(q[j]));
    let limit = _mm256_set1_pd(bound);
    let mut within = 0;
    for (g, (group, o)) in lanes.chunks_exact(D).zip(out.iter_mut()).enumerate() {
        let mut d = _mm256_setzero_pd();
        for (p, &qj) in group.iter().zip(&qv) {
            // SAFETY: `p` is four f64 (unaligned load).
            let e = _mm256_sub_pd(unsafe { _mm256_loadu_pd(p.as_ptr()) }, qj);
            d = _mm256_add_pd(d, _mm256_mul_pd(e, e));
        }
        // SAFETY: `o` is four f64 (unaligned store).
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), d) };
        within |= (_mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(d, limit)) as u32) << (g * LANES);
    }
    within
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every accepted point with its squared distance to `q`, nearest first (ties to the
    /// smallest item).
    fn brute_force<const D: usize>(pts: &[[f64; D]], q: &[f64; D], keep: impl Fn(u32) -> bool) -> Vec<(f64, u32)> {
        let mut all: Vec<(f64, u32)> = pts
            .iter()
            .enumerate()
            .filter(|(i, _)| keep(*i as u32))
            .map(|(i, p)| (p.iter().zip(q).map(|(a, b)| (a - b) * (a - b)).sum::<f64>(), i as u32))
            .collect();
        all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        all
    }

    #[test]
    fn nearest_and_k_nearest_match_brute_force_with_a_predicate() {
        let pts: Vec<[f64; 3]> =
            (0..500u32).map(|i| [((i * 37) % 101) as f64, ((i * 53) % 97) as f64, ((i * 11) % 7) as f64]).collect();
        let tree = KdTree::new(pts.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect());
        for qi in 0..60u32 {
            let q = [(qi * 13 % 100) as f64 + 0.5, (qi * 29 % 90) as f64, (qi % 7) as f64];
            let keep = |i: u32| i % 3 != qi % 3;
            let all = brute_force(&pts, &q, keep);
            assert_eq!(tree.nearest(&q, keep), all.first().copied());
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
            // Approximate: each match of rank i within (1 + ε)² of the exact one's distance,
            // all accepted, nearest first.
            for slack in [1.5, 2.25, 4.0] {
                let approx = tree.nearest_k_approx(&q, 8, slack, keep);
                assert_eq!(approx.len(), 8);
                for (i, (a, e)) in approx.iter().zip(&all).enumerate() {
                    assert!(a.0 <= slack * e.0, "query {qi}, slack {slack}, rank {i}: {} > {slack}·{}", a.0, e.0);
                    assert!(keep(a.1) && a.0 == dist(&pts[a.1 as usize], &q));
                }
                assert!(approx.windows(2).all(|w| w[0].0 <= w[1].0));
            }
        }
    }

    #[test]
    fn repeated_points_give_the_brute_force_result_ties_to_the_smallest_item() {
        // A flat region (one point 2 000 times), a two-valued one (checkerboard) and a few
        // distinct points; `-0.0` equals `0.0`.
        let mut pts: Vec<[f64; 3]> = vec![[0.0, 0.0, 0.0]; 2000];
        pts.extend((0..1000).map(|i| if i % 2 == 0 { [1.0, -0.0, 2.0] } else { [1.0, 0.0, 2.0] }));
        pts.extend((0..1000).map(|i| if i % 3 == 0 { [5.0, 5.0, 5.0] } else { [-5.0, 5.0, 5.0] }));
        pts.extend((0..50).map(|i| [i as f64 * 0.1, 1.0, 2.0]));
        let tree = KdTree::new(pts.iter().enumerate().map(|(i, p)| (*p, i as u32)).collect());
        for (qi, slack) in [(0usize, 1.0), (17, 2.25), (2001, 1.0), (2500, 2.25), (3001, 1.0), (4010, 1.0)] {
            let q = pts[qi];
            let keep = |i: u32| (i as usize).abs_diff(qi) > 300 && i % 7 != 3;
            let all = brute_force(&pts, &q, keep);
            for k in [1, 8, 40] {
                let got = tree.nearest_k_approx(&q, k, slack, keep);
                if slack == 1.0 {
                    assert_eq!(got, all[..k], "query {qi}, k {k}");
                } else {
                    assert!(got.iter().zip(&all).all(|(g, e)| g.0 <= slack * e.0 && keep(g.1)), "query {qi}, k {k}");
                }
            }
        }
    }

    #[test]
    fn leaf_distances_are_the_same_bits_with_and_without_avx() {
        let mut z = 7u64;
        let mut next = || {
            z = z.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (z >> 11) as f64 / (1u64 << 40) as f64 - 2000.0
        };
        let lanes: Vec<[f64; LANES]> = (0..8 * LEAF / LANES).map(|_| std::array::from_fn(|_| next())).collect();
        let q: [f64; 8] = std::array::from_fn(|_| next());
        let (mut a, mut b) = ([[0.0; LANES]; LEAF / LANES], [[0.0; LANES]; LEAF / LANES]);
        let bound = 3.0e7;
        let ma = group_distances(&lanes, &q, bound, &mut a);
        for (g, group) in lanes.chunks_exact(8).enumerate() {
            for l in 0..LANES {
                let p: [f64; 8] = std::array::from_fn(|j| group[j][l]);
                let mut d = 0.0;
                for j in 0..8 {
                    d += (p[j] - q[j]) * (p[j] - q[j]);
                }
                assert_eq!(a[g][l].to_bits(), d.to_bits());
                assert_eq!(ma >> (g * LANES + l) & 1 == 1, d <= bound);
            }
        }
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: AVX is present.
            let mb = unsafe { group_distances_avx(&lanes, &q, bound, &mut b) };
            assert_eq!((ma, a.map(|g| g.map(f64::to_bits))), (mb, b.map(|g| g.map(f64::to_bits))));
        }
    }
}
