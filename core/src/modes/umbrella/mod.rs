//! Just-in-time umbrella patches (design note §5): the mode for textures of discrete elements.
//! A handful of base umbrellas extracted from the exemplar ([`extract`]) are diversified into
//! a table of modified umbrellas and scattered over an infinite grid of cells ([`arrange`]);
//! every sample point is evaluated at request time ([`shape`]): the front-most umbrella that
//! contains it gives its colour, umbrellas in front of it that contain the point moved towards
//! the light shade it, and where none covers it another mode's output (the background) shows.
//! Coverage is rasterised with a fixed 4×4 pattern of sub-samples per pixel ([`raster`]); the
//! colour of what a pixel's sub-samples see is evaluated once per umbrella. Zoomed out, merged
//! levels of detail stand for clusters of umbrellas ([`lod`]). Everything is a function of
//! absolute coordinates, so windows are the same pixels cut from larger ones.

pub mod arrange;
pub mod extract;
pub mod handmade;
pub mod lod;
pub mod prepared;
pub mod raster;
pub mod shape;
pub mod sheet;
pub mod store;

use std::sync::Arc;


use rayon::prelude::*;
use serde_json::{json, Map, Value};

use crate::cache::Pyramid;
use crate::error::Result;
use crate::exemplar::Exemplar;
use crate::image::{Rendered, RgbWindow};
use crate::memo::Memo;
use crate::prepare::{Step, StepOf};
use crate::modes::mosaic::{self, MosaicParams};
use crate::modes::params::{check_period, Common, Kind, ParamReader, ParamSpec, Scope, ONE_Q16};
use crate::modes::synth::{Synth, SynthParams};
use crate::modes::tiling::{Tiling, TilingParams};
use crate::modes::{check_window, Cost, Mode, Needs, Source, View};

use arrange::{Arrangement, Placed};
use extract::{Elements, RAYS};
pub use prepared::{extraction_id, Extraction};

/// Largest window, in pixels, one call may render (2^24: sub-sampling makes pixels dear).
pub const MAX_PIXELS: i64 = 1 << 24;
/// Sub-samples per pixel side.
const AA: usize = 4;

/// The umbrella mode.
pub struct Umbrella;

/// What shows where no umbrella covers a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Background {
    /// The chaos mosaic of the same exemplar (cheap, looks like the texture).
    Mosaic,
    /// The main synthesis of the same exemplar (needs the analysis; dearer).
    Synth,
    /// The exemplar tiled.
    Tiling,
    /// The exemplar's mean colour (the paper's constant background).
    Mean,
}

impl Background {
    const NAMES: &'static [&'static str] = &["mosaic", "synth", "tiling", "mean"];

    fn name(self) -> &'static str {
        match self {
            Background::Mosaic => "mosaic",
            Background::Synth => "synth",
            Background::Tiling => "tiling",
            Background::Mean => "mean",
        }
    }

    fn parse(s: &str) -> Option<Background> {
        match s {
            "mosaic" => Some(Background::Mosaic),
            "synth" => Some(Background::Synth),
            "tiling" => Some(Background::Tiling),
            "mean" => Some(Background::Mean),
            _ => None,
        }
    }
}

/// Validated umbrella parameters.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct UmbrellaParams {
    /// Selects another arrangement and diversification.
    pub seed: u64,
    /// Period in texels (power of two ≥ the exemplar side): an arrangement on a torus.
    pub period: Option<i64>,
    /// Umbrellas per area, percent of the density that covers the plane about 1.6 times.
    pub density: u32,
    /// Scale range of placed umbrellas, thousandths of the exemplar's element size.
    pub scale: (u32, u32),
    /// Largest shape morph towards a variant's shape (Q16).
    pub shape: u32,
    /// Strength of the variants' colour offsets (Q16).
    pub colour: u32,
    /// Shadow strength `s` (Q16): each umbrella above the hit one that covers the point moved
    /// towards the light multiplies it by `1 − s`.
    pub shadow: u32,
    /// Shadow offset `ℓ`, texels along the diagonal.
    pub shadow_offset: u32,
    /// Umbrellas per cell list at most.
    pub k: u32,
    /// What shows between umbrellas.
    pub background: Background,
}

impl Default for UmbrellaParams {
    fn default() -> Self {
        UmbrellaParams {
            seed: 0,
            period: None,
            density: 100,
            scale: (850, 1150),
            shape: ONE_Q16 / 2,
            colour: ONE_Q16,
            shadow: ONE_Q16 * 3 / 10,
            shadow_offset: 2,
            k: 8,
            background: Background::Mosaic,
        }
    }
}

