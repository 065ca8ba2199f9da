//! Image encoding of rendered windows: PNG (deflate through zlib-rs or fdeflate, with the level,
//! row filter and, for material maps, grey or colour chosen by [`Effort`]), JPEG (quality 90), WebP (lossless). Settings are fixed so identical
//! pixels always give identical bytes with the pinned encoder versions (Cargo.lock); they are
//! part of the ETag version.

use std::io::Cursor;

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::codecs::webp::WebPEncoder;
use image::{ExtendedColorType, ImageEncoder, ImageError};

/// Version of the encoder settings (bump when they change).
pub const ENCODER_VERSION: u32 = 4;

/// Version of the material maps' encoding ([`Effort::Map`]), in their tiles' keys only: a change
/// of it changes the maps' ETags, not the colour's.
pub const MAP_ENCODER_VERSION: u32 = 2;

/// Output image formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// PNG.
    Png,
    /// Baseline JPEG.
    Jpeg,
    /// Lossless WebP.
    Webp,
}

impl Format {
    /// Parse a file extension (`png`, `jpg`, `jpeg`, `webp`).
    pub fn from_ext(ext: &str) -> Option<Format> {
        match ext {
            "png" => Some(Format::Png),
            "jpg" | "jpeg" => Some(Format::Jpeg),
            "webp" => Some(Format::Webp),
            _ => None,
        }
    }
    /// MIME type.
    pub fn content_type(self) -> &'static str {
        match self {
            Format::Png => "image/png",
            Format::Jpeg => "image/jpeg",
            Format::Webp => "image/webp",
        }
    }
    /// Canonical extension.
    pub fn ext(self) -> &'static str {
        match self {
            Format::Png => "png",
            Format::Jpeg => "jpg",
            Format::Webp => "webp",
        }
    }
}

/// How hard PNG compression works. Measured on 256² gravel tiles (synth / mosaic) through
/// zlib-rs: level 4 gives 83 / 71 KiB in 1.7 / 1.5 ms, level 1 gives 113 / 102 KiB in 0.8 / 0.7 ms
/// (the former miniz_oxide level 2: 84 / 80 KiB in 1.5 ms; fdeflate's "fast": 190 KiB in 0.2 ms,
/// it barely compresses noisy texture). Row filters: on mosaic tiles (blocks of exemplar pixels
/// with smoothed seams) Paeth makes level 1 both faster and smaller (gravel 0.75 → 0.66 ms,
/// 96.9 → 90.9 KiB; grass 0.93 → 0.84 ms, 98.6 → 96.4 KiB); on synthesized gravel every filter
/// made level 4 slower and larger, so synthesized tiles stay unfiltered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Effort {
    /// Smaller files: for synthesized tiles, whose ~10 ms synthesis dwarfs the encoding.
    Tight,
    /// Faster encoding: for mosaic tiles, computed in 0.4 ms, where encoding dominates.
    Quick,
    /// Fastest, for material maps, whose second map of a tile costs lookups and encoding only:
    /// fdeflate with the Paeth filter, and a grey map (every pixel r = g = b: height, specular,
    /// ao…) as an 8-bit grey PNG. Measured on 256² flagstones map tiles against Quick: normal
    /// 2.43 → 0.61 ms and 184 → 145 KiB (smooth normals suit fdeflate); height 2.34 → 0.28 ms and
    /// 155 → 64 KiB, specular 2.28 → 0.22 ms and 130 → 64 KiB.
    Map,
}

/// Encode RGB8 pixels. The result holds no spare capacity: the tile cache counts a tile by its
/// length, and an encoder's output buffer grows by doubling (up to twice the length held).
pub fn encode(rgb: &[u8], w: u32, h: u32, fmt: Format, effort: Effort) -> Result<Vec<u8>, ImageError> {
    let mut out = encode_into_vec(rgb, w, h, fmt, effort)?;
    out.shrink_to_fit();
    Ok(out)
}

