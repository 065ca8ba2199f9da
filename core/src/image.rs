//! Images as the modes produce them: an RGB8 window, what rendering it cost, and the exact box
//! filter that zoomed-out views of cheap modes are made with; and the bounded decoding of
//! images given to us (exemplars, hand-made umbrella images).

use std::io::Cursor;

use image::{DynamicImage, ImageDecoder, ImageReader, ImageResult, Limits};

/// A reader of encoded image bytes, its format guessed from them.
pub fn reader(bytes: &[u8]) -> ImageResult<ImageReader<Cursor<&[u8]>>> {
    Ok(ImageReader::new(Cursor::new(bytes)).with_guessed_format()?)
}

/// Decode encoded image bytes whose header size the caller has already checked, refusing any
/// axis over `max_side` and more than `max_alloc` bytes of allocation while decoding, and turned
/// upright as its EXIF orientation says (a phone's JPEG is stored sideways with a tag that says
/// so; the image a viewer shows is the one meant).
pub fn decode_within(bytes: &[u8], max_side: u32, max_alloc: u64) -> ImageResult<DynamicImage> {
    let mut r = reader(bytes)?;
    let mut limits = Limits::default();
    limits.max_image_width = Some(max_side);
    limits.max_image_height = Some(max_side);
    limits.max_alloc = Some(max_alloc);
    r.limits(limits);
    if r.format() == Some(image::ImageFormat::Jpeg) {
        jpeg_whole(bytes, max_side).map_err(|message| {
            image::ImageError::Decoding(image::error::DecodingError::new(
                image::ImageFormat::Jpeg.into(),
                format!("{message}: the JPEG is truncated or its header claims more than its data holds"),
            ))
        })?;
    }
    let mut decoder = r.into_decoder()?;
    let orientation = decoder.orientation()?;
    let mut img = DynamicImage::from_decoder(decoder)?;
    img.apply_orientation(orientation);
    Ok(img)
}

/// Whether a JPEG's data covers its whole image. The image crate's decoder fills what is
/// missing (a truncated file's lower part, or all but the first rows of a file whose header
/// claims a larger size) and succeeds; its strict mode says when the data runs out. A
/// sequential JPEG is checked without its end marker, so that running out of coded data before
/// the last block is an error rather than a fill; a progressive one needs its end marker to end
/// its scans, and its refinement scans fail on data that does not fit the size it claims.
fn jpeg_whole(bytes: &[u8], max_side: u32) -> Result<(), String> {
    use zune_core::options::DecoderOptions;
    use zune_jpeg::errors::DecodeErrors;
    use zune_jpeg::JpegDecoder;
    let options = DecoderOptions::default()
        .set_strict_mode(true)
        .set_max_width(max_side as usize)
        .set_max_height(max_side as usize);
    let decode = |data: &[u8]| -> Result<(), DecodeErrors> {
        JpegDecoder::new_with_options(Cursor::new(data), options).decode().map(drop)
    };
    let mut headers = JpegDecoder::new_with_options(Cursor::new(bytes), options);
    headers.decode_headers().map_err(|e| e.to_string())?;
    let progressive = headers.info().is_some_and(|i| i.sof.is_progressive());
    let end = if progressive {
        bytes.len()
    } else {
        bytes.windows(2).rposition(|w| w == [0xFF, 0xD9]).unwrap_or(bytes.len())
    };
    decode(&bytes[..end]).map_err(|e| e.to_string())
}

/// An RGB8 image of a window.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbWindow {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB bytes (`3·width·height`).
    pub pixels: Vec<u8>,
}

impl RgbWindow {
    /// The pixel at `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let i = 3 * (y as usize * self.width as usize + x as usize);
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }

    /// An image of `width × height` pixels from row-major RGB texels.
    pub fn from_texels((width, height): (u32, u32), texels: &[[u8; 3]]) -> Self {
        RgbWindow { width, height, pixels: texels.iter().flatten().copied().collect() }
    }

    /// The exact box average over `f × f` blocks (rounded to nearest); width and height must be
    /// multiples of `f`.
    pub fn box_down(&self, f: usize) -> RgbWindow {
        let (w, h) = (self.width as usize / f, self.height as usize / f);
        let iw = self.width as usize;
        let area = (f * f) as u32;
        let mut pixels = Vec::with_capacity(3 * w * h);
        for j in 0..h {
            for i in 0..w {
                let mut s = [0u32; 3];
                for y in j * f..(j + 1) * f {
                    let row = &self.pixels[3 * (y * iw + i * f)..3 * (y * iw + (i + 1) * f)];
                    for px in row.chunks_exact(3) {
                        for (acc, &v) in s.iter_mut().zip(px) {
                            *acc += v as u32;
                        }
                    }
                }
                pixels.extend(s.map(|v| ((v + area / 2) / area) as u8));
            }
        }
        RgbWindow { width: w as u32, height: h as u32, pixels }
    }

    /// The texels of this image, row-major.
    pub fn texels(&self) -> Vec<[u8; 3]> {
        self.pixels.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
    }
}

