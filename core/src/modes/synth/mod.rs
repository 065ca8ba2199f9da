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
#[cfg(test)]
mod kernel_agreement;
pub mod params;
pub mod plan;
pub mod window;

use crate::cache::Pyramid;
use crate::error::Result;
use crate::geom::Rect;
use crate::image::Rendered;
use crate::maps::UvWindow;
use crate::modes::magnify::{self, Detail};
use crate::modes::{Cost, Mode, Needs, Source, View};

pub use colour::{render, render_map, render_with};
pub use params::{Randomness, SynthParams, CONTROLS, KAPPA, MAX_PASSES, PASSES, RANDOMNESS, SUBPASSES};
pub use window::{synthesis_cost, synthesize, synthesize_with, CoordWindow, Synthesized};

/// The synth mode.
pub struct Synth;

impl Mode for Synth {
    const NAME: &'static str = "synth";
    const VERSION: u32 = 6;
    const SUMMARY: &'static str = "parallel controllable texture synthesis (Lefebvre & Hoppe 2005)";
    const NEEDS: Needs = Needs::Analysis;
    const COST: Cost = Cost::Heavy;
    const HAS_UV: bool = true;
    type Params = SynthParams;
    type State = ();

    fn render(p: &SynthParams, _: &(), src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        render_map(cache, src.analysis(Self::NAME)?, src.map, p, view.zoom_out, view.rect)
    }

    fn coordinates(p: &SynthParams, _: &(), src: &Source, cache: &Pyramid, view: View) -> Result<UvWindow> {
        let an = src.analysis(Self::NAME)?;
        if view.zoom_in == 0 {
            return colour::coordinates(cache, an, p, view.zoom_out, view.rect);
        }
        let (k, rect) = (view.zoom_in, view.rect);
        let sw = synthesize_with(cache, an, p, an.levels(), magnify::source_rect(rect, k))?;
        Ok(magnify::patch_points(&sw.window.coords, (an.width(), an.height()), k, rect))
    }

    fn magnify(p: &SynthParams, _: &(), src: &Source, cache: &Pyramid, k: u32, rect: Rect) -> Result<Rendered> {
        let an = src.analysis(Self::NAME)?;
        let sw = synthesize_with(cache, an, p, an.levels(), magnify::source_rect(rect, k))?;
        let toroidal = an.header.toroidal;
        let detail = match src.hires() {
            Some(h) => Detail { pixels: h, width: 2 * an.width(), height: 2 * an.height(), toroidal },
            None => Detail {
                pixels: src.map.map_or(&an.exemplar[..], |m| &m.texels),
                width: an.width(),
                height: an.height(),
                toroidal,
            },
        };
        let image = magnify::patches(&sw.window.coords, an.width(), detail, k, rect);
        Ok(Rendered { image, synthesized: sw.synthesized })
    }
}
