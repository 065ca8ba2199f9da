//! Replays the committed fuzzing corpus (`fuzz/corpus/TARGET/*`, grown by `cargo fuzz run`) through
//! the same entry points as the fuzz targets (`textile_server::robustness`), so every `cargo test`
//! catches a regression on any input the fuzzer ever kept, without running the fuzzer.

use std::path::PathBuf;

type Entry = fn(&[u8]);

const TARGETS: &[(&str, Entry)] = &[
    ("request", textile_server::robustness::request),
    ("exemplar", textile_server::robustness::exemplar),
    ("analysis_file", textile_server::robustness::analysis_file),
    ("samples_body", textile_server::robustness::samples_body),
    ("upload", textile_server::robustness::upload),
    ("degenerate_exemplar", textile_server::robustness::degenerate_exemplar),
];

#[test]
fn every_corpus_input_is_handled() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    for (target, entry) in TARGETS {
        let dir = root.join(target);
        let files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.expect("entry").path())
            .collect();
        assert!(!files.is_empty(), "no corpus for {target}");
        for f in &files {
            // An input can vanish while `cargo fuzz run` is reducing the corpus beside this test.
            let bytes = match std::fs::read(f) {
                Ok(b) => b,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                Err(e) => panic!("{}: {e}", f.display()),
            };
            let outcome = std::panic::catch_unwind(|| entry(&bytes));
            assert!(outcome.is_ok(), "{target}: {} panicked", f.display());
        }
        eprintln!("{target}: {} inputs", files.len());
    }
}
