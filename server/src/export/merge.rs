//! `textile merge`: part files ([`super::part`]) laid into one archive, streaming — each part's
//! tiles copied in order, one tile in memory at a time (the PMTiles writer itself keeps one
//! directory entry and one content hash per distinct tile: 16 M tiles are a few hundred MB).
//! The parts must be of one export (equal archive identity and tile count) and cover its tiles
//! exactly once; a gap, an overlap, a part of another export or a truncated part is an error
//! naming the parts. Their concatenation is the sequence a single-process export writes, so the
//! archive's bytes are the same.

use std::path::{Path, PathBuf};

use super::part::{self, Header};
use super::{open_sink, Report};

/// The fields of the archive identity a refusal names when two parts differ.
const IDENTITY: &[&str] = &["world", "texture", "mode", "parameters", "query", "engine", "analysis"];

/// Why part `b` is not of `a`'s export, if it is not.
fn differs(a: &(PathBuf, Header), b: &(PathBuf, Header)) -> Option<String> {
    let (ha, hb) = (&a.1, &b.1);
    if ha.archive == hb.archive && ha.total == hb.total {
        return None;
    }
    let (ta, tb) = (&ha.archive["textile"], &hb.archive["textile"]);
    let field = IDENTITY
        .iter()
        .find(|k| ta[**k] != tb[**k])
        .map(|k| format!("{k} {} against {}", tb[*k], ta[*k]))
        .or_else(|| {
            ["format", "minzoom", "maxzoom", "bounds", "name"]
                .iter()
                .find(|k| ha.archive[**k] != hb.archive[**k])
                .map(|k| format!("{k} {} against {}", hb.archive[*k], ha.archive[*k]))
        })
        .unwrap_or_else(|| format!("{} tiles in all against {}", hb.total, ha.total));
    Some(format!("{} is a part of another export than {}: {field}", b.0.display(), a.0.display()))
}

/// Check that `parts` are of one export and cover its tiles exactly once; sorted by range.
pub fn plan(paths: &[PathBuf]) -> Result<Vec<(PathBuf, Header)>, String> {
    if paths.is_empty() {
        return Err("no parts to merge".into());
    }
    let mut parts = Vec::with_capacity(paths.len());
    for p in paths {
        if p.as_os_str().to_string_lossy().ends_with(".partial") {
            return Err(format!("{}: a shard still being written (run its shard again to finish it)", p.display()));
        }
        parts.push((p.clone(), part::read_header(p)?));
    }
    for b in &parts[1..] {
        if let Some(why) = differs(&parts[0], b) {
            return Err(why);
        }
    }
    parts.sort_by_key(|(_, h)| (h.range.0, h.range.1));
    let total = parts[0].1.total;
    let mut covered = 0u64;
    let mut last: Option<&Path> = None;
    for (p, h) in &parts {
        let (s, e) = h.range;
        if s > covered {
            let after = last.map(|l| format!(" (after {})", l.display())).unwrap_or_default();
            return Err(format!("tiles {covered}..{s} of {total} are in no part{after}: a shard is missing"));
        }
        if s < covered {
            let other = last.map(|l| l.display().to_string()).unwrap_or_default();
            return Err(format!(
                "{} and {other} both hold tiles {s}..{}: parts of two different shardings, or one part given twice",
                p.display(),
                covered.min(e)
            ));
        }
        covered = e;
        last = Some(p);
    }
    if covered != total {
        let after = last.map(|l| l.display().to_string()).unwrap_or_default();
        return Err(format!("tiles {covered}..{total} of {total} are in no part (after {after}): a shard is missing"));
    }
    Ok(parts)
}

/// Merge `paths` into the archive `output` (`.pmtiles` or `.mbtiles`), written under a temporary
/// name and renamed when complete.
pub fn merge(paths: &[PathBuf], output: &Path) -> Result<Report, String> {
    let started = std::time::Instant::now();
    let parts = plan(paths)?;
    let tmp = textile_core::files::temp_path(output);
    let written = (|| {
        let mut sink = open_sink(output, &tmp, &parts[0].1.archive)?;
        let mut tiles = 0u64;
        let mut last_id = None;
        for (p, _) in &parts {
            let mut r = part::Reader::open(p)?;
            while let Some((z, x, y, bytes)) = r.next_tile()? {
                let id = super::pmtiles_sink::tile_id(z, x, y);
                if last_id.is_some_and(|l| l >= id) {
                    return Err(format!("{}: tile {z}/{x}/{y} out of order: damaged", p.display()));
                }
                last_id = Some(id);
                sink.add(z, x, y, &bytes)?;
                tiles += 1;
            }
        }
        sink.finish()?;
        Ok(tiles)
    })();
    match written {
        Ok(tiles) => {
            std::fs::rename(&tmp, output).map_err(|e| format!("{}: {e}", output.display()))?;
            let bytes = std::fs::metadata(output).map(|m| m.len()).unwrap_or(0);
            Ok(Report { tiles, bytes, secs: started.elapsed().as_secs_f64() })
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}
