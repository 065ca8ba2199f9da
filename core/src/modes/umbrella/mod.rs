//! Just-in-time umbrella patches (design note §5): the mode for textures of discrete elements.
//! A handful of base umbrellas extracted from the exemplar ([`extract`]) are diversified into
//! a table of modified umbrellas and scattered over an infinite grid of cells ([`arrange`]);
//! every sample point is evaluated at request time ([`shape`]): the front-most umbrella that
//! contains it gives its colour, umbrellas in front of it that contain the point moved towards
//! the light shade it, and where none covers it another mode's output (the background) shows.
//! A pixel whose four corners see the same thing is sampled once; the others take a fixed 4×4
//! pattern of sub-samples. Everything is a function of absolute coordinates, so windows are the
//! same pixels cut from larger ones.

pub mod arrange;
pub mod extract;
pub mod shape;
pub mod sheet;

use std::num::NonZeroUsize;
use std::sync::{Arc, Mutex, OnceLock};

use lru::LruCache;

use rayon::prelude::*;
use serde_json::{json, Map, Value};

use crate::cache::Pyramid;
use crate::error::Result;
use crate::exemplar::Exemplar;
use crate::image::{Rendered, RgbWindow};
use crate::modes::mosaic::{self, MosaicParams};
use crate::modes::params::{check_period, Common, Kind, ParamReader, ParamSpec, Scope, ONE_Q16};
use crate::modes::synth::{Synth, SynthParams};
use crate::modes::tiling::{Tiling, TilingParams};
use crate::modes::{check_window, Cost, Mode, Needs, Source, View};

use arrange::Arrangement;
use extract::{ray, Elements, RAYS};

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
    const VERSION: u32 = 2;
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

    fn render(p: &UmbrellaParams, src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        let rect = view.rect;
        check_window(rect, MAX_PIXELS)?;
        let (elements, ident) = elements(src.exemplar)?;
        let arr = Arrangement::new(&elements, p, &ident);
        let background = background(p, src, cache, view)?;
        // Zoomed out until elements are about two pixels across, and beyond: the background's
        // own zoomed-out pixels (the design note's merged levels of detail are not built; see
        // `umbrella_zooms`).
        let zooms = umbrella_zooms(&arr);
        if view.zoom_out > zooms {
            // Shifted to the umbrellas' mean colour, so that zooming out past the last drawn
            // zoom changes the detail, not the colour.
            let shift = colour_shift(&elements, &arr, p, src, cache, zooms)?;
            let mut image = background;
            for (i, v) in image.pixels.iter_mut().enumerate() {
                *v = (*v as f32 + shift[i % 3]).round().clamp(0.0, 255.0) as u8;
            }
            return Ok(Rendered { image, synthesized: rect.area() as u64 });
        }
        let image = paint(&elements, &arr, p, view, &background);
        Ok(Rendered { image, synthesized: (rect.area() * (AA * AA) as i64) as u64 })
    }
}

/// Zoom-out steps at which umbrellas are drawn: while a grid cell (about an element's
/// diameter) is at least two pixels wide. Further out, elements are too small for sub-samples
/// to resolve and a tile would need the lists of more cells than it has pixels; the view is then
/// the background's zoomed-out pixels.
pub fn umbrella_zooms(arr: &Arrangement) -> u32 {
    (arr.g as u64 / 2).max(1).trailing_zeros()
}

/// Mean colour of the umbrellas' view minus the background's, per channel, at the last zoom
/// where umbrellas are drawn, over a fixed 128² window at the origin (memoised per texture and
/// parameters): what the background is shifted by further out.
fn colour_shift(el: &Elements, arr: &Arrangement, p: &UmbrellaParams, src: &Source, cache: &Pyramid, zooms: u32) -> Result<[f32; 3]> {
    static MEMO: OnceLock<Mutex<LruCache<u64, [f32; 3]>>> = OnceLock::new();
    let memo = MEMO.get_or_init(|| Mutex::new(LruCache::new(NonZeroUsize::new(64).unwrap_or(NonZeroUsize::MIN))));
    if let Some(s) = memo.lock().ok().and_then(|mut m| m.get(&arr.key()).copied()) {
        return Ok(s);
    }
    let view = View::out(zooms, crate::geom::Rect::new(0, 0, 128, 128));
    let bg = background(p, src, cache, view)?;
    let umb = paint(el, arr, p, view, &bg);
    let mut shift = [0f32; 3];
    for (i, (a, b)) in umb.pixels.iter().zip(&bg.pixels).enumerate() {
        shift[i % 3] += *a as f32 - *b as f32;
    }
    let n = (umb.pixels.len() / 3).max(1) as f32;
    let shift = shift.map(|v| v / n);
    if let Ok(mut m) = memo.lock() {
        m.put(arr.key(), shift);
    }
    Ok(shift)
}