impl UmbrellaParams {
    /// Canonical text for cache keys and ETags.
    pub fn canonical(&self) -> String {
        format!(
            "seed={};density={};scale={},{};shape={};colour={};shadow={},{};k={};bg={};period={}",
            self.seed,
            self.density,
            self.scale.0,
            self.scale.1,
            self.shape,
            self.colour,
            self.shadow,
            self.shadow_offset,
            self.k,
            self.background.name(),
            self.period.map(|p| p.to_string()).unwrap_or_else(|| "none".into())
        )
    }
}

const DENSITY: ParamSpec = ParamSpec {
    name: "density",
    kind: Kind::Integer { min: 10, max: 400 },
    scope: Scope::Request,
    help: "umbrellas per area, percent (100 covers the plane about 1.6 times over)",
};
const SCALE: ParamSpec = ParamSpec {
    name: "scale",
    kind: Kind::Interval { min: 0.25, max: 4.0 },
    scope: Scope::Request,
    help: "MIN,MAX size of placed elements relative to the exemplar's",
};
const SHAPE: ParamSpec = ParamSpec {
    name: "shape",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "largest shape morph towards other elements of the exemplar (0 = the base shapes)",
};
const COLOUR: ParamSpec = ParamSpec {
    name: "colour",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "strength of the per-vertex colour variation taken from other elements",
};
const SHADOW: ParamSpec = ParamSpec {
    name: "shadow",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "strength of the shadow an element casts on those below it",
};
const SHADOW_OFFSET: ParamSpec = ParamSpec {
    name: "shadow_offset",
    kind: Kind::Integer { min: 0, max: 16 },
    scope: Scope::Request,
    help: "shadow offset in texels (towards the bottom right)",
};
const K: ParamSpec = ParamSpec {
    name: "k",
    kind: Kind::Integer { min: 1, max: 16 },
    scope: Scope::Request,
    help: "umbrellas kept per grid cell, front to back",
};
const BACKGROUND: ParamSpec = ParamSpec {
    name: "background",
    kind: Kind::Choice(Background::NAMES),
    scope: Scope::Request,
    help: "what shows between elements: mosaic, synth, tiling or mean (colour)",
};
const SPECS: &[ParamSpec] = &[DENSITY, SCALE, SHAPE, COLOUR, SHADOW, SHADOW_OFFSET, K, BACKGROUND];

impl Mode for Umbrella {
    const NAME: &'static str = "umbrella";
    const VERSION: u32 = 10;
    const SUMMARY: &'static str =
        "just-in-time umbrella patches: elements of the exemplar, diversified and scattered, evaluated per sample";
    const NEEDS: Needs = Needs::Exemplar;
    const COST: Cost = Cost::Heavy;
    type Params = UmbrellaParams;

