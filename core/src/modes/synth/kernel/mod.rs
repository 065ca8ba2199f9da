//! The correction kernel (design note §1.3): for one pixel, its 5×5 neighbourhood projected to
//! the runtime feature space, compared with the 18 k-coherence candidates of its 3×3 neighbours
//! — a candidate within `2h` of a non-toroidal exemplar's edge over the taps inside the exemplar
//! only; written twice — portable, and with AVX2 intrinsics (candidates found by vector gathers,
//! a 16-bit multiply-add projection, both candidates of a neighbour compared in one register by
//! a 16-bit multiply-add, the first minima by vector compares), chosen at run time — in integer
//! arithmetic, so both give identical results. The shared rules and the dispatch are here; the
//! two copies are [`portable`] and [`avx2`].

use crate::analysis::Candidate;
use crate::analysis::features::{InnerTaps, FEAT_SHIFT, RUNTIME_DIMS, TAPS5};

/// Distances are scaled by `WEIGHT_ONE / taps compared`, so a candidate near an exemplar edge,
/// compared over fewer taps, competes on its mean squared tap difference (the least common
/// multiple of every possible count: 9, 12, 15, 16, 20, 25) ...
const WEIGHT_ONE: u64 = 3600;
/// ... times this factor: a match over part of the neighbourhood is weaker evidence than one
/// over all of it. 2 keeps exemplar-likeness (texq `nn_err`) better than excluding edge texels
/// did while a band along an edge still reaches the output (1: more edge content, worse
/// `nn_err`; 3: less; bench/README.md).
const PARTIAL_FACTOR: u64 = 2;
/// The largest `φ` whose product with every distance scale stays below 2³¹ (the largest
/// scale is that of 9 taps compared), so that a u32 distance times it stays below 2⁶³;
/// κ ≤ 1 keeps `φ` at most `4 · 2¹⁶`, far below.
const MAX_PHI_NARROW: u64 = i32::MAX as u64 / (PARTIAL_FACTOR * WEIGHT_ONE / 9);
/// The distance scale of a candidate compared over all taps.
const FULL_WEIGHT: u64 = WEIGHT_ONE / TAPS5 as u64;

/// The distance scale of a candidate compared over `inner` only.
#[inline(always)]
fn partial_weight(inner: &InnerTaps) -> u64 {
    const BY_COUNT: [u64; TAPS5 + 1] = {
        let mut t = [0; TAPS5 + 1];
        let mut n = 1;
        while n <= TAPS5 {
            t[n] = PARTIAL_FACTOR * WEIGHT_ONE / n as u64;
            n += 1;
        }
        t
    };
    BY_COUNT[inner.count() as usize]
}

/// The correction kernel of one level: everything a pixel's correction reads besides the
/// snapshot buffers.
pub(crate) struct Kernel<'a> {
    /// Buffer offsets of the 5×5 neighbourhood, raster order.
    pub taps: [isize; TAPS5],
    /// Buffer offset and exemplar shift `−h·Δ` (x mod the width, y mod the height) of the 9
    /// candidate neighbours.
    pub nb_off: [(isize, u32, u32); 9],
    /// Projection widened to i32, `[tap][channel][dim]`.
    pub proj: &'a [i32],
    /// The same projection as i16 pairs for multiply-add (`vpmaddwd`): per tap, one row of
    /// `(red, green)` weights per dimension and one of `(blue, 0)`.
    pub pairs: [[i16; 2 * RUNTIME_DIMS]; 2 * TAPS5],
    /// The projection of two adjacent taps as i16 pairs: per row of taps, for columns (0, 1)
    /// and then (2, 3), one row of `(left, right)` weights per dimension for each channel.
    pub run_pairs: [[i16; 2 * RUNTIME_DIMS]; 30],
    pub cands: &'a [[Candidate; 2]],
    /// Exemplar width.
    pub ew: u32,
    /// Exemplar height.
    pub eh: u32,
    pub phi: [u64; 2],
    /// Stride `h` of the level.
    pub h: u32,
    /// Whether the exemplar has edges (not toroidal): candidates within `2h` of one are
    /// compared over their real texels only.
    pub edged: bool,
    /// Per exemplar column `x`, the first and one past the last tap (of five, stride `h`)
    /// around `x` inside the exemplar (read only when `edged`).
    pub span_x: Vec<[u8; 2]>,
    /// The same per exemplar row.
    pub span_y: Vec<[u8; 2]>,
    /// Per tap `Δ` (raster order), the packed exemplar shift `hΔ` (wrapped) that a coherent
    /// neighbourhood shows there ([`tap_shifts`]).
    pub shift: [u32; TAPS5],
}

/// [`Kernel::shift`] for a `w × h` exemplar at stride `stride`: `(s·dx mod w) | (s·dy mod h)
/// << 16` for the taps `(dx, dy)` of the 5×5 neighbourhood in raster order.
pub(crate) fn tap_shifts((w, h): (u32, u32), stride: u32) -> [u32; TAPS5] {
    let at = |d: i64, n: u32| (d * stride as i64).rem_euclid(n as i64) as u32;
    std::array::from_fn(|t| at(t as i64 % 5 - 2, w) | at(t as i64 / 5 - 2, h) << 16)
}

