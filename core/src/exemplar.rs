//! Exemplar preparation (design note §1.1): decode with bounded resources, composite alpha,
//! keep the image at its own width and height (only an image larger than [`MAX_SIDE`] is
//! shrunk, keeping its shape, with an exact integer area filter), and decide whether the
//! exemplar wraps around seamlessly (toroidal) at its own period.

use serde::{Deserialize, Serialize};

pub use crate::geom::{centred_square, levels_for};

use crate::error::{CoreError, Result};
use crate::lattice::{Lattice, LatticeChoice, Repeat};
use crate::maps::{MaterialMap, NormalConvention};
use crate::mask::RandomnessMask;

/// Smallest exemplar side accepted on input (and so the smallest prepared side).
pub const MIN_INPUT_SIDE: u32 = 16;
/// Largest prepared exemplar side: a larger image is scaled down to it, keeping its shape.
pub const MAX_SIDE: u32 = 512;

/// Least colour variation of a synthesizable exemplar: the standard deviation, in 8-bit levels,
/// of its most varied channel. Below it the image is flat (one colour, or noise of a level or
/// two): synthesis has nothing to arrange and only its analysis's ties to break.
pub const MIN_SPREAD: f64 = 2.0;

/// How an input image is accepted and prepared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ExemplarOptions {
    /// Largest accepted input side in pixels (default 1024); larger images are refused before
    /// their pixels are decoded.
    pub max_input_side: u32,
    /// Force the toroidal flag; `None` detects it from the wrap-around seam.
    pub toroidal: Option<bool>,
}

impl Default for ExemplarOptions {
    fn default() -> Self {
        ExemplarOptions { max_input_side: 1024, toroidal: None }
    }
}

/// What was done to the input to prepare it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Intake {
    /// Input width.
    pub input_width: u32,
    /// Input height.
    pub input_height: u32,
    /// Prepared width (the input's, unless it was scaled down to [`MAX_SIDE`]). Analyses
    /// written before exemplars kept their shape call it `side` (they were square).
    #[serde(alias = "side")]
    pub width: u32,
    /// Prepared height (0 in analyses written before exemplars kept their shape: the width).
    #[serde(default)]
    pub height: u32,
    /// Whether the toroidal flag was detected (false) or forced by the caller (true).
    pub toroidal_forced: bool,
    /// Seam energy ÷ interior gradient energy (≤ 1.5 means toroidal when detected).
    pub seam_ratio: f64,
    /// Whether the exemplar was remade toroidal by synthesis ([`crate::tileable::make_toroidal`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub toroidal_synthesized: bool,
}

/// A prepared exemplar: `width × height` RGB8 pixels, each side from [`MIN_INPUT_SIDE`] to
/// [`MAX_SIDE`].
#[derive(Debug, Clone, PartialEq)]
pub struct Exemplar {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB pixels.
    pub pixels: Vec<[u8; 3]>,
    /// Whether synthesis may wrap around the exemplar edges.
    pub toroidal: bool,
    /// What preparation did.
    pub preparation: Intake,
    /// The image the exemplar was reduced from, twice as wide and high, when it was given ([`Exemplar::from_hires`]): magnified zooms sample their detail from it.
    pub hires: Option<Vec<[u8; 3]>>,
    /// The randomness mask over the exemplar (`R_E`), when the texture has one
    /// ([`Exemplar::with_randomness_mask`]).
    pub randomness_mask: Option<RandomnessMask>,
    /// The colour variation of the image as it was given (before any resampling;
    /// [`Exemplar::spread`]), when it was resampled: flatness is judged on the
    /// image as sent, not on what shrinking made of it.
    pub input_spread: Option<f64>,
    /// The lattice of a near-regular exemplar ([`Exemplar::with_lattice`]).
    pub lattice: Option<Lattice>,
    /// The exact repeat of an exemplar that is a tile repeated (found with the lattice,
    /// [`Exemplar::with_lattice_choice`]): a texel's copies are never its second candidate.
    pub repeat: Option<Repeat>,
    /// What structure detection found ([`crate::lattice::Structure`]), for reports;
    /// `None` when it did not run (`lattice = "none"`).
    pub structure: Option<crate::lattice::Structure>,
    /// Its co-registered material maps ([`Exemplar::with_map`]); not part of
    /// [`Exemplar::hash_content`]: each map's tiles are keyed by the map's own hash.
    pub maps: Vec<MaterialMap>,
}

