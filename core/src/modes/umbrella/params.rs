//! The umbrella mode's parameters, declared once ([`crate::declare_params!`]): what shows
//! between elements ([`Background`]) and [`UmbrellaParams`] with their specs and canonical keys.

use super::*;
use crate::modes::declared::Choice;

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

impl Choice for Background {
    const NAMES: &'static [&'static str] = &["mosaic", "synth", "tiling", "mean"];
    const ALL: &'static [Background] = &[Background::Mosaic, Background::Synth, Background::Tiling, Background::Mean];
    fn index(self) -> usize {
        self as usize
    }
}

crate::declare_params! {
    /// Validated umbrella parameters.
    pub struct UmbrellaParams {
        /// Selects another arrangement and diversification.
        pub seed: u64 { default: 0, canonical: "seed=", seed }
        /// Umbrellas per area, percent of the density that covers the plane about 1.6 times.
        pub density: u32 { default: 100, canonical: ";density=",
            spec DENSITY = "density", Kind::Integer { min: 10, max: 400 }, Request,
            "umbrellas per area, percent (100 covers the plane about 1.6 times over)" }
        /// Scale range of placed umbrellas, thousandths of the exemplar's element size.
        pub scale: (u32, u32) { default: (850, 1150), canonical: ";scale=",
            spec SCALE = "scale", Kind::Interval { min: 0.25, max: 4.0 }, Request,
            "MIN,MAX size of placed elements relative to the exemplar's" }
        /// Largest shape morph towards a variant's shape (Q16).
        pub shape: u32 { default: ONE_Q16 / 2, canonical: ";shape=",
            spec SHAPE = "shape", Kind::Unit, Request,
            "largest shape morph towards other elements of the exemplar (0 = the base shapes)" }
        /// Strength of the variants' colour offsets (Q16).
        pub colour: u32 { default: ONE_Q16, canonical: ";colour=",
            spec COLOUR = "colour", Kind::Unit, Request,
            "strength of the per-vertex colour variation taken from other elements" }
        /// Shadow strength `s` (Q16): each umbrella above the hit one that covers the point
        /// moved towards the light multiplies it by `1 − s`.
        pub shadow: u32 { default: ONE_Q16 * 3 / 10, canonical: ";shadow=",
            spec SHADOW = "shadow", Kind::Unit, Request,
            "strength of the shadow an element casts on those below it" }
        /// Shadow offset `ℓ`, texels along the diagonal.
        pub shadow_offset: u32 { default: 2, canonical: ",",
            spec SHADOW_OFFSET = "shadow_offset", Kind::Integer { min: 0, max: 16 }, Request,
            "shadow offset in texels (towards the bottom right)" }
        /// Umbrellas per cell list at most.
        pub k: u32 { default: 8, canonical: ";k=",
            spec K = "k", Kind::Integer { min: 1, max: 16 }, Request,
            "umbrellas kept per grid cell, front to back" }
        /// What shows between umbrellas.
        pub background: Background { default: Background::Mosaic, canonical: ";bg=",
            spec BACKGROUND = "background", Kind::Choice(Background::NAMES), Request,
            "what shows between elements: mosaic, synth, tiling or mean (colour)" }
        /// Period in texels (power of two ≥ the exemplar side): an arrangement on a torus.
        pub period: Option<i64> { default: None, canonical: ";period=", period }
    }
    check(p, src) { check_period(p.period, src.exemplar.size().longer()) }
}
