//! k-coherence candidate sets, k = 2 (design note §1.2d): for every exemplar texel, itself and its
//! best match at least 5 % of the exemplar away. Nearest neighbours in the 7×7 PCA space with a
//! k-d tree: exact, or (the coherent search) on a grid of texels with approximate queries. Every texel is a candidate, those along a non-toroidal edge too: synthesis
//! compares them over their real texels only (`modes::synth::kernel`), so content along an edge
//! is not lost, where the design note's border zone excluded it.

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use crate::analysis::features::SEARCH_DIMS;
use crate::analysis::kdtree::KdTree;
use crate::error::{CoreError, Result};
use crate::lattice::{LevelLattice, Repeat};

/// Geometry of one level's candidate problem.
pub struct CandidateRules {
    /// Exemplar width.
    pub w: usize,
    /// Exemplar height.
    pub h: usize,
    /// Whether the exemplar wraps (toroidal distances and shifts).
    pub toroidal: bool,
    /// Minimum distance between the two candidates.
    pub separation: usize,
    /// The lattice at this level (design note §1.9, near-regular textures): `C_2(u)` only
    /// among texels on `u`'s phase; free without a lattice.
    pub phase: LevelLattice,
    /// The exemplar's exact repeat, where its copies may not be second candidates.
    pub copies: Option<Repeat>,
    /// Work budget: k-d tree leaves opened per texel, on average ([`LEAVES_PER_TEXEL`]).
    pub leaves_per_texel: u64,
}

impl CandidateRules {
    /// Rules for a `w × h` exemplar (separation `⌈0.05·max(w, h)⌉`).
    pub fn new((w, h): (usize, usize), toroidal: bool) -> Self {
        CandidateRules {
            w,
            h,
            toroidal,
            separation: (crate::geom::Size::of_dims((w, h)).longer() as usize * 5).div_ceil(100),
            phase: LevelLattice::FREE,
            copies: None,
            leaves_per_texel: LEAVES_PER_TEXEL,
        }
    }

    /// These rules with second candidates restricted to the lattice phase of their texel.
    pub fn with_phase(mut self, phase: LevelLattice) -> Self {
        self.phase = phase;
        self
    }

    /// These rules with the copies of an exemplar that is a tile repeated refused as second
    /// candidates: a copy offers the same content again. Set after [`CandidateRules::with_phase`]:
    /// where the level holds a grid whose every translation is a copy (a rectified exemplar
    /// that is its cell repeated, such as the embedded corkboard's `[2, 4]`), the only places on
    /// a texel's phase are its copies, and the phase wins — the lattice was asked for, and
    /// without a same-phase candidate the coarse grid would break — so copies stay allowed there.
    pub fn without_copies(mut self, repeat: Option<&Repeat>) -> Self {
        let phase_is_copies =
            |r: &Repeat| self.phase.grid_translations().is_some_and(|[a, b]| r.is_copy(a) && r.is_copy(b));
        self.copies = repeat.filter(|r| !phase_is_copies(r)).cloned();
        self
    }

    /// Whether `v` may be the second candidate of `u`: far enough from it, on its lattice
    /// phase, not its copy.
    fn allowed(&self, v: usize, u: usize) -> bool {
        let d = ((v % self.w) as i64 - (u % self.w) as i64, (v / self.w) as i64 - (u / self.w) as i64);
        self.phase.same_phase(d) && !self.is_copy(d) && self.far_enough(v, u)
    }

    /// Whether the lag `d` between two texels is a copy (on a toroidal exemplar, also once
    /// wrapped around).
    fn is_copy(&self, d: (i64, i64)) -> bool {
        let Some(r) = &self.copies else { return false };
        if r.is_copy(d) {
            return true;
        }
        let wrap = |v: i64, m: usize| {
            let m = m as i64;
            if v > m / 2 {
                v - m
            } else if v < -m / 2 {
                v + m
            } else {
                v
            }
        };
        self.toroidal && r.is_copy((wrap(d.0, self.w), wrap(d.1, self.h)))
    }