/// [`Kernel::span_x`] (or `span_y`) for an axis of `n` texels at stride `h`.
pub(crate) fn tap_spans(n: u32, h: u32) -> Vec<[u8; 2]> {
    (0..n).map(|v| InnerTaps::around(v, 0, h, (n, n))).map(|t| [t.c0, t.c1]).collect()
}

/// `a + b` for packed coordinates `x | y << 16` with each part below the exemplar's side
/// (`w`, `h`): the sum of the parts, wrapped once.
#[inline(always)]
pub(crate) fn add_wrapped(a: u32, b: u32, w: u32, h: u32) -> u32 {
    let mut t = a + b;
    if t & 0xFFFF >= w {
        t -= w;
    }
    if t >> 16 >= h {
        t -= h << 16;
    }
    t
}

// The gathers of `Kernel::candidates_avx2` address candidate pairs 40 bytes apart.
const _: () = assert!(std::mem::size_of::<[Candidate; 2]>() == 40);

mod portable;
#[cfg(target_arch = "x86_64")]
mod avx2;

impl Kernel<'_> {
    /// Correct the pixels `start, start + step, …` of one row (one per `out` entry). Runs a copy
    /// compiled for AVX2 when the processor has it; integer arithmetic makes both copies give
    /// identical results.
    pub fn row(&self, s: &[u32], col: &[u32], start: usize, step: usize, out: &mut [u32]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") && !portable_forced() {
                // SAFETY: the processor supports AVX2 (checked just above).
                unsafe { self.row_avx2(s, col, start, step, out) };
                return;
            }
        }
        self.row_portable(s, col, start, step, out);
    }

    /// Whether the 5×5 neighbourhood of the pixel at buffer index `idx` is coherent: every tap
    /// `Δ` holds `s[idx] + hΔ` (wrapped). Such a pixel keeps its texel, exactly as the search
    /// would decide: its neighbourhood's feature is the stored feature of `s[idx]` (the same
    /// colours and integer sums, over the same taps near an edge), so that candidate's
    /// distance is 0; and the first candidates of its 3×3 neighbours, which come first in the
    /// search and win ties, are all `s[idx]` (`C_1(u) = u`). Coherent pixels are common at the
    /// finest level (a third of its corrections on gravel), and cost 25 comparisons instead of
    /// the projection and 18 candidates.
    #[inline(always)]
    pub(super) fn coherent(&self, idx: usize, s: &[u32]) -> bool {
        let v = s[idx];
        // `x + (h·dx mod w) < 2w ≤ 2¹⁶`: the sum of packed coordinates carries nothing across.
        self.taps
            .iter()
            .zip(&self.shift)
            .all(|(&off, &sh)| s[(idx as isize + off) as usize] == add_wrapped(v, sh, self.ew, self.eh))
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

/// The two-tap multiply-add layout of a `[tap][channel][dim]` projection (see
/// [`Kernel::run_pairs`]).
pub(crate) fn projection_run_pairs(proj: &[i16]) -> [[i16; 2 * RUNTIME_DIMS]; 30] {
    let mut pairs = [[0i16; 2 * RUNTIME_DIMS]; 30];
    let at = |t: usize, c: usize, d: usize| proj.get((t * 3 + c) * RUNTIME_DIMS + d).copied().unwrap_or(0);
    for (i, row) in pairs.iter_mut().enumerate() {
        // Row of taps `r`, first column `2p`, channel `c`.
        let (r, p, c) = (i / 6, i % 6 / 3, i % 3);
        let left = 5 * r + 2 * p;
        for d in 0..RUNTIME_DIMS {
            row[2 * d] = at(left, c, d);
            row[2 * d + 1] = at(left + 1, c, d);
        }
    }
    pairs
}

/// Whether the portable kernel must run where AVX2 is there: only the kernel tests ask for it.
#[cfg(all(not(test), target_arch = "x86_64"))]
#[inline(always)]
const fn portable_forced() -> bool {
    false
}

#[cfg(all(test, target_arch = "x86_64"))]
use tests::portable_forced;

/// Whether coherent pixels must be searched like any other: only the test of the shortcut
/// asks for it.
#[cfg(not(test))]
#[inline(always)]
const fn full_search_forced() -> bool {
    false
}

#[cfg(test)]
use tests::full_search_forced;

/// A test that needs AVX2 on a processor without it: a notice the test output shows (written
/// past the harness's capture), so the test is not read as having checked anything.
#[cfg(test)]
pub(super) fn skip_without_avx2(test: &str) -> bool {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return false;
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "\n    SKIPPED {test}: this processor has no AVX2, so there is no SIMD kernel to compare\n");
    true
}

#[cfg(test)]
pub(super) mod tests {
    //! Switches the kernel's tests flip to compare its paths (`super::super::kernel_agreement`).
    use std::sync::atomic::{AtomicBool, Ordering};

    pub(in crate::modes::synth) static FORCE_PORTABLE: AtomicBool = AtomicBool::new(false);

    pub(super) fn portable_forced() -> bool {
        FORCE_PORTABLE.load(Ordering::Relaxed)
    }

    pub(in crate::modes::synth) static FORCE_FULL_SEARCH: AtomicBool = AtomicBool::new(false);

    pub(super) fn full_search_forced() -> bool {
        FORCE_FULL_SEARCH.load(Ordering::Relaxed)
    }
}
