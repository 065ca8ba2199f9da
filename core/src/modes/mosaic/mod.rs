//! Chaos mosaic (Xu, Guo & Shum; design note §4): the cheap mode. The exemplar is tiled; every
//! tile contributes one block of the exemplar (area between the paper's bounds) moved by the cat
//! map inside its super-tile and pasted over the tiling, higher priority on top; block and tile
//! edges are smoothed over three pixel layers. Everything is a function of absolute
//! coordinates, so any window equals the same pixels cut from any larger one.

mod layout;
mod paint;
pub mod params;
mod smooth;

use rayon::prelude::*;
use serde_json::{json, Map, Value};

use crate::cache::Pyramid;
use crate::error::{CoreError, Result};
use crate::exemplar::Exemplar;
use crate::geom::Rect;
use crate::image::{box_mip, Rendered, RgbWindow};
use crate::modes::params::{Common, Kind, ParamReader, ParamSpec, Scope};
use crate::modes::{Cost, Mode, Needs, Source, View};

pub use params::{MosaicParams, MAX_ITERATIONS, MAX_SMOOTHING};

use layout::Layout;
use paint::sources;
use smooth::native;

/// Largest native window, in pixels, one call may evaluate (2^26).
pub const MAX_PIXELS: i64 = 1 << 26;

/// The mosaic mode.
pub struct Mosaic;

const ITERATIONS: ParamSpec = ParamSpec {
    name: "iterations",
    kind: Kind::Integer { min: 0, max: MAX_ITERATIONS as u64 },
    scope: Scope::Request,
    help: "cat-map iterations that move the blocks (0 = blocks stay in place: the plain tiling)",
};
const BLOCK_AREA: ParamSpec = ParamSpec {
    name: "block_area",
    kind: Kind::Interval { min: 0.05, max: 1.0 },
    scope: Scope::Request,
    help: "MIN,MAX block area as fractions of the exemplar area",
};
const SMOOTHING: ParamSpec = ParamSpec {
    name: "smoothing",
    kind: Kind::Integer { min: 0, max: MAX_SMOOTHING as u64 },
    scope: Scope::Request,
    help: "pixel layers smoothed on each side of block and tile edges",
};
const SPECS: &[ParamSpec] = &[ITERATIONS, BLOCK_AREA, SMOOTHING];

impl Mode for Mosaic {
    const NAME: &'static str = "mosaic";
    const VERSION: u32 = 1;
    const SUMMARY: &'static str = "chaos mosaic (Xu, Guo & Shum): the tiled exemplar with blocks moved by the cat map; cheap";
    const NEEDS: Needs = Needs::Exemplar;
    const COST: Cost = Cost::Light;
    type Params = MosaicParams;

    fn specs() -> &'static [ParamSpec] {
        SPECS
    }

    fn defaults() -> MosaicParams {
        MosaicParams::default()
    }

    fn parse(base: &MosaicParams, common: &Common, r: &mut ParamReader, src: &Source) -> Result<MosaicParams> {
        let mut p = base.clone();
        common.apply(&mut p.seed, &mut p.period);
        if let Some(s) = r.get(&ITERATIONS) {
            p.iterations = ITERATIONS.integer(&s)? as u32;
        }
        if let Some(s) = r.get(&BLOCK_AREA) {
            (p.area_min, p.area_max) = BLOCK_AREA.interval_milli(&s)?;
        }
        if let Some(s) = r.get(&SMOOTHING) {
            p.smoothing = SMOOTHING.integer(&s)? as u32;
        }
        p.validate(src.side())?;
        Ok(p)
    }

    fn values(p: &MosaicParams, _: &Source) -> Map<String, Value> {
        let mut m = Map::new();
        m.insert("seed".into(), json!(p.seed));
        m.insert(ITERATIONS.name.into(), json!(p.iterations));
        m.insert(BLOCK_AREA.name.into(), json!([p.area_min as f64 / 1000.0, p.area_max as f64 / 1000.0]));
        m.insert(SMOOTHING.name.into(), json!(p.smoothing));
        m
    }

    fn canonical(p: &MosaicParams) -> String {
        p.canonical()
    }

    fn render(p: &MosaicParams, src: &Source, _: &Pyramid, view: View) -> Result<Rendered> {
        Ok(Rendered {
            image: render(src.exemplar, p, view.zoom_out, view.rect)?,
            synthesized: render_cost(view.zoom_out, view.rect),
        })
    }
}