    /// Texel `c` moved by `(dx, dy)` (wrapping when toroidal), unless that leaves the exemplar.
    fn shifted(&self, c: u32, dx: i64, dy: i64) -> Option<u32> {
        let (w, h) = (self.w as i64, self.h as i64);
        let (mut x, mut y) = ((c as i64) % w + dx, (c as i64) / w + dy);
        if self.toroidal {
            (x, y) = (x.rem_euclid(w), y.rem_euclid(h));
        } else if x < 0 || y < 0 || x >= w || y >= h {
            return None;
        }
        Some((y * w + x) as u32)
    }

    fn far_enough(&self, a: usize, b: usize) -> bool {
        let (w, h) = (self.w as i64, self.h as i64);
        let (ax, ay, bx, by) = ((a % self.w) as i64, (a / self.w) as i64, (b % self.w) as i64, (b / self.w) as i64);
        let (mut dx, mut dy) = ((ax - bx).abs(), (ay - by).abs());
        if self.toroidal {
            dx = dx.min(w - dx);
            dy = dy.min(h - dy);
        }
        let s = self.separation as i64;
        dx * dx + dy * dy >= s * s
    }
}

/// Offsets of the local refinement around each proposal.
const AROUND: [(i64, i64); 9] = [(-1, -1), (0, -1), (1, -1), (-1, 0), (0, 0), (1, 0), (-1, 1), (0, 1), (1, 1)];

/// Nearest matches kept per grid texel by [`candidate_sets`].
pub const GRID_MATCHES: usize = 8;

/// Slack of the coherent search's k-d tree queries on the grid levels (`(1 + ε)²`, ε ≈ 0.32;
/// see [`SearchPlan::slack`]).
pub const GRID_SLACK: f64 = 1.75;

/// Slack of the coherent search's queries on the levels searched at every texel (ε = 0.5).
pub const FINE_SLACK: f64 = 2.25;

/// How one level's candidates are searched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchPlan {
    /// Grid step: texels searched in the k-d tree on a grid of this step, the others from
    /// their grid neighbours' matches; 1 searches every texel.
    pub step: usize,
    /// A k-d tree cell is searched only if `slack` times its squared distance to the query is
    /// within the best match so far: 1 is exact; `(1 + ε)²` returns matches within `1 + ε` of
    /// the exact distance, far faster in these eight dimensions and mostly the same texels.
    pub slack: f64,
}

impl SearchPlan {
    /// Every texel, exactly.
    pub const EXACT: SearchPlan = SearchPlan { step: 1, slack: 1.0 };

    /// The coherent search at a level of stride `h`: every texel at the two finest levels
    /// (`h ≤ 2`), a grid of step 2 for `h = 4, 8` and 4 above, where blurred features make the
    /// search slow and the coherence strong; approximate queries (recall per level in
    /// bench/README.md).
    pub fn coherent(h: usize) -> SearchPlan {
        match h {
            0..=2 => SearchPlan { step: 1, slack: FINE_SLACK },
            3..=8 => SearchPlan { step: 2, slack: GRID_SLACK },
            _ => SearchPlan { step: 4, slack: GRID_SLACK },
        }
    }
}

/// Bands of rows each phase of [`candidate_sets`] is computed in: between two bands it reports
/// progress and may stop, so that even the slowest level answers within a fraction of its time.
pub const BANDS: usize = 8;

/// The work budget of one level's search: k-d tree leaves opened per texel, on average. Exemplars
/// of every kind open at most 130 (exact search, 128²) and 56 (coherent, 512²; bench/README.md,
/// Degenerate exemplars); brute force opens `m²/16` (16 384 at 512²). Past it the analysis
/// stops with [`CoreError::AnalysisWork`], the same on every machine, however fast.
pub const LEAVES_PER_TEXEL: u64 = 2000;

