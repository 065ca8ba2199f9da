//! Just-in-time umbrella patches (design note §5): the mode for textures of discrete elements.
//! A handful of base umbrellas extracted from the exemplar ([`extract`]) are diversified into
//! a table of modified umbrellas and scattered over an infinite grid of cells ([`arrange`]);
//! every sample point is evaluated at request time ([`shape`]): the front-most umbrella that
//! contains it gives its colour, umbrellas in front of it that contain the point moved towards
//! the light shade it, and where none covers it another mode's output (the background) shows.
//! Coverage is rasterised with a fixed pattern of sub-samples per pixel ([`raster`]: 4×4 at
//! native zoom, fewer zoomed out, [`sub_samples`]); the
//! colour of what a pixel's sub-samples see is evaluated once per umbrella. Zoomed out, merged
//! levels of detail stand for clusters of umbrellas ([`lod`]). Everything is a function of
//! absolute coordinates, so windows are the same pixels cut from larger ones.

pub mod arrange;
mod background;
pub mod caches;
pub mod extract;
pub mod handmade;
pub mod lod;
mod maps;
mod paint;
mod params;
pub mod prepared;
pub mod raster;
pub mod shape;
pub mod sheet;
pub mod store;

use std::sync::Arc;


use rayon::prelude::*;


use crate::cache::Pyramid;
use crate::error::Result;
use crate::exemplar::Exemplar;
use crate::image::{Rendered, RgbWindow};
use crate::memo::Memo;
use crate::modes::mosaic::{self, MosaicParams};
use crate::modes::params::{check_period, Kind, ONE_Q16};
use crate::modes::Declared;
use crate::modes::synth::{Synth, SynthParams};
use crate::modes::tiling::{Tiling, TilingParams};
use crate::modes::{check_window, Cost, Mode, Needs, Source, View};

use arrange::{Arrangement, Placed};
use extract::{Elements, RAYS};
pub use prepared::{extraction_id, Extraction};
pub use params::{Background, UmbrellaParams};
use background::{background, colour_shift, gap_shift, shifted};
use paint::paint;
pub use paint::storage_words;

/// Largest window, in pixels, one call may render (2^24: sub-sampling makes pixels dear).
pub const MAX_PIXELS: i64 = 1 << 24;

/// Sub-samples per pixel side at native zoom (and the most at any zoom).
const AA: usize = 4;

/// Sub-samples per pixel side of a view `zoom_out` steps out at level of detail `level`:
/// [`AA`] at native zoom; 2 zoomed out while the level-0 umbrellas are still drawn (one step
/// out, a sub-sample at every native pixel's centre, where 4 would be half a texel apart); 3 at
/// merged levels, where 2 breaks the zoom-consistency bound and 3 keeps it (development gravel
/// two steps out: mean 4.42 → 4.82, worst tile 4.99 → 5.40, bound 5 / 5.5). The fill's cost is
/// its sample rows: 3 instead of 4 per pixel row make a merged tile 8–12 % cheaper.
fn sub_samples(zoom_out: u32, level: u32) -> usize {
    match (zoom_out, level) {
        (0, _) => AA,
        (_, 0) => 2,
        _ => 3,
    }
}

/// The umbrella mode.
pub struct Umbrella;

impl Mode for Umbrella {
    const NAME: &'static str = "umbrella";
    const VERSION: u32 = 13;
    const SUMMARY: &'static str =
        "just-in-time umbrella patches: elements of the exemplar, diversified and scattered, evaluated per sample";
    const NEEDS: Needs = Needs::Prepared;
    const COST: Cost = Cost::Heavy;
    type Params = UmbrellaParams;
    type State = Extraction;

    /// A near-regular exemplar: umbrellas scatter elements freely, which breaks the lattice
    /// into a collage, so the mode says so rather than rendering one.
    fn declines(src: &Source) -> Option<String> {
        src.lattice().map(|l| {
            format!("it is near-regular ({l}), and umbrella patches scatter elements off any lattice; synth and mosaic keep it")
        })
    }

    /// The extraction: each base umbrella magnified with its rim and centre, and modified
    /// umbrellas of it below.
    fn sheet(p: &UmbrellaParams, state: &Extraction, _: &Source) -> Option<Result<RgbWindow>> {
        let sheet = || {
            let (el, id) = state.elements()?;
            Ok(sheet::debug_sheet(&el, &Arrangement::new(&el, p, &id)))
        };
        Some(sheet())
    }

    fn render(p: &UmbrellaParams, state: &Extraction, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        let rect = view.rect;
        check_window(rect, MAX_PIXELS)?;
        let (elements, ident) = match src.map {
            Some(map) => state.map_elements(src.exemplar, map)?,
            None => state.elements()?,
        };
        let caches = &state.caches;
        let arr = Arrangement::cached(&elements, p, &ident, caches.clone());
        // Shadows and the colour calibrations are the colour's: a map shows the elements'
        // own values over its background's.
        let colour = src.map.is_none();
        let shadowless = UmbrellaParams { shadow: 0, ..p.clone() };
        let p = if colour { p } else { &shadowless };
        // Level 0 (every umbrella) while a cell is at least `lod::LOD_PIXELS` wide, then the
        // merged levels of detail, then the background's own zoomed-out pixels.
        let level = lod::level(&arr, view.zoom_out);
        let Some(level) = level else {
            // Shifted to the umbrellas' mean colour, so that zooming out past the last drawn
            // zoom changes the detail, not the colour.
            let shift = match colour {
                true => colour_shift(&arr, &elements, p, &ident, src, cache, umbrella_zooms(&arr))?,
                false => [0.0; 3],
            };
            let image = shifted(background(p, src, cache, view)?, shift);
            return Ok(Rendered { image, synthesized: rect.area() as u64 });
        };
        let gaps = if colour { gap_shift(&arr, &elements, p, &ident, src, cache)? } else { [0.0; 3] };
        let image = paint(&elements, &arr, p, view, level, || Ok(shifted(background(p, src, cache, view)?, gaps)))?;
        let aa = sub_samples(view.zoom_out, level) as i64;
        Ok(Rendered { image, synthesized: (rect.area() * aa * aa) as u64 })
    }
}

/// Zoom-out steps at which umbrellas are drawn: every one of them while a grid cell (about an
/// element's diameter) is at least [`lod::LOD_PIXELS`] wide, merged ones down to
/// [`lod::MAX_LEVEL`]. Further out the view is the background's zoomed-out pixels.
pub fn umbrella_zooms(arr: &Arrangement) -> u32 {
    (0..64).take_while(|&z| lod::level(arr, z).is_some()).last().unwrap_or(0)
}

/// The elements of an exemplar, extracted now, with the id that names them; none → a
/// parameter error naming the mode.
pub fn elements(ex: &Exemplar) -> Result<(Arc<Elements>, String)> {
    Extraction::extract(ex).elements()
}
