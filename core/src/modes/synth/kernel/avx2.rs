//! The AVX2 copy of the correction kernel (x86-64 only, chosen at run time): candidates found by
//! vector gathers, the projection by 16-bit multiply-adds, both candidates of a neighbour
//! compared in one register, the first minima by vector compares — the same integers as the
//! portable copy.

use super::*;

impl Kernel<'_> {
    /// The AVX2 copy. The projection — most of the work — multiplies the 8-bit channels as
    /// 16-bit pairs with `vpmaddwd` (every product and pair sum exact in i32): for a pixel
    /// whose candidates are all away from an exemplar edge, one channel of two adjacent taps
    /// per instruction, summing whole rows; otherwise two channels of one tap, keeping the
    /// 2-D prefix sums of the taps' terms for [`Kernel::edge_distances_avx2`]. Both give the same sum.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    pub(super) fn row_avx2(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        use std::arch::x86_64::*;
        // SAFETY (both): `[i16; 16]` and `__m256i` have the same size; unaligned loads.
        let w: [__m256i; 2 * TAPS5] =
            self.pairs.map(|row| unsafe { _mm256_loadu_si256(row.as_ptr() as *const __m256i) });
        let wr: [__m256i; 30] =
            self.run_pairs.map(|row| unsafe { _mm256_loadu_si256(row.as_ptr() as *const __m256i) });
        // From a colour 0x00BBGGRR broadcast to every 32-bit lane: (R, G) and (B, 0) as i16 pairs.
        let (rg, b0) = (_mm256_set1_epi32(0x8001_8000u32 as i32), _mm256_set1_epi32(0x8080_8002u32 as i32));
        // From two colours broadcast to every 64-bit lane: one channel of both as an i16 pair.
        let chan = [0x8004_8000u32, 0x8005_8001, 0x8006_8002].map(|m| _mm256_set1_epi32(m as i32));
        let single = |v: u32, wt: &[__m256i]| {
            let v = _mm256_set1_epi32(v as i32);
            _mm256_add_epi32(
                _mm256_madd_epi16(_mm256_shuffle_epi8(v, rg), wt[0]),
                _mm256_madd_epi16(_mm256_shuffle_epi8(v, b0), wt[1]),
            )
        };
        // For the comparisons near an exemplar edge: the sum of the projection's terms of the
        // taps above and left of `[row][column]` (2-D prefix sums; row and column 0 stay zero).
        // 8 × 8 so that indices masked by 7 need no bounds checks; rows and columns 6, 7 unused.
        let mut pre = [[_mm256_setzero_si256(); 8]; 8];
        let nb = Neighbours::new(self);
        // The loads below read the 3×3 neighbours (`s[idx ± w ± 1]`, raster order) unchecked,
        // and the gathers `cands` at texels below `m²`.
        let last = start + out.len().saturating_sub(1) * step;
        let (lo, hi) = self.nb_off[1..].iter().fold((0, 0), |(a, b), &(o, _, _)| (o.min(a), o.max(b)));
        let rows = self.nb_off[0].0 == 0
            && (1..9).all(|n| {
                // Raster position 0–8 of neighbour `n` (the centre, position 4, is `n = 0`).
                let r = (if n <= 4 { n - 1 } else { n }) as isize;
                self.nb_off[n].0 == (r / 3 - 1) * nb.w as isize + r % 3 - 1
            });
        if out.is_empty()
            || !rows
            || nb.w < 2
            || (start as isize + lo) < 0
            || last as isize + hi >= s.len() as isize
            || self.cands.len() < self.ew as usize * self.eh as usize
            || self.ew.max(self.eh) > crate::exemplar::MAX_SIDE
            // An exemplar at most `4h` across has every texel near an edge: the vector test
            // of [`Kernel::near_edge_avx2`] assumes some are not.
            || (self.edged && self.ew.min(self.eh) <= 4 * self.h)
        {
            return self.row_portable(s, col, start, step, out);
        }
        let coherent = Coherence::new(self);
        for (i, o) in out.iter_mut().enumerate() {
            let idx = start + i * step;
            if !full_search_forced() && coherent.at(self, idx, s) {
                *o = s[idx];
                continue;
            }
            let (texel, coord, edge) = self.candidates_avx2(idx, s, &nb);
            let mut acc = _mm256_setzero_si256();
            // The 5×5 taps are five runs of five adjacent pixels: one bounds check per run.
            for r in 0..5 {
                let at = (idx as isize + self.taps[5 * r]) as usize;
                let run: &[u32; 5] = col[at..at + 5].try_into().unwrap_or(&[0; 5]);
                if edge == 0 {
                    for (p, wp) in wr[6 * r..6 * r + 6].chunks_exact(3).enumerate() {
                        let v = _mm256_set1_epi64x((run[2 * p] as u64 | (run[2 * p + 1] as u64) << 32) as i64);
                        let t = _mm256_add_epi32(
                            _mm256_madd_epi16(_mm256_shuffle_epi8(v, chan[0]), wp[0]),
                            _mm256_madd_epi16(_mm256_shuffle_epi8(v, chan[1]), wp[1]),
                        );
                        acc = _mm256_add_epi32(acc, _mm256_add_epi32(t, _mm256_madd_epi16(_mm256_shuffle_epi8(v, chan[2]), wp[2])));
                    }
                    acc = _mm256_add_epi32(acc, single(run[4], &w[10 * r + 8..10 * r + 10]));
                } else {
                    // The 2-D prefix sums of the taps' terms, as they are computed.
                    let mut run_sum = _mm256_setzero_si256();
                    for (c, &v) in run.iter().enumerate() {
                        run_sum = _mm256_add_epi32(run_sum, single(v, &w[10 * r + 2 * c..10 * r + 2 * c + 2]));
                        pre[r + 1][c + 1] = _mm256_add_epi32(pre[r][c + 1], run_sum);
                    }
                }
            }
            let acc = if edge == 0 { acc } else { pre[5][5] };
            let ns = _mm256_srai_epi32(acc, FEAT_SHIFT as i32);
            *o = self.best_avx2(s[idx], &texel, &coord, edge, &pre, ns);
        }
    }

    /// The exemplar texels of the pixel at buffer index `idx`'s 3×3 neighbours shifted to it
    /// (centre first, then raster order), and the coordinates of their candidates, rank-major:
    /// candidate `i` is candidate `i / 9` of neighbour `i % 9`. The eight around the centre
    /// are gathered as vectors; `nb` holds their buffer offsets and exemplar shifts.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn candidates_avx2(&self, idx: usize, s: &[u32], nb: &Neighbours) -> ([u32; 9], [[u32; 9]; 2], u32) {
        use std::arch::x86_64::*;
        let (mut texel, mut coord) = ([0u32; 9], [[0u32; 9]; 2]);
        let v = s[idx];
        texel[0] = (v >> 16) * self.ew + (v & 0xFFFF);
        // The eight neighbours are three runs of the buffer: loaded as rows (a gather's
        // latency was a tenth of the kernel's time) and put in raster order.
        // SAFETY: `row_avx2` checked that `idx − w − 1` and `idx + w + 1` lie inside `s`, for
        // every `idx` of its row; each load reads four texels between the two.
        let (above, middle, below) = unsafe {
            let p = s.as_ptr().add(idx);
            (
                _mm_loadu_si128(p.sub(nb.w + 1) as *const __m128i),
                _mm_loadu_si128(p.sub(1) as *const __m128i),
                _mm_loadu_si128(p.add(nb.w - 2) as *const __m128i),
            )
        };
        // (nw, n, ne, w) and (e, sw, s, se).
        let v = _mm256_set_m128i(
            _mm_blend_epi32::<0b0001>(below, _mm_shuffle_epi32::<2>(middle)),
            _mm_blend_epi32::<0b1000>(above, _mm_shuffle_epi32::<0>(middle)),
        );
        // Each coordinate plus its shift, wrapped once: less the side where it reached it.
        let wrap = |v: __m256i, last: __m256i, side: __m256i| {
            _mm256_sub_epi32(v, _mm256_and_si256(_mm256_cmpgt_epi32(v, last), side))
        };
        let vx = wrap(_mm256_add_epi32(_mm256_and_si256(v, nb.low), nb.subx), nb.last_x, nb.w_side);
        let vy = wrap(_mm256_add_epi32(_mm256_srli_epi32(v, 16), nb.suby), nb.last_y, nb.h_side);
        // Row-major texel index: a shift for a power-of-two width (a multiply's latency sits
        // on the gathers' critical path), else a multiply.
        let t = match nb.log2w {
            Some(log2w) => _mm256_or_si256(_mm256_sll_epi32(vy, log2w), vx),
            None => _mm256_add_epi32(_mm256_mullo_epi32(vy, nb.w_side), vx),
        };
        // SAFETY (all four): 8 u32 = 256 bits at `texel[1..]`, `coord[k][1..]`; the gathered
        // texels are below `w·h` (both coordinates wrapped) and `row_avx2` checked that
        // `cands` holds `w·h` pairs of five-u32 candidates.
        unsafe { _mm256_storeu_si256(texel[1..].as_mut_ptr() as *mut __m256i, t) };
        // Candidate pairs are 40 bytes apart; `coord` lies at the same offset in each.
        let base = unsafe { (self.cands.as_ptr() as *const u8).add(std::mem::offset_of!(Candidate, coord)) };
        // Byte offsets of the pairs: below 40·512² < 2^31 (exemplars have at most 512² texels).
        // (`32·t + 8·t`: shifts and an add, not a multiply, on the gathers' critical path.)
        let at = _mm256_add_epi32(_mm256_slli_epi32(t, 5), _mm256_slli_epi32(t, 3));
        // Bit `i`: candidate `i` lies near an edge ([`Kernel::near_edge`]), from the registers.
        let mut edge = 0;
        for (k, c) in coord.iter_mut().enumerate() {
            c[0] = self.cands[texel[0] as usize][k].coord;
            let g = unsafe { _mm256_i32gather_epi32::<1>(base.add(20 * k) as *const i32, at) };
            unsafe { _mm256_storeu_si256(c[1..].as_mut_ptr() as *mut __m256i, g) };
            if self.edged {
                edge |= (self.near_edge(c[0]) as u32 | self.near_edge_avx2(g) << 1) << (9 * k);
            }
        }
        (texel, coord, edge)
    }

    /// [`Kernel::best`] for AVX2, given the candidates: the 18 squared distances as vectors,
    /// summed eight at a time by a horizontal-add tree (wrapping, like the scalar sum), then
    /// compared in the same order with the same tie rule. The candidates flagged in `edge`
    /// are compared again by [`Kernel::edge_distances_avx2`], and then every distance is
    /// scaled by its share of taps, as [`Kernel::best`] does.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn best_avx2(
        &self,
        own: u32,
        texel: &[u32; 9],
        coord: &[[u32; 9]; 2],
        edge: u32,
        pre: &[[std::arch::x86_64::__m256i; 8]; 8],
        ns: std::arch::x86_64::__m256i,
    ) -> u32 {
        use std::arch::x86_64::*;
        const N: usize = 18;
        // Features fit i16 and so do their differences (|Ñ| ≤ 255·√75·4·(1 + 2⁻¹²) < 8 900
        // in quarter colour units, for any subset of taps too): both candidates of a
        // neighbour are compared in one register, `vpmaddwd` squaring and pair-summing
        // the differences (each pair sum < 2³¹), the same values as the scalar sum.
        let ns16 = both_halves_i16(ns);
        let mut sq = [_mm256_setzero_si256(); 9];
        for (n, &t) in texel.iter().enumerate() {
            let pair = &self.cands[t as usize];
            // SAFETY: `feat` is 8 i16 = 128 bits; unaligned loads.
            let f = unsafe {
                _mm256_loadu2_m128i(pair[1].feat.as_ptr() as *const __m128i, pair[0].feat.as_ptr() as *const __m128i)
            };
            let e = _mm256_sub_epi16(ns16, f);
            sq[n] = _mm256_madd_epi16(e, e);
        }
        let coord = coord.as_flattened();
        if edge == 0 {
            // All compared over every tap: the common scale can be left out, and within a rank
            // the first smallest distance is the first smallest scaled one; the first rank wins
            // a tie between the two, as in the scan of [`Kernel::best`].
            let (b0, m0, b1, m1) = first_minima(&sq);
            let win = if m1 as u64 * self.phi[1] < m0 as u64 * self.phi[0] { b1 } else { b0 };
            return coord[win];
        }
        let mut weight = [FULL_WEIGHT; N];
        self.edge_distances_avx2(pre, edge, texel, &mut sq, &mut weight);
        let d = hsum18(&sq);
        // `φ · scale` stays below 2³¹ when `κ ≤ 1` (φ ≤ 4·2¹⁶, scales ≤ 800): the 18
        // products then compare as vectors; otherwise one by one.
        if self.phi[1].max(self.phi[0]) <= MAX_PHI_NARROW {
            let scale: [u32; N] = std::array::from_fn(|i| (self.phi[i / 9] * weight[i]) as u32);
            return coord[first_smallest_product(&d, &scale)];
        }
        let mut best = (u64::MAX, own);
        for (i, ((&d, &c), &w)) in d.iter().zip(coord).zip(&weight).enumerate() {
            let dd = d as u64 * self.phi[i / 9] * w;
            if dd < best.0 {
                best = (dd, c);
            }
        }
        best.1
    }

    /// [`Kernel::near_edge`] of eight packed coordinates, as bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn near_edge_avx2(&self, v: std::arch::x86_64::__m256i) -> u32 {
        use std::arch::x86_64::*;
        let b = _mm256_set1_epi32((2 * self.h) as i32);
        // `v − 2h < w − 4h` (unsigned) ⇔ `min(v − 2h, w − 4h − 1) = v − 2h` (`row_avx2` checked
        // that `w, h > 4h`).
        let last_x = _mm256_set1_epi32((self.ew - 4 * self.h - 1) as i32);
        let last_y = _mm256_set1_epi32((self.eh - 4 * self.h - 1) as i32);
        let x = _mm256_sub_epi32(_mm256_and_si256(v, _mm256_set1_epi32(0xFFFF)), b);
        let y = _mm256_sub_epi32(_mm256_srli_epi32(v, 16), b);
        let inside = _mm256_and_si256(
            _mm256_cmpeq_epi32(_mm256_min_epu32(x, last_x), x),
            _mm256_cmpeq_epi32(_mm256_min_epu32(y, last_y), y),
        );
        !(_mm256_movemask_ps(_mm256_castsi256_ps(inside)) as u32) & 0xFF
    }

    /// The squared feature differences and distance scales of the candidates flagged in
    /// `edge` (bit `k·9 + n`: candidate `k` of neighbour `n`, whose texel is `texel[n]`),
    /// compared over their real texels only: the pixel's projection summed over the taps
    /// inside the exemplar, from the 2-D prefix sums of its taps' terms (`pre`: any rectangle
    /// of taps in three operations).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline(never)]
    fn edge_distances_avx2(
        &self,
        pre: &[[std::arch::x86_64::__m256i; 8]; 8],
        edge: u32,
        texel: &[u32; 9],
        sq: &mut [std::arch::x86_64::__m256i; 9],
        weight: &mut [u64; 18],
    ) {
        use std::arch::x86_64::*;
        for k in 0..2 {
            let mut bits = edge >> (9 * k) & 0x1FF;
            while bits != 0 {
                let n = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                let cand = &self.cands[texel[n] as usize][k];
                let t = self.inner_of(cand.coord);
                weight[9 * k + n] = partial_weight(&t);
                // Spans are at most 5 ([`InnerTaps::around`]): the masks only spare the checks.
                let (r0, r1, c0, c1) = (t.r0 as usize & 7, t.r1 as usize & 7, t.c0 as usize & 7, t.c1 as usize & 7);
                let q = _mm256_sub_epi32(
                    _mm256_add_epi32(pre[r1][c1], pre[r0][c0]),
                    _mm256_add_epi32(pre[r0][c1], pre[r1][c0]),
                );
                let q = _mm256_srai_epi32(q, FEAT_SHIFT as i32);
                let q16 = _mm_packs_epi32(_mm256_castsi256_si128(q), _mm256_extracti128_si256(q, 1));
                // SAFETY: `feat` is 8 i16 = 128 bits; unaligned load.
                let f = unsafe { _mm_loadu_si128(cand.feat.as_ptr() as *const __m128i) };
                let e = _mm_sub_epi16(q16, f);
                let v = _mm_madd_epi16(e, e);
                sq[n] = if k == 0 { _mm256_inserti128_si256(sq[n], v, 0) } else { _mm256_inserti128_si256(sq[n], v, 1) };
            }
        }
    }
}

