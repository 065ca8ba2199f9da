//! Tree-structured vector quantiser (Wei & Levoy 2000; design note §3): an index of
//! fixed-length vectors for approximate nearest-neighbour search with limited backtracking.
//!
//! **Build** (deterministic, no randomness): a node's codeword is the centroid of its vectors;
//! a node over more than `leaf_cap` vectors is split along its principal axis (power iteration
//! from a fixed start) by generalised Lloyd iterations from the two codewords `c ± ε·σ·axis`
//! (at most [`LLOYD_ITERATIONS`], stopping when the distortion drops by less than 0.1 %; ties go
//! to the left child); a split that leaves either side with under an eighth of the vectors is
//! replaced by the median split on the axis, which bounds the depth. Leaves keep the items.
//!
//! **Search**: best-first descent towards the nearer codeword; the sibling not taken is pushed
//! on a min-heap by its codeword distance, and after each leaf the nearest pending node is
//! descended again, until `B` leaves are scanned. `B = 1` is greedy; `B ≥` [`Tsvq::leaves`]
//! is exhaustive and returns exactly the brute-force nearest (ties to the smallest item).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Most generalised-Lloyd iterations per split.
pub const LLOYD_ITERATIONS: usize = 12;

enum Node {
    Leaf { start: usize, end: usize },
    Split { left: usize, right: usize },
}

/// A static TSVQ over `dim`-dimensional `f32` vectors, each tagged with an item number.
pub struct Tsvq {
    dim: usize,
    /// Vectors, leaf by leaf.
    data: Vec<f32>,
    /// Item of each vector in `data`.
    items: Vec<u32>,
    nodes: Vec<Node>,
    /// Codeword (centroid) of each node, `dim` values per node.
    codewords: Vec<f32>,
    leaves: usize,
}

/// Squared Euclidean distance.
#[inline]
pub fn distance(a: &[f32], b: &[f32]) -> f32 {
    let mut d = 0.0f32;
    for (x, y) in a.iter().zip(b) {
        let e = x - y;
        d += e * e;
    }
    d
}

impl Tsvq {
    /// Build over `vectors` (`dim` values each, item `i` = the `i`-th vector), leaves of at most
    /// `leaf_cap` vectors.
    pub fn new(dim: usize, vectors: &[f32], leaf_cap: usize) -> Self {
        let n = vectors.len().checked_div(dim).unwrap_or(0);
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut t =
            Tsvq { dim, data: Vec::new(), items: Vec::new(), nodes: Vec::new(), codewords: Vec::new(), leaves: 0 };
        if n > 0 {
            t.build(vectors, &mut order, 0, leaf_cap.max(1));
        }
        t.data.reserve(n * dim);
        for &i in &order {
            t.data.extend_from_slice(&vectors[i as usize * dim..(i as usize + 1) * dim]);
        }
        t.items = order;
        t
    }

    /// Number of leaves.
    pub fn leaves(&self) -> usize {
        self.leaves
    }

    /// Vector dimension.
    pub fn dim(&self) -> usize {
        self.dim
    }

    fn build(&mut self, v: &[f32], order: &mut [u32], start: usize, leaf_cap: usize) -> usize {
        let dim = self.dim;
        let id = self.nodes.len();
        let centroid = mean(v, dim, order);
        self.codewords.extend_from_slice(&centroid);
        if order.len() <= leaf_cap {
            self.nodes.push(Node::Leaf { start, end: start + order.len() });
            self.leaves += 1;
            return id;
        }
        self.nodes.push(Node::Leaf { start, end: start });
        let cut = split(v, dim, order, &centroid);
        let (lo, hi) = order.split_at_mut(cut);
        let left = self.build(v, lo, start, leaf_cap);
        let right = self.build(v, hi, start + cut, leaf_cap);
        self.nodes[id] = Node::Split { left, right };
        id
    }

    fn codeword(&self, node: usize) -> &[f32] {
        &self.codewords[node * self.dim..(node + 1) * self.dim]
    }

