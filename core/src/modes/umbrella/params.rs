//! The umbrella mode's parameters: what shows between elements ([`Background`]) and
//! [`UmbrellaParams`] with their specs, read by the mode's `parse`.

use super::*;

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

    pub(super) fn name(self) -> &'static str {
        match self {
            Background::Mosaic => "mosaic",
            Background::Synth => "synth",
            Background::Tiling => "tiling",
            Background::Mean => "mean",
        }
    }

    pub(super) fn parse(s: &str) -> Option<Background> {
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

pub(super) const DENSITY: ParamSpec = ParamSpec {
    name: "density",
    kind: Kind::Integer { min: 10, max: 400 },
    scope: Scope::Request,
    help: "umbrellas per area, percent (100 covers the plane about 1.6 times over)",
};

pub(super) const SCALE: ParamSpec = ParamSpec {
    name: "scale",
    kind: Kind::Interval { min: 0.25, max: 4.0 },
    scope: Scope::Request,
    help: "MIN,MAX size of placed elements relative to the exemplar's",
};

pub(super) const SHAPE: ParamSpec = ParamSpec {
    name: "shape",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "largest shape morph towards other elements of the exemplar (0 = the base shapes)",
};

pub(super) const COLOUR: ParamSpec = ParamSpec {
    name: "colour",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "strength of the per-vertex colour variation taken from other elements",
};

pub(super) const SHADOW: ParamSpec = ParamSpec {
    name: "shadow",
    kind: Kind::Unit,
    scope: Scope::Request,
    help: "strength of the shadow an element casts on those below it",
};

pub(super) const SHADOW_OFFSET: ParamSpec = ParamSpec {
    name: "shadow_offset",
    kind: Kind::Integer { min: 0, max: 16 },
    scope: Scope::Request,
    help: "shadow offset in texels (towards the bottom right)",
};

pub(super) const K: ParamSpec = ParamSpec {
    name: "k",
    kind: Kind::Integer { min: 1, max: 16 },
    scope: Scope::Request,
    help: "umbrellas kept per grid cell, front to back",
};

pub(super) const BACKGROUND: ParamSpec = ParamSpec {
    name: "background",
    kind: Kind::Choice(Background::NAMES),
    scope: Scope::Request,
    help: "what shows between elements: mosaic, synth, tiling or mean (colour)",
};

pub(super) const SPECS: &[ParamSpec] = &[DENSITY, SCALE, SHAPE, COLOUR, SHADOW, SHADOW_OFFSET, K, BACKGROUND];
