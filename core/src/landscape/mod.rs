//! Landscapes: several textures in one endless ground. This module owns what is a landscape's
//! own and no mode's: where each layer shows ([`splat`], from [`noise`] or a painted map) and
//! how the layers' rendered windows join ([`blend`]). A mode renders a layer's window exactly as
//! it renders any texture's; the caller renders the layers a window needs and hands their
//! pixels here.
//!
//! Coordinates: a landscape's texel grid is that of its native zoom. A window of it is a
//! [`crate::View`]: pixel `(i, j)` of `rect` seen `k` steps coarser (negative: magnified) has
//! its centre at texel `((x0 + i + ½)·2^k, (y0 + j + ½)·2^k)`.

pub mod blend;
pub mod noise;
pub mod splat;

pub use blend::Blend;
pub use splat::{Splat, Weights};

/// Most layers a landscape has.
pub const MAX_LAYERS: usize = 16;

/// Centre of pixel `i` of a window starting at `x0`, seen `zoom` steps from native, in texels.
#[inline]
pub fn texel_centre(x0: i64, i: usize, zoom: i64) -> f64 {
    let p = x0 as f64 + i as f64 + 0.5;
    if zoom >= 0 {
        p * (1u64 << zoom.min(62)) as f64
    } else {
        p / (1u64 << (-zoom).min(62)) as f64
    }
}