    /// The item nearest to `q` among those `keep` accepts, scanning at most `b` leaves (best
    /// first), with its squared distance; ties go to the smallest item.
    pub fn nearest(&self, q: &[f32], b: usize, keep: impl Fn(u32) -> bool) -> Option<(f32, u32)> {
        let mut best = (f32::INFINITY, u32::MAX);
        if self.nodes.is_empty() {
            return None;
        }
        let mut pending = BinaryHeap::new();
        pending.push(Pending(0.0, 0));
        let mut scanned = 0;
        while let Some(Pending(_, mut node)) = pending.pop() {
            loop {
                match self.nodes[node] {
                    Node::Leaf { start, end } => {
                        for i in start..end {
                            let d = distance(&self.data[i * self.dim..(i + 1) * self.dim], q);
                            let item = self.items[i];
                            if (d < best.0 || (d == best.0 && item < best.1)) && keep(item) {
                                best = (d, item);
                            }
                        }
                        break;
                    }
                    Node::Split { left, right } => {
                        let (dl, dr) = (distance(self.codeword(left), q), distance(self.codeword(right), q));
                        let (near, far, dfar) = if dl <= dr { (left, right, dr) } else { (right, left, dl) };
                        pending.push(Pending(dfar, far));
                        node = near;
                    }
                }
            }
            scanned += 1;
            if scanned >= b {
                break;
            }
        }
        (best.1 != u32::MAX).then_some(best)
    }
}

/// A node waiting to be descended, by its codeword distance (nearest first; ties to the
/// smaller node index, for determinism).
struct Pending(f32, usize);

