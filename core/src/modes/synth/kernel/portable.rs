//! The portable copy of the correction kernel: per pixel, the projection of its neighbourhood
//! tap by tap, then the best of its neighbours' candidates, with edge-aware distances for
//! candidates near a non-toroidal exemplar's edge.

use super::*;

impl Kernel<'_> {
    #[inline(always)]
    pub(super) fn row_portable(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        for (i, o) in out.iter_mut().enumerate() {
            let idx = start + i * step;
            if !full_search_forced() && self.coherent(idx, s) {
                *o = s[idx];
                continue;
            }
            let terms = self.tap_terms(idx, col);
            *o = self.best(idx, s, &terms, sum_taps(&terms, 0..5, 0..5));
        }
    }

    /// Each tap's term of the projection of the synthesized 5×5 neighbourhood around buffer
    /// index `idx` (before the shift), raster order.
    #[inline(always)]
    pub(super) fn tap_terms(&self, idx: usize, col: &[u32]) -> [[i32; RUNTIME_DIMS]; TAPS5] {
        let mut tp = [[0i32; RUNTIME_DIMS]; TAPS5];
        for ((&off, pr), acc) in self.taps.iter().zip(self.proj.chunks_exact(3 * RUNTIME_DIMS)).zip(tp.iter_mut()) {
            let c = col[(idx as isize + off) as usize];
            let (r, g, b) = ((c & 255) as i32, ((c >> 8) & 255) as i32, ((c >> 16) & 255) as i32);
            for d in 0..RUNTIME_DIMS {
                acc[d] = pr[d] * r + pr[RUNTIME_DIMS + d] * g + pr[2 * RUNTIME_DIMS + d] * b;
            }
        }
        tp
    }

    /// Whether a candidate at packed exemplar coordinate `coord` lies within `2h` of an edge of
    /// a non-toroidal exemplar (branch-free: the common case is a no).
    #[inline(always)]
    pub(super) fn near_edge(&self, coord: u32) -> bool {
        let (x, y) = (coord & 0xFFFF, coord >> 16);
        let b = 2 * self.h;
        let (inner_x, inner_y) = (self.ew.saturating_sub(4 * self.h), self.eh.saturating_sub(4 * self.h));
        self.edged & ((x.wrapping_sub(b) >= inner_x) | (y.wrapping_sub(b) >= inner_y))
    }

    /// Which taps a candidate at packed exemplar coordinate `coord` is compared over: `None`
    /// for all of them (toroidal exemplars, and texels at least `2h` from every edge).
    #[inline(always)]
    pub(super) fn inner_taps(&self, coord: u32) -> Option<InnerTaps> {
        self.near_edge(coord).then(|| self.inner_of(coord))
    }

    /// The taps inside the exemplar around the candidate at packed coordinate `coord` of a
    /// non-toroidal exemplar ([`InnerTaps::around`], looked up per axis).
    #[inline(always)]
    pub(super) fn inner_of(&self, coord: u32) -> InnerTaps {
        let ([r0, r1], [c0, c1]) = (self.span_y[(coord >> 16) as usize], self.span_x[(coord & 0xFFFF) as usize]);
        InnerTaps { r0, r1, c0, c1 }
    }

    /// The best of the 18 k-coherence candidates for the pixel at buffer index `idx`, whose
    /// neighbourhood's per-tap terms are `terms` and feature `ns`: the smallest squared feature
    /// distance, scaled by `φ` of the candidate's rank and by the share of taps compared.
    #[inline(always)]
    pub(super) fn best(&self, idx: usize, s: &[u32], terms: &[[i32; RUNTIME_DIMS]; TAPS5], ns: [i32; RUNTIME_DIMS]) -> u32 {
        let mut best = (u64::MAX, s[idx]);
        for (k, &phi_k) in self.phi.iter().enumerate() {
            for &(off, subx, suby) in &self.nb_off {
                let v = add_wrapped(s[(idx as isize + off) as usize], subx | suby << 16, self.ew, self.eh);
                let cand = &self.cands[(v >> 16) as usize * self.ew as usize + (v & 0xFFFF) as usize][k];
                let (q, weight) = match self.inner_taps(cand.coord) {
                    None => (ns, FULL_WEIGHT),
                    Some(t) => (
                        sum_taps(terms, t.r0 as usize..t.r1 as usize, t.c0 as usize..t.c1 as usize),
                        partial_weight(&t),
                    ),
                };
                let mut d = 0u32;
                for (a, &b) in q.iter().zip(&cand.feat) {
                    let e = a - b as i32;
                    d = d.wrapping_add((e * e) as u32);
                }
                let dd = d as u64 * phi_k * weight;
                if dd < best.0 {
                    best = (dd, cand.coord);
                }
            }
        }
        best.1
    }
}

/// The feature of the taps in `rows × cols` of a neighbourhood's per-tap terms (raster order).
#[inline(always)]
fn sum_taps(
    terms: &[[i32; RUNTIME_DIMS]; TAPS5],
    rows: std::ops::Range<usize>,
    cols: std::ops::Range<usize>,
) -> [i32; RUNTIME_DIMS] {
    let mut q = [0i32; RUNTIME_DIMS];
    for r in rows {
        for t in &terms[5 * r + cols.start..5 * r + cols.end] {
            for d in 0..RUNTIME_DIMS {
                q[d] += t[d];
            }
        }
    }
    q.map(|a| a >> FEAT_SHIFT)
}
