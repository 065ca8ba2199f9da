//! Entry points for fuzzing (`fuzz/`, cargo-fuzz) and for the test that replays the committed
//! corpus (`tests/fuzz_corpus.rs`): each takes arbitrary bytes, feeds them to one parser of
//! untrusted input exactly as the service does, and must return — never panic, hang or allocate
//! without bound — whatever the bytes.

use std::sync::{Arc, OnceLock};

use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress};

use crate::config::TextureConfig;
use crate::encode::Format;
use crate::request::{params, parse_tile, parse_window, query_reader};
use crate::sampling::{parse_binary, parse_json, Records};
use crate::textures::Texture;

/// A small analysed texture (a 32² crop of the embedded gravel), built once.
fn texture() -> &'static Arc<Texture> {
    static T: OnceLock<Arc<Texture>> = OnceLock::new();
    T.get_or_init(|| {
        let bytes = crate::textures::embedded("gravel.png").unwrap_or_default();
        let img = image::load_from_memory(bytes).map(|i| i.to_rgba8()).unwrap_or_default();
        let px: Vec<[u8; 4]> = (0..32 * 32)
            .map(|i| img.get_pixel_checked(i % 32, i / 32).map(|p| p.0).unwrap_or([128, 128, 128, 255]))
            .collect();
        let ex = Exemplar::from_rgba(32, 32, &px, &ExemplarOptions::default());
        let an = Analysis::build(&ex, &NoProgress);
        match Texture::new(TextureConfig::new("gravel", "embedded:gravel.png"), 0, ex, an) {
            Ok(t) => Arc::new(t),
            Err(e) => panic!("the fuzzing texture: {e}"),
        }
    })
}

/// A tile or window request: `Z/X/Y.FMT?QUERY` — the path segments parsed as a tile address, the
/// query as a window's geometry, then as the texture's mode parameters.
pub fn request(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let (path, query) = text.split_once('?').unwrap_or((&text, ""));
    let tex = texture();
    let segs: Vec<&str> = path.split('/').collect();
    if let [z, x, y, ..] = segs[..] {
        let _ = parse_tile(tex, z, x, y);
    }
    let Ok(mut r) = query_reader(Some(query)) else { return };
    let _ = parse_window(tex, &mut r, Format::Png);
    let _ = params(tex, r);
}

/// An exemplar image, decoded and prepared as a configured or uploaded one is (at most 256 px
/// per side here, to keep each run fast; the limits are the same code at any size).
pub fn exemplar(data: &[u8]) {
    let opts = ExemplarOptions { max_input_side: 256, ..ExemplarOptions::default() };
    let _ = Exemplar::from_bytes(data, &opts);
}

/// A degenerate exemplar made from the bytes — a few colours (the first byte's low half the
/// period, its bits 4–5 the layout: flat, checkerboard, stripes, or colours picked by the later
/// bytes; bit 7 a 64² instead of a 32² exemplar), checked and analysed as an upload is: refused
/// as flat, or analysed with its ties and repeats in bounded time.
pub fn degenerate_exemplar(data: &[u8]) {
    let Some((&shape, rest)) = data.split_first() else { return };
    let side: u32 = if shape & 0x80 != 0 { 64 } else { 32 };
    let colours: Vec<[u8; 4]> = rest.chunks_exact(3).take(4).map(|c| [c[0], c[1], c[2], 255]).collect();
    if colours.is_empty() {
        return;
    }
    let picks = rest.get(colours.len() * 3..).filter(|p| !p.is_empty()).unwrap_or(&[0]);
    let period = u32::from(shape & 0x0f).max(1);
    let px: Vec<[u8; 4]> = (0..side * side)
        .map(|i| {
            let (x, y) = (i % side, i / side);
            let k = match (shape >> 4) & 3 {
                0 => 0,
                1 => (x / period + y / period) as usize,
                2 => (x / period) as usize,
                _ => picks[i as usize % picks.len()] as usize,
            };
            colours[k % colours.len()]
        })
        .collect();
    let ex = Exemplar::from_rgba(side, side, &px, &ExemplarOptions::default());
    if ex.check_not_flat().is_ok() {
        let _ = Analysis::try_build(&ex, &NoProgress, &textile_core::Cancel::new());
    }
}

/// An analysis file's bytes, loaded as the server loads one from its data directory.
pub fn analysis_file(data: &[u8]) {
    let _ = Analysis::from_bytes(data);
}

/// A `POST /samples` body: the first byte chooses JSON, binary texels or binary footprints.
pub fn samples_body(data: &[u8]) {
    let Some((&kind, body)) = data.split_first() else { return };
    let tex = texture();
    let _ = match kind % 3 {
        0 => parse_json(tex.zooms(), body),
        1 => parse_binary(tex.zooms(), body, Records::Texels),
        _ => parse_binary(tex.zooms(), body, Records::Footprints),
    };
}

/// An upload: the first line as the query of a raw-body upload (its fields read into a texture
/// configuration, as `POST /admin/textures` does; `map.NAME` keys as its map parts), the rest
/// as a stored upload record
/// (`uploads/ID.toml`, as read at start-up) and as the image whose format is sniffed.
pub fn upload(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let (query, rest) = text.split_once('\n').unwrap_or((&text, ""));
    let fields: Vec<(String, String)> =
        form_urlencoded::parse(query.as_bytes()).map(|(k, v)| (k.into_owned(), v.into_owned())).collect();
    let (maps, fields): (Vec<_>, Vec<_>) = fields.into_iter().partition(|(k, _)| k.starts_with("map."));
    let maps: Vec<(String, &str)> = maps.iter().map(|(k, _)| (k["map.".len()..].to_string(), "png")).collect();
    if let Ok(t) = crate::uploads::texture_config(&fields, &maps) {
        // Whatever is accepted names files inside the uploads folder only.
        for (_, f) in t.map_images() {
            assert!(std::path::Path::new(f).file_name().is_some_and(|n| n == f), "map file {f}");
        }
    }
    let _ = crate::uploads::parse_record(rest);
    let _ = crate::uploads::image_extension(rest.as_bytes());
}
