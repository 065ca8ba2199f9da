//! Golden bytes: blake3 digests of rendered windows for every mode × zoom (native, native−1,
//! native−3) × period (none, a world of 2 tiles) × two seeds, on two embedded exemplars.
//!
//! Output bytes are a permanent contract: tiles are cached for a year by clients and CDNs under
//! ETags that include each mode's version. A failure here means a change altered the pixels of
//! a mode. If that was not intended, it is a bug. If it was, bump that mode's `VERSION`
//! (`core/src/modes/<mode>/mod.rs`) so ETags and cache keys change with the bytes, and replace
//! the digests below with the table this test prints.

mod common;

use textile_core::{
    Analysis, Defaults, Exemplar, ExemplarOptions, NoProgress, ParamReader, Pyramid, Rect, RgbWindow, Source, View,
    MODE_NAMES,
};

fn golden_source(name: &str) -> (Exemplar, Analysis) {
    let bytes = std::fs::read(common::embedded_exemplar(name)).expect("read exemplar");
    let ex = Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).expect("decode exemplar");
    let an = Analysis::build(&ex, &NoProgress);
    (ex, an)
}

/// Render through the same path as a request: the query read over the built-in defaults.
fn render_mode((ex, an): &(Exemplar, Analysis), query: &str, zoom_out: u32, rect: Rect) -> RgbWindow {
    // What a texture prepares, as the server keeps it (umbrella: its extraction).
    let prepared = textile_core::modes::Prepared::compute(ex).unwrap();
    let src = Source::new(ex, an).with_prepared(&prepared);
    let pairs = query.split('&').filter_map(|kv| kv.split_once('='));
    let params = Defaults::builtin(&src).request(&src, ParamReader::request(pairs).unwrap()).unwrap();
    params.render(&src, &Pyramid::off(), View::out(zoom_out, rect)).unwrap().image
}

/// A 96×64 window straddling tile borders, away from the origin.
const WINDOW: Rect = Rect { x0: -40, y0: 1000, x1: 56, y1: 1064 };

