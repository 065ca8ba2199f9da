//! `textile export`: tiles of a configured texture into a PMTiles or MBTiles archive.

use super::args::{CliResult, ExportArgs};
use super::{configured_texture, param_pairs};
use crate::encode::Format;
use crate::export;

/// `textile export`: tiles into a PMTiles or MBTiles archive.
pub fn run(a: ExportArgs) -> CliResult {
    let tex = configured_texture(&a.config, &a.texture)?;
    let mut pairs = param_pairs(&a.params, &a.mode, a.seed, None)?;
    if a.map != "albedo" {
        pairs.push(("map".into(), a.map.clone()));
    }
    let bbox = match &a.bbox {
        Some(b) => {
            let v: Vec<u32> = b
                .split(',')
                .map(|s| s.trim().parse::<u32>())
                .collect::<Result<_, _>>()
                .map_err(|_| "--bbox must be X0,Y0,X1,Y1 non-negative integers")?;
            let [x0, y0, x1, y1] = v[..] else {
                return Err("--bbox must be X0,Y0,X1,Y1".into());
            };
            Some((x0, y0, x1, y1))
        }
        None => None,
    };
    let zooms = match &a.zoom {
        Some(z) => {
            let (lo, hi) = z.split_once("..").unwrap_or((z, z));
            let n = |s: &str| s.trim().parse::<u32>().map_err(|_| format!("--zoom '{z}' must be MIN..MAX or Z"));
            Some((n(lo)?, n(hi)?))
        }
        None => None,
    };
    let format = Format::from_ext(&a.format).ok_or("--format must be png, jpg or webp")?;
    let plan = export::Plan::new(tex, pairs, a.world, bbox, zooms, format)?;
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !matches!(ext, "pmtiles" | "mbtiles") {
        return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", a.output.display()).into());
    }
    eprintln!(
        "exporting {} tiles of '{}{}' (archive zooms {}..={}) to {}",
        plan.count(),
        plan.tex.config.id,
        plan.query_suffix(),
        plan.zooms.0,
        plan.zooms.1,
        a.output.display()
    );
    let r = export::run(&plan, &a.output)?;
    println!(
        "wrote {} ({} tiles, {} bytes) in {:.1} s: {:.0} tiles/s",
        a.output.display(),
        r.tiles,
        r.bytes,
        r.secs,
        r.tiles as f64 / r.secs.max(1e-9)
    );
    Ok(())
}
