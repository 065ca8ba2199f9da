//! MBTiles 1.3 archives (SQLite, through `rusqlite` with SQLite bundled): the `metadata` table
//! (name, format, bounds, center, zooms, type, attribution, the plan's JSON) and the `tiles`
//! table with TMS rows (`tile_row = 2^z − 1 − y`), written in one transaction.

use std::path::Path;

use rusqlite::{params, Connection};

use super::Sink;

/// An MBTiles archive being written.
pub struct MbtilesSink {
    db: Connection,
}

fn sql(e: rusqlite::Error) -> String {
    format!("MBTiles: {e}")
}

impl MbtilesSink {
    /// Start an archive at `path` with an export's metadata ([`super::Plan::metadata`]).
    pub fn create(path: &Path, meta: &serde_json::Value) -> Result<Self, String> {
        let [w, s, e, n] = super::meta_bounds(meta)?;
        let (lo, hi) = super::meta_zooms(meta)?;
        let _ = std::fs::remove_file(path);
        let db = Connection::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
        db.execute_batch(
            "PRAGMA journal_mode = OFF; PRAGMA synchronous = OFF; PRAGMA application_id = 0x4d504258;
             CREATE TABLE metadata (name TEXT, value TEXT);
             CREATE TABLE tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_data BLOB);
             BEGIN;",
        )
        .map_err(sql)?;
        let text = |k: &str| meta[k].as_str().unwrap_or("").to_string();
        let rows = [
            ("name", text("name")),
            ("format", text("format")),
            ("bounds", format!("{w},{s},{e},{n}")),
            ("center", format!("{},{},{lo}", (w + e) / 2.0, (s + n) / 2.0)),
            ("minzoom", lo.to_string()),
            ("maxzoom", hi.to_string()),
            ("type", "baselayer".to_string()),
            ("description", text("description")),
            ("attribution", text("attribution")),
            ("version", text("version")),
            ("json", serde_json::json!({ "textile": meta["textile"] }).to_string()),
        ];
        for (k, v) in rows {
            db.execute("INSERT INTO metadata (name, value) VALUES (?1, ?2)", params![k, v]).map_err(sql)?;
        }
        Ok(MbtilesSink { db })
    }
}

impl Sink for MbtilesSink {
    fn add(&mut self, z: u8, x: u32, y: u32, bytes: &[u8]) -> Result<(), String> {
        let row = (1i64 << z) - 1 - y as i64;
        let mut st = self
            .db
            .prepare_cached("INSERT INTO tiles (zoom_level, tile_column, tile_row, tile_data) VALUES (?1, ?2, ?3, ?4)")
            .map_err(sql)?;
        st.execute(params![z, x, row, bytes]).map_err(sql)?;
        Ok(())
    }

    fn finish(self: Box<Self>) -> Result<(), String> {
        self.db
            .execute_batch("CREATE UNIQUE INDEX tile_index ON tiles (zoom_level, tile_column, tile_row); COMMIT;")
            .map_err(sql)?;
        self.db.close().map_err(|(_, e)| sql(e))
    }
}
