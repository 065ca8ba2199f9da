//! The exemplar analysis (design note §1.2): everything synthesis needs, computed once per
//! texture — the Gaussian stack, per-level runtime projections and the k = 2 candidate sets with
//! their features stored next to them. See [`crate::analysis::file`] for how it is stored.

pub mod candidates;
pub mod features;
pub mod file;
pub mod kdtree;
mod preparation;

pub use preparation::INDEX;

use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use crate::analysis::candidates::{candidate_sets, CandidateRules, SearchPlan, BANDS};
use crate::analysis::features::{
    principal_directions, project_runtime, quantise_projection, InnerTaps, LevelColours, SearchProjection,
    RUNTIME_DIMS, SEARCH_DIMS,
};
use crate::cache::{Pyramid, Stack};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::exemplar::{Exemplar, Intake};
use crate::image::box_stack;
use crate::lattice::{Lattice, LevelLattice, Repeat};
use crate::mask::RandomnessMask;
use crate::stack::{build_stack, to_u8};

/// Version of the analysis (its content and file layout; part of the analysis id, so a change
/// recomputes stored analyses). Each mode's output has its own version (`Mode::VERSION`).
pub const ALGORITHM_VERSION: u32 = 4;
/// First pyramid level that is corrected. LH05 leaves levels 0–2 uncorrected; we also leave
/// level 3, whose 5×5 neighbourhood at stride `h_3 = m/8` spans over half the exemplar: there,
/// correction grows coherent runs that can only repeat the few positions the exemplar offers
/// at that scale, and the repetition shows as regular streaks 64–100 texels apart when zoomed
/// out (texq `streak` 3.5–6.6 on the development set; 1.5–2.6 without, bench/README.md).
/// From level 4 on (`h ≤ m/16`) neighbourhoods span at most a quarter of the exemplar.
pub const FIRST_CORRECTED_LEVEL: u32 = 4;

/// Exemplars at least this wide are analysed with the coherent search by default
/// ([`IndexChoice::Auto`]); smaller ones exactly.
pub const COHERENT_FROM_SIDE: u32 = 256;

/// Stack levels below the finest that separate an exemplar's fine detail from its low
/// frequencies ([`Analysis::fine_detail`]; the synth mode's seam blend cross-fades that
/// low-pass, stride 4).
pub const FINE_DETAIL_STEPS: u32 = 2;

/// Version of the coherent search (part of coherent analyses' ids): 2 since its k-d tree
/// queries are approximate.
pub const COHERENT_VERSION: u32 = 2;

/// How the candidate sets are searched (design note §1.2d).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SearchIndex {
    /// Exact nearest neighbours of every texel in a k-d tree.
    #[default]
    Exact,
    /// Approximate matches on a grid of texels, propagated to the texels between by coherence
    /// and refined locally, and approximate matches of every texel at the finest two levels
    /// ([`candidates::SearchPlan::coherent`]): several times faster on large exemplars, most
    /// candidates identical or one texel off.
    Coherent,
}

impl SearchIndex {
    /// The name `index` settings and reports use.
    pub fn name(self) -> &'static str {
        match self {
            SearchIndex::Exact => "exact",
            SearchIndex::Coherent => "coherent",
        }
    }
}

/// The search asked for: one of [`SearchIndex`], or chosen by exemplar size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum IndexChoice {
    /// [`SearchIndex::Coherent`] from [`COHERENT_FROM_SIDE`] texels wide, else exact.
    #[default]
    Auto,
    /// Always [`SearchIndex::Exact`].
    Exact,
    /// Always [`SearchIndex::Coherent`].
    Coherent,
}