    fn specs() -> &'static [ParamSpec] {
        SPECS
    }

    fn defaults() -> UmbrellaParams {
        UmbrellaParams::default()
    }

    fn parse(base: &UmbrellaParams, common: &Common, r: &mut ParamReader, src: &Source) -> Result<UmbrellaParams> {
        let mut p = base.clone();
        common.apply(&mut p.seed, &mut p.period);
        if let Some(s) = r.get(&DENSITY) {
            p.density = DENSITY.integer(&s)? as u32;
        }
        if let Some(s) = r.get(&SCALE) {
            p.scale = SCALE.interval_milli(&s)?;
        }
        if let Some(s) = r.get(&SHAPE) {
            p.shape = SHAPE.unit(&s)?;
        }
        if let Some(s) = r.get(&COLOUR) {
            p.colour = COLOUR.unit(&s)?;
        }
        if let Some(s) = r.get(&SHADOW) {
            p.shadow = SHADOW.unit(&s)?;
        }
        if let Some(s) = r.get(&SHADOW_OFFSET) {
            p.shadow_offset = SHADOW_OFFSET.integer(&s)? as u32;
        }
        if let Some(s) = r.get(&K) {
            p.k = K.integer(&s)? as u32;
        }
        if let Some(s) = r.get(&BACKGROUND) {
            BACKGROUND.check(&s)?;
            p.background = Background::parse(&s).unwrap_or(Background::Mosaic);
        }
        check_period(p.period, src.side())?;
        Ok(p)
    }

    fn values(p: &UmbrellaParams, _: &Source) -> Map<String, Value> {
        let q = |v: u32| v as f64 / ONE_Q16 as f64;
        let mut m = Map::new();
        m.insert("seed".into(), json!(p.seed));
        m.insert(DENSITY.name.into(), json!(p.density));
        m.insert(SCALE.name.into(), json!([p.scale.0 as f64 / 1000.0, p.scale.1 as f64 / 1000.0]));
        m.insert(SHAPE.name.into(), json!(q(p.shape)));
        m.insert(COLOUR.name.into(), json!(q(p.colour)));
        m.insert(SHADOW.name.into(), json!(q(p.shadow)));
        m.insert(SHADOW_OFFSET.name.into(), json!(p.shadow_offset));
        m.insert(K.name.into(), json!(p.k));
        m.insert(BACKGROUND.name.into(), json!(p.background.name()));
        m
    }

    fn canonical(p: &UmbrellaParams) -> String {
        p.canonical()
    }

    fn preparation() -> Option<&'static dyn Step> {
        Some(&StepOf::<Extraction>::NEW)
    }

    /// The extraction: each base umbrella magnified with its rim and centre, and modified
    /// umbrellas of it below.
    fn sheet(p: &UmbrellaParams, src: &Source) -> Option<Result<RgbWindow>> {
        let sheet = || {
            let (el, id) = state(src)?.elements()?;
            Ok(sheet::debug_sheet(&el, &Arrangement::new(&el, p, &id)))
        };
        Some(sheet())
    }

    fn render(p: &UmbrellaParams, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        let rect = view.rect;
        check_window(rect, MAX_PIXELS)?;
        let state = state(src)?;
        let (elements, ident) = state.elements()?;
        let caches = &state.caches;
        let arr = Arrangement::cached(&elements, p, &ident, caches.clone());
        // Level 0 (every umbrella) while a cell is at least `lod::LOD_PIXELS` wide, then the
        // merged levels of detail, then the background's own zoomed-out pixels.
        let level = lod::level(&arr, view.zoom_out);
        let Some(level) = level else {
            // Shifted to the umbrellas' mean colour, so that zooming out past the last drawn
            // zoom changes the detail, not the colour.
            let shift = colour_shift(&arr, &elements, p, &ident, src, cache, umbrella_zooms(&arr))?;
            let image = shifted(background(p, src, cache, view)?, shift);
            return Ok(Rendered { image, synthesized: rect.area() as u64 });
        };
        let gaps = gap_shift(&arr, &elements, p, &ident, src, cache)?;
        let image = paint(&elements, &arr, p, view, level, || Ok(shifted(background(p, src, cache, view)?, gaps)))?;
        Ok(Rendered { image, synthesized: (rect.area() * (AA * AA) as i64) as u64 })
    }
}

/// Zoom-out steps at which umbrellas are drawn: every one of them while a grid cell (about an
/// element's diameter) is at least [`lod::LOD_PIXELS`] wide, merged ones down to
/// [`lod::MAX_LEVEL`]. Further out the view is the background's zoomed-out pixels.
pub fn umbrella_zooms(arr: &Arrangement) -> u32 {
    (0..64).take_while(|&z| lod::level(arr, z).is_some()).last().unwrap_or(0)
}

/// `image` with `shift` added to each channel, rounded and clamped (a table per channel, not a
/// rounding per pixel).
fn shifted(mut image: RgbWindow, shift: [f32; 3]) -> RgbWindow {
    let table: [[u8; 256]; 3] =
        std::array::from_fn(|c| std::array::from_fn(|v| (v as f32 + shift[c]).round().clamp(0.0, 255.0) as u8));
    for px in image.pixels.chunks_exact_mut(3) {
        for (v, t) in px.iter_mut().zip(&table) {
            *v = t[*v as usize];
        }
    }
    image
}

/// The texture's umbrella state: prepared with it, or (for a caller that prepared none) extracted
/// now.
fn state(src: &Source) -> Result<Arc<Extraction>> {
    if let Some(s) = src.prepared.and_then(|p| p.get::<Extraction>(Umbrella::NAME)) {
        return Ok(s);
    }
    Ok(Arc::new(Extraction::extract(src.exemplar)))
}

/// A colour calibration of texture `ident` with parameters `p`, memoised in `memo` (one of
/// the texture's caches, beside `arr`'s): `f` is given the parameters it is measured with —
/// `p` with seed 0, since a calibration is a statistic of the arrangement that another seed
/// changes only by chance, and a new seed should not pay for it again — and their arrangement.
fn calibrated(
    memo: &Memo<String, [f32; 3]>,
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    f: impl FnOnce(&UmbrellaParams, &Arrangement) -> Result<[f32; 3]>,
) -> Result<[f32; 3]> {
    let p = UmbrellaParams { seed: 0, ..p.clone() };
    let key = format!("{ident};{}", p.canonical());
    if let Some(s) = memo.get(&key) {
        return Ok(s);
    }
    let caches = arr.caches_arc();
    let s = f(&p, &Arrangement::cached(el, &p, ident, caches))?;
    memo.put(key.clone(), s, key.len() as u64 + 64);
    Ok(s)
}

