//! PMTiles v3 archives through the `pmtiles` crate's streaming writer: tile type from the
//! encoding, zoom range and bounds from the plan (the crate would default the maximum zoom to
//! 22), the plan's JSON metadata, tiles added in ascending Hilbert id so the archive is clustered.

use std::fs::File;
use std::path::Path;

use pmtiles::{PmTilesStreamWriter, PmTilesWriter, TileCoord, TileId, TileType};

use super::{Entry, Plan, Sink};
use crate::encode::Format;

/// The PMTiles tile id of archive tile `z/x/y` (zoom, then Hilbert order).
pub fn tile_id(z: u8, x: u32, y: u32) -> u64 {
    TileCoord::new(z, x, y).map(|c| TileId::from(c).value()).unwrap_or(u64::MAX)
}

/// A PMTiles archive being written.
pub struct PmtilesSink {
    writer: PmTilesStreamWriter<File>,
}

impl PmtilesSink {
    /// Start an archive at `path` for a plan.
    pub fn create(path: &Path, plan: &Plan) -> Result<Self, String> {
        let kind = match plan.format {
            Format::Png => TileType::Png,
            Format::Jpeg => TileType::Jpeg,
            Format::Webp => TileType::Webp,
        };
        let [w, s, e, n] = plan.bounds();
        let (lo, hi) = plan.zooms;
        let file = File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let writer = PmTilesWriter::new(kind)
            .min_zoom(lo as u8)
            .max_zoom(hi as u8)
            .bounds(w, s, e, n)
            .center_zoom(lo as u8)
            .center((w + e) / 2.0, (s + n) / 2.0)
            .metadata(plan.metadata().to_string())
            .create(file)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(PmtilesSink { writer })
    }
}

impl Sink for PmtilesSink {
    fn add(&mut self, e: &Entry, bytes: &[u8]) -> Result<(), String> {
        let coord = TileCoord::new(e.z, e.x, e.y).map_err(|err| format!("tile {}/{}/{}: {err}", e.z, e.x, e.y))?;
        self.writer.add_tile(coord, bytes).map_err(|err| format!("writing tile {}/{}/{}: {err}", e.z, e.x, e.y))
    }

    fn finish(self: Box<Self>) -> Result<(), String> {
        self.writer.finalize().map_err(|e| format!("finishing the archive: {e}"))
    }
}