impl Exemplar {
    /// Decode and prepare an exemplar from encoded image bytes (PNG, JPEG, WebP, TGA, BMP).
    pub fn from_bytes(bytes: &[u8], opts: &ExemplarOptions) -> Result<Exemplar> {
        let reader = crate::image::reader(bytes).map_err(|e| CoreError::ExemplarUndecodable(e.to_string()))?;
        if reader.format().is_none() {
            return Err(CoreError::ExemplarUndecodable(
                "unrecognised image format (expected PNG, JPEG, WebP, TGA or BMP)".into(),
            ));
        }
        let (w, h) = reader.into_dimensions().map_err(|e| CoreError::ExemplarUndecodable(e.to_string()))?;
        check_size(w, h, opts.max_input_side)?;
        let img = crate::image::decode_within(bytes, opts.max_input_side, 256 << 20)
            .map_err(|e| CoreError::ExemplarUndecodable(e.to_string()))?;
        let rgba = img.to_rgba8();
        let (w, h) = rgba.dimensions();
        let px: Vec<[u8; 4]> = rgba.pixels().map(|p| p.0).collect();
        Ok(Self::from_rgba(w, h, &px, opts))
    }

    /// Prepare an exemplar from raw RGBA pixels (row-major, `w × h`). The size must already be
    /// valid (see [`Exemplar::from_bytes`]).
    pub fn from_rgba(w: u32, h: u32, px: &[[u8; 4]], opts: &ExemplarOptions) -> Exemplar {
        let rgb = composite_over_mean(px);
        let (width, height) = prepared_size(w, h);
        let input_spread = ((width, height) != (w, h)).then(|| spread_of(&rgb));
        let pixels = if (width, height) == (w, h) {
            rgb
        } else {
            area_resample(&rgb, (w as usize, h as usize), (width as usize, height as usize))
        };
        let seam_ratio = seam_ratio(&pixels, width as usize, height as usize);
        let toroidal = opts.toroidal.unwrap_or(seam_ratio <= 1.5);
        Exemplar {
            width,
            height,
            pixels,
            toroidal,
            preparation: Intake {
                input_width: w,
                input_height: h,
                width,
                height,
                toroidal_forced: opts.toroidal.is_some(),
                seam_ratio,
                toroidal_synthesized: false,
            },
            hires: None,
            randomness_mask: None,
            input_spread,
            lattice: None,
            repeat: None,
            structure: None,
            maps: Vec::new(),
        }
    }

    /// Synthesis levels of this exemplar ([`levels_for`]).
    pub fn levels(&self) -> u32 {
        self.size().levels()
    }

    /// Its size ([`crate::geom::Size`]: longer side, levels).
    pub fn size(&self) -> crate::geom::Size {
        crate::geom::Size::new(self.width, self.height)
    }

    /// Its size as `(width, height)` in `usize`, for indexing.
    pub fn dims(&self) -> (usize, usize) {
        (self.width as usize, self.height as usize)
    }

    /// The colour variation of the prepared pixels: the standard deviation, in 8-bit levels,
    /// of the most varied channel.
    pub fn spread(&self) -> f64 {
        spread_of(&self.pixels)
    }