/// Largest shift of the background's colour for the gaps ([`gap_shift`]), per channel.
const MAX_GAP_SHIFT: f32 = 48.0;

/// What the background is shifted by, per channel, where it shows between umbrellas: so that
/// the native view's mean colour is the exemplar's. The background stands for the gaps between
/// elements, but it is another mode's view of the whole exemplar — elements included — so
/// with light elements on dark gaps (leaves, smallstone, gravel) the output came out brighter
/// than the exemplar, and darker for dark ones (granite). Measured over a fixed 256² native
/// window at the origin: the mean colour, and the background's weight in it (the view with a
/// white background less the view with a black one); the difference to the exemplar's mean
/// over that weight, at most [`MAX_GAP_SHIFT`]. Elements keep their colours. Measured with
/// seed 0 and memoised ([`calibrated`]).
fn gap_shift(
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    src: &Source,
    cache: &Pyramid,
) -> Result<[f32; 3]> {
    calibrated(&arr.caches().gaps, arr, el, p, ident, |p, arr| {
        let Some(level) = lod::level(arr, 0) else {
            return Ok([0.0; 3]);
        };
        let view = View::out(0, crate::geom::Rect::new(0, 0, 256, 256));
        let flat = |v: u8| move || Ok(RgbWindow { width: 256, height: 256, pixels: vec![v; 3 * 256 * 256] });
        let image = paint(el, arr, p, view, level, || background(p, src, cache, view))?;
        let black = paint(el, arr, p, view, level, flat(0))?;
        let white = paint(el, arr, p, view, level, flat(255))?;
        let mut sums = [[0f64; 3]; 2];
        for (i, ((&v, &b), &w)) in image.pixels.iter().zip(&black.pixels).zip(&white.pixels).enumerate() {
            sums[0][i % 3] += v as f64;
            sums[1][i % 3] += w as f64 - b as f64;
        }
        let n = (image.pixels.len() / 3).max(1) as f64;
        // The exemplar's mean (for a hand-made set too, whose elements' mean it is not).
        let target = mean_colour(src.exemplar);
        Ok(std::array::from_fn(|c| {
            let (mean, weight) = (sums[0][c] / n, sums[1][c] / n / 255.0);
            let target = target[c];
            if weight < 0.05 {
                0.0
            } else {
                ((target - mean) / weight).clamp(-MAX_GAP_SHIFT as f64, MAX_GAP_SHIFT as f64) as f32
            }
        }))
    })
}

/// Mean colour of the umbrellas' view (its gaps shifted, [`gap_shift`]) minus the background's,
/// per channel, at the last zoom where umbrellas are drawn, over a fixed 128² window at the
/// origin (measured with seed 0 and memoised, [`calibrated`]): what the background is shifted
/// by further out.
fn colour_shift(
    arr: &Arrangement,
    el: &Elements,
    p: &UmbrellaParams,
    ident: &str,
    src: &Source,
    cache: &Pyramid,
    zooms: u32,
) -> Result<[f32; 3]> {
    let gaps = gap_shift(arr, el, p, ident, src, cache)?;
    calibrated(&arr.caches().colours, arr, el, p, ident, |p, arr| {
        let view = View::out(zooms, crate::geom::Rect::new(0, 0, 128, 128));
        let level = lod::level(arr, zooms).unwrap_or(0);
        let raw = background(p, src, cache, view)?;
        let gapped = shifted(raw.clone(), gaps);
        let umb = paint(el, arr, p, view, level, || Ok(gapped))?;
        let mut shift = [0f32; 3];
        for (i, (a, b)) in umb.pixels.iter().zip(&raw.pixels).enumerate() {
            shift[i % 3] += *a as f32 - *b as f32;
        }
        let n = (umb.pixels.len() / 3).max(1) as f32;
        Ok(shift.map(|v| v / n))
    })
}