impl PartialEq for Pending {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Pending {}
impl PartialOrd for Pending {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Pending {
    fn cmp(&self, o: &Self) -> Ordering {
        // BinaryHeap is a max-heap: reverse so the smallest distance comes out first.
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

fn mean(v: &[f32], dim: usize, order: &[u32]) -> Vec<f32> {
    let mut c = vec![0f64; dim];
    for &i in order {
        for (k, x) in v[i as usize * dim..(i as usize + 1) * dim].iter().enumerate() {
            c[k] += *x as f64;
        }
    }
    let n = order.len().max(1) as f64;
    c.into_iter().map(|s| (s / n) as f32).collect()
}

/// Reorder `order` so that its first `cut` vectors form the left child: generalised Lloyd from
/// the principal-axis codewords, or the median split on the axis when Lloyd is unbalanced.
fn split(v: &[f32], dim: usize, order: &mut [u32], c: &[f32]) -> usize {
    let at = |i: u32| &v[i as usize * dim..(i as usize + 1) * dim];
    // Principal axis by power iteration from a fixed start.
    let mut axis = vec![1.0f64 / (dim as f64).sqrt(); dim];
    let mut var = 0.0;
    for _ in 0..8 {
        let mut next = vec![0f64; dim];
        for &i in order.iter() {
            let x = at(i);
            let p: f64 = (0..dim).map(|k| (x[k] - c[k]) as f64 * axis[k]).sum();
            for k in 0..dim {
                next[k] += p * (x[k] - c[k]) as f64;
            }
        }
        let norm = next.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            break;
        }
        var = norm / order.len() as f64;
        axis = next.into_iter().map(|x| x / norm).collect();
    }
    let sigma = var.sqrt();
    let eps = 0.5;
    let mut a: Vec<f32> = (0..dim).map(|k| c[k] + (eps * sigma * axis[k]) as f32).collect();
    let mut b: Vec<f32> = (0..dim).map(|k| c[k] - (eps * sigma * axis[k]) as f32).collect();
    let mut side = vec![false; order.len()];
    let mut last = f64::INFINITY;
    for _ in 0..LLOYD_ITERATIONS {
        let mut distortion = 0.0f64;
        let (mut sa, mut sb) = (vec![0f64; dim], vec![0f64; dim]);
        let (mut na, mut nb) = (0usize, 0usize);
        for (j, &i) in order.iter().enumerate() {
            let x = at(i);
            let (da, db) = (distance(x, &a), distance(x, &b));
            side[j] = db < da;
            let (s, n) = if side[j] { (&mut sb, &mut nb) } else { (&mut sa, &mut na) };
            *n += 1;
            for k in 0..dim {
                s[k] += x[k] as f64;
            }
            distortion += da.min(db) as f64;
        }
        if na == 0 || nb == 0 {
            break;
        }
        a = sa.iter().map(|s| (s / na as f64) as f32).collect();
        b = sb.iter().map(|s| (s / nb as f64) as f32).collect();
        if last - distortion <= 0.001 * last {
            break;
        }
        last = distortion;
    }
    let left = side.iter().filter(|s| !**s).count();
    let n = order.len();
    let least = (n / 8).max(1);
    if left < least || n - left < least {
        // Unbalanced: the median on the principal axis (ties by item).
        let proj = |i: u32| -> f64 { (0..dim).map(|k| (at(i)[k] - c[k]) as f64 * axis[k]).sum() };
        order.sort_by(|&x, &y| proj(x).total_cmp(&proj(y)).then(x.cmp(&y)));
        return n / 2;
    }
    // Stable partition: left side first, each side in its original order.
    let (l, r): (Vec<u32>, Vec<u32>) = {
        let mut l = Vec::with_capacity(left);
        let mut r = Vec::with_capacity(n - left);
        for (j, &i) in order.iter().enumerate() {
            if side[j] {
                r.push(i)
            } else {
                l.push(i)
            }
        }
        (l, r)
    };
    order[..left].copy_from_slice(&l);
    order[left..].copy_from_slice(&r);
    left
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points(n: usize, dim: usize) -> Vec<f32> {
        (0..n * dim).map(|i| ((i as u64 * 2654435761 % 1000) as f32) / 10.0).collect()
    }

    fn brute(v: &[f32], dim: usize, q: &[f32], keep: impl Fn(u32) -> bool) -> Option<(f32, u32)> {
        (0..v.len() / dim)
            .filter(|&i| keep(i as u32))
            .map(|i| (distance(&v[i * dim..(i + 1) * dim], q), i as u32))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
    }

    #[test]
    fn exhaustive_backtracking_equals_brute_force() {
        let dim = 9;
        let v = points(3000, dim);
        let t = Tsvq::new(dim, &v, 16);
        assert!(t.leaves() > 100);
        for qi in 0..50 {
            let q: Vec<f32> = (0..dim).map(|k| ((qi * 31 + k * 7) % 100) as f32).collect();
            let keep = |i: u32| i % 5 != qi as u32 % 5;
            assert_eq!(t.nearest(&q, t.leaves(), keep), brute(&v, dim, &q, keep));
        }
        // Duplicates: ties go to the smallest item.
        let dup: Vec<f32> = [1.0, 2.0, 1.0, 2.0, 1.0, 2.0].repeat(20);
        let t = Tsvq::new(2, &dup, 4);
        assert_eq!(t.nearest(&[1.0, 2.0], t.leaves(), |_| true), Some((0.0, 0)));
    }

    #[test]
    fn greedy_search_is_close_and_the_build_is_deterministic() {
        let dim = 6;
        let v = points(4000, dim);
        let (a, b) = (Tsvq::new(dim, &v, 16), Tsvq::new(dim, &v, 16));
        assert_eq!(a.items, b.items);
        assert_eq!(a.codewords, b.codewords);
        let mut exact = 0;
        for qi in 0..200usize {
            let q = &v[qi * 17 % 4000 * dim..][..dim];
            let got = a.nearest(q, 8, |_| true).unwrap();
            let want = brute(&v, dim, q, |_| true).unwrap();
            assert!(got.0 >= want.0);
            exact += (got.0 == want.0) as usize;
        }
        assert!(exact >= 190, "{exact}/200 exact with B = 8");
    }
}
