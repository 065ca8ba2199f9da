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
pub const ENCODER_VERSION: u32 = 6;

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

/// How hard PNG compression works. Synthesized (Tight) and mosaic (Quick) tiles are deflated in
/// parallel parts ([`png_parts`]): on two cores a 256² gravel tile 2.3 → 1.3 ms (84 KiB either
/// way), a mosaic one 1.04 → 0.69 ms (106 → 105 KiB).
/// Measured on 256² gravel tiles (synth / mosaic), one stream, through
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
/// level 1 with the Paeth filter, both in parallel parts ([`png_parts`]); Map is fdeflate with
/// the Paeth filter, grey when the pixels are.
fn png(rgb: &[u8], w: u32, h: u32, effort: Effort) -> Result<Vec<u8>, ImageError> {
    match effort {
        Effort::Tight => return png_parts(rgb, w, h, TIGHT_LEVEL, RowFilter::None),
        Effort::Quick => return png_parts(rgb, w, h, QUICK_LEVEL, RowFilter::Paeth),
        Effort::Map => {}
    }
    let mut out = Cursor::new(Vec::new());
    let encoder = PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Paeth);
    if rgb.chunks_exact(3).all(|p| p[0] == p[1] && p[1] == p[2]) {
        let l: Vec<u8> = rgb.chunks_exact(3).map(|p| p[0]).collect();
        encoder.write_image(&l, w, h, ExtendedColorType::L8)?;
    } else {
        encoder.write_image(rgb, w, h, ExtendedColorType::Rgb8)?;
    }
    Ok(out.into_inner())
}

/// Rows of image data deflated as one part by [`png_parts`].
const PART_ROWS: u32 = 64;
/// Deflate's window: each part is primed with this much of the data before it.
const WINDOW: usize = 32 * 1024;
/// The deflate level of [`Effort::Tight`].
const TIGHT_LEVEL: u32 = 4;
/// The deflate level of [`Effort::Quick`].
const QUICK_LEVEL: u32 = 1;

/// The PNG row filter [`png_parts`] applies to every row (PNG filter method 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RowFilter {
    /// Type 0: the row as it is.
    None,
    /// Type 4: each byte less the Paeth predictor of its left, upper and upper-left bytes.
    Paeth,
}

impl RowFilter {
    /// Write `row`'s filter type byte and its filtered bytes to `out` (one byte longer than
    /// `row`); `prev` is the row above (`None` for the first, whose upper bytes count as 0).
    fn write(self, prev: Option<&[u8]>, row: &[u8], out: &mut [u8]) {
        let (kind, out) = out.split_at_mut(1);
        match self {
            RowFilter::None => {
                kind[0] = 0;
                out.copy_from_slice(row);
            }
            RowFilter::Paeth => {
                kind[0] = 4;
                let zeros;
                let up = match prev {
                    Some(p) => p,
                    None => {
                        zeros = vec![0; row.len()];
                        &zeros
                    }
                };
                // The first pixel has no left neighbours: its predictor is the byte above.
                let first = row.len().min(3);
                for ((o, &x), &b) in out.iter_mut().zip(&row[..first]).zip(up) {
                    *o = x.wrapping_sub(b);
                }
                // The others: x, a (left), b (above), c (upper left), as four aligned slices.
                let (x, a) = (&row[first..], &row[..row.len() - first]);
                let (b, c) = (&up[first..], &up[..row.len() - first]);
                let predicted = a.iter().zip(b).zip(c).map(|((&a, &b), &c)| paeth(a, b, c));
                for ((o, &x), p) in out[first..].iter_mut().zip(x).zip(predicted) {
                    *o = x.wrapping_sub(p);
                }
            }
        }
    }
}

/// The Paeth predictor (PNG specification, section 9.4): of left `a`, above `b` and upper-left
/// `c`, the one closest to `a + b − c`, ties going to `a`, then `b`.
fn paeth(a: u8, b: u8, c: u8) -> u8 {
    let (ia, ib, ic) = (i16::from(a), i16::from(b), i16::from(c));
    let pa = (ib - ic).abs();
    let pb = (ia - ic).abs();
    let pc = (ia + ib - 2 * ic).abs();
    if pa <= pb && pa <= pc {
        a
    } else if pb <= pc {
        b
    } else {
        c
    }
}

