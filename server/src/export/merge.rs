//! `textile merge`: part files ([`super::part`]) laid into one archive, streaming — each part's
//! tiles copied in order, one tile in memory at a time (the PMTiles writer itself keeps one
//! directory entry and one content hash per distinct tile: 16 M tiles are a few hundred MB).
//! The parts must be of one export (equal archive identity, tile count and layout) and cover
//! its tiles exactly once; a gap, an overlap, a part of another export is an error naming the
//! parts, and every record is proved as it is read (its checksum, its place in the layout), so
//! a damaged, truncated or reordered part is an error naming the part, the record and the tile.
//! Their concatenation is the sequence a single-process export writes, so the archive's bytes
//! are the same.
//!
//! The output is safe: written under a temporary name that is removed after any failure, never
//! one of the inputs, and an existing file is replaced only when asked (`--force`); otherwise
//! the archive is linked into place, which fails if a file appeared there meanwhile.

use std::path::{Path, PathBuf};

use super::part::{self, Header};
use super::{open_sink, Report};

/// The fields of the archive identity a refusal names when two parts differ.
const IDENTITY: &[&str] = &["world", "texture", "landscape", "mode", "parameters", "query", "engine", "analysis"];

/// Why part `b` is not of `a`'s export, if it is not.
fn differs(a: &(PathBuf, Header), b: &(PathBuf, Header)) -> Option<String> {
    let (ha, hb) = (&a.1, &b.1);
    if ha.archive == hb.archive && ha.total == hb.total && ha.layout == hb.layout {
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

/// Refuse an output that cannot be written safely: a directory, one of the `inputs` (also
/// through another name or link), or an existing file unless `replace`.
pub fn check_output(inputs: &[PathBuf], output: &Path, replace: bool) -> Result<(), String> {
    use std::os::unix::fs::MetadataExt;
    let Ok(out) = std::fs::metadata(output) else { return Ok(()) };
    if out.is_dir() {
        return Err(format!("{} is a directory: name the archive file to write", output.display()));
    }
    for p in inputs {
        if std::fs::metadata(p).is_ok_and(|m| m.dev() == out.dev() && m.ino() == out.ino()) {
            return Err(format!(
                "{} is one of the parts being merged ({}): write the archive under another name",
                output.display(),
                p.display()
            ));
        }
    }
    if !replace {
        return Err(format!("{} exists: give --force to replace it, or another name", output.display()));
    }
    Ok(())
}

/// Merge `paths` into the archive `output` (`.pmtiles` or `.mbtiles`), written under a temporary
/// name and put in place when complete: replacing an existing file only if `replace`.
pub fn merge(paths: &[PathBuf], output: &Path, replace: bool) -> Result<Report, String> {
    let started = std::time::Instant::now();
    check_output(paths, output, replace)?;
    let parts = plan(paths)?;
    let tmp = textile_core::files::temp_path(output);
    let written: Result<u64, String> = (|| {
        let mut sink = open_sink(output, &tmp, &parts[0].1.archive)?;
        let mut tiles = 0u64;
        for (p, _) in &parts {
            let mut r = part::Reader::open(p)?;
            while let Some((z, x, y, bytes)) = r.next_tile()? {
                sink.add(z, x, y, &bytes)?;
                tiles += 1;
            }
        }
        sink.finish()?;
        let placed = if replace { std::fs::rename(&tmp, output) } else { std::fs::hard_link(&tmp, output) };
        placed.map_err(|e| match e.kind() {
            std::io::ErrorKind::AlreadyExists => {
                format!("{} appeared while merging: give --force to replace it, or another name", output.display())
            }
            _ => format!("{}: {e}", output.display()),
        })?;
        Ok(tiles)
    })();
    // After a failure, and after a link, the temporary file goes.
    let _ = std::fs::remove_file(&tmp);
    let tiles = written?;
    let bytes = std::fs::metadata(output).map(|m| m.len()).unwrap_or(0);
    Ok(Report { tiles, bytes, secs: started.elapsed().as_secs_f64() })
}