    /// Refuse a flat exemplar ([`MIN_SPREAD`]): [`CoreError::FlatExemplar`]. Judged on the
    /// image as it was given where it was resampled (a 1-px checkerboard larger than the
    /// largest side shrinks to grey, but was not sent flat).
    pub fn check_not_flat(&self) -> Result<()> {
        let spread = self.spread().max(self.input_spread.unwrap_or(0.0));
        if spread < MIN_SPREAD {
            return Err(CoreError::FlatExemplar { spread, min: MIN_SPREAD });
        }
        Ok(())
    }

    /// Feed everything that determines this exemplar's pixels in every mode to `h`: size (the
    /// width alone for a square, as when exemplars were all square), toroidal flag, pixels, and its randomness mask, lattice and high-resolution image when it has them
    /// (only then, so the hashes of exemplars without them never change).
    pub fn hash_content(&self, h: &mut blake3::Hasher) {
        h.update(&self.width.to_le_bytes());
        if self.height != self.width {
            h.update(b"height");
            h.update(&self.height.to_le_bytes());
        }
        h.update(&[self.toroidal as u8]);
        // One update for all the pixels (the same bytes as one per pixel, hashed faster).
        h.update(self.pixels.as_flattened());
        if let Some(mask) = &self.randomness_mask {
            h.update(b"randomness-mask");
            h.update(mask.hash.as_bytes());
        }
        if let Some(l) = &self.lattice {
            l.hash_into(h);
        }
        if let Some(r) = &self.repeat {
            r.hash_into(h);
        }
        if let Some(hires) = &self.hires {
            h.update(b"hires");
            h.update(hires.as_flattened());
        }
    }

    /// The exemplar of a high-resolution image: `hires` (prepared, `2w × 2h`; an odd last row
    /// or column is dropped) reduced by the exact 2×2 box average to `w × h`, keeping `hires`
    /// for magnified zooms (design note §1.8: magnified tiles then show the image's own
    /// detail, not interpolation). The toroidal flag is `hires`'s when forced, else detected on
    /// the reduced exemplar.
    pub fn from_hires(hires: Exemplar) -> Result<Exemplar> {
        let (big_w, big_h) = (hires.width, hires.height);
        if big_w.min(big_h) < 2 * MIN_INPUT_SIDE {
            return Err(CoreError::ExemplarSize {
                width: big_w,
                height: big_h,
                min: 2 * MIN_INPUT_SIDE,
                max: MAX_SIDE,
            });
        }
        let (width, height) = (big_w / 2, big_h / 2);
        let (big, pixels) = halve(&hires.pixels, (big_w, big_h));
        let seam_ratio = seam_ratio(&pixels, width as usize, height as usize);
        let forced = hires.preparation.toroidal_forced;
        let toroidal = if forced { hires.toroidal } else { seam_ratio <= 1.5 };
        let preparation = Intake { width, height, seam_ratio, ..hires.preparation };
        Ok(Exemplar {
            width,
            height,
            pixels,
            toroidal,
            preparation,
            hires: Some(big),
            randomness_mask: None,
            input_spread: hires.input_spread,
            lattice: None,
            repeat: None,
            structure: None,
            maps: Vec::new(),
        })
    }

    /// This exemplar with a randomness mask (design note §1.9, `R_E`): `mask` is the mask
    /// image prepared like the exemplar's own image (same input size, so the same
    /// resampling; for an exemplar reduced from `exemplar_hires`, the size of that image), its
    /// luma the mask values (white: free, black: kept as in the exemplar).
    pub fn with_randomness_mask(mut self, mask: &Exemplar) -> Result<Exemplar> {
        let (p, q) = (&self.preparation, &mask.preparation);
        if (p.input_width, p.input_height) != (q.input_width, q.input_height) {
            return Err(CoreError::Param {
                name: "randomness_mask",
                message: format!(
                    "is {}x{}; it must be the size of the exemplar image, {}x{}",
                    q.input_width, q.input_height, p.input_width, p.input_height
                ),
            });
        }
        let pixels = if mask.dims() == self.dims() {
            mask.pixels.clone()
        } else {
            area_resample(&mask.pixels, mask.dims(), self.dims())
        };
        let luma = pixels
            .iter()
            .map(|c| ((299 * c[0] as u32 + 587 * c[1] as u32 + 114 * c[2] as u32 + 500) / 1000) as u8)
            .collect();
        self.randomness_mask = Some(RandomnessMask::new(self.width, self.height, luma, self.toroidal)?);
        Ok(self)
    }

