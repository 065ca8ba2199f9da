//! Which archive tiles an export holds, and in which order they are written: every zoom of its
//! range in turn, each in ascending PMTiles tile id (Hilbert order). Plans render this sequence,
//! part headers carry it, and merge checks every record against it, so a record that is not the
//! next tile of its part's range is refused by name.

use pmtiles::{TileCoord, TileId};
use serde::{Deserialize, Serialize};

/// An export's tiles: archive zooms `lo..=hi`, and the rectangle at the highest zoom (its
/// parents below); no rectangle is a periodic world (every tile of every zoom).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Layout {
    /// Archive zooms, inclusive.
    pub zooms: (u8, u8),
    /// `[x0, y0, x1, y1)` at the highest zoom, or `None` for a whole world.
    pub rect: Option<[u32; 4]>,
}

/// One archive tile: zoom, column, row.
pub type Coord = (u8, u32, u32);

/// The PMTiles tile id of archive tile `z/x/y` (zoom, then Hilbert order).
pub fn tile_id(z: u8, x: u32, y: u32) -> u64 {
    TileCoord::new(z, x, y).map(|c| TileId::from(c).value()).unwrap_or(u64::MAX)
}

/// Tiles in the pyramid's zooms below `z` (the first tile id of zoom `z`).
fn first_id(z: u8) -> u64 {
    ((1u64 << (2 * u32::from(z))) - 1) / 3
}

impl Layout {
    /// Whether the numbers can describe an export (zooms in order and within PMTiles' range,
    /// a non-empty rectangle inside its zoom).
    pub fn is_valid(&self) -> bool {
        let (lo, hi) = self.zooms;
        lo <= hi
            && hi <= 26
            && self.rect.is_none_or(|[x0, y0, x1, y1]| x0 < x1 && y0 < y1 && x1 <= 1 << hi && y1 <= 1 << hi)
    }

    /// Columns and rows `[x0, x1) × [y0, y1)` at archive zoom `a`.
    pub fn tiles_at(&self, a: u8) -> (u32, u32, u32, u32) {
        match self.rect {
            None => (0, 0, 1 << a, 1 << a),
            Some([x0, y0, x1, y1]) => {
                let s = self.zooms.1 - a;
                (x0 >> s, y0 >> s, ((x1 - 1) >> s) + 1, ((y1 - 1) >> s) + 1)
            }
        }
    }

    /// Tiles at archive zoom `a`.
    fn count_at(&self, a: u8) -> u64 {
        let (x0, y0, x1, y1) = self.tiles_at(a);
        u64::from(x1 - x0) * u64::from(y1 - y0)
    }

    /// Tiles in all.
    pub fn count(&self) -> u64 {
        (self.zooms.0..=self.zooms.1).map(|a| self.count_at(a)).sum()
    }

    /// The tiles of zoom `a`, in ascending tile id.
    pub fn zoom_tiles(&self, a: u8) -> Vec<Coord> {
        let (x0, y0, x1, y1) = self.tiles_at(a);
        let mut level: Vec<(u64, Coord)> =
            (y0..y1).flat_map(|y| (x0..x1).map(move |x| (tile_id(a, x, y), (a, x, y)))).collect();
        level.sort_unstable_by_key(|(id, _)| *id);
        level.into_iter().map(|(_, c)| c).collect()
    }

    /// The tiles from the `start`-th on (0-based), in the order they are written.
    pub fn tiles_from(&self, start: u64) -> Tiles {
        let mut zoom = self.zooms.0;
        let mut skip = start;
        while zoom <= self.zooms.1 && skip >= self.count_at(zoom) {
            skip -= self.count_at(zoom);
            zoom += 1;
        }
        Tiles { layout: *self, zoom, index: skip, level: Vec::new() }
    }
}

/// The tiles of a [`Layout`] in order, from some index on.
pub struct Tiles {
    layout: Layout,
    zoom: u8,
    /// Index within the zoom.
    index: u64,
    /// The zoom's tiles, for a rectangle (a world's come from their ids).
    level: Vec<Coord>,
}

impl Iterator for Tiles {
    type Item = Coord;

    fn next(&mut self) -> Option<Coord> {
        while self.zoom <= self.layout.zooms.1 {
            if self.index < self.layout.count_at(self.zoom) {
                let i = self.index;
                self.index += 1;
                return Some(match self.layout.rect {
                    None => {
                        let c = TileId::new(first_id(self.zoom) + i).map(TileCoord::from).ok()?;
                        (c.z(), c.x(), c.y())
                    }
                    Some(_) => {
                        if self.level.is_empty() {
                            self.level = self.layout.zoom_tiles(self.zoom);
                        }
                        *self.level.get(i as usize)?
                    }
                });
            }
            self.zoom += 1;
            self.index = 0;
            self.level.clear();
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_from_any_index_continue_the_whole_sequence() {
        for layout in [
            Layout { zooms: (0, 4), rect: None },
            Layout { zooms: (2, 4), rect: None },
            Layout { zooms: (1, 5), rect: Some([3, 5, 29, 17]) },
        ] {
            let all: Vec<Coord> = (layout.zooms.0..=layout.zooms.1).flat_map(|a| layout.zoom_tiles(a)).collect();
            assert_eq!(all.len() as u64, layout.count());
            let ids: Vec<u64> = all.iter().map(|&(z, x, y)| tile_id(z, x, y)).collect();
            assert!(ids.windows(2).all(|w| w[0] < w[1]), "ascending tile ids");
            for start in [0, 1, 7, all.len() as u64 / 2, all.len() as u64 - 1, all.len() as u64] {
                let from: Vec<Coord> = layout.tiles_from(start).collect();
                assert_eq!(from, all[start as usize..], "{layout:?} from {start}");
            }
        }
        assert!(!Layout { zooms: (3, 2), rect: None }.is_valid());
        assert!(!Layout { zooms: (0, 2), rect: Some([0, 0, 5, 1]) }.is_valid());
    }
}