/// The background of a view: another mode's pixels (or the mean colour). Zoomed out, the
/// mosaic's sampled pixels (each labelled once, at its centre, and averaged over its footprint
/// around that label's source), not its exact box filter of the native ones: the background
/// shows only between umbrellas, and the exact filter cost a fifth of a zoom-out-1 tile.
fn background(p: &UmbrellaParams, src: &Source, cache: &Pyramid, view: View) -> Result<RgbWindow> {
    let ex = src.exemplar;
    Ok(match p.background {
        Background::Mosaic => {
            let mp = MosaicParams { seed: p.seed, period: p.period, ..MosaicParams::default() };
            mosaic::render_sampled(ex, &mp, view.zoom_out, view.rect)?
        }
        Background::Synth => {
            let sp = SynthParams { seed: p.seed, period: p.period, ..SynthParams::default() };
            <Synth as Mode>::render(&sp, src, cache, view)?.image
        }
        Background::Tiling => {
            let tp = TilingParams { seed: p.seed, period: p.period };
            <Tiling as Mode>::render(&tp, src, cache, view)?.image
        }
        Background::Mean => {
            let (w, h) = (view.rect.width() as usize, view.rect.height() as usize);
            // Rounded half up, as the exact integer means were.
            let mean = mean_colour(ex).map(|v| v.round() as u8);
            RgbWindow { width: w as u32, height: h as u32, pixels: mean.repeat(w * h) }
        }
    })
}

/// The exemplar's mean colour, RGB in `[0, 255]` (exact sums).
fn mean_colour(ex: &Exemplar) -> [f64; 3] {
    let n = ex.pixels.len().max(1) as u64;
    let mut s = [0u64; 3];
    for p in &ex.pixels {
        for k in 0..3 {
            s[k] += p[k] as u64;
        }
    }
    s.map(|v| v as f64 / n as f64)
}

/// The elements of an exemplar, extracted now, with the id that names them; none → a
/// parameter error naming the mode.
pub fn elements(ex: &Exemplar) -> Result<(Arc<Elements>, String)> {
    Extraction::extract(ex).elements()
}