/// The background of a view: another mode's pixels (or the mean colour).
fn background(p: &UmbrellaParams, src: &Source, cache: &Pyramid, view: View) -> Result<RgbWindow> {
    let ex = src.exemplar;
    Ok(match p.background {
        Background::Mosaic => {
            let mp = MosaicParams { seed: p.seed, period: p.period, ..MosaicParams::default() };
            mosaic::render(ex, &mp, view.zoom_out, view.rect)?
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
            let mean = mean_colour(ex);
            RgbWindow { width: w as u32, height: h as u32, pixels: mean.repeat(w * h) }
        }
    })
}

fn mean_colour(ex: &Exemplar) -> [u8; 3] {
    let n = ex.pixels.len().max(1) as u64;
    let mut s = [0u64; 3];
    for p in &ex.pixels {
        for k in 0..3 {
            s[k] += p[k] as u64;
        }
    }
    s.map(|v| ((v + n / 2) / n) as u8)
}

/// The extraction of an exemplar, memoised by its content hash (deterministic, so computing it
/// twice gives the same; kept for the textures in use), with that hash.
pub fn elements(ex: &Exemplar) -> Result<(Arc<Elements>, String)> {
    static MEMO: OnceLock<Mutex<LruCache<String, Arc<Elements>>>> = OnceLock::new();
    let mut h = blake3::Hasher::new();
    h.update(b"textile-umbrella-elements");
    ex.hash_content(&mut h);
    let id = h.finalize().to_hex()[..16].to_string();
    let memo = MEMO.get_or_init(|| Mutex::new(LruCache::new(NonZeroUsize::new(32).unwrap_or(NonZeroUsize::MIN))));
    if let Some(e) = memo.lock().ok().and_then(|mut m| m.get(&id).cloned()) {
        return Ok((e, id));
    }
    let e = Arc::new(extract::extract(&ex.pixels, ex.side as usize, ex.toroidal)?);
    if let Ok(mut m) = memo.lock() {
        m.put(id.clone(), e.clone());
    }
    Ok((e, id))
}

/// What a sample point sees: a signature (the hit umbrella's id, or none, and how many
/// umbrellas shade it) and, when asked for, its colour (hits) or shade (background).
struct Sample {
    sig: u64,
    hit: Option<[f32; 3]>,
    shade: f32,
}

/// Evaluate one sample point at absolute texel position `(x, y)` (f64 only to reach the cell;
/// everything after is relative to it); the hit's colour only `if colour`.
#[allow(clippy::too_many_arguments)]
fn sample(el: &Elements, arr: &Arrangement, tabs: &Tabs, lists: &Lists, x: f64, y: f64, shadow: f32, colour: bool) -> Sample {
    let g = arr.g as f64;
    let (cx, cy) = ((x / g).floor() as i64, (y / g).floor() as i64);
    let (px, py) = ((x - cx as f64 * g) as f32, (y - cy as f64 * g) as f32);
    sample_in(el, arr, tabs, lists.get(cx, cy).iter(), px, py, shadow, colour)
}

/// [`sample`] at `(px, py)` relative to a cell, over `list` — the cell's list, or the part of
/// it that can matter near the point (front to back either way).
#[allow(clippy::too_many_arguments)]
fn sample_in<'a>(
    el: &Elements,
    arr: &Arrangement,
    tabs: &Tabs,
    list: impl Iterator<Item = &'a arrange::Placed>,
    px: f32,
    py: f32,
    shadow: f32,
    colour: bool,
) -> Sample {
    let l = arr.shadow_offset;
    let (mut shade, mut shaded) = (1.0f32, 0u64);
    for u in list {
        let m = &arr.table[u.modified as usize];
        // Whether the point is inside, and where (only when `exact`: a point well inside the
        // rim is known to be in without locating it).
        let inside = |qx: f32, qy: f32, exact: bool| {
            let (dx, dy) = (qx - u.cx, qy - u.cy);
            let d2 = dx * dx + dy * dy;
            if d2 > u.reach2 {
                return None;
            }
            if !exact && d2 < u.inner2 {
                return Some(None);
            }
            // Into the umbrella's frame: rotate back, unscale.
            let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
            let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
            m.rim.locate(&tabs.sectors, lx, ly).map(Some)
        };
        if let Some(hit) = inside(px, py, colour) {
            let sig = (u.depth | 0xFF) ^ shaded;
            let c = hit.map(|hit| shape::colour(&el.bases[m.base], &tabs.rays, &m.colour, hit).map(|v| v * shade));
            return Sample { sig, hit: c, shade };
        }
        // An umbrella in front that covers the point moved towards the light shades it.
        if l > 0.0 && inside(px - l, py - l, false).is_some() {
            shade *= 1.0 - shadow;
            shaded += 1;
        }
    }
    Sample { sig: shaded, hit: None, shade }
}