/// RGB8 with one row filter, its image data deflated at `level` in parts of [`PART_ROWS`] rows
/// at once on the pool's threads — each part a run of deflate blocks ended by a sync flush (the
/// last by the final block), so that their concatenation is one zlib stream, and primed with the
/// 32 KiB of data before it, the window a decoder then holds (pigz's scheme): a part refers back
/// across its start as one stream would. The parts depend on the image's size only: the same
/// bytes whatever the thread count. A 256² synthesized tile at level 4: four parts, about half
/// the time of one stream on two cores, for the same size (81 089 → 81 121 bytes on a gravel
/// tile; bench/README.md). The png crate filters rows only inside its own single stream, hence
/// the filter here.
fn png_parts(rgb: &[u8], w: u32, h: u32, level: u32, filter: RowFilter) -> Result<Vec<u8>, ImageError> {
    use flate2::{Compress, Compression, FlushCompress, Status};
    use rayon::prelude::*;
    let stride = 3 * w as usize;
    if w == 0 || h == 0 || rgb.len() != stride * h as usize {
        return Err(ImageError::Parameter(image::error::ParameterError::from_kind(
            image::error::ParameterErrorKind::DimensionMismatch,
        )));
    }
    // The image data: each row's filter type, then the filtered row (bands filtered in
    // parallel, each in its place).
    let (band, line) = (stride * PART_ROWS as usize, stride + 1);
    let part = line * PART_ROWS as usize;
    let mut raw = vec![0u8; line * h as usize];
    raw.par_chunks_mut(part).zip(rgb.par_chunks(band)).enumerate().for_each(|(i, (out, rows))| {
        let mut prev = (i > 0).then(|| &rgb[i * band - stride..i * band]);
        for (o, row) in out.chunks_exact_mut(line).zip(rows.chunks_exact(stride)) {
            filter.write(prev, row, o);
            prev = Some(row);
        }
    });
    let starts: Vec<usize> = (0..raw.len()).step_by(part).collect();
    let parts: Vec<Result<Vec<u8>, flate2::CompressError>> = starts
        .par_iter()
        .map(|&start| {
            let end = (start + part).min(raw.len());
            let last = end == raw.len();
            let flush = if last { FlushCompress::Finish } else { FlushCompress::Sync };
            let mut z = Compress::new(Compression::new(level), false);
            // What a decoder holds in its window when it reaches this part (as pigz does).
            if start > 0 {
                z.set_dictionary(&raw[start.saturating_sub(WINDOW)..start])?;
            }
            let input = &raw[start..end];
            let mut out = Vec::with_capacity(input.len() / 2 + 1024);
            loop {
                if out.len() == out.capacity() {
                    out.reserve(input.len() / 4 + 1024);
                }
                let status = z.compress_vec(&input[z.total_in() as usize..], &mut out, flush)?;
                let consumed = z.total_in() as usize == input.len();
                // Done once the input is in and the flush fitted (room was left over).
                if (last && status == Status::StreamEnd) || (!last && consumed && out.len() < out.capacity()) {
                    return Ok(out);
                }
            }
        })
        .collect();
    // The zlib header (deflate, 32 KiB window; FLEVEL 1: a fast level), the parts, Adler-32.
    let mut zlib = vec![0x78, 0x5E];
    for part in parts {
        zlib.extend_from_slice(&part.map_err(encoding_error)?);
    }
    zlib.extend_from_slice(&simd_adler32::adler32(&raw.as_slice()).to_be_bytes());
    let mut out = Vec::with_capacity(zlib.len() + 64);
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header().map_err(encoding_error)?;
    writer.write_chunk(png::chunk::IDAT, &zlib).map_err(encoding_error)?;
    writer.finish().map_err(encoding_error)?;
    Ok(out)
}