/// Render a view at level of detail `level` (whose cells are at least two pixels wide) over a
/// background (rendered meanwhile): band by band — one row of cells each, a
/// frame of [`lod::FRAME`] cells at a time — the coverage of every pixel's fixed 4×4
/// sub-samples ([`raster`]) by the cells' umbrellas (level 0: the union of the cells' lists,
/// each umbrella masked to the cells that list it; merged levels: the merged umbrellas around
/// the row, [`lod::list`]), then per pixel the colour of each umbrella (or the background) its
/// sub-samples see, evaluated once at their centroid and weighted by their number, darkened by
/// their shadows: multisample anti-aliasing, with one colour evaluation for a pixel inside one
/// umbrella.
fn paint(
    el: &Elements,
    arr: &Arrangement,
    p: &UmbrellaParams,
    view: View,
    level: u32,
    background: impl FnOnce() -> Result<RgbWindow> + Send,
) -> Result<RgbWindow> {
    let rect = view.rect;
    let step = 1i64 << view.zoom_out.min(40);
    let side = arr.g << level;
    debug_assert!(2 * step <= side, "umbrellas are drawn while a cell is two pixels wide");
    // Pixels per cell side.
    let ppc = (side / step).max(1);
    let (w, a) = (rect.width() as usize, AA as i64);
    let sp = step as f32 / AA as f32;
    let shadow = p.shadow as f32 / ONE_Q16 as f32;
    let shadows = (shadow > 0.0 && arr.shadow_offset > 0.0).then_some(arr.shadow_offset);
    let mut darken = [1f32; 256];
    for n in 1..256 {
        darken[n] = darken[n - 1] * (1.0 - shadow);
    }
    let sectors = shape::SectorTable::default();
    let rays = &arr.rays;
    let (cx0, cx1) = (rect.x0.div_euclid(ppc), (rect.x1 - 1).div_euclid(ppc) + 1);
    let (cy0, cy1) = (rect.y0.div_euclid(ppc), (rect.y1 - 1).div_euclid(ppc) + 1);
    let row_cells = (cx1 - cx0) as usize;
    // The background, and meanwhile the cells: level 0, the lists of all cells at once (spawn
    // cells placed once), unless a huge window has more than is worth holding (then a row of
    // cells at a time); merged levels, the merged cells around the view, in parallel.
    let reach = if level > 0 { lod::around(arr, level) } else { 0 };
    let (mx0, my0, mw) = (cx0 - reach, cy0 - reach, (cx1 - cx0 + 2 * reach) as usize);
    let (bg, (all, merged)) = rayon::join(background, || {
        let all = (level == 0 && (cx1 - cx0) as u64 * (cy1 - cy0) as u64 <= 1 << 16).then(|| arr.lists(cx0, cy0, cx1, cy1));
        let merged: Vec<(i64, i64, Arc<Vec<lod::Merged>>)> = if level > 0 {
            let mh = (cy1 - cy0 + 2 * reach) as usize;
            (0..mw * mh)
                .into_par_iter()
                .map(|n| {
                    let (x, y) = (mx0 + (n % mw) as i64, my0 + (n / mw) as i64);
                    (x, y, lod::cell(el, arr, &sectors, level, x, y))
                })
                .collect()
        } else {
            Vec::new()
        };
        (all, merged)
    });
    let bg = bg?;
    // Per pixel column, its left edge relative to the origin of its frame of cells (the same
    // in every band).
    let oxs: Vec<f32> = (rect.x0..rect.x1).map(|x| ((x - lod::frame_of(x.div_euclid(ppc)) * ppc) * step) as f32).collect();
    let bands: Vec<Vec<u8>> = (cy0..cy1)
        .into_par_iter()
        .map(|cy| {
            let (j0, j1) = (rect.y0.max(cy * ppc), rect.y1.min((cy + 1) * ppc));
            let rows_px = (j1 - j0) as usize;
            let mut cov = raster::Coverage::new(w * AA, rows_px * AA);
            let rows = ((j0 - cy * ppc) * a, (j1 - cy * ppc) * a);
            let own;
            let mut placed: Vec<Placed> = Vec::new();
            let mut locals: Vec<lod::Local> = Vec::new();
            let lists: &[Arc<Vec<Placed>>] = match (&all, level) {
                (_, 1..) => &[],
                (Some(v), _) => &v[(cy - cy0) as usize * row_cells..][..row_cells],
                (None, _) => {
                    own = arr.lists(cx0, cy, cx1, cy + 1);
                    &own
                }
            };
            // The row in stretches, one per frame of `lod::FRAME` cells it meets, each
            // rasterised with one list, in positions relative to the frame's origin (the same
            // whichever window asks): each umbrella filled once, not once per cell it reaches.
            let mut fx = cx0;
            while fx < cx1 {
                let frame = lod::frame_of(fx);
                let end = cx1.min(frame + lod::FRAME);
                let (i0, i1) = (rect.x0.max(fx * ppc), rect.x1.min(end * ppc));
                let cols = ((i0 - frame * ppc) * a, (i1 - frame * ppc) * a);
                let band = (0, (i0 - rect.x0) * a);
                if level == 0 {
                    // The union of the cells' lists, each umbrella masked to the cells that list it.
                    let union = arr.union((fx..end).map(|cx| (cx, &lists[(cx - cx0) as usize][..])), frame);
                    let cells = raster::Cells { base: (fx - frame) * ppc * a, width: ppc * a };
                    let shape = raster::placed_shape(arr, &union);
                    cov.fill_list(union.len(), shape, cells, placed.len() as u32, sp, rows, cols, band, shadows);
                    placed.extend(union.iter().map(|(u, _)| *u));
                } else {
                    let near = (cy - reach..=cy + reach)
                        .flat_map(|y| (fx - reach..end + reach).map(move |x| (x, y)))
                        .map(|(x, y)| &*merged[(y - my0) as usize * mw + (x - mx0) as usize].2);
                    let list = lod::list(near, arr, level, frame, (fx, end), cy);
                    let shape = |n: usize, o: f32, extent: [f32; 4]| {
                        let l = &list[n];
                        raster::disc_reaches(l.o[0] + o, l.o[1] + o, l.reach2, extent).then(|| (l.rim.shifted(o), u64::MAX))
                    };
                    cov.fill_list(list.len(), shape, raster::Cells::ALL, locals.len() as u32, sp, rows, cols, band, shadows);
                    locals.extend(list);
                }
                fx = end;
            }
            let mut out = vec![0u8; 3 * w * rows_px];
            for (j, row) in out.chunks_exact_mut(3 * w).enumerate() {
                let y = j0 + j as i64;
                let oy = (y.rem_euclid(ppc) * step) as f32;
                let bg_row = &bg.pixels[3 * (y - rect.y0) as usize * w..][..3 * w];
                for i in 0..w {
                    let ox = oxs[i];
                    let b = &bg_row[3 * i..3 * i + 3];
                    // What a group of sub-samples sees, at `(qx, qy)` from the frame's origin.
                    let eval = |key: u64, qx: f32, qy: f32| -> [f32; 3] {
                        let (id, f) = ((key >> 8) as u32, darken[(key & 0xFF) as usize]);
                        if id == raster::NONE {
                            return [0, 1, 2].map(|k| b[k] as f32 * f);
                        }
                        if level > 0 {
                            let c = lod::colour_at(&locals[id as usize], [qx, qy], el, arr, &sectors, rays, step as f32);
                            return c.map(|v| v * f * 255.0);
                        }
                        let u = &placed[id as usize];
                        let m = &arr.table[u.modified as usize];
                        let (dx, dy) = (qx - u.cx, qy - u.cy);
                        let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
                        let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
                        let hit = m.rim.locate_clamped(&sectors, lx, ly);
                        shape::colour(&el.bases[m.base], rays, &m.colour, hit, step as f32 * u.inv_scale).map(|v| v * f * 255.0)
                    };
                    // A pixel whose sub-samples all see the same (most are): one evaluation.
                    // A sample's key: the umbrella it sees and its shadows.
                    let key = |k: usize| (cov.hit[k] as u64) << 8 | cov.shade[k] as u64;
                    let k0 = j * AA * cov.width + i * AA;
                    let (h0, s0) = (cov.hit[k0], cov.shade[k0]);
                    let uniform = (0..AA).all(|sy| {
                        let k = k0 + sy * cov.width;
                        cov.hit[k..k + AA].iter().all(|&h| h == h0) && cov.shade[k..k + AA].iter().all(|&s| s == s0)
                    });
                    let out = if uniform {
                        eval(key(k0), ox + 0.5 * step as f32, oy + 0.5 * step as f32)
                    } else {
                        let keys: [u64; AA * AA] = std::array::from_fn(|n| key(k0 + (n / AA) * cov.width + n % AA));
                        // Groups of equal sub-samples: key, count, sum of positions.
                        let mut groups = [(0u64, 0u32, 0f32, 0f32); AA * AA];
                        let mut ng = 0;
                        for (n, &key) in keys.iter().enumerate() {
                            let qx = ox + ((n % AA) as f32 + 0.5) * sp;
                            let qy = oy + ((n / AA) as f32 + 0.5) * sp;
                            match groups[..ng].iter_mut().find(|g| g.0 == key) {
                                Some(g) => {
                                    g.1 += 1;
                                    g.2 += qx;
                                    g.3 += qy;
                                }
                                None => {
                                    groups[ng] = (key, 1, qx, qy);
                                    ng += 1;
                                }
                            }
                        }
                        let mut acc = [0f32; 3];
                        for &(key, n, sx, sy) in &groups[..ng] {
                            let c = eval(key, sx / n as f32, sy / n as f32);
                            for k in 0..3 {
                                acc[k] += c[k] * n as f32;
                            }
                        }
                        acc.map(|v| v / (AA * AA) as f32)
                    };
                    for k in 0..3 {
                        // Rounded half up (non-negative; `f32::round` is a call without SSE4.1).
                        row[3 * i + k] = (out[k].clamp(0.0, 255.0) + 0.5) as u8;
                    }
                }
            }
            out
        })
        .collect();
    Ok(RgbWindow { width: w as u32, height: rect.height() as u32, pixels: bands.concat() })
}