/// Per-ray constants.
struct Tabs {
    rays: [[f32; 2]; RAYS],
    sectors: shape::SectorTable,
}

/// The cell lists covering a view, fetched once.
struct Lists {
    x0: i64,
    y0: i64,
    w: i64,
    lists: Vec<Arc<Vec<arrange::Placed>>>,
}

impl Lists {
    fn get(&self, cx: i64, cy: i64) -> &[arrange::Placed] {
        let i = (cy - self.y0) * self.w + (cx - self.x0);
        &self.lists[i as usize]
    }
}

/// Render a view: every pixel's 4×4 sub-samples, hits coloured, misses from the background.
fn paint(el: &Elements, arr: &Arrangement, p: &UmbrellaParams, view: View, bg: &RgbWindow) -> RgbWindow {
    let rect = view.rect;
    let scale = (1u64 << view.zoom_out.min(40)) as f64;
    let g = arr.g as f64;
    // Cells covering the footprint of the view.
    let (tx0, ty0) = (rect.x0 as f64 * scale, rect.y0 as f64 * scale);
    let (tx1, ty1) = (rect.x1 as f64 * scale, rect.y1 as f64 * scale);
    let (cx0, cy0) = ((tx0 / g).floor() as i64, (ty0 / g).floor() as i64);
    // Inclusive of the far edge: pixel corners lie on it.
    let (cx1, cy1) = ((tx1 / g).floor() as i64 + 1, (ty1 / g).floor() as i64 + 1);
    let tabs = Tabs { rays: std::array::from_fn(ray), sectors: shape::SectorTable::default() };
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    // Far zoomed out, a view covers more cells than is worth listing: sample the cells sparsely
    // (the lists are fetched lazily per row band below).
    let cells = (cx1 - cx0) as u64 * (cy1 - cy0) as u64;
    let shadow = p.shadow as f32 / ONE_Q16 as f32;
    let lists = if cells <= 1 << 16 {
        Some(Lists {
            x0: cx0,
            y0: cy0,
            w: cx1 - cx0,
            lists: arr.lists(cx0, cy0, cx1, cy1),
        })
    } else {
        None
    };
    let probe = |ax: f64, ay: f64, colour: bool| match &lists {
        Some(l) => sample(el, arr, &tabs, l, ax, ay, shadow, colour),
        None => {
            let (cx, cy) = ((ax / g).floor() as i64, (ay / g).floor() as i64);
            let one = Lists { x0: cx, y0: cy, w: 1, lists: vec![arr.list(cx, cy)] };
            sample(el, arr, &tabs, &one, ax, ay, shadow, colour)
        }
    };
    // Signatures at the pixel corners: where all four agree (same umbrella or none, same
    // shadows), the pixel is taken as uniform and sampled once at its centre; elsewhere (edges)
    // with the fixed 4×4 pattern. Corners are absolute positions, so this stays a function of
    // position only.
    let corners: Vec<u64> = (0..=h)
        .into_par_iter()
        .flat_map_iter(|j| {
            let y = (rect.y0 + j as i64) as f64 * scale;
            (0..=w).map(move |i| ((rect.x0 + i as i64) as f64 * scale, y)).collect::<Vec<_>>()
        })
        .map(|(ax, ay)| probe(ax, ay, false).sig)
        .collect();
    let step = 1i64 << view.zoom_out.min(40);
    let mut pixels = vec![0u8; 3 * w * h];
    pixels.par_chunks_mut(3 * w).enumerate().for_each(|(j, row)| {
        let y = rect.y0 + j as i64;
        let mut near_list: Vec<&arrange::Placed> = Vec::new();
        for i in 0..w {
            let x = rect.x0 + i as i64;
            let b = &bg.pixels[3 * (j * w + i)..3 * (j * w + i) + 3];
            let c = &corners[j * (w + 1) + i..];
            let uniform = c[0] == c[1] && c[0] == c[w + 1] && c[0] == c[w + 2];
            let colour_of = |s: Sample| match s.hit {
                Some(c) => c.map(|v| v * 255.0),
                None => [0, 1, 2].map(|k| b[k] as f32 * s.shade),
            };
            let out = if uniform {
                colour_of(probe((x as f64 + 0.5) * scale, (y as f64 + 0.5) * scale, true))
            } else if let (true, Some(l)) = (step <= arr.g, &lists) {
                // A pixel lies in one cell (both are aligned powers of two, the pixel no wider):
                // only the umbrellas whose disc meets the pixel, or the pixel moved by −ℓ, can
                // matter to its sub-samples; the same results as the whole list (the same f32
                // coordinates, exactly), with fewer tests.
                let (tx, ty) = (x * step, y * step);
                let (cx, cy) = (tx.div_euclid(arr.g), ty.div_euclid(arr.g));
                let (x0, y0) = ((tx - cx * arr.g) as f32, (ty - cy * arr.g) as f32);
                let (lo, sf) = (arr.shadow_offset, step as f32);
                // Conservatively: the centre's distance to the pixel square moved by −(ox, oy).
                let near = |u: &arrange::Placed, ox: f32, oy: f32| {
                    let ddx = u.cx - u.cx.clamp(x0 - ox, x0 + sf - ox);
                    let ddy = u.cy - u.cy.clamp(y0 - oy, y0 + sf - oy);
                    ddx * ddx + ddy * ddy <= u.reach2 * 1.001 + 1e-3
                };
                near_list.clear();
                near_list.extend(l.get(cx, cy).iter().filter(|u| near(u, 0.0, 0.0) || (lo > 0.0 && near(u, lo, lo))));
                let mut acc = [0f32; 3];
                for sy in 0..AA {
                    for sx in 0..AA {
                        let px = x0 + (sx as f32 + 0.5) / AA as f32 * sf;
                        let py = y0 + (sy as f32 + 0.5) / AA as f32 * sf;
                        let c = colour_of(sample_in(el, arr, &tabs, near_list.iter().copied(), px, py, shadow, true));
                        for k in 0..3 {
                            acc[k] += c[k];
                        }
                    }
                }
                acc.map(|v| v / (AA * AA) as f32)
            } else {
                let mut acc = [0f32; 3];
                for sy in 0..AA {
                    for sx in 0..AA {
                        let ax = (x as f64 + (sx as f64 + 0.5) / AA as f64) * scale;
                        let ay = (y as f64 + (sy as f64 + 0.5) / AA as f64) * scale;
                        let c = colour_of(probe(ax, ay, true));
                        for k in 0..3 {
                            acc[k] += c[k];
                        }
                    }
                }
                acc.map(|v| v / (AA * AA) as f32)
            };
            for k in 0..3 {
                row[3 * i + k] = out[k].round().clamp(0.0, 255.0) as u8;
            }
        }
    });
    RgbWindow { width: w as u32, height: h as u32, pixels }
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
    fn shadows_come_only_from_umbrellas_in_front_of_the_hit_one() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, id) = elements(&ex).unwrap();
        let p = UmbrellaParams { shadow_offset: 4, shadow: ONE_Q16 / 2, ..UmbrellaParams::default() };
        let arr = Arrangement::new(&el, &p, &id);
        let tabs = Tabs { rays: std::array::from_fn(ray), sectors: shape::SectorTable::default() };
        let lists = Lists { x0: -2, y0: -2, w: 6, lists: arr.lists(-2, -2, 4, 4) };
        let (mut shaded, mut hits) = (0, 0);
        for i in 0..4000 {
            let (x, y) = ((i % 61) as f64 * 0.37 - 5.0, (i / 61) as f64 * 0.41 - 6.0);
            let s = sample(&el, &arr, &tabs, &lists, x, y, 0.5, true);
            // Independently: the first umbrella of the cell's list containing the point is hit;
            // only those before it that contain the point moved by −ℓ shade it.
            let g = arr.g as f64;
            let (cx, cy) = ((x / g).floor() as i64, (y / g).floor() as i64);
            let (px, py) = ((x - cx as f64 * g) as f32, (y - cy as f64 * g) as f32);
            let contains = |u: &arrange::Placed, qx: f32, qy: f32| {
                let (dx, dy) = (qx - u.cx, qy - u.cy);
                let lx = (u.cos * dx + u.sin * dy) * u.inv_scale;
                let ly = (-u.sin * dx + u.cos * dy) * u.inv_scale;
                dx * dx + dy * dy <= u.reach2
                    && shape::locate(&shape::ray_angles(), &tabs.rays, &arr.table[u.modified as usize].radii, lx, ly).is_some()
            };
            let list = lists.get(cx, cy);
            let hit = list.iter().position(|u| contains(u, px, py));
            let front = &list[..hit.unwrap_or(list.len())];
            let n = front.iter().filter(|u| contains(u, px - 4.0, py - 4.0)).count();
            assert_eq!(s.shade, 0.5f32.powi(n as i32), "point {x},{y}");
            assert_eq!(s.hit.is_some(), hit.is_some());
            shaded += (n > 0) as u32;
            hits += hit.is_some() as u32;
        }
        eprintln!("{hits} of 4000 points hit an umbrella, {shaded} shaded");
        assert!(shaded > 100 && hits > 1000, "the test saw shadows ({shaded}) and hits ({hits})");
    }
}