/// Compute `[C_1(u), C_2(u)] = [u, C_2(u)]` (texel indices `y·m + x`) for every texel as
/// `plan` says: searching only the texels of a grid of step `plan.step` in the k-d tree (their
/// [`GRID_MATCHES`] nearest matches far enough from them, the first of which is `C_2`) and
/// taking every other texel's `C_2` from the four grid texels around it: each of their matches
/// shifted by the texel's offset from the grid texel (the coherence of a smooth level) and
/// every texel within one of those, the best far enough; a tree search where no proposal
/// qualifies. Step 1 searches every texel.
///
/// The work comes in `2 ×` [`BANDS`] bands of rows (the grid's, then the texels'; step 1 has
/// only the second); `between(done)` is called before band `done` and after the last one
/// (`done = 2 × BANDS`), and an error it returns (cancellation) stops the search.
pub fn candidate_sets(
    feats: &[[f64; SEARCH_DIMS]],
    rules: &CandidateRules,
    plan: SearchPlan,
    between: &dyn Fn(usize) -> Result<()>,
) -> Result<Vec<[u32; 2]>> {
    let (w, h) = (rules.w, rules.h);
    let tree = KdTree::new((0..feats.len()).map(|i| (feats[i], i as u32)).collect());
    // The work so far, checked against the budget between bands.
    let leaves = AtomicU64::new(0);
    let budget = rules.leaves_per_texel * feats.len() as u64;
    let between = |done: usize| {
        let opened = leaves.load(Ordering::Relaxed);
        if opened > budget {
            return Err(CoreError::AnalysisWork {
                side: crate::geom::Size::of_dims((w, h)).longer(),
                leaves: opened,
                budget,
            });
        }
        between(done)
    };
    let nearest = |u: usize, k: usize| {
        let (found, opened) = tree.nearest_k_counted(&feats[u], k, plan.slack, |v| rules.allowed(v as usize, u));
        leaves.fetch_add(opened, Ordering::Relaxed);
        found
    };
    let search = |u: usize| [u as u32, nearest(u, 1).first().map_or(u as u32, |b| b.1)];
    let step = plan.step.clamp(1, w.min(h).max(1));
    if step == 1 {
        between(0)?;
        let sets = in_bands(h, w, BANDS, &|b| between(BANDS + b), &|_: &mut (), u| search(u))?;
        between(2 * BANDS)?;
        return Ok(sets);
    }
    // Per grid texel: its nearest matches far enough from it (C_2 first).
    let (gw, gh) = (w.div_ceil(step), h.div_ceil(step));
    let grid: Vec<Vec<u32>> = in_bands(gh, gw, BANDS, &between, &|_: &mut (), g| {
        let u = (g / gw) * step * w + (g % gw) * step;
        nearest(u, GRID_MATCHES).into_iter().map(|b| b.1).collect()
    })?;
    let sets = in_bands(h, w, BANDS, &|b| between(BANDS + b), &|props: &mut Vec<u32>, u| {
        let (x, y) = (u % w, u / w);
        if x % step == 0 && y % step == 0 {
            let g = &grid[(y / step) * gw + x / step];
            return [u as u32, g.first().copied().unwrap_or(u as u32)];
        }
        proposals(rules, &grid, (gw, gh), step, x, y, props);
        let q = &feats[u];
        let best = props
            .iter()
            .filter(|&&v| rules.allowed(v as usize, u))
            .map(|&v| (distance(q, &feats[v as usize]), v))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        match best {
            Some((_, c2)) => [u as u32, c2],
            None => search(u),
        }
    })?;
    between(2 * BANDS)?;
    Ok(sets)
}