/// Words of storage of the paper's Table 1, `J = b·w·h + 2·b·v + n·(1 + 3v) + k·W·H`, for a
/// region of `cells_x × cells_y` grid cells: bases' texels, their vertices, the modified
/// umbrellas and the cell lists.
pub fn storage_words(el: &Elements, arr: &Arrangement, cells_x: u64, cells_y: u64) -> u64 {
    let v = (RAYS + 1) as u64;
    let textures: u64 = el.bases.iter().map(|b| b.w as u64 * b.h as u64).sum();
    let b = el.bases.len() as u64;
    let n = arr.table.len() as u64;
    textures + 2 * b * v + n * (1 + 3 * v) + arr.k as u64 * cells_x * cells_y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exemplar::ExemplarOptions;

    #[test]
    fn a_row_filled_with_the_union_of_its_lists_is_each_list_filled_in_its_cell() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, id) = elements(&ex).unwrap();
        let p = UmbrellaParams { shadow_offset: 3, k: 3, ..UmbrellaParams::default() };
        let arr = Arrangement::new(&el, &p, &id);
        let (sp, n, cy, cells) = (0.25f32, arr.g * 4, -2i64, 61..69i64);
        let width = (n * (cells.end - cells.start)) as usize;
        let lists: Vec<Arc<Vec<Placed>>> = cells.clone().map(|cx| arr.list(cx, cy)).collect();
        // Each list in its cell, in the cell's coordinates.
        let mut each = raster::Coverage::new(width, n as usize);
        let mut ids = Vec::new();
        for (i, list) in lists.iter().enumerate() {
            let listed: Vec<(Placed, u64)> = list.iter().map(|u| (*u, u64::MAX)).collect();
            let shape = raster::placed_shape(&arr, &listed);
            let band = (0, i as i64 * n);
            each.fill_list(list.len(), shape, raster::Cells::ALL, ids.len() as u32, sp, (0, n), (0, n), band, Some(3.0));
            ids.extend(list.iter().map(|u| u.id));
        }
        // The union, in the frame's coordinates (cells 0..64), masked.
        let union = arr.union(cells.clone().zip(&lists).map(|(cx, l)| (cx, &l[..])), 0);
        assert!(union.iter().any(|(_, m)| m.count_ones() > 1), "umbrellas listed in several cells");
        let mut once = raster::Coverage::new(width, n as usize);
        let mask = raster::Cells { base: cells.start * n, width: n };
        let cols = (cells.start * n, cells.end * n);
        once.fill_list(union.len(), raster::placed_shape(&arr, &union), mask, 0, sp, (0, n), cols, (0, 0), Some(3.0));
        let who = |hit: u32, ids: &dyn Fn(usize) -> (i64, i64, u32)| (hit != raster::NONE).then(|| ids(hit as usize));
        let (mut differ, mut hits) = (0, 0);
        for k in 0..each.hit.len() {
            let a = (who(each.hit[k], &|i| ids[i]), each.shade[k]);
            let b = (who(once.hit[k], &|i| union[i].0.id), once.shade[k]);
            differ += (a != b) as usize;
            hits += a.0.is_some() as usize;
        }
        eprintln!("{hits} of {} samples hit, {differ} differ (rounding at rims)", each.hit.len());
        assert!(hits * 2 > each.hit.len() && differ * 1000 <= each.hit.len(), "{differ} samples differ");
    }

    #[test]
    fn coverage_sees_the_first_umbrella_and_shadows_come_only_from_those_in_front_of_it() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, id) = elements(&ex).unwrap();
        let p = UmbrellaParams { shadow_offset: 4, shadow: ONE_Q16 / 2, ..UmbrellaParams::default() };
        let arr = Arrangement::new(&el, &p, &id);
        let (angles, rays) = (shape::ray_angles(), arr.rays);
        // Independently, per point: inside by the barycentric test in the umbrella's frame.
        let contains = |u: &Placed, qx: f32, qy: f32| {
            let (dx, dy) = (qx - u.cx, qy - u.cy);
            let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
            let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
            shape::locate(&angles, &rays, &arr.table[u.modified as usize].radii, lx, ly).is_some()
        };
        // Whether a rim passes within 0.01 texels of the point (where the two tests may round
        // differently).
        let on_rim = |u: &Placed, qx: f32, qy: f32| {
            let c = contains(u, qx, qy);
            [(0.01, 0.0), (-0.01, 0.0), (0.0, 0.01), (0.0, -0.01)].iter().any(|&(ex, ey)| contains(u, qx + ex, qy + ey) != c)
        };
        let (sp, n) = (0.25f32, arr.g * 4);
        let (mut shaded, mut hits, mut total, mut borderline) = (0, 0, 0, 0);
        for cy in -2..3 {
            for cx in -2..3 {
                let list = arr.list(cx, cy);
                let mut cov = raster::Coverage::new(n as usize, n as usize);
                let listed: Vec<(Placed, u64)> = list.iter().map(|u| (*u, u64::MAX)).collect();
                cov.fill_list(list.len(), raster::placed_shape(&arr, &listed), raster::Cells::ALL, 0, sp, (0, n), (0, n), (0, 0), Some(4.0));
                for r in 0..n {
                    for c in 0..n {
                        let (qx, qy) = ((c as f32 + 0.5) * sp, (r as f32 + 0.5) * sp);
                        // The first umbrella of the list containing the point is hit; only those
                        // before it containing the point moved by −ℓ shade it.
                        let hit = list.iter().position(|u| contains(u, qx, qy));
                        let front = &list[..hit.unwrap_or(list.len())];
                        let shade = front.iter().filter(|u| contains(u, qx - 4.0, qy - 4.0)).count();
                        let k = (r * n + c) as usize;
                        let got = ((cov.hit[k] != raster::NONE).then_some(cov.hit[k] as usize), cov.shade[k] as usize);
                        if got != (hit, shade) {
                            let near = list.iter().any(|u| on_rim(u, qx, qy) || on_rim(u, qx - 4.0, qy - 4.0));
                            assert!(near, "cell {cx},{cy} sample {c},{r}: coverage {got:?}, walk {:?}", (hit, shade));
                            borderline += 1;
                        }
                        total += 1;
                        shaded += (shade > 0) as u32;
                        hits += hit.is_some() as u32;
                    }
                }
            }
        }
        eprintln!("{hits} of {total} samples hit an umbrella, {shaded} shaded, {borderline} differ on a rim");
        assert!(borderline * 1000 <= total, "{borderline} of {total} samples differ");
        assert!(shaded > 100 && hits > 1000, "the test saw shadows ({shaded}) and hits ({hits})");
    }
}
