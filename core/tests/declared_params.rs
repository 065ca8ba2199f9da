//! Every parameter of every mode, from its one declaration: each value it takes changes the
//! canonical text that keys caches and ETags — or, where a declaration says a field does not
//! change the pixels (`canonical: none`), the pixels are shown to be the same — and every mode's
//! parameters read back from their own texts (defaults round-trip). The values tried come from
//! each spec's kind and range (its ends, its middle, every choice), so a parameter added to a
//! declaration is covered without touching this file.

mod common;

use std::collections::BTreeMap;

use textile_core::modes::params::{Common, Kind, ParamSpec, COMMON};
use textile_core::modes::{all, Needs, Prepared};
use textile_core::{Defaults, ModeParams, ParamReader, Pyramid, Rect, Source, View, MODE_NAMES};

/// Values to try for `spec`: its range's ends and middle, every choice.
fn samples(spec: &ParamSpec, levels: u32) -> Vec<String> {
    match spec.kind {
        Kind::Choice(values) => values.iter().map(|v| v.to_string()).collect(),
        Kind::Integer { min, max } => vec![min.to_string(), max.to_string(), (min + (max - min) / 2).to_string()],
        Kind::PowerOfTwo { min, max } => vec![min.to_string(), (min * 4).min(max).to_string()],
        Kind::Unit => vec!["0".into(), "0.5".into(), "1".into()],
        Kind::Levels => {
            let list: Vec<String> =
                (0..=levels).map(|l| if l % 2 == 0 { "0.25" } else { "0.75" }.to_string()).collect();
            vec!["0".into(), "1".into(), "default".into(), list.join(",")]
        }
        Kind::Interval { min, max } => vec![format!("{min},{max}"), format!("{min},{min}"), format!("{max},{max}")],
        // {"strokes":[{"at":[3,4],"radius":8,"value":0}]} and {"noise":{"scale":16,"range":[0.2,1]}}.
        Kind::Text { .. } => vec![
            "eyJzdHJva2VzIjpbeyJhdCI6WzMsNF0sInJhZGl1cyI6OCwidmFsdWUiOjB9XX0".into(),
            "eyJub2lzZSI6eyJzY2FsZSI6MTYsInJhbmdlIjpbMC4yLDFdfX0".into(),
        ],
    }
}

/// `key = value` read over `base` as a texture's setting would be (request parameters and
/// texture settings alike).
fn read(base: &ModeParams, src: &Source, pairs: &[(&str, String)]) -> textile_core::Result<ModeParams> {
    let mut r = ParamReader::texture(pairs.iter().map(|(k, v)| (k.to_string(), v.clone())))?;
    let common = Common::read(&mut r, src.exemplar.size().longer())?;
    let p = base.parse(&common, &mut r, src)?;
    assert!(r.is_empty(), "{pairs:?} left keys unread");
    Ok(p)
}

fn pixels(p: &ModeParams, src: &Source) -> Vec<u8> {
    p.render(src, &Pyramid::off(), View::native(Rect::new(-20, 13, 24, 24))).expect("render").image.pixels
}

#[test]
fn every_value_of_every_parameter_changes_the_key_or_not_the_pixels() {
    let ex = common::toroidal_exemplar(64, 11);
    let an = textile_core::Analysis::build(&ex, &textile_core::NoProgress);
    let prepared = Prepared::compute(&ex).expect("prepared");
    let src = Source::new(&ex, &an).with_prepared(&prepared);
    let defaults = Defaults::builtin(&src);
    for info in all() {
        let base = defaults.get(info.name).expect("mode").clone();
        let mut variants: Vec<(String, ModeParams)> = vec![("defaults".into(), base.clone())];
        for spec in COMMON.iter().filter(|s| s.name != "mode").chain(info.specs) {
            let mut changed = false;
            for v in samples(spec, src.levels()) {
                let Ok(p) = read(&base, &src, &[(spec.name, v.clone())]) else { continue };
                changed |= p != base;
                variants.push((format!("{}={v}", spec.name), p));
            }
            assert!(changed, "no value tried of {}'s '{}' changes its parameters", info.name, spec.name);
        }
        for (i, (a, pa)) in variants.iter().enumerate() {
            for (b, pb) in &variants[..i] {
                if pa == pb || pa.canonical() != pb.canonical() {
                    continue;
                }
                // One key for two different parameter sets: only right if the pixels agree.
                assert_eq!(
                    pixels(pa, &src),
                    pixels(pb, &src),
                    "mode={} '{a}' and '{b}' share the key {} but render differently",
                    info.name,
                    pa.canonical()
                );
            }
        }
    }
}

#[test]
fn every_mode_reads_its_parameters_back_from_their_texts() {
    let ex = common::toroidal_exemplar(64, 12);
    let src = Source::exemplar(&ex);
    let defaults = Defaults::builtin(&src);
    for info in all() {
        let base = defaults.get(info.name).expect("mode").clone();
        // Every parameter moved off its default, where a value tried does.
        let mut moved = base.clone();
        for spec in info.specs {
            for v in samples(spec, src.levels()) {
                if let Ok(p) = read(&moved, &src, &[(spec.name, v)]) {
                    if p != moved {
                        moved = p;
                        break;
                    }
                }
            }
        }
        let texts = |p: &ModeParams| p.texts();
        let back = read(&moved, &src, &texts(&base)).expect("defaults read back");
        assert_eq!(back, base, "mode={}: the defaults' texts {:?} read back differently", info.name, texts(&base));
        let back = read(&base, &src, &texts(&moved)).expect("moved read back");
        assert_eq!(back, moved, "mode={}: {:?} read back differently", info.name, texts(&moved));
        // The description names every declared parameter.
        let values = base.values(&src);
        for spec in info.specs {
            assert!(values.contains_key(spec.name), "mode={}: values lack '{}'", info.name, spec.name);
        }
    }
}

#[test]
fn a_mode_needs_its_prepared_state_exactly_when_it_prepares_one() {
    for info in all() {
        assert_eq!(info.needs == Needs::Prepared, info.preparation.is_some(), "mode={}", info.name);
    }
    // Configured defaults go through the same declarations.
    let ex = common::toroidal_exemplar(64, 13);
    let src = Source::exemplar(&ex);
    let tables: BTreeMap<String, Vec<(String, String)>> =
        [("mosaic".to_string(), vec![("iterations".to_string(), "3".to_string())])].into();
    let d = Defaults::configure(&src, MODE_NAMES[1], 0, &tables).expect("configured");
    assert!(d.get("mosaic").expect("mosaic").canonical().contains(";it=3;"));
}
