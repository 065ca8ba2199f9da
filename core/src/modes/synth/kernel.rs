//! The correction kernel (design note §1.3): for one pixel, its 5×5 neighbourhood projected to
//! the runtime feature space, compared with the 18 k-coherence candidates of its 3×3 neighbours;
//! written twice — portable, and with AVX2 intrinsics (16-bit multiply-add projection, a
//! horizontal-add tree for the 18 distances), chosen at run time — in integer arithmetic, so
//! both give identical results.

use crate::analysis::Candidate;
use crate::analysis::features::{FEAT_SHIFT, RUNTIME_DIMS, TAPS5};

/// The correction kernel of one level: everything a pixel's correction reads besides the
/// snapshot buffers.
pub(crate) struct Kernel<'a> {
    /// Buffer offsets of the 5×5 neighbourhood, raster order.
    pub taps: [isize; TAPS5],
    /// Buffer offset and exemplar shift `−h·Δ mod m` (x, y) of the 9 candidate neighbours.
    pub nb_off: [(isize, u32, u32); 9],
    /// Projection widened to i32, `[tap][channel][dim]`.
    pub proj: &'a [i32],
    /// The same projection as i16 pairs for multiply-add (`vpmaddwd`): per tap, one row of
    /// `(red, green)` weights per dimension and one of `(blue, 0)`.
    pub pairs: [[i16; 2 * RUNTIME_DIMS]; 2 * TAPS5],
    pub cands: &'a [[Candidate; 2]],
    pub m: usize,
    pub mask: u32,
    pub phi: [u64; 2],
}

impl Kernel<'_> {
    /// Correct the pixels `start, start + step, …` of one row (one per `out` entry). Runs a copy
    /// compiled for AVX2 when the processor has it; integer arithmetic makes both copies give
    /// identical results.
    pub fn row(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") && !tests::portable_forced() {
                // SAFETY: the processor supports AVX2 (checked just above).
                unsafe { self.row_avx2(s, col, start, step, out) };
                return;
            }
        }
        self.row_portable(s, col, start, step, out);
    }

    /// The AVX2 copy. The projection — most of the work — multiplies the 8-bit channels as
    /// 16-bit pairs with `vpmaddwd` (two channels per instruction, every product and pair sum
    /// exact in i32); the candidate comparison is the shared code, compiled for AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn row_avx2(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        use std::arch::x86_64::*;
        // SAFETY: `[i16; 16]` and `__m256i` have the same size; unaligned loads are used.
        let w: [__m256i; 2 * TAPS5] =
            self.pairs.map(|row| unsafe { _mm256_loadu_si256(row.as_ptr() as *const __m256i) });
        // From a colour 0x00BBGGRR broadcast to every 32-bit lane: (R, G) and (B, 0) as i16 pairs.
        let rg = _mm256_set1_epi32(0x8001_8000u32 as i32);
        let b0 = _mm256_set1_epi32(0x8080_8002u32 as i32);
        for (i, o) in out.iter_mut().enumerate() {
            let idx = start + i * step;
            let mut acc = _mm256_setzero_si256();
            // The 5×5 taps are five runs of five adjacent pixels: one bounds check per run.
            for (r, wr) in w.chunks_exact(10).enumerate() {
                let at = (idx as isize + self.taps[5 * r]) as usize;
                let run: &[u32; 5] = col[at..at + 5].try_into().unwrap_or(&[0; 5]);
                for (&c, wt) in run.iter().zip(wr.chunks_exact(2)) {
                    let c = _mm256_set1_epi32(c as i32);
                    acc = _mm256_add_epi32(acc, _mm256_madd_epi16(_mm256_shuffle_epi8(c, rg), wt[0]));
                    acc = _mm256_add_epi32(acc, _mm256_madd_epi16(_mm256_shuffle_epi8(c, b0), wt[1]));
                }
            }
            *o = self.best_avx2(idx, s, _mm256_srai_epi32(acc, FEAT_SHIFT as i32));
        }
    }

    /// [`Kernel::best`] for AVX2: the 18 squared distances as vectors, summed eight at a time
    /// by a horizontal-add tree (wrapping, like the scalar sum), then compared in the same
    /// order with the same tie rule.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    #[inline]
    fn best_avx2(&self, idx: usize, s: &[u32], ns: std::arch::x86_64::__m256i) -> u32 {
        use std::arch::x86_64::*;
        const N: usize = 18;
        let (mut sq, mut coord) = ([_mm256_setzero_si256(); N + 6], [0u32; N]);
        for (n, &(off, subx, suby)) in self.nb_off.iter().enumerate() {
            let v = s[(idx as isize + off) as usize];
            let vx = ((v & 0xFFFF) + subx) & self.mask;
            let vy = ((v >> 16) + suby) & self.mask;
            let pair = &self.cands[vy as usize * self.m + vx as usize];
            for (k, cand) in pair.iter().enumerate() {
                // SAFETY: `feat` is 8 i16 = 128 bits; unaligned load.
                let f = unsafe { _mm_loadu_si128(cand.feat.as_ptr() as *const __m128i) };
                let e = _mm256_sub_epi32(ns, _mm256_cvtepi16_epi32(f));
                sq[k * 9 + n] = _mm256_mullo_epi32(e, e);
                coord[k * 9 + n] = cand.coord;
            }
        }
        let mut d = [0u32; N + 6];
        for (group, out) in sq.chunks(8).zip(d.chunks_mut(8)) {
            let h = |a: usize, b: usize| _mm256_hadd_epi32(group[a], group[b]);
            let (u0, u1) = (_mm256_hadd_epi32(h(0, 1), h(2, 3)), _mm256_hadd_epi32(h(4, 5), h(6, 7)));
            let sums =
                _mm256_add_epi32(_mm256_permute2x128_si256(u0, u1, 0x20), _mm256_permute2x128_si256(u0, u1, 0x31));
            // SAFETY: `out` is 8 u32 = 256 bits; unaligned store.
            unsafe { _mm256_storeu_si256(out.as_mut_ptr() as *mut __m256i, sums) };
        }
        let mut best = (u64::MAX, s[idx]);
        for (i, (&d, &c)) in d.iter().zip(&coord).enumerate() {
            let dd = d as u64 * self.phi[i / 9];
            if dd < best.0 {
                best = (dd, c);
            }
        }
        best.1
    }

    #[inline(always)]
    fn row_portable(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        for (i, o) in out.iter_mut().enumerate() {
            let idx = start + i * step;
            *o = self.best(idx, s, self.project(idx, col));
        }
    }

    /// The runtime feature of the synthesized 5×5 neighbourhood around buffer index `idx`.
    #[inline(always)]
    fn project(&self, idx: usize, col: &[u32]) -> [i32; RUNTIME_DIMS] {
        let mut acc = [0i32; RUNTIME_DIMS];
        for (t, &off) in self.taps.iter().enumerate() {
            let c = col[(idx as isize + off) as usize];
            let (r, g, b) = ((c & 255) as i32, ((c >> 8) & 255) as i32, ((c >> 16) & 255) as i32);
            let pr: &[i32; 3 * RUNTIME_DIMS] = self.proj[t * 3 * RUNTIME_DIMS..(t + 1) * 3 * RUNTIME_DIMS]
                .try_into()
                .unwrap_or(&[0; 3 * RUNTIME_DIMS]);
            for d in 0..RUNTIME_DIMS {
                acc[d] += pr[d] * r + pr[RUNTIME_DIMS + d] * g + pr[2 * RUNTIME_DIMS + d] * b;
            }
        }
        acc.map(|a| a >> FEAT_SHIFT)
    }

    /// The best of the 18 k-coherence candidates for the pixel at buffer index `idx`, whose
    /// neighbourhood feature is `ns`.
    #[inline(always)]
    fn best(&self, idx: usize, s: &[u32], ns: [i32; RUNTIME_DIMS]) -> u32 {
        let mut best = (u64::MAX, s[idx]);
        for (k, &phi_k) in self.phi.iter().enumerate() {
            for &(off, subx, suby) in &self.nb_off {
                let v = s[(idx as isize + off) as usize];
                let vx = ((v & 0xFFFF) + subx) & self.mask;
                let vy = ((v >> 16) + suby) & self.mask;
                let cand = &self.cands[vy as usize * self.m + vx as usize][k];
                let mut d = 0u32;
                for (a, &b) in ns.iter().zip(&cand.feat) {
                    let e = a - b as i32;
                    d = d.wrapping_add((e * e) as u32);
                }
                let dd = d as u64 * phi_k;
                if dd < best.0 {
                    best = (dd, cand.coord);
                }
            }
        }
        best.1
    }
}