/// The eight neighbours around the centre of [`Kernel::nb_off`] as vectors, for
/// [`Kernel::candidates_avx2`].
#[cfg(target_arch = "x86_64")]
struct Neighbours {
    /// The buffer's width: the neighbours are at `±1`, `±w`, `±w ± 1`.
    w: usize,
    subx: std::arch::x86_64::__m256i,
    suby: std::arch::x86_64::__m256i,
    /// The exemplar's width and height, and each less one.
    w_side: std::arch::x86_64::__m256i,
    h_side: std::arch::x86_64::__m256i,
    last_x: std::arch::x86_64::__m256i,
    last_y: std::arch::x86_64::__m256i,
    low: std::arch::x86_64::__m256i,
    /// `log2` of a power-of-two width.
    log2w: Option<std::arch::x86_64::__m128i>,
}

#[cfg(target_arch = "x86_64")]
impl Neighbours {
    #[target_feature(enable = "avx2")]
    fn new(k: &Kernel) -> Self {
        use std::arch::x86_64::*;
        let lane = |f: &dyn Fn(&(isize, u32, u32)) -> i32| {
            let v: [i32; 8] = std::array::from_fn(|n| f(&k.nb_off[n + 1]));
            // SAFETY: 8 i32 = 256 bits; unaligned load.
            unsafe { _mm256_loadu_si256(v.as_ptr() as *const __m256i) }
        };
        Neighbours {
            w: k.nb_off[7].0.unsigned_abs(),
            subx: lane(&|n| n.1 as i32),
            suby: lane(&|n| n.2 as i32),
            w_side: _mm256_set1_epi32(k.ew as i32),
            h_side: _mm256_set1_epi32(k.eh as i32),
            last_x: _mm256_set1_epi32(k.ew as i32 - 1),
            last_y: _mm256_set1_epi32(k.eh as i32 - 1),
            low: _mm256_set1_epi32(0xFFFF),
            log2w: k.ew.is_power_of_two().then(|| _mm_cvtsi32_si128(k.ew.trailing_zeros() as i32)),
        }
    }
}

