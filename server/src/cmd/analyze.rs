//! `textile analyze EXEMPLAR -o FILE`: the analysis, with a progress bar, and what each mode
//! prepares beside it (`FILE.<extension>`).

use textile_core::prepare::{Input, Origin};
use textile_core::{Analysis, Cancel};

use super::args::{AnalyzeArgs, CliResult};
use super::Bar;
use std::sync::Mutex;

/// `textile analyze EXEMPLAR -o FILE`.
pub fn run(a: AnalyzeArgs) -> CliResult {
    let t = std::time::Instant::now();
    let ex = a.recipe.make(&a.exemplar)?;
    let prepared_secs = t.elapsed().as_secs_f64();
    let an = Analysis::try_build_with(&ex, a.recipe.index, &Bar(Mutex::new(None), "analysing"), &Cancel::new())?;
    an.save(&a.output)?;
    // What each mode prepares, beside it (`FILE.<extension>`), for `textile info` and for a
    // server whose data directory holds them all.
    for (_, step) in textile_core::modes::preparations() {
        let beside = a.output.with_extension(step.extension());
        let input = Input::exemplar(&ex);
        if let (_, Origin::Computed { not_stored: Some(e), .. }) = step.run(
            &textile_core::modes::Prepared::new(),
            &input,
            Some(&beside),
            true,
            &|| true,
            &textile_core::NoProgress,
            &Cancel::new(),
        )? {
            return Err(format!("{}: {e}", beside.display()).into());
        }
    }
    if let Some(s) = &ex.structure {
        println!("structure: {} (exemplar prepared in {:.0} ms)", s, 1000.0 * prepared_secs);
    }
    match &ex.lattice {
        Some(l) => println!("lattice: {l}"),
        None => println!("lattice: none"),
    }
    println!(
        "analysed {} ({}x{} → {}x{}, toroidal {}, {} search) in {:.2}s → {} (id {})",
        a.exemplar.display(),
        ex.preparation.input_width,
        ex.preparation.input_height,
        ex.width,
        ex.height,
        ex.toroidal,
        an.header.index.name(),
        t.elapsed().as_secs_f64(),
        a.output.display(),
        an.header.id
    );
    Ok(())
}