impl IndexChoice {
    /// As settings write it: `auto`, `exact` or `coherent`.
    pub fn name(self) -> &'static str {
        match self {
            IndexChoice::Auto => "auto",
            IndexChoice::Exact => "exact",
            IndexChoice::Coherent => "coherent",
        }
    }

    /// Parse `auto`, `exact` or `coherent`.
    pub fn parse(s: &str) -> Result<IndexChoice> {
        match s {
            "auto" => Ok(IndexChoice::Auto),
            "exact" => Ok(IndexChoice::Exact),
            "coherent" => Ok(IndexChoice::Coherent),
            _ => Err(CoreError::Param {
                name: "index",
                message: format!("must be auto, exact or coherent, not {:?}", crate::error::clip(s)),
            }),
        }
    }

    /// The search used for an exemplar whose longer side is `side`.
    pub fn resolve(self, side: u32) -> SearchIndex {
        match self {
            IndexChoice::Exact => SearchIndex::Exact,
            IndexChoice::Coherent => SearchIndex::Coherent,
            IndexChoice::Auto if side >= COHERENT_FROM_SIDE => SearchIndex::Coherent,
            IndexChoice::Auto => SearchIndex::Exact,
        }
    }
}

pub use crate::progress::{NoProgress, Progress};

/// One candidate: an exemplar coordinate and its runtime feature vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Candidate {
    /// Packed exemplar coordinate `x | y << 16`.
    pub coord: u32,
    /// Runtime feature `Ñ_E(coord)` (quantised PCA projection of its 5×5 neighbourhood).
    pub feat: [i16; RUNTIME_DIMS],
}

/// Analysis data of one corrected level.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CorrectionLevel {
    /// Quantised projection, `[tap][channel][dim]`, i16 (unit vectors × 2^12).
    pub proj: Vec<i16>,
    /// `[C_1(u), C_2(u)]` for every texel `u = y·m + x`.
    pub cands: Vec<[Candidate; 2]>,
}

/// Sums of squares over an exemplar's texels and channels (8-bit units):
/// [`Analysis::fine_detail`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FineDetail {
    /// Of each value's difference from stack level `L −` [`FINE_DETAIL_STEPS`].
    pub fine: u64,
    /// Of each value's difference from the mean colour.
    pub total: u64,
    /// Values summed (3 per texel).
    pub samples: u64,
}

/// Descriptive header of an analysis (stored as JSON in the file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnalysisHeader {
    /// Content hash of exemplar pixels, flags and algorithm version (hex): the analysis id.
    pub id: String,
    /// Algorithm version the analysis was made for.
    pub algorithm_version: u32,
    /// Exemplar width (analyses written when exemplars were square call it `side`).
    #[serde(alias = "side")]
    pub width: u32,
    /// Exemplar height (0 in analyses written when exemplars were square: the width).
    #[serde(default)]
    pub height: u32,
    /// `L = ⌈log2 max(width, height)⌉`: the finest level index.
    pub levels: u32,
    /// Wrap-around synthesis.
    pub toroidal: bool,
    /// How the input image was prepared.
    pub preparation: Intake,
    /// How the candidate sets were searched (files from before the choice existed: exact).
    #[serde(default)]
    pub index: SearchIndex,
    /// Hash of the exemplar's randomness mask, when it has one: synthesis then needs the mask
    /// ([`Analysis::attach`]), which is kept with the exemplar, not in the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub randomness_mask: Option<String>,
    /// The lattice of a near-regular exemplar: coarse candidates keep their lattice phase, and
    /// synthesis rounds coarse jitter to whole cells.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lattice: Option<Lattice>,
    /// The exact repeat of an exemplar that is a tile repeated: no texel's copy is its second
    /// candidate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeat: Option<Repeat>,
    /// What structure detection found (class, basis, scores; see
    /// [`crate::lattice::Structure`]), for `textile info`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub structure: Option<crate::lattice::Structure>,
}

/// A complete exemplar analysis.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Header data.
    pub header: AnalysisHeader,
    /// The prepared exemplar, RGB8, row-major.
    pub exemplar: Vec<[u8; 3]>,
    /// Gaussian stack, `levels + 1` images, value·256.
    pub stack: Vec<Vec<[u16; 3]>>,
    /// Levels `FIRST_CORRECTED_LEVEL..=levels`.
    pub corrected: Vec<CorrectionLevel>,
    /// Derived: 8-bit stack colours (not stored).
    pub(crate) stack8: Vec<Vec<[u8; 3]>>,
    /// Derived on first use: [`Analysis::fine_detail`].
    pub(crate) detail: OnceLock<FineDetail>,
    /// The exemplar's randomness mask (not stored: [`Analysis::attach`]).
    pub(crate) randomness_mask: Option<RandomnessMask>,
}