/// [`Kernel::coherent`] for AVX2: each row of five taps compared at once.
#[cfg(target_arch = "x86_64")]
struct Coherence {
    /// Per row of taps, the shifts of its five taps (lanes 5–7 unused).
    shift: [std::arch::x86_64::__m256i; 5],
    /// Both packed coordinates' largest values (`w − 1 | (h − 1) << 16`) and sides.
    last: std::arch::x86_64::__m256i,
    sides: std::arch::x86_64::__m256i,
    /// Lanes 0–4 of a row: loaded and compared.
    lanes: std::arch::x86_64::__m256i,
}

#[cfg(target_arch = "x86_64")]
impl Coherence {
    #[target_feature(enable = "avx2")]
    fn new(k: &Kernel) -> Self {
        use std::arch::x86_64::*;
        let load = |v: [u32; 8]| {
            // SAFETY: 8 u32 = 256 bits; unaligned load.
            unsafe { _mm256_loadu_si256(v.as_ptr() as *const __m256i) }
        };
        Coherence {
            shift: std::array::from_fn(|r| load(std::array::from_fn(|c| if c < 5 { k.shift[5 * r + c] } else { 0 }))),
            last: _mm256_set1_epi32(((k.ew - 1) | ((k.eh - 1) << 16)) as i32),
            sides: _mm256_set1_epi32((k.ew | k.eh << 16) as i32),
            lanes: load(std::array::from_fn(|c| if c < 5 { u32::MAX } else { 0 })),
        }
    }

