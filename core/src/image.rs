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
    let mut decoder = r.into_decoder()?;
    let orientation = decoder.orientation()?;
    let mut img = DynamicImage::from_decoder(decoder)?;
    img.apply_orientation(orientation);
    Ok(img)
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

    /// An image of `side × side` pixels from row-major RGB texels.
    pub fn from_texels(side: u32, texels: &[[u8; 3]]) -> Self {
        RgbWindow { width: side, height: side, pixels: texels.iter().flatten().copied().collect() }
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

/// An `n × n` exemplar box-filtered `lvl` times (side `n >> lvl`).
pub fn box_mip(texels: &[[u8; 3]], n: usize, lvl: usize) -> Vec<[u8; 3]> {
    RgbWindow::from_texels(n as u32, texels).box_down(1 << lvl).texels()
}

/// Sums of an `n × n` exemplar's texels over `f × f` boxes anywhere on its torus, from an
/// integral image of the exemplar extended by `f` texels right and down (wrapping).
pub(crate) struct Integral {
    /// Side of the exemplar (a power of two).
    n: usize,
    /// Box side (a power of two, at most `n`).
    f: usize,
    /// `(n + f + 1)²` prefix sums per channel: entry `(x, y)` sums the texels left of and
    /// above it.
    sums: Vec<[u32; 3]>,
}

impl Integral {
    pub(crate) fn new(texels: &[[u8; 3]], n: usize, f: usize) -> Integral {
        debug_assert!(n.is_power_of_two() && f.is_power_of_two() && f <= n);
        let s = n + f + 1;
        let mut sums = vec![[0u32; 3]; s * s];
        for y in 1..s {
            for x in 1..s {
                let t = texels[((y - 1) & (n - 1)) * n + ((x - 1) & (n - 1))];
                let (l, u, d) = (sums[y * s + x - 1], sums[(y - 1) * s + x], sums[(y - 1) * s + x - 1]);
                sums[y * s + x] = std::array::from_fn(|c| t[c] as u32 + l[c] + u[c] - d[c]);
            }
        }
        Integral { n, f, sums }
    }

    /// The mean (rounded to nearest) of the `f × f` texels centred on texel `(x, y)` (from
    /// `f/2` before it to `f/2 − 1` after), on the torus.
    pub(crate) fn mean_around(&self, x: usize, y: usize) -> [u8; 3] {
        let (n, f, s) = (self.n, self.f, self.n + self.f + 1);
        let (x0, y0) = ((x + n - f / 2) & (n - 1), (y + n - f / 2) & (n - 1));
        let at = |x: usize, y: usize| self.sums[y * s + x];
        let (a, b, c, d) = (at(x0, y0), at(x0 + f, y0), at(x0, y0 + f), at(x0 + f, y0 + f));
        // `f` is a power of two: dividing by the area is a shift.
        let shift = 2 * f.trailing_zeros();
        std::array::from_fn(|k| ((d[k] + a[k] - b[k] - c[k] + (1 << shift >> 1)) >> shift) as u8)
    }
}

/// The centred box means of an `n × n` exemplar at every scale: entry `k` (`0..=log2 n`) holds,
/// for each texel, the mean of the `2^k × 2^k` texels centred on it on the torus (see
/// [`Integral::mean_around`]). A zoomed-out pixel whose native texels are the exemplar's block
/// around one coordinate shows exactly this colour.
pub fn box_stack(texels: &[[u8; 3]], n: usize) -> Vec<Vec<[u8; 3]>> {
    let levels = n.trailing_zeros() as usize;
    (0..=levels)
        .map(|k| {
            let sums = Integral::new(texels, n, 1 << k);
            (0..n * n).map(|i| sums.mean_around(i % n, i / n)).collect()
        })
        .collect()
}