impl Analysis {
    /// Analyse a prepared exemplar with the search [`IndexChoice::Auto`] picks. Deterministic:
    /// the same exemplar always gives the same analysis, whatever the thread count.
    ///
    /// # Panics
    /// If the search exceeds its work budget ([`CoreError::AnalysisWork`]), which no exemplar
    /// measured comes near; analyse untrusted exemplars with [`Analysis::try_build`].
    pub fn build(ex: &Exemplar, progress: &dyn Progress) -> Analysis {
        match Self::try_build(ex, progress, &Cancel::new()) {
            Ok(a) => a,
            Err(e) => panic!("analysis failed: {e}"),
        }
    }

    /// [`Analysis::build`], stopped between steps (at least every [`candidates::BANDS`]-th of a
    /// level) with [`CoreError::Cancelled`] once `cancel` is set, or with
    /// [`CoreError::AnalysisWork`] past its work budget.
    pub fn try_build(ex: &Exemplar, progress: &dyn Progress, cancel: &Cancel) -> Result<Analysis> {
        Self::try_build_with(ex, IndexChoice::Auto, progress, cancel)
    }

    /// [`Analysis::try_build`] with the candidate search chosen by `index`.
    pub fn try_build_with(
        ex: &Exemplar,
        index: IndexChoice,
        progress: &dyn Progress,
        cancel: &Cancel,
    ) -> Result<Analysis> {
        let search = index.resolve(ex.size().longer());
        let dims = ex.dims();
        let levels = ex.levels();
        // Steps: the stack, then every corrected level's bands of candidate search.
        let per_level = 2 * BANDS as u32;
        let total = 1 + (levels + 1 - FIRST_CORRECTED_LEVEL) * per_level;
        progress.step(0, total, "gaussian stack");
        let stack = build_stack(&ex.pixels, dims, ex.toroidal);
        let stack8 = derive_stack8(&stack);
        let mut corrected = Vec::new();
        for l in FIRST_CORRECTED_LEVEL..=levels {
            let first = 1 + (l - FIRST_CORRECTED_LEVEL) * per_level;
            let between = |done: usize| {
                cancel.check()?;
                progress.step(first + done as u32, total, "neighbourhoods and candidates");
                Ok(())
            };
            let h = 1 << (levels - l);
            let phase = ex.lattice.as_ref().map_or(LevelLattice::FREE, |lat| lat.level(h as i64, ex.size().longer()));
            let rules = CandidateRules::new(dims, ex.toroidal).with_phase(phase).without_copies(ex.repeat.as_ref());
            corrected.push(analyse_level(&stack8[l as usize], &rules, h as usize, search, &between)?);
        }
        progress.step(total, total, "done");
        let header = AnalysisHeader {
            id: analysis_id(ex, search),
            algorithm_version: ALGORITHM_VERSION,
            width: ex.width,
            height: ex.height,
            levels,
            toroidal: ex.toroidal,
            preparation: ex.preparation.clone(),
            index: search,
            randomness_mask: ex.randomness_mask.as_ref().map(|m| m.hash.clone()),
            lattice: ex.lattice.clone(),
            repeat: ex.repeat.clone(),
            structure: ex.structure.clone(),
        };
        let randomness_mask = ex.randomness_mask.clone();
        Ok(Analysis {
            header,
            exemplar: ex.pixels.clone(),
            stack,
            corrected,
            stack8,
            detail: OnceLock::new(),
            randomness_mask,
        })
    }

    /// The analysis id an exemplar would get with the search `index` chooses: compare with a
    /// stored analysis's `header.id` to know whether it is still current.
    pub fn id_for(ex: &Exemplar, index: IndexChoice) -> String {
        analysis_id(ex, index.resolve(ex.size().longer()))
    }