    /// Whether the 5×5 neighbourhood of buffer index `idx` is coherent.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn at(&self, k: &Kernel, idx: usize, s: &[u32]) -> bool {
        use std::arch::x86_64::*;
        let v = _mm256_set1_epi32(s[idx] as i32);
        // The centre row first, then outwards: most pixels that are not coherent show it
        // there, and leave after one row.
        for r in [2, 1, 3, 0, 4] {
            let at = (idx as isize + k.taps[5 * r]) as usize;
            let Some(run) = s.get(at..at + 5) else { return k.coherent(idx, s) };
            // SAFETY: only lanes 0–4 are read (`lanes`), all inside `run`.
            let got = unsafe { _mm256_maskload_epi32(run.as_ptr() as *const i32, self.lanes) };
            // Both 16-bit halves wrapped once (each below 2¹⁰: the signed compare is right).
            let sum = _mm256_add_epi32(v, self.shift[r]);
            let want = _mm256_sub_epi16(sum, _mm256_and_si256(_mm256_cmpgt_epi16(sum, self.last), self.sides));
            if _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(got, want))) & 0x1F != 0x1F {
                return false;
            }
        }
        true
    }
}

/// A pixel's feature (eight i32 lanes, each within i16) as eight i16 lanes, in both halves.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn both_halves_i16(v: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    // Per half: (0–3, 0–3) and (4–7, 4–7); then 64-bit lanes (0, 2, 0, 2).
    _mm256_permute4x64_epi64(_mm256_packs_epi32(v, v), 0b10_00_10_00)
}

