//! `mode=synth`: Lefebvre & Hoppe's parallel controllable texture synthesis (design note §1),
//! the main engine. The stages, one file each:
//!
//! 1. [`plan`] — which padded rectangle each level must compute for a window to be exact;
//! 2. [`window`] — upsample, jitter by a hash of absolute coordinates, correct in subpasses
//!    (`kernel`); `generations` and `history` share work through the pyramidal cache;
//! 3. [`colour`] — exemplar coordinates to colours, at native or zoomed-out scale (magnified:
//!    [`crate::modes::magnify::patches`]);
//! 4. [`params`] — the validated parameters.

pub mod colour;
mod seams;
pub mod controls;
mod generations;
mod history;
mod kernel;
pub mod params;
pub mod plan;
pub mod window;

use serde_json::{json, Map, Value};

use crate::cache::Pyramid;
use crate::error::Result;
use crate::geom::Rect;
use crate::image::Rendered;
use crate::maps::UvWindow;
use crate::modes::magnify::{self, Detail};
use crate::modes::params::{Common, Kind, ParamReader, ParamSpec, Scope, ONE_Q16};
use crate::modes::{Cost, Mode, Needs, Source, View};

pub use colour::{render, render_map, render_with};
pub use params::{Randomness, SynthParams, MAX_PASSES};
pub use window::{synthesis_cost, synthesize, synthesize_with, CoordWindow, Synthesized};

/// The synth mode.
pub struct Synth;

const RANDOMNESS: ParamSpec = ParamSpec {
    name: "randomness",
    kind: Kind::Levels,
    scope: Scope::Request,
    help: "jitter strength per synthesis level: one value in [0, 1] for every level, or a comma list of one per level, coarse to fine",
};
const CONTROLS: ParamSpec = ParamSpec {
    name: "controls",
    kind: Kind::Text { max_len: controls::MAX_CONTROLS_LEN as u64 },
    scope: Scope::Request,
    help: "spatial modulation of randomness over the output (R_S): base64url of JSON {\"noise\": {\"scale\": 64, \"range\": [0.2, 1]}, \"strokes\": [{\"at\": [x, y], \"radius\": 40, \"soft\": 8, \"value\": 0}], \"features\": [{\"at\": [x, y], \"source\": [u, v], \"inner\": 12, \"outer\": 40}]} (native texels; values in [0, 1]: 0 calm, 1 the full randomness; a feature shows the exemplar around its source within its inner radius; at most 64 strokes and 32 features)",
};
const KAPPA: ParamSpec = ParamSpec {
    name: "kappa",
    kind: Kind::Unit,
    scope: Scope::Texture,
    help: "κ, the penalty on jumps to a pixel's second candidate (default 1): higher keeps exemplar patches more coherent and the colour distribution closer to the exemplar's",
};
const PASSES: ParamSpec = ParamSpec {
    name: "passes",
    kind: Kind::Integer { min: 0, max: MAX_PASSES as u64 },
    scope: Scope::Texture,
    help: "correction passes per corrected level, one more at the third-finest (0 switches correction off)",
};
const SUBPASSES: ParamSpec = ParamSpec {
    name: "subpasses",
    kind: Kind::Integer { min: 1, max: 4 },
    scope: Scope::Texture,
    help: "subpasses per pass: 4 (parity classes, the paper's order) or 1 (all pixels at once)",
};
const SPECS: &[ParamSpec] = &[RANDOMNESS, KAPPA, PASSES, SUBPASSES, CONTROLS];

/// A fixed-point value in `[0, 1]` as a short decimal (4 places: no float noise).
fn unit_value(v: u32) -> f64 {
    (v as f64 / ONE_Q16 as f64 * 10_000.0).round() / 10_000.0
}

impl Mode for Synth {
    const NAME: &'static str = "synth";
    const VERSION: u32 = 6;
    const SUMMARY: &'static str = "parallel controllable texture synthesis (Lefebvre & Hoppe 2005)";
    const NEEDS: Needs = Needs::Analysis;
    const COST: Cost = Cost::Heavy;
    const HAS_UV: bool = true;
    type Params = SynthParams;

    fn specs() -> &'static [ParamSpec] {
        SPECS
    }

    fn defaults() -> SynthParams {
        SynthParams::default()
    }

    fn parse(base: &SynthParams, common: &Common, r: &mut ParamReader, src: &Source) -> Result<SynthParams> {
        let mut p = base.clone();
        common.apply(&mut p.seed, &mut p.period);
        if let Some(s) = r.get(&RANDOMNESS) {
            p.randomness = Randomness::parse(&s)?;
        }
        if let Some(s) = r.get(&CONTROLS) {
            p.controls = controls::Controls::parse(&s)?;
        }
        if let Some(s) = r.get(&KAPPA) {
            p.kappa = KAPPA.unit(&s)?;
        }
        if let Some(s) = r.get(&PASSES) {
            p.passes = PASSES.integer(&s)? as u32;
        }
        if let Some(s) = r.get(&SUBPASSES) {
            p.subpasses = SUBPASSES.integer(&s)? as u32;
        }
        p.validate(src.side())?;
        Ok(p)
    }

    fn values(p: &SynthParams, src: &Source) -> Map<String, Value> {
        let r: Vec<f64> = p.randomness.resolve(src.levels()).into_iter().map(unit_value).collect();
        let mut m = Map::new();
        m.insert("seed".into(), json!(p.seed));
        m.insert(RANDOMNESS.name.into(), json!(r));
        m.insert(KAPPA.name.into(), json!(unit_value(p.kappa)));
        m.insert(CONTROLS.name.into(), p.controls.to_json());
        m.insert(PASSES.name.into(), json!(p.passes));
        m.insert(SUBPASSES.name.into(), json!(p.subpasses));
        m
    }

    fn canonical(p: &SynthParams) -> String {
        p.canonical()
    }

    fn render(p: &SynthParams, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        render_map(cache, src.analysis(Self::NAME)?, src.map, p, view.zoom_out, view.rect)
    }

    fn coordinates(p: &SynthParams, src: &Source, cache: &Pyramid, view: View) -> Result<UvWindow> {
        let an = src.analysis(Self::NAME)?;
        if view.zoom_in == 0 {
            return colour::coordinates(cache, an, p, view.zoom_out, view.rect);
        }
        let (k, rect) = (view.zoom_in, view.rect);
        let sw = synthesize_with(cache, an, p, an.levels(), magnify::source_rect(rect, k))?;
        Ok(magnify::patch_points(&sw.window.coords, an.side(), an.header.toroidal, k, rect))
    }

    fn magnify(p: &SynthParams, src: &Source, cache: &Pyramid, k: u32, rect: Rect) -> Result<Rendered> {
        let an = src.analysis(Self::NAME)?;
        let sw = synthesize_with(cache, an, p, an.levels(), magnify::source_rect(rect, k))?;
        let toroidal = an.header.toroidal;
        let detail = match src.hires() {
            Some(h) => Detail { pixels: h, side: 2 * an.side(), toroidal },
            None => Detail { pixels: src.map.map_or(&an.exemplar[..], |m| &m.texels), side: an.side(), toroidal },
        };
        let image = magnify::patches(&sw.window.coords, an.side(), detail, k, rect);
        Ok(Rendered { image, synthesized: sw.synthesized })
    }
}