    /// The exemplar as the analysis holds it (pixels, size, flags, lattice; not the
    /// high-resolution image or randomness mask, which stay with the texture).
    pub fn exemplar(&self) -> Exemplar {
        let h = &self.header;
        Exemplar {
            width: h.width,
            height: h.height,
            pixels: self.exemplar.clone(),
            toroidal: h.toroidal,
            preparation: h.preparation.clone(),
            hires: None,
            randomness_mask: None,
            input_spread: None,
            lattice: h.lattice.clone(),
            repeat: h.repeat.clone(),
            structure: h.structure.clone(),
            maps: Vec::new(),
        }
    }

    /// The lattice its candidate sets keep (the prepared exemplar's when it was analysed):
    /// synthesis holds it; the other modes read it through their source's `lattice()`.
    pub fn lattice(&self) -> Option<&Lattice> {
        self.header.lattice.as_ref()
    }

    /// Exemplar width.
    pub fn width(&self) -> u32 {
        self.header.width
    }

    /// Exemplar height.
    pub fn height(&self) -> u32 {
        self.header.height
    }

    /// Exemplar size `(width, height)` for indexing.
    pub fn dims(&self) -> (usize, usize) {
        (self.header.width as usize, self.header.height as usize)
    }

    /// Its exemplar's size ([`crate::geom::Size`]: longer side, levels).
    pub fn size(&self) -> crate::geom::Size {
        crate::geom::Size::new(self.header.width, self.header.height)
    }

    /// Finest level index `L`.
    pub fn levels(&self) -> u32 {
        self.header.levels
    }

    /// The analysis of corrected level `l`, if `l` is corrected.
    pub fn correction_level(&self, l: u32) -> Option<&CorrectionLevel> {
        l.checked_sub(FIRST_CORRECTED_LEVEL).and_then(|i| self.corrected.get(i as usize))
    }

    /// 8-bit stack colours of level `l`.
    pub fn colours8(&self, l: u32) -> &[[u8; 3]] {
        &self.stack8[l as usize]
    }

    /// The exemplar's box means over `2^k × 2^k` texels centred on each texel, for every `k`
    /// (`0`: the exemplar itself; `levels`: the mean colour everywhere), derived on first use
    /// and kept in `cache` within its bytes.
    pub fn box_stack(&self, cache: &Pyramid) -> Stack {
        cache.derived(&format!("boxes|{}", self.header.id), || box_stack(&self.exemplar, self.dims()))
    }

    /// How much of the exemplar's variation is fine detail: its energy above stack level
    /// `L −` [`FINE_DETAIL_STEPS`] against its whole variance (exact integer sums over texels
    /// and channels).
    pub fn fine_detail(&self) -> FineDetail {
        *self.detail.get_or_init(|| {
            let levels = self.header.levels as usize;
            let (low, mean) = (&self.stack8[levels.saturating_sub(FINE_DETAIL_STEPS as usize)], self.stack8[0][0]);
            let mut d = FineDetail { fine: 0, total: 0, samples: 0 };
            for (e, l) in self.exemplar.iter().zip(low) {
                for c in 0..3 {
                    d.fine += (e[c] as i64 - l[c] as i64).pow(2) as u64;
                    d.total += (e[c] as i64 - mean[c] as i64).pow(2) as u64;
                }
                d.samples += 3;
            }
            d
        })
    }

    /// Mean colour of the exemplar (8-bit).
    pub fn mean_colour(&self) -> [u8; 3] {
        self.stack8[0][0]
    }

    /// Rebuild derived tables after loading.
    pub(crate) fn from_parts(
        header: AnalysisHeader,
        exemplar: Vec<[u8; 3]>,
        stack: Vec<Vec<[u16; 3]>>,
        corrected: Vec<CorrectionLevel>,
    ) -> Analysis {
        let stack8 = derive_stack8(&stack);
        Analysis { header, exemplar, stack, corrected, stack8, detail: OnceLock::new(), randomness_mask: None }
    }