/// The squared distances of `sq` (neighbour `n`'s rank-0 candidate in the low half of
/// `sq[n]`, its rank-1 candidate in the high half; four partial sums each), summed by a
/// horizontal-add tree: neighbours 0–3 of each rank (rank 0 in the low half, rank 1 in the
/// high half), neighbours 4–7 likewise, and neighbour 8 in lane 0 of each half.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn hsum18_vectors(
    sq: &[std::arch::x86_64::__m256i; 9],
) -> (std::arch::x86_64::__m256i, std::arch::x86_64::__m256i, std::arch::x86_64::__m256i) {
    use std::arch::x86_64::*;
    let h = |a: __m256i, b: __m256i| _mm256_hadd_epi32(a, b);
    let zero = _mm256_setzero_si256();
    (h(h(sq[0], sq[1]), h(sq[2], sq[3])), h(h(sq[4], sq[5]), h(sq[6], sq[7])), h(h(sq[8], zero), zero))
}

/// The 18 squared distances of `sq` ([`hsum18_vectors`]), rank-major: distance `k·9 + n` is
/// that of candidate `k` of neighbour `n`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn hsum18(sq: &[std::arch::x86_64::__m256i; 9]) -> [u32; 18] {
    use std::arch::x86_64::*;
    let (x, y, z) = hsum18_vectors(sq);
    let mut d = [0u32; 18];
    // SAFETY (both): 8 u32 = 256 bits at `d[0..]` and `d[9..]`; unaligned stores.
    unsafe { _mm256_storeu_si256(d.as_mut_ptr() as *mut __m256i, _mm256_permute2x128_si256(x, y, 0x20)) };
    d[8] = _mm256_extract_epi32(z, 0) as u32;
    unsafe { _mm256_storeu_si256(d[9..].as_mut_ptr() as *mut __m256i, _mm256_permute2x128_si256(x, y, 0x31)) };
    d[17] = _mm256_extract_epi32(z, 4) as u32;
    d
}