/// A rendered window and the work it took.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rendered {
    /// The image.
    pub image: RgbWindow,
    /// Pixels computed for it at all levels (padding included; what a cache supplied is not
    /// counted): the numerator of the computation ratio.
    pub synthesized: u64,
}

/// The mean colour of `texels` (rounded to nearest).
pub fn mean_colour(texels: &[[u8; 3]]) -> [u8; 3] {
    let n = texels.len().max(1) as u64;
    let mut sum = [0u64; 3];
    for t in texels {
        for c in 0..3 {
            sum[c] += t[c] as u64;
        }
    }
    sum.map(|v| ((v + n / 2) / n) as u8)
}

/// A `w × h` exemplar box-filtered `lvl` times (size `(w >> lvl) × (h >> lvl)`).
pub fn box_mip(texels: &[[u8; 3]], (w, h): (usize, usize), lvl: usize) -> Vec<[u8; 3]> {
    RgbWindow::from_texels((w as u32, h as u32), texels).box_down(1 << lvl).texels()
}

/// Sums of a `w × h` exemplar's texels over `f × f` boxes anywhere on its torus, from an
/// integral image of the exemplar extended by `f` texels right and down (wrapping).
pub(crate) struct Integral {
    /// Size of the exemplar.
    w: usize,
    h: usize,
    /// Box side (a power of two; it may exceed the exemplar, whose texels then repeat).
    f: usize,
    /// `(w + f + 1) × (h + f + 1)` prefix sums per channel: entry `(x, y)` sums the texels
    /// left of and above it.
    sums: Vec<[u32; 3]>,
}

impl Integral {
    pub(crate) fn new(texels: &[[u8; 3]], (w, h): (usize, usize), f: usize) -> Integral {
        debug_assert!(f.is_power_of_two());
        let (sw, sh) = (w + f + 1, h + f + 1);
        let mut sums = vec![[0u32; 3]; sw * sh];
        for y in 1..sh {
            for x in 1..sw {
                let t = texels[((y - 1) % h) * w + (x - 1) % w];
                let (l, u, d) = (sums[y * sw + x - 1], sums[(y - 1) * sw + x], sums[(y - 1) * sw + x - 1]);
                sums[y * sw + x] = std::array::from_fn(|c| t[c] as u32 + l[c] + u[c] - d[c]);
            }
        }
        Integral { w, h, f, sums }
    }

    /// The mean (rounded to nearest) of the `f × f` texels centred on texel `(x, y)` (from
    /// `f/2` before it to `f/2 − 1` after), on the torus.
    pub(crate) fn mean_around(&self, x: usize, y: usize) -> [u8; 3] {
        let (f, sw) = (self.f, self.w + self.f + 1);
        let half = (f / 2) as i64;
        let (x0, y0) = (
            (x as i64 - half).rem_euclid(self.w as i64) as usize,
            (y as i64 - half).rem_euclid(self.h as i64) as usize,
        );
        let at = |x: usize, y: usize| self.sums[y * sw + x];
        let (a, b, c, d) = (at(x0, y0), at(x0 + f, y0), at(x0, y0 + f), at(x0 + f, y0 + f));
        // `f` is a power of two: dividing by the area is a shift.
        let shift = 2 * f.trailing_zeros();
        std::array::from_fn(|k| ((d[k] + a[k] - b[k] - c[k] + (1 << shift >> 1)) >> shift) as u8)
    }
}

/// The centred box means of a `w × h` exemplar at every scale: entry `k` (`0..=L`,
/// [`crate::geom::levels_for`]) holds, for each texel, the mean of the `2^k × 2^k` texels
/// centred on it on the torus (see [`Integral::mean_around`]). A zoomed-out pixel whose native
/// texels are the exemplar's block around one coordinate shows exactly this colour.
pub fn box_stack(texels: &[[u8; 3]], (w, h): (usize, usize)) -> Vec<Vec<[u8; 3]>> {
    let levels = crate::geom::levels_for(w as u32, h as u32) as usize;
    (0..=levels)
        .map(|k| {
            let sums = Integral::new(texels, (w, h), 1 << k);
            (0..w * h).map(|i| sums.mean_around(i % w, i / w)).collect()
        })
        .collect()
}