    /// Attach what an analysis read from a file keeps with the exemplar instead (its
    /// randomness mask), from the exemplar it was made for; an exemplar whose mask differs
    /// from the one the analysis was made with is refused.
    pub fn attach(&mut self, ex: &Exemplar) -> Result<()> {
        let hash = ex.randomness_mask.as_ref().map(|m| m.hash.clone());
        if hash != self.header.randomness_mask {
            return Err(CoreError::Param {
                name: "randomness_mask",
                message: "differs from the one the analysis was made with".into(),
            });
        }
        self.randomness_mask = ex.randomness_mask.clone();
        Ok(())
    }

    /// The randomness mask synthesis scales jitter by: `Ok(None)` without one, an error when
    /// the analysis was made with a mask that was not [`Analysis::attach`]ed.
    pub fn randomness_mask(&self) -> Result<Option<&RandomnessMask>> {
        match (&self.header.randomness_mask, &self.randomness_mask) {
            (None, _) => Ok(None),
            (Some(_), Some(m)) => Ok(Some(m)),
            (Some(_), None) => Err(CoreError::Param {
                name: "randomness_mask",
                message: "the analysis was made with a randomness mask that is not attached (Analysis::attach)".into(),
            }),
        }
    }
}

fn derive_stack8(stack: &[Vec<[u16; 3]>]) -> Vec<Vec<[u8; 3]>> {
    stack.iter().map(|lv| lv.iter().map(|p| p.map(to_u8)).collect()).collect()
}

/// Content hash of what determines an analysis: algorithm version, side, toroidal flag, pixels,
/// and the search (only when not exact, so exact analyses keep the ids they always had); also
/// the high-resolution image when there is one, which magnified tiles show, so that the id
/// (and through it every cache key and ETag) names everything a tile's pixels depend on.
fn analysis_id(ex: &Exemplar, search: SearchIndex) -> String {
    let mut h = blake3::Hasher::new();
    h.update(b"textile-analysis");
    h.update(&ALGORITHM_VERSION.to_le_bytes());
    if search == SearchIndex::Coherent {
        h.update(b"coherent");
        h.update(&COHERENT_VERSION.to_le_bytes());
    }
    ex.hash_content(&mut h);
    h.finalize().to_hex()[..16].to_string()
}

fn analyse_level(
    px: &[[u8; 3]],
    rules: &CandidateRules,
    h: usize,
    search_index: SearchIndex,
    between: &dyn Fn(usize) -> Result<()>,
) -> Result<CorrectionLevel> {
    use rayon::prelude::*;
    let (w, ht, toroidal) = (rules.w, rules.h, rules.toroidal);
    let cols = LevelColours { px, width: w as i64, height: ht as i64, toroidal, h: h as i64 };
    let dirs5 = principal_directions(&cols, 2, RUNTIME_DIMS);
    let proj = quantise_projection(&dirs5);
    let search_proj = SearchProjection::new(&principal_directions(&cols, 3, SEARCH_DIMS));
    let (runtime, search): (Vec<[i16; RUNTIME_DIMS]>, Vec<[f64; SEARCH_DIMS]>) = (0..w * ht)
        .into_par_iter()
        .map_init(Vec::new, |buf, i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            cols.neighbourhood(x, y, 2, buf);
            // Near a non-toroidal edge, the feature of the real texels only (outside: zero).
            if let Some(inner) = (!toroidal).then(|| InnerTaps::at(x, y, h as i64, (w as i64, ht as i64))).flatten() {
                for (t, rgb) in buf.chunks_mut(3).enumerate() {
                    if !inner.contains(t) {
                        rgb.fill(0);
                    }
                }
            }
            let r = project_runtime(&proj, buf);
            cols.neighbourhood(x, y, 3, buf);
            (r, search_proj.project(buf))
        })
        .unzip();
    let plan = match search_index {
        SearchIndex::Exact => SearchPlan::EXACT,
        SearchIndex::Coherent => SearchPlan::coherent(h),
    };
    let sets = candidate_sets(&search, rules, plan, between)?;
    let cand = |i: u32| {
        let i = i as usize;
        Candidate { coord: (i % w) as u32 | ((i / w) as u32) << 16, feat: runtime[i] }
    };
    let cands = sets.iter().map(|&[a, b]| [cand(a), cand(b)]).collect();
    Ok(CorrectionLevel { proj, cands })
}
