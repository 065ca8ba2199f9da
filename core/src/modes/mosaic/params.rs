//! The mosaic's parameters, declared once ([`crate::declare_params!`]): cat-map iterations,
//! block area bounds, smoothing, seed and period, with their specs and canonical keys.

use crate::error::{CoreError, Result};
use crate::modes::params::{check_period, Kind};

/// Largest number of cat-map iterations accepted.
pub const MAX_ITERATIONS: u32 = 64;
/// Smoothing layers at most (the tent filter is 7×7).
pub const MAX_SMOOTHING: u32 = 3;

crate::declare_params! {
    /// Validated mosaic parameters.
    pub struct MosaicParams {
        /// Selects another arrangement of blocks.
        pub seed: u64 { default: 0, canonical: "seed=", seed }
        /// Cat-map iterations (0 = blocks stay in place: the plain tiling).
        pub iterations: u32 { default: 10, canonical: ";it=",
            spec ITERATIONS = "iterations", Kind::Integer { min: 0, max: MAX_ITERATIONS as u64 }, Request,
            "cat-map iterations that move the blocks (0 = blocks stay in place: the plain tiling)" }
        /// Smallest and largest block area, per mille of the exemplar area.
        pub block_area: (u32, u32) { default: (500, 750), canonical: ";area=",
            spec BLOCK_AREA = "block_area", Kind::Interval { min: 0.05, max: 1.0 }, Request,
            "MIN,MAX block area as fractions of the exemplar area" }
        /// Pixel layers smoothed on each side of block and tile edges (0–3).
        pub smoothing: u32 { default: 3, canonical: ";smooth=",
            spec SMOOTHING = "smoothing", Kind::Integer { min: 0, max: MAX_SMOOTHING as u64 }, Request,
            "pixel layers smoothed on each side of block and tile edges" }
        /// Optional period in texels (power of two ≥ the exemplar side, a multiple of its
        /// width and height): a mosaic on a torus.
        pub period: Option<i64> { default: None, canonical: ";period=", period }
    }
    check(p, src) { p.validate(src.exemplar.width, src.exemplar.height) }
}

impl MosaicParams {
    /// Check ranges for a `w × h` exemplar (parameters made in code are checked here too, not
    /// only parsed ones).
    pub fn validate(&self, w: u32, h: u32) -> Result<()> {
        let bad = |name, message: String| Err(CoreError::Param { name, message });
        if self.iterations > MAX_ITERATIONS {
            return bad("iterations", format!("{} is outside 0..={MAX_ITERATIONS}", self.iterations));
        }
        let (min, max) = self.block_area;
        if !(50..=1000).contains(&min) || !(min..=1000).contains(&max) {
            return bad(
                "block_area",
                format!(
                    "{},{} must be two fractions of the exemplar area with 0.05 <= min <= max <= 1",
                    min as f64 / 1000.0,
                    max as f64 / 1000.0
                ),
            );
        }
        if self.smoothing > MAX_SMOOTHING {
            return bad("smoothing", format!("{} is outside 0..={MAX_SMOOTHING}", self.smoothing));
        }
        check_period(self.period, crate::geom::Size::new(w, h).longer())?;
        // The mosaic's background is the tiled exemplar: a periodic mosaic repeats whole tiles.
        if let Some(n) = self.period {
            if n % w as i64 != 0 || n % h as i64 != 0 {
                return bad(
                    "world",
                    format!(
                        "a periodic mosaic repeats whole tiles of the exemplar, and its {w}x{h} \
                         tiles do not divide the period of {n} texels; use mode=synth, whose \
                         world= takes any exemplar"
                    ),
                );
            }
        }
        Ok(())
    }
}