/// `(exemplar, mode, seed, zoom_out, world, digest)`.
#[rustfmt::skip]
const GOLDEN: &[(&str, &str, u64, u32, u32, &str)] = &[
    ("gravel.png", "synth", 0, 0, 0, "339c553dd7347768"),
    ("gravel.png", "synth", 0, 0, 2, "05709bd2015a2422"),
    ("gravel.png", "synth", 0, 1, 0, "c731579d20e512e6"),
    ("gravel.png", "synth", 0, 1, 2, "06ebfd8ee99e0d34"),
    ("gravel.png", "synth", 0, 3, 0, "67b88f06c4c31dab"),
    ("gravel.png", "synth", 0, 3, 2, "970211f62e6cd47d"),
    ("gravel.png", "synth", 7, 0, 0, "9fdeade434f2560b"),
    ("gravel.png", "synth", 7, 0, 2, "97b166443b92e679"),
    ("gravel.png", "synth", 7, 1, 0, "457b942c12503855"),
    ("gravel.png", "synth", 7, 1, 2, "6ee16b430f9c9262"),
    ("gravel.png", "synth", 7, 3, 0, "61fd892e337ce25c"),
    ("gravel.png", "synth", 7, 3, 2, "4b73f4cea057c15f"),
    ("gravel.png", "mosaic", 0, 0, 0, "2743d1b55860d4a4"),
    ("gravel.png", "mosaic", 0, 0, 2, "d89082bbba093829"),
    ("gravel.png", "mosaic", 0, 1, 0, "e8590785363cc2a8"),
    ("gravel.png", "mosaic", 0, 1, 2, "2bc27855fdda9d1b"),
    ("gravel.png", "mosaic", 0, 3, 0, "0ee3c5b5c764aa8b"),
    ("gravel.png", "mosaic", 0, 3, 2, "a0ffe29b8119bbe5"),
    ("gravel.png", "mosaic", 7, 0, 0, "9c25469cceeb77c5"),
    ("gravel.png", "mosaic", 7, 0, 2, "ec305c14a9c72b1f"),
    ("gravel.png", "mosaic", 7, 1, 0, "b11f3e3c7e86f88c"),
    ("gravel.png", "mosaic", 7, 1, 2, "ec1e3f249770ab82"),
    ("gravel.png", "mosaic", 7, 3, 0, "cf20c4af9a3c1124"),
    ("gravel.png", "mosaic", 7, 3, 2, "1bf508cc5be30d20"),
    ("gravel.png", "tiling", 0, 0, 0, "cea8f1f54ec38487"),
    ("gravel.png", "tiling", 0, 0, 2, "cea8f1f54ec38487"),
    ("gravel.png", "tiling", 0, 1, 0, "608d9503098b2c71"),
    ("gravel.png", "tiling", 0, 1, 2, "608d9503098b2c71"),
    ("gravel.png", "tiling", 0, 3, 0, "be55af37f4f1748a"),
    ("gravel.png", "tiling", 0, 3, 2, "be55af37f4f1748a"),
    ("gravel.png", "tiling", 7, 0, 0, "cea8f1f54ec38487"),
    ("gravel.png", "tiling", 7, 0, 2, "cea8f1f54ec38487"),
    ("gravel.png", "tiling", 7, 1, 0, "608d9503098b2c71"),
    ("gravel.png", "tiling", 7, 1, 2, "608d9503098b2c71"),
    ("gravel.png", "tiling", 7, 3, 0, "be55af37f4f1748a"),
    ("gravel.png", "tiling", 7, 3, 2, "be55af37f4f1748a"),
    ("gravel.png", "umbrella", 0, 0, 0, "60e462e21d7b1ff7"),
    ("gravel.png", "umbrella", 0, 0, 2, "61b17c46856ce8f9"),
    ("gravel.png", "umbrella", 0, 1, 0, "d15c6626b3fecfc4"),
    ("gravel.png", "umbrella", 0, 1, 2, "c4c0ebb5bc2aae32"),
    ("gravel.png", "umbrella", 0, 3, 0, "86b76f83aa4344e7"),
    ("gravel.png", "umbrella", 0, 3, 2, "ea8dec327e3e3594"),
    ("gravel.png", "umbrella", 7, 0, 0, "fa75a400e6d1faf1"),
    ("gravel.png", "umbrella", 7, 0, 2, "a6fc244983b0e1e3"),
    ("gravel.png", "umbrella", 7, 1, 0, "99c06f080939b609"),
    ("gravel.png", "umbrella", 7, 1, 2, "04659e87dd1c607a"),
    ("gravel.png", "umbrella", 7, 3, 0, "10e5f8c9d3edbcdb"),
    ("gravel.png", "umbrella", 7, 3, 2, "058cb7fd4a6422a2"),
    ("brick.png", "synth", 0, 0, 0, "6a28a8124759e004"),
    ("brick.png", "synth", 0, 0, 2, "f9c6da015ba9228f"),
    ("brick.png", "synth", 0, 1, 0, "327bef5cfea9cb78"),
    ("brick.png", "synth", 0, 1, 2, "ef8de2d7a918b198"),
    ("brick.png", "synth", 0, 3, 0, "e470913d8c48ad6f"),
    ("brick.png", "synth", 0, 3, 2, "ceace74226bdacde"),
    ("brick.png", "synth", 7, 0, 0, "03f7dc6e41396856"),
    ("brick.png", "synth", 7, 0, 2, "dce9c9a1fc275a82"),
    ("brick.png", "synth", 7, 1, 0, "149d4207a524ea02"),
    ("brick.png", "synth", 7, 1, 2, "3be782f9a6d51580"),
    ("brick.png", "synth", 7, 3, 0, "e21698860a604e43"),
    ("brick.png", "synth", 7, 3, 2, "aec5660ee4f2fafb"),
    ("brick.png", "mosaic", 0, 0, 0, "ea46e408fbe07e44"),
    ("brick.png", "mosaic", 0, 0, 2, "05750d5d6d1dd25c"),
    ("brick.png", "mosaic", 0, 1, 0, "111c005e05d0acf3"),
    ("brick.png", "mosaic", 0, 1, 2, "ad77fcbbd1a6730f"),
    ("brick.png", "mosaic", 0, 3, 0, "8723cc7480beb9a8"),
    ("brick.png", "mosaic", 0, 3, 2, "59d8543b642f6a61"),
    ("brick.png", "mosaic", 7, 0, 0, "e266cdfa948c5303"),
    ("brick.png", "mosaic", 7, 0, 2, "efe5625eb4434ac8"),
    ("brick.png", "mosaic", 7, 1, 0, "59f7f7681ecff035"),
    ("brick.png", "mosaic", 7, 1, 2, "d6f41709e8abaed8"),
    ("brick.png", "mosaic", 7, 3, 0, "4880165a454861f5"),
    ("brick.png", "mosaic", 7, 3, 2, "021dbeda22bb8bae"),
    ("brick.png", "tiling", 0, 0, 0, "3c555c35b2f39217"),
    ("brick.png", "tiling", 0, 0, 2, "3c555c35b2f39217"),
    ("brick.png", "tiling", 0, 1, 0, "93598de7d3185132"),
    ("brick.png", "tiling", 0, 1, 2, "93598de7d3185132"),
    ("brick.png", "tiling", 0, 3, 0, "4a9562ccaae89469"),
    ("brick.png", "tiling", 0, 3, 2, "4a9562ccaae89469"),
    ("brick.png", "tiling", 7, 0, 0, "3c555c35b2f39217"),
    ("brick.png", "tiling", 7, 0, 2, "3c555c35b2f39217"),
    ("brick.png", "tiling", 7, 1, 0, "93598de7d3185132"),
    ("brick.png", "tiling", 7, 1, 2, "93598de7d3185132"),
    ("brick.png", "tiling", 7, 3, 0, "4a9562ccaae89469"),
    ("brick.png", "tiling", 7, 3, 2, "4a9562ccaae89469"),
    ("brick.png", "umbrella", 0, 0, 0, "c5aa3539e29669b5"),
    ("brick.png", "umbrella", 0, 0, 2, "c8577b17a78842c3"),
    ("brick.png", "umbrella", 0, 1, 0, "cf66f688c250c8dc"),
    ("brick.png", "umbrella", 0, 1, 2, "04d92fdf9241f921"),
    ("brick.png", "umbrella", 0, 3, 0, "75494e042b31e2a3"),
    ("brick.png", "umbrella", 0, 3, 2, "8687856355170df3"),
    ("brick.png", "umbrella", 7, 0, 0, "1e2b864172ea8c10"),
    ("brick.png", "umbrella", 7, 0, 2, "e40fbbdd08374b9f"),
    ("brick.png", "umbrella", 7, 1, 0, "34c91cd7d0daa47c"),
    ("brick.png", "umbrella", 7, 1, 2, "82bd79abe6033030"),
    ("brick.png", "umbrella", 7, 3, 0, "9ae3dd36d44be594"),
    ("brick.png", "umbrella", 7, 3, 2, "91e055915745d1dd"),
];

