//! `textile tileable EXEMPLAR --size N -o FILE`: one seamless tileable image (Wei & Levoy 2000
//! with a TSVQ), with a progress bar.

use std::sync::Mutex;

use textile_core::files::write_atomic;
use textile_core::{Cancel, ExemplarOptions};

use super::args::{CliResult, TileableArgs};
use super::{output_format, read_exemplar, toroidal_flag, Bar};
use crate::encode::{encode, Effort};

/// `textile tileable EXEMPLAR --size N -o FILE`.
pub fn run(a: TileableArgs) -> CliResult {
    use textile_core::tileable::{synthesize, Search, TileableOptions};
    let format = output_format(&a.output)?;
    let toroidal = toroidal_flag(&a.toroidal);
    let ex = read_exemplar(&a.exemplar, &ExemplarOptions { max_input_side: a.max_side, toroidal })?;
    let search = if a.exact { Search::Exact } else { Search::Tsvq { backtrack: a.backtrack } };
    let opts = TileableOptions { size: a.size, seed: a.seed, search };
    let t = std::time::Instant::now();
    let img = synthesize(&ex, &opts, &Bar(Mutex::new(None), "synthesizing"), &Cancel::new())?;
    let bytes = encode(&img.pixels, img.width, img.height, format, Effort::Tight)?;
    write_atomic(&a.output, &bytes)?;
    println!(
        "wrote {} ({}x{}, tileable) from {} ({}x{}, toroidal {}) in {:.2}s, {}",
        a.output.display(),
        a.size,
        a.size,
        a.exemplar.display(),
        ex.width,
        ex.height,
        ex.toroidal,
        t.elapsed().as_secs_f64(),
        if a.exact { "exhaustive search".to_string() } else { format!("TSVQ search, {} leaves", a.backtrack) }
    );
    Ok(())
}