    /// This exemplar with material map `name` ([`MaterialMap::new`]): `image` is the map
    /// prepared like the exemplar's own image (same input size, hence the same
    /// resampling; for an exemplar reduced from a high-resolution image, that image's size). A
    /// map of the same name is replaced.
    pub fn with_map(mut self, name: &str, image: &Exemplar, convention: Option<NormalConvention>) -> Result<Exemplar> {
        let (p, q) = (&self.preparation, &image.preparation);
        if (p.input_width, p.input_height) != (q.input_width, q.input_height) {
            return Err(CoreError::Map {
                name: name.to_string(),
                message: format!(
                    "is {}x{}; it must be the size of the exemplar image, {}x{}",
                    q.input_width, q.input_height, p.input_width, p.input_height
                ),
            });
        }
        let (texels, hires) = match &self.hires {
            Some(_) => {
                let (big, reduced) = halve(&image.pixels, (image.width, image.height));
                (reduced, Some(big))
            }
            None => (image.pixels.clone(), None),
        };
        if texels.len() != self.pixels.len() {
            return Err(CoreError::Map {
                name: name.to_string(),
                message: format!("prepares to {} texels, the exemplar to {}", texels.len(), self.pixels.len()),
            });
        }
        let map = MaterialMap::new(name, (self.width, self.height), texels, hires, convention)?;
        self.maps.retain(|m| m.name != name);
        self.maps.push(map);
        Ok(self)
    }

    /// The material map called `name`.
    pub fn map(&self, name: &str) -> Option<&MaterialMap> {
        self.maps.iter().find(|m| m.name == name)
    }

    /// This exemplar as a near-regular one (design note §1.9): a rectified exemplar that a
    /// lattice of `nx × ny` cells tiles. Synthesis moves its coarse content by whole cells and
    /// keeps coarse candidates on the same lattice phase, so the grid survives while the cells
    /// vary. The exemplar must be toroidal (a lattice that tiles it wraps around it; force
    /// `toroidal` when preparing it) and the counts must divide its width and height.
    pub fn with_lattice(mut self, nx: u32, ny: u32) -> Result<Exemplar> {
        if !self.toroidal {
            return Err(CoreError::Param {
                name: "lattice",
                message: "needs a toroidal exemplar (the lattice tiles it, so it wraps around): set toroidal".into(),
            });
        }
        self.lattice = Some(Lattice::cells(nx, ny, self.width, self.height)?);
        Ok(self)
    }

    /// This exemplar with the lattice `choice` gives it: detected from its pixels (`auto`),
    /// none, cells ([`Exemplar::with_lattice`]) or given waves. Except with `none`, its
    /// structure is detected ([`crate::lattice::detect`]): reported, and an exact repeat kept
    /// so that copies are not candidates, whichever lattice the modes hold.
    pub fn with_lattice_choice(mut self, choice: &LatticeChoice) -> Result<Exemplar> {
        if *choice == LatticeChoice::None {
            (self.lattice, self.repeat, self.structure) = (None, None, None);
            return Ok(self);
        }
        // A given lattice is checked before the pixels are looked at.
        match *choice {
            LatticeChoice::Cells(nx, ny) => self = self.with_lattice(nx, ny)?,
            _ => self.lattice = choice.explicit(self.width, self.height)?,
        }
        let found = crate::lattice::detect(&self.pixels, self.width, self.height);
        if *choice == LatticeChoice::Auto {
            self.lattice = found.lattice.clone();
        }
        self.structure = Some(crate::lattice::Structure::of(&found));
        self.repeat = found.repeat;
        Ok(self)
    }
}