fn encode_into_vec(rgb: &[u8], w: u32, h: u32, fmt: Format, effort: Effort) -> Result<Vec<u8>, ImageError> {
    match fmt {
        Format::Png => png(rgb, w, h, effort),
        Format::Jpeg => {
            let mut out = Vec::new();
            JpegEncoder::new_with_quality(&mut out, 90).write_image(rgb, w, h, ExtendedColorType::Rgb8)?;
            Ok(out)
        }
        Format::Webp => {
            let mut out = Vec::new();
            WebPEncoder::new_lossless(&mut out).write_image(rgb, w, h, ExtendedColorType::Rgb8)?;
            Ok(out)
        }
    }
}

/// Encode RGB8 pixels as PNG with the fixed settings of an effort: Tight is level 4 unfiltered
/// (synthesized texture repeats exemplar texels, which deflate finds unfiltered), Quick is
/// level 1 with the Paeth filter, Map is fdeflate with the Paeth filter, grey when the pixels are.
fn png(rgb: &[u8], w: u32, h: u32, effort: Effort) -> Result<Vec<u8>, ImageError> {
    let (compression, filter) = match effort {
        Effort::Tight => (CompressionType::Level(4), FilterType::NoFilter),
        Effort::Quick => (CompressionType::Level(1), FilterType::Paeth),
        Effort::Map => (CompressionType::Fast, FilterType::Paeth),
    };
    let mut out = Cursor::new(Vec::new());
    let encoder = PngEncoder::new_with_quality(&mut out, compression, filter);
    let grey = effort == Effort::Map && rgb.chunks_exact(3).all(|p| p[0] == p[1] && p[1] == p[2]);
    if grey {
        let l: Vec<u8> = rgb.chunks_exact(3).map(|p| p[0]).collect();
        encoder.write_image(&l, w, h, ExtendedColorType::L8)?;
    } else {
        encoder.write_image(rgb, w, h, ExtendedColorType::Rgb8)?;
    }
    Ok(out.into_inner())
}

/// `map=uv` as a 16-bit RGB PNG: R = u, G = v in `1/UV_SCALE` exemplar texel, B = 0 (the
/// encoder takes native-endian samples and writes them big-endian, as PNG stores them);
/// fdeflate with the Paeth filter, as [`Effort::Map`].
pub fn png_uv(uv: &textile_core::maps::UvWindow) -> Result<Vec<u8>, ImageError> {
    let mut bytes = vec![0u8; 6 * uv.uv.len()];
    for (px, [u, v]) in bytes.chunks_exact_mut(6).zip(&uv.uv) {
        px[..2].copy_from_slice(&u.to_ne_bytes());
        px[2..4].copy_from_slice(&v.to_ne_bytes());
    }
    let mut out = Cursor::new(Vec::new());
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Paeth).write_image(
        &bytes,
        uv.width,
        uv.height,
        ExtendedColorType::Rgb16,
    )?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoded_tiles_hold_no_spare_capacity_and_decode_to_their_pixels() {
        // The tile cache bounds its memory by the sum of lengths: capacity must equal length.
        let rgb: Vec<u8> = (0..256 * 256 * 3u32).map(|i| ((i * 7919) >> 5) as u8).collect();
        for fmt in [Format::Png, Format::Jpeg, Format::Webp] {
            for effort in [Effort::Tight, Effort::Quick, Effort::Map] {
                let out = encode(&rgb, 256, 256, fmt, effort).unwrap();
                assert_eq!(out.capacity(), out.len(), "{fmt:?} {effort:?}");
                let img = image::load_from_memory(&out).unwrap().to_rgb8();
                assert_eq!(img.dimensions(), (256, 256));
                if fmt != Format::Jpeg {
                    assert_eq!(img.into_raw(), rgb, "{fmt:?} {effort:?} is lossless");
                }
            }
        }
        // A grey map is a grey PNG with the same pixels.
        let grey: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[1]; 3]).collect();
        let out = encode(&grey, 256, 256, Format::Png, Effort::Map).unwrap();
        let img = image::load_from_memory(&out).unwrap();
        assert_eq!(img.color(), image::ColorType::L8);
        assert_eq!(img.to_rgb8().into_raw(), grey);
    }
}
