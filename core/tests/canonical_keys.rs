//! The canonical text of every mode's parameters — what keys the caches and every ETag — pinned
//! for the built-in defaults and for one request that sets every parameter. Tiles are kept by
//! clients and CDNs for a year under these keys, so a change to them is always deliberate:
//! only a mode's `VERSION` (which is part of the text) or a new parameter given a non-default
//! value may change them.

mod common;

use std::collections::BTreeMap;

use textile_core::{Defaults, ParamReader, Source};

fn configured(mode: &str, table: &[(&str, &str)]) -> String {
    let ex = common::toroidal_exemplar(64, 3);
    let src = Source::exemplar(&ex);
    let mut tables = BTreeMap::new();
    tables.insert(mode.to_string(), table.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect());
    let d = Defaults::configure(&src, mode, 0, &tables).expect("configured");
    d.get(mode).expect("mode").canonical()
}

fn requested(mode: &str, query: &[(&str, &str)]) -> String {
    let ex = common::toroidal_exemplar(64, 3);
    let src = Source::exemplar(&ex);
    let d = Defaults::builtin(&src);
    let mut pairs = vec![("mode", mode)];
    pairs.extend_from_slice(query);
    d.request(&src, ParamReader::request(pairs).expect("reader")).expect("request").canonical()
}

#[test]
fn the_defaults_keep_their_canonical_text() {
    let ex = common::toroidal_exemplar(64, 3);
    let src = Source::exemplar(&ex);
    let d = Defaults::builtin(&src);
    let got: Vec<String> = textile_core::MODE_NAMES.iter().map(|m| d.get(m).expect("mode").canonical()).collect();
    assert_eq!(
        got,
        [
            "mode=synth;v6;seed=0;r=default;passes=2;sub=4;kappa=65536;period=none",
            "mode=mosaic;v3;seed=0;it=10;area=500,750;smooth=3;period=none",
            "mode=tiling;v1;",
            "mode=umbrella;v13;seed=0;density=100;scale=850,1150;shape=32768;colour=65536;shadow=19660,2;k=8;bg=mosaic;period=none",
        ]
    );
}

#[test]
fn every_parameter_set_keeps_its_canonical_text() {
    // eyJzdHJva2VzIjpbeyJhdCI6WzMsNF0sInJhZGl1cyI6OCwidmFsdWUiOjB9XX0 is
    // {"strokes":[{"at":[3,4],"radius":8,"value":0}]}.
    let controls = "eyJzdHJva2VzIjpbeyJhdCI6WzMsNF0sInJhZGl1cyI6OCwidmFsdWUiOjB9XX0";
    assert_eq!(
        requested("synth", &[("seed", "7"), ("world", "4"), ("randomness", "0.25"), ("controls", controls)]),
        "mode=synth;v6;seed=7;r=16384;passes=2;sub=4;kappa=65536;period=1024;controls=s3,4,8,0,0"
    );
    assert_eq!(
        configured(
            "synth",
            &[("kappa", "0.5"), ("passes", "3"), ("subpasses", "1"), ("randomness", "0,0,1,1,0.5,0.5,0.1")]
        ),
        "mode=synth;v6;seed=0;r=0,0,65536,65536,32768,32768,6554;passes=3;sub=1;kappa=32768;period=none"
    );
    assert_eq!(
        requested(
            "mosaic",
            &[("seed", "3"), ("world", "1"), ("iterations", "5"), ("block_area", "0.25,0.5"), ("smoothing", "1")]
        ),
        "mode=mosaic;v3;seed=3;it=5;area=250,500;smooth=1;period=256"
    );
    assert_eq!(requested("tiling", &[("seed", "3"), ("world", "2")]), "mode=tiling;v1;");
    assert_eq!(
        requested(
            "umbrella",
            &[
                ("seed", "5"),
                ("world", "8"),
                ("density", "150"),
                ("scale", "0.5,2"),
                ("shape", "0.25"),
                ("colour", "0.75"),
                ("shadow", "0.5"),
                ("shadow_offset", "4"),
                ("k", "3"),
                ("background", "tiling"),
            ]
        ),
        "mode=umbrella;v13;seed=5;density=150;scale=500,2000;shape=16384;colour=49152;shadow=32768,4;k=3;bg=tiling;period=2048"
    );
}