/// Of the 18 squared distances of `sq` (as [`hsum18`]), the first smallest of rank 0 (0–8)
/// and of rank 1 (9–17), with their values — both ranks at once by vector minima and compare
/// masks (a scalar scan is a chain of loads and conditional moves).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn first_minima(sq: &[std::arch::x86_64::__m256i; 9]) -> (usize, u32, usize, u32) {
    use std::arch::x86_64::*;
    let (x, y, z) = hsum18_vectors(sq);
    // Per half (rank), the minimum over neighbours 0–3, 4–7 and 8, then in every lane.
    let m = _mm256_min_epu32(_mm256_min_epu32(x, y), _mm256_shuffle_epi32(z, 0));
    let m = _mm256_min_epu32(m, _mm256_shuffle_epi32(m, 0b01_00_11_10));
    let m = _mm256_min_epu32(m, _mm256_shuffle_epi32(m, 0b10_11_00_01));
    let mask = |v: __m256i| _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(v, m))) as u32;
    let (mx, my) = (mask(x), mask(y));
    // Bit `n`: neighbour `n` (0–7) reaches the minimum; none — neighbour 8 does.
    let first = |bits: u32| if bits != 0 { bits.trailing_zeros() as usize } else { 8 };
    let b0 = first((mx & 0xF) | (my & 0xF) << 4);
    let b1 = 9 + first(mx >> 4 | (my >> 4) << 4);
    (b0, _mm256_extract_epi32(m, 0) as u32, b1, _mm256_extract_epi32(m, 4) as u32)
}