/// Texels [`render`] evaluates for this view (with the smoothing margin), for computation ratios.
pub fn render_cost(zoom_out: u32, rect: Rect) -> u64 {
    match zoom_out {
        0 => rect.grow(4).area() as u64,
        k if k <= 3 => {
            let f = 1i64 << k;
            Rect { x0: rect.x0 * f, y0: rect.y0 * f, x1: rect.x1 * f, y1: rect.y1 * f }.grow(4).area() as u64
        }
        _ => rect.area() as u64,
    }
}

/// Render `rect` of the mosaic viewed `zoom_out` steps coarser than native.
pub fn render(ex: &Exemplar, p: &MosaicParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    render_view(ex, p, zoom_out, rect, true)
}

/// `rect` of the mosaic `zoom_out` steps out by labelling one sample per pixel at every zoom
/// (see [`sampled`]; zoom-outs 1–3 averaging the pixel's footprint around its sample's source):
/// cheaper than [`render`]'s exact box filter of the native pixels for zoom-outs 1–3, for
/// callers to whom an approximate view will do (the umbrella mode's background, which shows
/// only between umbrellas).
pub fn render_sampled(ex: &Exemplar, p: &MosaicParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    render_view(ex, p, zoom_out, rect, false)
}

/// [`render`] (`exact`: zoom-outs 1–3 box-filter the native pixels) or [`render_sampled`].
fn render_view(ex: &Exemplar, p: &MosaicParams, zoom_out: u32, rect: Rect, exact: bool) -> Result<RgbWindow> {
    p.validate(ex.side)?;
    let scale = 1i64.checked_shl(zoom_out.min(62)).unwrap_or(i64::MAX);
    let boxed = exact && (1..=3).contains(&zoom_out);
    if rect.is_empty() || rect.area() > MAX_PIXELS || (boxed && rect.area() * scale * scale > MAX_PIXELS) {
        let scale_note = if exact || !(1..=3).contains(&zoom_out) { " at native scale" } else { "" };
        return Err(CoreError::Window {
            width: rect.width(),
            height: rect.height(),
            message: format!("must be non-empty with at most {MAX_PIXELS} pixels{scale_note}"),
        });
    }
    let layout = Layout::new(ex.side as i64, p);
    if zoom_out == 0 {
        return Ok(native(ex, &layout, rect));
    }
    if boxed {
        // Exact: the box average of the native pixels.
        let big = native(
            ex,
            &layout,
            Rect { x0: rect.x0 * scale, y0: rect.y0 * scale, x1: rect.x1 * scale, y1: rect.y1 * scale },
        );
        return Ok(big.box_down(scale as usize));
    }
    Ok(sampled(ex, &layout, zoom_out, rect))
}

/// Rows per band of [`sampled`]'s parallel labelling.
const SAMPLED_BAND: i64 = 32;

