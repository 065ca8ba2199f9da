//! The one recipe from images to a prepared exemplar: what a texture's settings say about its
//! exemplar (largest side, wrap-around, high-resolution source, lattice, randomness mask,
//! material maps), applied in one order. `textile serve` (configured textures and uploads),
//! `textile analyze` and `textile render --exemplar` all make their exemplars here, so the same
//! image and settings give the same exemplar, analysis and pixels everywhere.
//!
//! It sits above [`crate::exemplar`] and [`crate::tileable`] (which makes the seamless
//! replacement), and nothing in the core depends on it.
//!
//! Order: decode (refusing an image that is too large before decoding it) → refuse a flat one →
//! halve a high-resolution source → synthesize a toroidal replacement if asked → detect or take
//! the lattice → attach the randomness mask → attach each map. The mask and maps are decoded like
//! the exemplar's image, so that they stay co-registered with it.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};
use crate::exemplar::{Exemplar, ExemplarOptions};
use crate::lattice::LatticeChoice;
use crate::maps::NormalConvention;

/// Whether an exemplar wraps around.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Toroidal {
    /// Detect from the wrap-around seam.
    #[default]
    Auto,
    /// The exemplar wraps seamlessly.
    True,
    /// The exemplar does not wrap.
    False,
    /// The exemplar does not wrap: replace it by a seamless texture of the same size
    /// synthesized from it (Wei & Levoy 2000, as `textile tileable`), which wraps.
    Synthesize,
}

/// The spellings of [`Toroidal`], for help texts.
pub const TOROIDAL_VALUES: [&str; 4] = ["auto", "true", "false", "synthesize"];

impl Toroidal {
    /// The image is read with this wrap-around option under `lattice`: a lattice of cells tiles
    /// the exemplar, which therefore wraps around (the one place that rule stands); an
    /// exemplar said not to wrap cannot have one.
    pub fn with_lattice(self, lattice: &LatticeChoice) -> std::result::Result<Option<bool>, &'static str> {
        match (lattice.needs_toroidal(), self) {
            (true, Toroidal::Auto | Toroidal::True) => Ok(Some(true)),
            (true, _) => Err("a lattice tiles the exemplar, which therefore wraps around: use auto or true"),
            (false, Toroidal::Auto) => Ok(None),
            (false, Toroidal::True) => Ok(Some(true)),
            (false, Toroidal::False | Toroidal::Synthesize) => Ok(Some(false)),
        }
    }
}

impl FromStr for Toroidal {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(Toroidal::Auto),
            "true" => Ok(Toroidal::True),
            "false" => Ok(Toroidal::False),
            "synthesize" => Ok(Toroidal::Synthesize),
            _ => Err(format!("'{s}' is not one of {}", TOROIDAL_VALUES.join(", "))),
        }
    }
}

/// Everything a texture's settings say about how its exemplar is made.
#[derive(Debug, Clone, PartialEq)]
pub struct Recipe {
    /// Largest accepted input side in pixels.
    pub max_input_side: u32,
    /// Whether it wraps around.
    pub toroidal: Toroidal,
    /// The image is a high-resolution source, halved into the exemplar
    /// ([`Exemplar::from_hires`]).
    pub hires: bool,
    /// Its lattice.
    pub lattice: LatticeChoice,
    /// The tangent-space convention of its `normal` map, if it has one.
    pub normal_convention: Option<NormalConvention>,
}

impl Default for Recipe {
    fn default() -> Recipe {
        Recipe {
            max_input_side: ExemplarOptions::default().max_input_side,
            toroidal: Toroidal::Auto,
            hires: false,
            lattice: LatticeChoice::Auto,
            normal_convention: None,
        }
    }
}

/// The images an exemplar is made from: its own, and its randomness mask's and material maps'
/// if it has them (each map by name, with a label — its file — for errors).
#[derive(Debug, Clone, Copy, Default)]
pub struct Images<'a> {
    /// The exemplar's image (or its high-resolution source).
    pub exemplar: &'a [u8],
    /// The randomness mask's image.
    pub mask: Option<&'a [u8]>,
    /// `(name, label, bytes)` of each material map.
    pub maps: &'a [(&'a str, &'a str, &'a [u8])],
}

/// What the recipe did that its user should hear of.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// The exemplar was halved from its high-resolution source.
    FromHires {
        /// The exemplar's size.
        size: (u32, u32),
    },
    /// A seamless replacement was synthesized (`toroidal = "synthesize"`).
    MadeToroidal {
        /// Seconds it took.
        secs: f64,
    },
    /// The image was scaled to the largest side exemplars are used at.
    Scaled {
        /// The image's size.
        from: (u32, u32),
        /// The exemplar's.
        to: (u32, u32),
    },
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Note::FromHires { size: (w, h) } => {
                write!(f, "exemplar {w}x{h} reduced from its {}x{} exemplar_hires", 2 * w, 2 * h)
            }
            Note::MadeToroidal { secs } => {
                write!(f, "exemplar made toroidal by synthesis (toroidal = \"synthesize\") in {secs:.2}s")
            }
            Note::Scaled { from: (a, b), to: (w, h) } => write!(
                f,
                "exemplar {a}x{b} scaled to {w}x{h} (exemplars are used up to {} texels a side)",
                crate::exemplar::MAX_SIDE
            ),
        }
    }
}

impl Recipe {
    /// The prepared exemplar of `images` (module comment); `note` hears what was done to it.
    pub fn make(&self, images: &Images, note: &dyn Fn(Note)) -> Result<Exemplar> {
        let toroidal = self
            .toroidal
            .with_lattice(&self.lattice)
            .map_err(|message| CoreError::Param { name: "toroidal", message: message.into() })?;
        let opts = ExemplarOptions { max_input_side: self.max_input_side, toroidal };
        let mut ex = Exemplar::from_bytes(images.exemplar, &opts)?;
        ex.check_not_flat()?;
        let mask = images.mask.map(|bytes| Exemplar::from_bytes(bytes, &opts)).transpose()?;
        if self.hires {
            ex = Exemplar::from_hires(ex)?;
            note(Note::FromHires { size: (ex.width, ex.height) });
        }
        if self.toroidal == Toroidal::Synthesize {
            let started = std::time::Instant::now();
            ex = crate::tileable::make_toroidal(&ex, 0)?;
            note(Note::MadeToroidal { secs: started.elapsed().as_secs_f64() });
        }
        ex = ex.with_lattice_choice(&self.lattice)?;
        if let Some(mask) = &mask {
            ex = ex.with_randomness_mask(mask)?;
        }
        for (name, label, bytes) in images.maps {
            let map = Exemplar::from_bytes(bytes, &opts)
                .map_err(|e| CoreError::Map { name: (*name).into(), message: format!("({label}): {e}") })?;
            ex = ex.with_map(name, &map, self.normal_convention)?;
        }
        let prep = &ex.preparation;
        if (prep.input_width, prep.input_height) != (prep.width, prep.height) {
            note(Note::Scaled { from: (prep.input_width, prep.input_height), to: (prep.width, prep.height) });
        }
        Ok(ex)
    }
}
