//! The caches one texture's umbrella requests share, bounded in bytes and kept with its
//! prepared state ([`super::prepared::Extraction`]), and the plain values they hold: umbrellas
//! placed in a cell ([`Placed`], made by [`super::arrange`]) and merged clusters of them
//! ([`Merged`], made by [`super::lod`]). A leaf of the mode: it names no other part of it, so
//! the arrangement, the levels of detail and the prepared state all build on it.

use std::sync::Arc;

use crate::memo::Memo;

/// An umbrella in a cell list, relative to that cell's origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    /// Centre, texels from the cell's origin.
    pub cx: f32,
    /// Centre, texels from the cell's origin.
    pub cy: f32,
    /// Rotation (cosine) of the umbrella.
    pub cos: f32,
    /// Rotation (sine).
    pub sin: f32,
    /// 1 / scale.
    pub inv_scale: f32,
    /// Placed radius (largest rim radius × scale).
    pub reach: f32,
    /// Its square.
    pub reach2: f32,
    /// Square of the placed radius of the disc certainly inside.
    pub inner2: f32,
    /// Index into the modified table.
    pub modified: u32,
    /// Depth key (larger is in front).
    pub depth: u64,
    /// Id: spawn cell and index in it.
    pub id: (i64, i64, u32),
}

/// A merged umbrella: a convex rim around its centre, colours at the centre and the vertices
/// (no texture).
#[derive(Debug, Clone, PartialEq)]
pub struct Merged {
    /// Centre, absolute texels.
    pub o: [f64; 2],
    /// Rim, absolute texels, convex, in angular order about `o`.
    pub rim: Vec<[f64; 2]>,
    /// Colour at each rim vertex, RGB in `[0, 1]` (none for a cluster of one).
    pub colour: Vec<[f32; 3]>,
    /// Colour at the centre (a cluster of one: the background, unused).
    pub centre: [f32; 3],
    /// Largest centre–vertex distance.
    pub reach: f64,
    /// Depth key (the front-most member's).
    pub depth: u64,
    /// Id (the front-most member's).
    pub id: (i64, i64, u32),
    /// A cluster of one: its umbrella, still coloured from its (mipmapped) base texture.
    pub single: Option<Placed>,
}

/// Bytes of caches a texture keeps unless told otherwise ([`Preparation::limit_caches`]).
pub const DEFAULT_CACHE_BYTES: u64 = 16 << 20;
/// Bytes the colour calibrations may hold (a few dozen entries).
const CALIBRATION_BYTES: u64 = 64 << 10;

/// The caches of one texture's umbrella requests.
pub struct Caches {
    /// Cell lists, by arrangement and cell.
    pub(crate) lists: Memo<(u64, i64, i64), Arc<Vec<Placed>>>,
    /// Merged umbrellas, by arrangement, level and cell.
    pub(crate) cells: Memo<(u64, u32, i64, i64), Arc<Vec<Merged>>>,
    /// Background shifts for the gaps, by canonical parameters.
    pub(crate) gaps: Memo<String, [f32; 3]>,
    /// Background shifts beyond the drawn zooms, by canonical parameters.
    pub(crate) colours: Memo<String, [f32; 3]>,
}

impl Caches {
    /// Empty caches of at most `bytes` in all.
    pub fn new(bytes: u64) -> Caches {
        let (lists, cells) = Self::split(bytes);
        Caches {
            lists: Memo::new(lists),
            cells: Memo::new(cells),
            gaps: Memo::new(CALIBRATION_BYTES.min(bytes / 4)),
            colours: Memo::new(CALIBRATION_BYTES.min(bytes / 4)),
        }
    }

    fn split(bytes: u64) -> (u64, u64) {
        let rest = bytes.saturating_sub(2 * CALIBRATION_BYTES.min(bytes / 4));
        (rest * 3 / 8, rest - rest * 3 / 8)
    }

    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.lists.bytes() + self.cells.bytes() + self.gaps.bytes() + self.colours.bytes()
    }

    pub(super) fn set_limit(&self, bytes: u64) {
        let (lists, cells) = Self::split(bytes);
        self.lists.set_limit(lists);
        self.cells.set_limit(cells);
        self.gaps.set_limit(CALIBRATION_BYTES.min(bytes / 4));
        self.colours.set_limit(CALIBRATION_BYTES.min(bytes / 4));
    }
}

impl Default for Caches {
    fn default() -> Self {
        Caches::new(DEFAULT_CACHE_BYTES)
    }
}

