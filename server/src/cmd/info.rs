//! `textile info FILE`: an analysis file's header, and what each mode prepared beside it
//! (read from `FILE.<extension>` when current, else computed).

use textile_core::prepare::Input;
use textile_core::{Analysis, Cancel};

use super::args::{CliResult, InfoArgs};

/// `textile info FILE`.
pub fn run(a: InfoArgs) -> CliResult {
    let an = Analysis::load(&a.file)?;
    let h = &an.header;
    println!("file:              {}", a.file.display());
    println!("analysis id:       {}", h.id);
    println!("file hash:         {}", an.file_hash());
    println!("format version:    {}", textile_core::analysis::file::FORMAT_VERSION);
    println!("algorithm version: {}", h.algorithm_version);
    println!(
        "exemplar:          {}x{} (input {}x{})",
        h.width, h.height, h.preparation.input_width, h.preparation.input_height
    );
    println!(
        "toroidal:          {} ({})",
        h.toroidal,
        if h.preparation.toroidal_forced { "forced" } else { "detected" }
    );
    println!("levels:            {} (native zoom {})", h.levels + 1, h.levels);
    println!("candidate search:  {}", h.index.name());
    // What each mode prepares: stored beside the file (`FILE.<extension>`) when there is one
    // for this exemplar, else computed from the exemplar the file holds.
    let ex = an.exemplar();
    for (_, step) in textile_core::modes::preparations() {
        let beside = a.file.with_extension(step.extension());
        let (stored, from) = match step.load(&beside) {
            Ok(state) => (Some(state), format!("stored in {}", beside.display())),
            Err(textile_core::CoreError::Io { .. }) => (None, "computed".to_string()),
            Err(e) => (None, format!("computed ({e})")),
        };
        let input = Input::exemplar(&ex);
        let current = || {
            step.run(
                &textile_core::modes::Prepared::new(),
                &input,
                None,
                false,
                &|| true,
                &textile_core::NoProgress,
                &Cancel::new(),
            )
        };
        let (state, from) = match stored {
            // Of this exemplar and version (its id), else computed.
            Some(state) if state.id() == step.id(&input) => (state, from),
            Some(_) => (current()?.0, format!("computed ({} is of another exemplar or version)", beside.display())),
            None => (current()?.0, from),
        };
        let fields: Vec<String> = state.describe().iter().map(|(k, v)| format!("{k} {v}")).collect();
        println!("{:<18} {}", format!("{}:", step.what()), fields.join(", "));
        println!("{:<18} {from}", format!("{} source:", step.what()));
    }
    match &h.structure {
        Some(s) => println!("structure:         {}", s),
        None => println!("structure:         not detected (lattice = none)"),
    }
    match &h.lattice {
        Some(l) => println!("lattice:           {l} (kept by the modes)"),
        None => println!("lattice:           none (the modes keep none)"),
    }
    Ok(())
}