fn table() -> Vec<(&'static str, &'static str, u64, u32, u32, String)> {
    let mut out = Vec::new();
    for exemplar in ["gravel.png", "brick.png"] {
        let src = golden_source(exemplar);
        for mode in MODE_NAMES {
            for seed in [0u64, 7] {
                for zoom_out in [0u32, 1, 3] {
                    for world in [0u32, 2] {
                        let query = format!(
                            "mode={mode}&seed={seed}{}",
                            if world > 0 { format!("&world={world}") } else { String::new() }
                        );
                        let img = render_mode(&src, &query, zoom_out, WINDOW);
                        let digest = blake3::hash(&img.pixels).to_hex()[..16].to_string();
                        out.push((exemplar, *mode, seed, zoom_out, world, digest));
                    }
                }
            }
        }
    }
    out
}

#[test]
fn rendered_bytes_match_the_pinned_digests() {
    let got = table();
    let printed: String =
        got.iter().map(|(e, m, s, z, w, d)| format!("    ({e:?}, {m:?}, {s}, {z}, {w}, {d:?}),\n")).collect();
    let mut changed = Vec::new();
    for row in &got {
        let pinned = GOLDEN.iter().find(|g| (g.0, g.1, g.2, g.3, g.4) == (row.0, row.1, row.2, row.3, row.4));
        match pinned {
            Some(g) if g.5 == row.5 => {}
            Some(g) => changed.push(format!(
                "{} {} seed {} zoom-out {} world {}: pinned {}, got {}",
                row.0, row.1, row.2, row.3, row.4, g.5, row.5
            )),
            None => changed.push(format!(
                "{} {} seed {} zoom-out {} world {}: not pinned (got {})",
                row.0, row.1, row.2, row.3, row.4, row.5
            )),
        }
    }
    assert!(
        changed.is_empty(),
        "rendered bytes changed:\n  {}\n\nIf this was not intended, it is a bug. If it was: bump the VERSION of each mode \
         whose bytes changed (core/src/modes/<mode>/mod.rs) and replace GOLDEN in core/tests/golden.rs with:\n{printed}",
        changed.join("\n  ")
    );
    assert_eq!(got.len(), GOLDEN.len(), "GOLDEN has rows for modes or cases that no longer exist:\n{printed}");
}
