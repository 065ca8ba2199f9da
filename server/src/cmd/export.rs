//! `textile export`: tiles of a configured texture or landscape into a PMTiles or MBTiles
//! archive, or one shard's part file of it; `textile merge`: parts into the archive.

use super::args::{CliResult, ExportArgs, MergeArgs};
use super::{configured_landscape, configured_texture, param_pairs};
use crate::encode::Format;
use crate::export;
use crate::textures::Served;

/// `textile export`: tiles into a PMTiles or MBTiles archive.
pub fn run(a: ExportArgs) -> CliResult {
    let shard = a.shard.as_deref().map(export::Shard::parse).transpose()?;
    rayon::ThreadPoolBuilder::new()
        .num_threads(a.workers)
        .thread_name(|i| format!("textile-export-{i}"))
        .build_global()?;
    let served = match configured_landscape(&a.config, &a.texture)? {
        Some(land) => {
            if a.mode.is_some() || !a.params.is_empty() {
                return Err("a landscape exports with --seed, --world and --map only (its layers' parameters are \
                            its configuration's)"
                    .into());
            }
            Served::Landscape(land)
        }
        None => Served::Texture(configured_texture(&a.config, &a.texture)?),
    };
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
    let plan = export::Plan::new(served, pairs, a.world, bbox, zooms, format)?;
    if let Some(shard) = shard {
        let (start, end) = shard.range(plan.count());
        eprintln!(
            "exporting shard {}/{}: tiles {start}..{end} of {} of '{}{}' to {}",
            shard.index,
            shard.count,
            plan.count(),
            plan.what.id(),
            plan.query_suffix(),
            a.output.display()
        );
        wrote(&a.output, "tiles rendered", &export::render_part(&plan, shard, &a.output)?);
        return Ok(());
    }
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !matches!(ext, "pmtiles" | "mbtiles") {
        return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", a.output.display()).into());
    }
    eprintln!(
        "exporting {} tiles of '{}{}' (archive zooms {}..={}) to {}",
        plan.count(),
        plan.what.id(),
        plan.query_suffix(),
        plan.zooms.0,
        plan.zooms.1,
        a.output.display()
    );
    wrote(&a.output, "tiles", &export::run(&plan, &a.output)?);
    Ok(())
}

/// The line saying what an export or a shard wrote: `what` counts `r.tiles`.
fn wrote(output: &std::path::Path, what: &str, r: &export::Report) {
    println!(
        "wrote {} ({} {what}, {} bytes) in {:.1} s: {:.0} tiles/s",
        output.display(),
        r.tiles,
        r.bytes,
        r.secs,
        r.tiles as f64 / r.secs.max(1e-9)
    );
}

/// `textile merge PART… -o ARCHIVE`.
pub fn merge(a: MergeArgs) -> CliResult {
    let ext = a.output.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !matches!(ext, "pmtiles" | "mbtiles") {
        return Err(format!("{}: the archive must end in .pmtiles or .mbtiles", a.output.display()).into());
    }
    let r = export::merge::merge(&a.parts, &a.output, a.force)?;
    println!(
        "merged {} parts into {} ({} tiles, {} bytes) in {:.1} s: {:.0} MB/s",
        a.parts.len(),
        a.output.display(),
        r.tiles,
        r.bytes,
        r.secs,
        r.bytes as f64 / 1e6 / r.secs.max(1e-9)
    );
    Ok(())
}
