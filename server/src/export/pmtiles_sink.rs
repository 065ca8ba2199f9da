//! PMTiles v3 archives through the `pmtiles` crate's streaming writer: tile type from the
//! encoding, zoom range and bounds from the plan (the crate would default the maximum zoom to
//! 22), the plan's JSON metadata, tiles added in ascending Hilbert id so the archive is clustered.

use std::fs::File;
use std::path::Path;

use pmtiles::{PmTilesStreamWriter, PmTilesWriter, TileCoord, TileType};

use super::Sink;
use crate::encode::Format;

/// A PMTiles archive being written.
pub struct PmtilesSink {
    writer: PmTilesStreamWriter<File>,
}

impl PmtilesSink {
    /// Start an archive at `path` with an export's metadata ([`super::Plan::metadata`]).
    pub fn create(path: &Path, meta: &serde_json::Value) -> Result<Self, String> {
        let kind = match Format::from_ext(meta["format"].as_str().unwrap_or("")) {
            Some(Format::Png) => TileType::Png,
            Some(Format::Jpeg) => TileType::Jpeg,
            Some(Format::Webp) => TileType::Webp,
            None => return Err(format!("an archive of tiles in format {}", meta["format"])),
        };
        let [w, s, e, n] = super::meta_bounds(meta)?;
        let (lo, hi) = super::meta_zooms(meta)?;
        let file = File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let writer = PmTilesWriter::new(kind)
            .min_zoom(lo)
            .max_zoom(hi)
            .bounds(w, s, e, n)
            .center_zoom(lo)
            .center((w + e) / 2.0, (s + n) / 2.0)
            .metadata(meta.to_string())
            .create(file)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(PmtilesSink { writer })
    }
}

impl Sink for PmtilesSink {
    fn add(&mut self, z: u8, x: u32, y: u32, bytes: &[u8]) -> Result<(), String> {
        let coord = TileCoord::new(z, x, y).map_err(|err| format!("tile {z}/{x}/{y}: {err}"))?;
        self.writer.add_tile(coord, bytes).map_err(|err| format!("writing tile {z}/{x}/{y}: {err}"))
    }

    fn finish(self: Box<Self>) -> Result<(), String> {
        self.writer.finalize().map_err(|e| format!("finishing the archive: {e}"))
    }
}