/// The index of the first smallest of the 18 products `d[i] · scale[i]`, for scales below 2³¹
/// (so every product is below 2⁶³): the same as a scan keeping the first strictly smaller one.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn first_smallest_product(d: &[u32; 18], scale: &[u32; 18]) -> usize {
    use std::arch::x86_64::*;
    // Padded to 20 with a product no real one exceeds ((2³² − 1) · 2³¹ < 2⁶³).
    let (mut dp, mut sp) = ([u32::MAX; 20], [1u32 << 31; 20]);
    dp[..18].copy_from_slice(d);
    sp[..18].copy_from_slice(scale);
    // SAFETY: 4 u32 = 128 bits at `4j` for `j < 5`, inside the 20; unaligned loads.
    let load = |a: &[u32; 20], j: usize| unsafe { _mm256_cvtepu32_epi64(_mm_loadu_si128(a[4 * j..].as_ptr() as *const __m128i)) };
    let v: [__m256i; 5] = std::array::from_fn(|j| _mm256_mul_epu32(load(&dp, j), load(&sp, j)));
    // Products are below 2⁶³: signed comparison is the unsigned one.
    let min = |a: __m256i, b: __m256i| _mm256_blendv_epi8(b, a, _mm256_cmpgt_epi64(b, a));
    let m = min(min(min(v[0], v[1]), min(v[2], v[3])), v[4]);
    let m = min(m, _mm256_permute4x64_epi64(m, 0b01_00_11_10));
    let m = min(m, _mm256_permute4x64_epi64(m, 0b10_11_00_01));
    let bits = v.iter().enumerate().fold(0u32, |bits, (j, &x)| {
        bits | (_mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(x, m))) as u32) << (4 * j)
    });
    bits.trailing_zeros() as usize
}

#[cfg(all(test, target_arch = "x86_64"))]
mod minima_tests {
    use super::*;

    /// The vector minima equal the scalar scan's first smallest per rank, ties and the largest
    /// values included.
    #[test]
    fn first_minima_equal_a_scalar_scan() {
        if skip_without_avx2("first_minima_equal_a_scalar_scan") {
            return;
        }
        use std::arch::x86_64::*;
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for round in 0..20_000 {
            // Few distinct values (many ties), the extremes, or anything.
            let value = |r: u64| match round % 3 {
                0 => (r % 4) as u32,
                1 => [0, 1, u32::MAX - 1, u32::MAX][(r % 4) as usize],
                _ => r as u32,
            };
            // Each distance is one lane of its half (neighbour `i % 9`, rank `i / 9`), the other
            // three zero, so the sum is that lane.
            let mut d = [0u32; 18];
            let mut halves = [[0u32; 8]; 9];
            for (i, v) in d.iter_mut().enumerate() {
                *v = value(next());
                halves[i % 9][4 * (i / 9) + (next() % 4) as usize] = *v;
            }
            // SAFETY: 8 u32 = 256 bits; unaligned loads.
            let sq = halves.map(|h| unsafe { _mm256_loadu_si256(h.as_ptr() as *const __m256i) });
            let first_min = |r: std::ops::Range<usize>| {
                let mut b = r.start;
                for i in r {
                    if d[i] < d[b] {
                        b = i;
                    }
                }
                b
            };
            let (b0, b1) = (first_min(0..9), first_min(9..18));
            // SAFETY: the processor supports AVX2 (checked above).
            assert_eq!(unsafe { first_minima(&sq) }, (b0, d[b0], b1, d[b1]), "{d:?}");
            assert_eq!(unsafe { hsum18(&sq) }, d);
            // Scales as near an edge: κ = 1 at most (φ ≤ 4·2¹⁶) and up to the bound of the vector path.
            let scale: [u32; 18] = std::array::from_fn(|_| match next() % 3 {
                0 => 4 << 16,
                1 => (MAX_PHI_NARROW * 800) as u32,
                _ => (next() % (MAX_PHI_NARROW * 800)) as u32,
            });
            let mut best = (u64::MAX, 18);
            for i in 0..18 {
                let p = d[i] as u64 * scale[i] as u64;
                if p < best.0 {
                    best = (p, i);
                }
            }
            // SAFETY: the processor supports AVX2 (checked above).
            assert_eq!(unsafe { first_smallest_product(&d, &scale) }, best.1, "{d:?} {scale:?}");
        }
    }
}