/// The multiply-add layout of a `[tap][channel][dim]` projection (see [`Kernel::pairs`]).
pub(crate) fn projection_pairs(proj: &[i16]) -> [[i16; 2 * RUNTIME_DIMS]; 2 * TAPS5] {
    let mut pairs = [[0i16; 2 * RUNTIME_DIMS]; 2 * TAPS5];
    let at = |t: usize, c: usize, d: usize| proj.get((t * 3 + c) * RUNTIME_DIMS + d).copied().unwrap_or(0);
    for (t, two) in pairs.chunks_mut(2).enumerate() {
        for d in 0..RUNTIME_DIMS {
            two[0][2 * d] = at(t, 0, d);
            two[0][2 * d + 1] = at(t, 1, d);
            two[1][2 * d] = at(t, 2, d);
        }
    }
    pairs
}

#[cfg(not(test))]
mod tests {
    pub(super) fn portable_forced() -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicBool, Ordering};

    use crate::geom::Rect;
    use crate::modes::synth::params::SynthParams;
    use crate::modes::synth::window::synthesize;
    use crate::{Analysis, Exemplar, ExemplarOptions, NoProgress};

    static FORCE_PORTABLE: AtomicBool = AtomicBool::new(false);

    pub(super) fn portable_forced() -> bool {
        FORCE_PORTABLE.load(Ordering::Relaxed)
    }

    #[test]
    fn simd_and_portable_kernels_agree() {
        let px: Vec<[u8; 4]> = (0..64 * 64u32)
            .map(|i| {
                let (x, y) = (i % 64, i / 64);
                [((x * 7 + y * 3) % 256) as u8, ((x * y) % 251) as u8, ((x ^ y) * 5 % 256) as u8, 255]
            })
            .collect();
        let an = Analysis::build(&Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default()), &NoProgress);
        let other = SynthParams { seed: 9, passes: 3, subpasses: 1, kappa: 1 << 16, ..SynthParams::default() };
        for p in [SynthParams::default(), other] {
            let r = Rect::new(-70, 33, 150, 90);
            let fast = synthesize(&an, &p, 6, r).unwrap();
            FORCE_PORTABLE.store(true, Ordering::Relaxed);
            let portable = synthesize(&an, &p, 6, r).unwrap();
            FORCE_PORTABLE.store(false, Ordering::Relaxed);
            assert_eq!(fast, portable, "{p:?}");
        }
    }
}
