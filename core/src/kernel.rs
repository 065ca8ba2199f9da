//! The correction kernel (design note §1.3): for one pixel, its 5×5 neighbourhood projected to
//! the runtime feature space, compared with the 18 k-coherence candidates of its 3×3 neighbours;
//! compiled twice (portable and AVX2, chosen at run time), with integer arithmetic so both give
//! identical results.

use crate::analysis::Candidate;
use crate::features::{FEAT_SHIFT, RUNTIME_DIMS, TAPS5};

/// The correction kernel of one level: everything a pixel's correction reads besides the
/// snapshot buffers.
pub(crate) struct Kernel<'a> {
    /// Buffer offsets of the 5×5 neighbourhood, raster order.
    pub taps: [isize; TAPS5],
    /// Buffer offset and exemplar shift `−h·Δ mod m` (x, y) of the 9 candidate neighbours.
    pub nb_off: [(isize, u32, u32); 9],
    /// Projection widened to i32, `[tap][channel][dim]`.
    pub proj: &'a [i32],
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

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn row_avx2(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        self.row_portable(s, col, start, step, out);
    }

    #[inline(always)]
    fn row_portable(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.pixel(start + i * step, s, col);
        }
    }

    /// The best of the 18 k-coherence candidates for the pixel at buffer index `idx`.
    #[inline(always)]
    fn pixel(&self, idx: usize, s: &[u32], col: &[u32]) -> u32 {
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
        let ns = acc.map(|a| a >> FEAT_SHIFT);
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
    use crate::params::SynthParams;
    use crate::synth::synthesize;
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
        let p = SynthParams::default();
        let r = Rect::new(-70, 33, 150, 90);
        let fast = synthesize(&an, &p, 6, r).unwrap();
        FORCE_PORTABLE.store(true, Ordering::Relaxed);
        let portable = synthesize(&an, &p, 6, r).unwrap();
        FORCE_PORTABLE.store(false, Ordering::Relaxed);
        assert_eq!(fast, portable);
    }
}