/// Zoomed out `k` steps (`2^k` texels per pixel) by labelling each pixel with its centre
/// texel's source: approximate, like the paper's reduced-scale rendering. Zoom-outs 1–3 (asked
/// for only by [`render_sampled`]): the mean of the `2^k × 2^k` exemplar texels around that
/// source (toroidally), from an integral image — the exact box filter of the native pixels
/// wherever they all share the label, all but a block edge's pixels. Further out: the texel of
/// the box-filtered exemplar that holds the source (a pixel spans block edges anyway), the mean
/// colour once a pixel covers the whole exemplar.
fn sampled(ex: &Exemplar, layout: &Layout, k: u32, rect: Rect) -> RgbWindow {
    let n = layout.n as usize;
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let step = 1i64 << k.min(40);
    let colouring = if k <= 3 {
        Colouring::Footprint(Integral::new(&ex.pixels, n, step as usize))
    } else {
        let lvl = k.min(ex.side.trailing_zeros()) as usize;
        let texels = box_mip(&ex.pixels, n, lvl);
        if let [mean] = texels[..] {
            // A pixel covers the whole exemplar: every label gives its mean.
            return RgbWindow { width: w as u32, height: h as u32, pixels: mean.repeat(w * h) };
        }
        Colouring::Mip { lvl, side: n >> lvl, texels }
    };
    // Bands of rows in parallel (each pixel's label depends on its position alone).
    let pixels: Vec<Vec<u8>> = (rect.y0..rect.y1)
        .step_by(SAMPLED_BAND as usize)
        .collect::<Vec<i64>>()
        .into_par_iter()
        .map(|y0| {
            let band = Rect { y0, y1: rect.y1.min(y0 + SAMPLED_BAND), ..rect };
            let mut pixels = Vec::with_capacity(3 * w * band.height() as usize);
            for v in &sources(layout, band, ex.toroidal, step, step / 2) {
                pixels.extend_from_slice(&colouring.at((v & 0xFFFF) as usize, (v >> 16) as usize));
            }
            pixels
        })
        .collect();
    RgbWindow { width: w as u32, height: h as u32, pixels: pixels.concat() }
}

/// How [`sampled`] colours a pixel from its label's source texel.
enum Colouring {
    /// Zoom-outs 1–3: the mean of the pixel's footprint around the source.
    Footprint(Integral),
    /// Further out: the texel of the exemplar box-filtered by `2^lvl` (`side²` texels) that
    /// holds the source.
    Mip { lvl: usize, side: usize, texels: Vec<[u8; 3]> },
}

impl Colouring {
    /// The colour of a pixel whose label's source is exemplar texel `(x, y)`.
    fn at(&self, x: usize, y: usize) -> [u8; 3] {
        match self {
            Colouring::Footprint(sums) => sums.mean_around(x, y),
            Colouring::Mip { lvl, side, texels } => texels[(y >> lvl).min(side - 1) * side + (x >> lvl).min(side - 1)],
        }
    }
}

/// Sums of the exemplar's texels over `f × f` boxes anywhere on its torus, from an integral
/// image of the exemplar extended by `f` texels right and down (wrapping).
struct Integral {
    /// Side of the exemplar.
    n: usize,
    /// Box side.
    f: usize,
    /// `(n + f + 1)²` prefix sums per channel: entry `(x, y)` sums the texels left of and
    /// above it.
    sums: Vec<[u32; 3]>,
}

impl Integral {
    fn new(texels: &[[u8; 3]], n: usize, f: usize) -> Integral {
        debug_assert!(n.is_power_of_two() && f <= n, "a power-of-two exemplar, boxes no wider");
        let s = n + f + 1;
        let mut sums = vec![[0u32; 3]; s * s];
        for y in 1..s {
            for x in 1..s {
                let t = texels[((y - 1) % n) * n + (x - 1) % n];
                let (l, u, d) = (sums[y * s + x - 1], sums[(y - 1) * s + x], sums[(y - 1) * s + x - 1]);
                sums[y * s + x] = std::array::from_fn(|c| t[c] as u32 + l[c] + u[c] - d[c]);
            }
        }
        Integral { n, f, sums }
    }

    /// The mean (rounded to nearest) of the `f × f` texels centred on texel `(x, y)` (from
    /// `f/2` before it to `f/2 − 1` after), on the torus.
    fn mean_around(&self, x: usize, y: usize) -> [u8; 3] {
        let (n, f, s) = (self.n, self.f, self.n + self.f + 1);
        // `n` is a power of two (exemplar sides are), `f/2 < n`.
        let (x0, y0) = ((x + n - f / 2) & (n - 1), (y + n - f / 2) & (n - 1));
        let at = |x: usize, y: usize| self.sums[y * s + x];
        let (a, b, c, d) = (at(x0, y0), at(x0 + f, y0), at(x0, y0 + f), at(x0 + f, y0 + f));
        // `f` is a power of two too: dividing by the area is a shift.
        let shift = 2 * f.trailing_zeros();
        std::array::from_fn(|k| ((d[k] + a[k] - b[k] - c[k] + (1 << shift >> 1)) >> shift) as u8)
    }
}