/// A PNG encoding failure as the image crate reports one.
fn encoding_error(e: impl std::fmt::Display) -> ImageError {
    ImageError::Encoding(image::error::EncodingError::new(
        image::error::ImageFormatHint::Exact(image::ImageFormat::Png),
        e.to_string(),
    ))
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

    #[test]
    fn pngs_deflated_in_parts_are_one_valid_stream_whatever_the_threads() {
        // Texture-like data with long repeats (as synthesized tiles copy exemplar texels), at
        // sizes with no, one, several and a ragged last part.
        let exemplar: Vec<u8> = (0..97 * 3u32).map(|i| ((i * 7919) >> 3) as u8).collect();
        // Size allowed beyond one stream, in percent: level 1 loses a little more at each
        // part's flush (300×131: 14 871 bytes against 14 423; a 256² mosaic tile: the same).
        for (effort, level, filter, row_filter, slack) in [
            (Effort::Tight, 4, FilterType::NoFilter, RowFilter::None, 1),
            (Effort::Quick, 1, FilterType::Paeth, RowFilter::Paeth, 4),
        ] {
            for (w, h) in [(1, 1), (5, 63), (256, 64), (300, 131), (256, 256)] {
                let rgb: Vec<u8> = (0..w * h * 3)
                    .map(|i| exemplar[(i as usize * 5 / 3 + i as usize / 700) % exemplar.len()])
                    .collect();
                let pool = |n| rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
                let one = pool(1).install(|| encode(&rgb, w, h, Format::Png, effort).unwrap());
                let four = pool(4).install(|| encode(&rgb, w, h, Format::Png, effort).unwrap());
                assert_eq!(one, four, "{effort:?} {w}×{h}: the same bytes on 1 and 4 threads");
                let img = image::load_from_memory(&one).unwrap().to_rgb8();
                assert_eq!((img.dimensions(), img.into_raw()), ((w, h), rgb.clone()), "{effort:?} {w}×{h}");
                // The image data as zlib itself reads it (the png decoder skips the Adler-32).
                let (mut at, mut idat) = (8, Vec::new());
                while at + 12 <= one.len() {
                    let n = u32::from_be_bytes(one[at..at + 4].try_into().unwrap()) as usize;
                    if &one[at + 4..at + 8] == b"IDAT" {
                        idat.extend_from_slice(&one[at + 8..at + 8 + n]);
                    }
                    at += 12 + n;
                }
                let mut raw = Vec::new();
                std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&idat[..]), &mut raw).unwrap();
                let stride = 3 * w as usize;
                let mut rows = vec![0u8; (stride + 1) * h as usize];
                let mut prev = None;
                for (o, row) in rows.chunks_exact_mut(stride + 1).zip(rgb.chunks_exact(stride)) {
                    row_filter.write(prev, row, o);
                    prev = Some(row);
                }
                assert_eq!(raw, rows, "{effort:?} {w}×{h}: one zlib stream, checksum and all");
                // Priming each part with the window before it keeps the size of one stream, and
                // the filter is the png crate's (same size within the parts' flushes).
                let mut single = Cursor::new(Vec::new());
                PngEncoder::new_with_quality(&mut single, CompressionType::Level(level), filter)
                    .write_image(&rgb, w, h, ExtendedColorType::Rgb8)
                    .unwrap();
                let single = single.into_inner().len();
                assert!(
                    one.len() * 100 <= single * (100 + slack) + 100,
                    "{effort:?} {w}×{h}: {} bytes against {single} in one stream",
                    one.len()
                );
            }
        }
    }

    #[test]
    fn paeth_rows_match_the_png_crate_filter() {
        // A Quick PNG's rows, unfiltered by the png crate's decoder, are the pixels (checked
        // above); here the filter bytes themselves on edge cases: zeros, saturation, ties.
        for (a, b, c, want) in
            [(0, 0, 0, 0), (10, 20, 10, 20), (20, 10, 10, 20), (255, 0, 255, 0), (5, 5, 5, 5), (0, 255, 128, 128)]
        {
            let p = i16::from(a) + i16::from(b) - i16::from(c);
            let best = [a, b, c].into_iter().min_by_key(|&v| (p - i16::from(v)).abs()).unwrap();
            assert_eq!(paeth(a, b, c), best, "{a} {b} {c}");
            assert_eq!(paeth(a, b, c), want, "{a} {b} {c}");
        }
    }
}
