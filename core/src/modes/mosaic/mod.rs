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

use crate::cache::Pyramid;
use crate::error::Result;
use crate::exemplar::Exemplar;
use crate::geom::Rect;
use crate::image::{mean_colour, Integral, Rendered, RgbWindow};
use crate::modes::{check_window, Cost, Mode, Needs, Source, View};

pub use params::{MosaicParams, BLOCK_AREA, ITERATIONS, MAX_ITERATIONS, MAX_SMOOTHING, SMOOTHING};

use layout::Layout;
use paint::sources;
use smooth::native;

/// Largest native window, in pixels, one call may evaluate (2^26).
pub const MAX_PIXELS: i64 = 1 << 26;

/// The mosaic mode.
pub struct Mosaic;

impl Mode for Mosaic {
    const NAME: &'static str = "mosaic";
    const VERSION: u32 = 3;
    const SUMMARY: &'static str = "chaos mosaic (Xu, Guo & Shum): the tiled exemplar with blocks moved by the cat map; cheap";
    const NEEDS: Needs = Needs::Exemplar;
    const COST: Cost = Cost::Light;
    type Params = MosaicParams;
    type State = ();

    fn render(p: &MosaicParams, _: &(), src: &Source, cache: &Pyramid, view: View) -> Result<Rendered> {
        Ok(Rendered {
            image: render_texels(src, cache, p, view.zoom_out, view.rect)?,
            synthesized: render_cost(view.zoom_out, view.rect),
        })
    }
}

/// Texels [`render`] evaluates for this view (with the smoothing margin at native zoom; one
/// label per pixel zoomed out), for computation ratios.
pub fn render_cost(zoom_out: u32, rect: Rect) -> u64 {
    match zoom_out {
        0 => rect.grow(4).area() as u64,
        _ => rect.area() as u64,
    }
}

/// Render `rect` of the mosaic viewed `zoom_out` steps coarser than native: native pixels, or
/// (zoomed out) one label per pixel coloured by its footprint around the label's source (see
/// [`sampled`]): as cheap at every zoom as at native, and the box filter of the native pixels
/// but where a pixel spans a block edge.
pub fn render(ex: &Exemplar, p: &MosaicParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    render_texels(&Source::exemplar(ex), &Pyramid::off(), p, zoom_out, rect)
}

/// [`render`] showing `src`'s texels at the exemplar's coordinates: its colours, or one of its
/// material maps; what it derives from them is kept in `cache`.
pub fn render_texels(src: &Source, cache: &Pyramid, p: &MosaicParams, zoom_out: u32, rect: Rect) -> Result<RgbWindow> {
    let ex = src.exemplar;
    p.validate(ex.width, ex.height)?;
    check_window(rect, MAX_PIXELS)?;
    let layout = Layout::new((ex.width as i64, ex.height as i64), p, src.lattice());
    if zoom_out == 0 {
        return Ok(native(ex, src.texels(), &layout, rect));
    }
    Ok(sampled(src, cache, &layout, zoom_out, rect))
}

/// Pixels per parallel piece of [`sampled`]'s colouring.
const SAMPLED_PIXELS: usize = 1 << 13;

/// Zoomed out `k` steps (`2^k` texels per pixel) by labelling each pixel with its centre
/// texel's source, like the paper's reduced-scale rendering, coloured with the mean of the
/// `2^k × 2^k` exemplar texels around that source, toroidally (the box means the analysis or
/// the map holds, else from an integral image): the exact box filter of the native pixels
/// wherever they all share the label, all but a block edge's pixels; the mean colour once a
/// pixel covers the whole exemplar.
fn sampled(src: &Source, cache: &Pyramid, layout: &Layout, k: u32, rect: Rect) -> RgbWindow {
    let (ex, texels) = (src.exemplar, src.texels());
    let (ew, eh) = (layout.ew as usize, layout.eh as usize);
    let (w, h) = (rect.width() as usize, rect.height() as usize);
    let step = 1i64 << k.min(40);
    let levels = ex.levels();
    if k >= levels {
        let mean = mean_colour(texels);
        return RgbWindow { width: w as u32, height: h as u32, pixels: mean.repeat(w * h) };
    }
    let labels = sources(layout, rect, ex.toroidal, step, step / 2);
    // The box means the analysis or the map holds, else each pixel's from an integral image.
    let mean: Box<dyn Fn(usize, usize) -> [u8; 3] + Sync> = match src.box_stack(cache) {
        Some(stack) => Box::new(move |x, y| stack[k as usize][y * ew + x]),
        None => {
            let sums = Integral::new(texels, (ew, eh), step as usize);
            Box::new(move |x, y| sums.mean_around(x, y))
        }
    };
    let mut pixels = vec![0u8; 3 * w * h];
    pixels.par_chunks_mut(3 * SAMPLED_PIXELS).zip(labels.par_chunks(SAMPLED_PIXELS)).for_each(|(out, labels)| {
        for (o, &v) in out.chunks_exact_mut(3).zip(labels) {
            o.copy_from_slice(&mean((v & 0xFFFF) as usize, (v >> 16) as usize));
        }
    });
    RgbWindow { width: w as u32, height: h as u32, pixels }
}


