//! Validated mosaic parameters: cat-map iterations, block area bounds, smoothing, seed, period.

use crate::error::{CoreError, Result};
use crate::modes::params::check_period;

/// Largest number of cat-map iterations accepted.
pub const MAX_ITERATIONS: u32 = 64;
/// Smoothing layers at most (the tent filter is 7×7).
pub const MAX_SMOOTHING: u32 = 3;

/// Validated mosaic parameters.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct MosaicParams {
    /// Selects another arrangement of blocks.
    pub seed: u64,
    /// Cat-map iterations (0 = blocks stay in place: the plain tiling).
    pub iterations: u32,
    /// Smallest block area, per mille of the exemplar area.
    pub area_min: u32,
    /// Largest block area, per mille of the exemplar area.
    pub area_max: u32,
    /// Pixel layers smoothed on each side of block and tile edges (0–3).
    pub smoothing: u32,
    /// Optional period in texels (power of two ≥ the exemplar side): a mosaic on a torus.
    pub period: Option<i64>,
}

impl Default for MosaicParams {
    fn default() -> Self {
        MosaicParams { seed: 0, iterations: 10, area_min: 500, area_max: 750, smoothing: 3, period: None }
    }
}

impl MosaicParams {
    /// Check ranges for an exemplar of side `side`.
    pub fn validate(&self, side: u32) -> Result<()> {
        let bad = |name, message: String| Err(CoreError::Param { name, message });
        if self.iterations > MAX_ITERATIONS {
            return bad("iterations", format!("{} is outside 0..={MAX_ITERATIONS}", self.iterations));
        }
        if !(50..=1000).contains(&self.area_min) || !(self.area_min..=1000).contains(&self.area_max) {
            return bad(
                "block_area",
                format!(
                    "{},{} must be two fractions of the exemplar area with 0.05 <= min <= max <= 1",
                    self.area_min as f64 / 1000.0,
                    self.area_max as f64 / 1000.0
                ),
            );
        }
        if self.smoothing > MAX_SMOOTHING {
            return bad("smoothing", format!("{} is outside 0..={MAX_SMOOTHING}", self.smoothing));
        }
        check_period(self.period, side)?;
        Ok(())
    }

    /// Canonical text form for cache keys and ETags.
    pub fn canonical(&self) -> String {
        format!(
            "seed={};it={};area={},{};smooth={};period={}",
            self.seed,
            self.iterations,
            self.area_min,
            self.area_max,
            self.smoothing,
            self.period.map(|p| p.to_string()).unwrap_or_else(|| "none".into())
        )
    }
}
