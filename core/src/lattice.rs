//! Near-regular textures (design note §1.9): a lattice of `nx × ny` cells that tiles a
//! rectified, toroidal exemplar (holes of a corkboard, tiles of a floor, windows of a facade on
//! their grid). On the levels whose stride is at least a cell, jitter moves content by whole
//! cells and candidates keep their lattice phase, so the output keeps the exemplar's grid;
//! finer levels vary the cells' content as usual.

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// A lattice of `nx × ny` cells over the exemplar: each cell `side/nx × side/ny` texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Lattice {
    /// Cells across.
    pub nx: u32,
    /// Cells down.
    pub ny: u32,
}

impl Lattice {
    /// A lattice of `nx × ny` cells over an exemplar of side `side`: each count must divide
    /// the side (a power of two), so that cells are whole texels.
    pub fn new(nx: u32, ny: u32, side: u32) -> Result<Lattice> {
        for n in [nx, ny] {
            if n == 0 || n > side || !side.is_multiple_of(n) {
                return Err(CoreError::Param {
                    name: "lattice",
                    message: format!(
                        "{nx}x{ny} does not divide the {side}x{side} exemplar into whole cells: \
                         each count must be a power of two from 1 to {side}"
                    ),
                });
            }
        }
        Ok(Lattice { nx, ny })
    }

    /// Cell size in texels `(w, h)` on an exemplar of side `side`.
    pub fn cell(&self, side: u32) -> (u32, u32) {
        (side / self.nx.max(1), side / self.ny.max(1))
    }

    /// The lattice's moduli at a level of stride `h`: per axis, the cell size where `h` is at
    /// least half a cell (there jitter is rounded to whole cells and candidates keep their
    /// phase), else 1 (unconstrained). The design note says "at least a cell"; but a level's
    /// jitter moves content by up to `h/2`, and at `h = cell/2` that is a quarter of a cell in
    /// every block: on the development set's corkboard (2×4 cells of 64×32) the holes then lose
    /// their grid (autocorrelation at the lattice vectors 0.03–0.08, as without a lattice),
    /// while rounding from half a cell keeps it (0.26–0.33) and the cells still vary
    /// (rounding from a quarter cell: 0.73, close to a tiling). bench/README.md.
    pub fn moduli(&self, side: u32, h: u32) -> (u32, u32) {
        let (cw, ch) = self.cell(side);
        (if 2 * h >= cw { cw } else { 1 }, if 2 * h >= ch { ch } else { 1 })
    }
}

/// `d` rounded to the nearest multiple of `q` (halves up); `q ≤ 1` leaves it unchanged.
#[inline]
pub fn round_to(d: i64, q: i64) -> i64 {
    if q <= 1 {
        d
    } else {
        q * (d + q / 2).div_euclid(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_must_divide_the_side() {
        assert!(Lattice::new(2, 4, 128).is_ok());
        assert!(Lattice::new(1, 128, 128).is_ok());
        for (nx, ny) in [(3, 4), (0, 2), (2, 256), (2, 6)] {
            let e = Lattice::new(nx, ny, 128).unwrap_err().to_string();
            assert!(e.contains("lattice") && e.contains(&format!("{nx}x{ny}")), "{e}");
        }
    }

    #[test]
    fn moduli_apply_from_a_cell_up() {
        let l = Lattice::new(2, 4, 128).unwrap();
        assert_eq!(l.cell(128), (64, 32));
        assert_eq!(l.moduli(128, 128), (64, 32));
        assert_eq!(l.moduli(128, 64), (64, 32));
        assert_eq!(l.moduli(128, 32), (64, 32));
        assert_eq!(l.moduli(128, 16), (1, 32));
        assert_eq!(l.moduli(128, 8), (1, 1));
    }

    #[test]
    fn rounding_to_cells() {
        assert_eq!([-33, -32, -31, 0, 31, 32, 95, 96].map(|d| round_to(d, 64)), [-64, 0, 0, 0, 0, 64, 64, 128]);
        assert_eq!(round_to(-7, 1), -7);
    }
}