/// The colour variation of `pixels`: the standard deviation, in 8-bit levels, of the most
/// varied channel.
fn spread_of(pixels: &[[u8; 3]]) -> f64 {
    let n = pixels.len().max(1) as f64;
    (0..3)
        .map(|c| {
            let (s, s2) = pixels.iter().fold((0u64, 0u64), |(s, s2), p| {
                let v = p[c] as u64;
                (s + v, s2 + v * v)
            });
            let mean = s as f64 / n;
            (s2 as f64 / n - mean * mean).max(0.0).sqrt()
        })
        .fold(0.0, f64::max)
}

fn check_size(w: u32, h: u32, max: u32) -> Result<()> {
    if w < MIN_INPUT_SIDE || h < MIN_INPUT_SIDE || w > max || h > max {
        return Err(CoreError::ExemplarSize { width: w, height: h, min: MIN_INPUT_SIDE, max });
    }
    Ok(())
}

/// A `w × h` image made even (an odd last row or column dropped) and its exact 2×2 box
/// reduction: what [`Exemplar::from_hires`] keeps and uses, for the colour and every map alike.
fn halve(pixels: &[[u8; 3]], (w, h): (u32, u32)) -> (Vec<[u8; 3]>, Vec<[u8; 3]>) {
    let (bw, bh) = (w as usize / 2 * 2, h as usize / 2 * 2);
    let big: Vec<[u8; 3]> = (0..bh).flat_map(|y| &pixels[y * w as usize..][..bw]).copied().collect();
    let reduced = area_resample(&big, (bw, bh), (bw / 2, bh / 2));
    (big, reduced)
}

/// The prepared size of a `w × h` image: the same, unless a side exceeds [`MAX_SIDE`]; then
/// scaled so that the longer side is [`MAX_SIDE`], keeping the shape (the shorter side
/// rounded, at least [`MIN_INPUT_SIDE`]).
pub fn prepared_size(w: u32, h: u32) -> (u32, u32) {
    let long = crate::geom::Size::new(w, h).longer();
    if long <= MAX_SIDE {
        return (w, h);
    }
    let scale =
        |s: u32| ((s as u64 * MAX_SIDE as u64 + long as u64 / 2) / long as u64).max(MIN_INPUT_SIDE as u64) as u32;
    (scale(w), scale(h))
}

/// Composite RGBA over the alpha-weighted mean colour of the image, with integer rounding.
fn composite_over_mean(px: &[[u8; 4]]) -> Vec<[u8; 3]> {
    let (mut sum, mut wsum) = ([0u64; 3], 0u64);
    for p in px {
        for c in 0..3 {
            sum[c] += p[c] as u64 * p[3] as u64;
        }
        wsum += p[3] as u64;
    }
    let mean: [u64; 3] = if wsum == 0 { [0; 3] } else { [0, 1, 2].map(|c| (sum[c] + wsum / 2) / wsum) };
    px.iter()
        .map(|p| {
            let a = p[3] as u64;
            [0, 1, 2].map(|c| ((p[c] as u64 * a + mean[c] * (255 - a) + 127) / 255) as u8)
        })
        .collect()
}