/// `f` of every index `0..rows·row_len`, in parallel, computed in `bands` bands of whole rows
/// with `before(band)` called before each (its error stops the work); each rayon job keeps a
/// scratch `S`.
fn in_bands<T: Send, S: Default>(
    rows: usize,
    row_len: usize,
    bands: usize,
    before: &dyn Fn(usize) -> Result<()>,
    f: &(dyn Fn(&mut S, usize) -> T + Sync),
) -> Result<Vec<T>> {
    let per = rows.div_ceil(bands).max(1);
    let mut out = Vec::with_capacity(rows * row_len);
    for b in 0..bands {
        before(b)?;
        let (r0, r1) = ((b * per).min(rows), ((b + 1) * per).min(rows));
        out.par_extend((r0 * row_len..r1 * row_len).into_par_iter().map_init(S::default, f));
    }
    Ok(out)
}

/// The matches of the grid texels around `(x, y)`, shifted by its offset from each, and every
/// texel within one of those that lies in the exemplar (duplicates possible).
fn proposals(
    rules: &CandidateRules,
    grid: &[Vec<u32>],
    (gw, gh): (usize, usize),
    step: usize,
    x: usize,
    y: usize,
    out: &mut Vec<u32>,
) {
    out.clear();
    let (gx0, gy0) = ((x / step) as i64, (y / step) as i64);
    let (gwi, ghi) = (gw as i64, gh as i64);
    for gy in gy0..=gy0 + 1 {
        for gx in gx0..=gx0 + 1 {
            let (tx, ty) = (gx * step as i64, gy * step as i64);
            let (gx, gy) = if rules.toroidal { (gx.rem_euclid(gwi), gy.rem_euclid(ghi)) } else { (gx, gy) };
            if gx < 0 || gy < 0 || gx >= gwi || gy >= ghi {
                continue;
            }
            let (gx, gy) = (gx as usize, gy as usize);
            let (dx, dy) = (x as i64 - tx, y as i64 - ty);
            for &c in &grid[gy * gw + gx] {
                for (ex, ey) in AROUND {
                    if let Some(v) = rules.shifted(c, dx + ex, dy + ey) {
                        out.push(v);
                    }
                }
            }
        }
    }
}

fn distance(a: &[f64; SEARCH_DIMS], b: &[f64; SEARCH_DIMS]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Features of a small random exemplar (deterministic).
    fn features(n: usize) -> Vec<[f64; SEARCH_DIMS]> {
        let mut z = 0x2545_F491_4F6C_DD1Du64;
        (0..n)
            .map(|_| {
                std::array::from_fn(|_| {
                    z ^= z << 13;
                    z ^= z >> 7;
                    z ^= z << 17;
                    (z % 1000) as f64
                })
            })
            .collect()
    }

    #[test]
    fn a_search_over_its_work_budget_stops_with_a_clear_error() {
        let feats = features(64 * 64);
        let rules = CandidateRules::new((64, 64), true);
        assert!(candidate_sets(&feats, &rules, SearchPlan::EXACT, &|_| Ok(())).is_ok());
        let tight = CandidateRules { leaves_per_texel: 1, ..CandidateRules::new((64, 64), true) };
        match candidate_sets(&feats, &tight, SearchPlan::EXACT, &|_| Ok(())) {
            Err(CoreError::AnalysisWork { side: 64, leaves, budget: 4096 }) => assert!(leaves > 4096),
            other => panic!("expected the work budget's error, got {:?}", other.map(|v| v.len())),
        }
    }

    #[test]
    fn the_search_stops_between_bands_when_asked_and_reports_each() {
        let feats = features(32 * 32);
        let rules = CandidateRules::new((32, 32), true);
        let seen = std::sync::Mutex::new(Vec::new());
        let stop_at_3 = |done: usize| {
            seen.lock().unwrap().push(done);
            if done == 3 {
                Err(CoreError::Cancelled)
            } else {
                Ok(())
            }
        };
        assert!(matches!(
            candidate_sets(&feats, &rules, SearchPlan::coherent(8), &stop_at_3),
            Err(CoreError::Cancelled)
        ));
        assert_eq!(*seen.lock().unwrap(), [0, 1, 2, 3]);
    }
}
