//! Shared fixtures for the core tests: exemplars from the shared development set, analysed
//! once per test binary.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::OnceLock;

use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress};

/// Path of a development exemplar in `../shared/exemplars` (beside the repository).
pub fn shared_exemplar(name: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/exemplars").join(name);
    assert!(p.exists(), "missing development exemplar {} (shared/ must sit beside the repo)", p.display());
    p
}

/// Path of an embedded default exemplar in `config/exemplars`.
pub fn embedded_exemplar(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars").join(name)
}

pub fn analyse(path: &PathBuf, opts: ExemplarOptions) -> Analysis {
    let bytes = std::fs::read(path).expect("read exemplar");
    let ex = Exemplar::from_bytes(&bytes, &opts).expect("decode exemplar");
    Analysis::build(&ex, &NoProgress)
}

/// A 64×64 crop of the gravel exemplar (non-toroidal).
pub fn small_exemplar() -> &'static Exemplar {
    static E: OnceLock<Exemplar> = OnceLock::new();
    E.get_or_init(|| {
        let bytes = std::fs::read(embedded_exemplar("gravel.png")).expect("read gravel");
        let img = image::load_from_memory(&bytes).expect("decode").to_rgba8();
        let small = image::imageops::crop_imm(&img, 0, 0, 64, 64).to_image();
        let px: Vec<[u8; 4]> = small.pixels().map(|p| p.0).collect();
        Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default())
    })
}

/// The analysis of [`small_exemplar`].
pub fn small() -> &'static Analysis {
    static A: OnceLock<Analysis> = OnceLock::new();
    A.get_or_init(|| Analysis::build(small_exemplar(), &NoProgress))
}