/// Exact area resampling of a `sw × sh` image to `tw × th` with integer weights (works both
/// ways, per axis). Output pixel `i` covers source interval `[i·s/t, (i+1)·s/t)`; weights are
/// overlap lengths in units of `1/t` source pixels, so every sum is an exact integer.
pub(crate) fn area_resample(src: &[[u8; 3]], (sw, sh): (usize, usize), (tw, th): (usize, usize)) -> Vec<[u8; 3]> {
    let weights = |s: usize, t: usize| -> Vec<Vec<(usize, u64)>> {
        (0..t)
            .map(|i| {
                let (a, b) = (i * s, (i + 1) * s); // in units of 1/t source pixels
                let mut w = Vec::new();
                for j in a / t..b.div_ceil(t) {
                    let lo = a.max(j * t);
                    let hi = b.min((j + 1) * t);
                    if hi > lo {
                        w.push((j, (hi - lo) as u64));
                    }
                }
                w
            })
            .collect()
    };
    let (wx, wy) = (weights(sw, tw), weights(sh, th));
    // Horizontal pass (sums of weight·value, total weight sw per output pixel).
    let mut tmp = vec![[0u64; 3]; sh * tw];
    for y in 0..sh {
        for (x, w) in wx.iter().enumerate() {
            let mut acc = [0u64; 3];
            for &(j, wt) in w {
                let p = src[y * sw + j];
                for c in 0..3 {
                    acc[c] += wt * p[c] as u64;
                }
            }
            tmp[y * tw + x] = acc;
        }
    }
    let total = (sw * sh) as u64;
    let mut out = vec![[0u8; 3]; tw * th];
    for (y, w) in wy.iter().enumerate() {
        for x in 0..tw {
            let mut acc = [0u64; 3];
            for &(j, wt) in w {
                let p = tmp[j * tw + x];
                for c in 0..3 {
                    acc[c] += wt * p[c];
                }
            }
            out[y * tw + x] = acc.map(|v| ((v + total / 2) / total).min(255) as u8);
        }
    }
    out
}

/// Mean absolute gradient across the wrap-around edges of a `w × h` image divided by the
/// interior mean.
pub(crate) fn seam_ratio(px: &[[u8; 3]], w: usize, h: usize) -> f64 {
    let diff = |a: [u8; 3], b: [u8; 3]| -> u64 { (0..3).map(|c| a[c].abs_diff(b[c]) as u64).sum() };
    let (mut inner, mut n_inner) = (0u64, 0u64);
    let (mut seam, mut n_seam) = (0u64, 0u64);
    for y in 0..h {
        for x in 0..w {
            let p = px[y * w + x];
            let right = px[y * w + (x + 1) % w];
            let down = px[((y + 1) % h) * w + x];
            if x + 1 < w {
                inner += diff(p, right);
                n_inner += 1;
            } else {
                seam += diff(p, right);
                n_seam += 1;
            }
            if y + 1 < h {
                inner += diff(p, down);
                n_inner += 1;
            } else {
                seam += diff(p, down);
                n_seam += 1;
            }
        }
    }
    let inner = inner as f64 / n_inner.max(1) as f64;
    let seam = seam as f64 / n_seam.max(1) as f64;
    if inner == 0.0 {
        if seam == 0.0 {
            1.0
        } else {
            f64::INFINITY
        }
    } else {
        seam / inner
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_kept_up_to_the_cap() {
        assert_eq!(prepared_size(50, 50), (50, 50));
        assert_eq!(prepared_size(300, 200), (300, 200));
        assert_eq!(prepared_size(1024, 600), (512, 300));
        assert_eq!(levels_for(128, 128), 7);
        assert_eq!(levels_for(100, 100), 7);
        assert_eq!(levels_for(300, 200), 9);
        assert_eq!(levels_for(78, 43), 7);
        assert_eq!(levels_for(16, 16), 4);
    }

    #[test]
    fn area_resample_preserves_flat_images_and_means() {
        let src = vec![[10u8, 20, 30]; 100 * 100];
        let out = area_resample(&src, (100, 100), (64, 50));
        assert!(out.iter().all(|p| *p == [10, 20, 30]));
        let src: Vec<[u8; 3]> = (0..16 * 16).map(|i| [(i % 2 * 255) as u8; 3]).collect();
        let out = area_resample(&src, (16, 16), (32, 24));
        assert_eq!(out.len(), 32 * 24);
    }
}
