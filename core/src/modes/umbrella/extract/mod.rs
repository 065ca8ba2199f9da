//! Base umbrellas extracted from the exemplar (design note §5.6): the texture's elements —
//! stones, leaves — segmented by a luminance threshold, each a star-shaped patch around its
//! deepest interior point with a rim found by ray casting, its texture cropped with an alpha
//! mask; a few bases chosen by clustering the elements, the other members of each cluster giving
//! colour offsets and morph targets; and the arrangement statistics (density, size spread).
//! Deterministic: integer image work, fixed orders, ties by index.

use crate::error::{CoreError, Result};

mod cluster;
mod rims;
mod segment;

pub use rims::ray;
pub(super) use cluster::orientation_spread;
use cluster::*;
use rims::*;
use segment::*;

/// Rays cast from an element's centre: its rim vertices, one per ray at angles `2πi/RAYS`.
pub const RAYS: usize = 24;

/// Fewest and most bases kept.
pub const MIN_BASES: usize = 4;

/// Most bases kept.
pub const MAX_BASES: usize = 10;

/// Version of what extraction computes: bump it whenever an exemplar's extraction changes, so
/// that stored extractions of earlier versions are recomputed.
pub const EXTRACTION_VERSION: u32 = 3;

/// Variants (colour offsets and morph targets) kept per base at most.
pub const MAX_VARIANTS: usize = 4;

/// A base umbrella: an element of the exemplar as a star-shaped patch.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseUmbrella {
    /// Crop width (the element's bounding box plus a 2-texel margin).
    pub w: u32,
    /// Crop height.
    pub h: u32,
    /// Crop pixels, RGB in `[0, 1]`, row-major.
    pub texture: Vec<[f32; 3]>,
    /// The element's mask over the crop (its alpha: true on the element's texels).
    pub alpha: Vec<bool>,
    /// The texture box-filtered by halves (levels 1, 2, … down to one texel), for lookups
    /// whose footprint spans several texels.
    pub mips: Vec<Mip>,
    /// Centre in crop coordinates (the texture coordinate of the centre vertex).
    pub centre: [f32; 2],
    /// Rim radius along each of the [`RAYS`] rays (texels): vertex `i` is at
    /// `centre + radii[i]·(cos 2πi/RAYS, sin 2πi/RAYS)`.
    pub radii: [f32; RAYS],
    /// Colour offsets and morph targets from the other members of its cluster (the first is the
    /// base itself: no offset, no morph).
    pub variants: Vec<Variant>,
    /// Where the element was in the exemplar (its centre), for inspection.
    pub source: [u32; 2],
}

/// One level of a base texture's mipmap.
#[derive(Debug, Clone, PartialEq)]
pub struct Mip {
    /// Width.
    pub w: u32,
    /// Height.
    pub h: u32,
    /// Texels, RGB in `[0, 1]`, row-major.
    pub texels: Vec<[f32; 3]>,
}

/// The mipmap of a `w × h` texture whose element texels are `alpha`: each level the mean of
/// (up to) 2×2 texels of the one before weighted by their share of element texels (so that the
/// margin around the element does not bleed into its colour), until one texel is left.
pub fn mipmap(w: u32, h: u32, texture: &[[f32; 3]], alpha: &[bool]) -> Vec<Mip> {
    let mut levels: Vec<Mip> = Vec::new();
    let (mut w, mut h) = (w as usize, h as usize);
    let mut prev: Vec<([f32; 3], f32)> = texture.iter().zip(alpha).map(|(&c, &a)| (c, a as u8 as f32)).collect();
    while w > 1 || h > 1 {
        let (nw, nh) = (w.div_ceil(2), h.div_ceil(2));
        let mut next = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let (mut sum, mut wsum, mut plain, mut n) = ([0f32; 3], 0f32, [0f32; 3], 0f32);
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (2 * x + dx, 2 * y + dy);
                    if sx < w && sy < h {
                        let (c, a) = prev[sy * w + sx];
                        for k in 0..3 {
                            sum[k] += a * c[k];
                            plain[k] += c[k];
                        }
                        wsum += a;
                        n += 1.0;
                    }
                }
                let c = if wsum > 0.0 { sum.map(|v| v / wsum) } else { plain.map(|v| v / n) };
                next.push((c, wsum / n));
            }
        }
        levels.push(Mip { w: nw as u32, h: nh as u32, texels: next.iter().map(|t| t.0).collect() });
        (w, h, prev) = (nw, nh, next);
    }
    levels
}

/// A variant of a base: another element of its cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct Variant {
    /// Morph target: rim radius per ray, rescaled to the base's mean radius.
    pub radii: [f32; RAYS],
    /// Signed colour offset per vertex (centre first, then the rim), RGB in `[-1, 1]`.
    pub colour: [[f32; 3]; RAYS + 1],
}

/// What extraction found: the bases and the arrangement statistics.
#[derive(Debug, Clone, PartialEq)]
pub struct Elements {
    /// The base umbrellas (4–10).
    pub bases: Vec<BaseUmbrella>,
    /// Elements found (before choosing the bases).
    pub found: usize,
    /// Mean element area (texels).
    pub mean_area: f64,
    /// Scale spread of the elements: 10th and 90th percentile of `sqrt(area / mean area)`.
    pub scale_spread: (f64, f64),
    /// Mean colour of the exemplar, RGB in `[0, 1]`.
    pub mean_colour: [f32; 3],
    /// How the elements were segmented, for `textile info` and reports.
    pub segmentation: String,
    /// Fraction of the exemplar in the elements' class (the foreground): how much of the plane
    /// elements should cover.
    pub foreground: f64,
    /// How far the elements' orientations spread, in whole degrees (0–180): placed umbrellas
    /// are rotated by at most this either way from the orientation they were cut in. 180 (any
    /// rotation) for round elements or elements pointing every way.
    pub orientation_spread: u32,
    /// Whether the textures are a tangent-space normal map's (`rgb = (n + 1) / 2`), whose
    /// vectors turn with their umbrella ([`Elements::oriented`]); the colour's are not.
    pub normals: bool,
}

/// A segmented element: its texels (a mask over the exemplar), centre and rim.
pub(super) struct Element {
    pub(super) texels: Vec<usize>,
    centre: (usize, usize),
    radii: [f32; RAYS],
    area: usize,
    mean: [f32; 3],
}

/// Extract the elements of an exemplar (`m × m` RGB) and choose its base umbrellas.
pub fn extract(px: &[[u8; 3]], m: usize, toroidal: bool) -> Result<Elements> {
    let lum = luma(px, m, toroidal);
    let mut sorted = lum.clone();
    sorted.sort_unstable();
    let total = (m * m) as f64;
    let (amin, amax) = ((0.002 * total).ceil() as usize, (0.10 * total) as usize);
    // Try thresholds, polarities and erosions; keep the segmentation whose usable elements
    // (area within [0.2 %, 10 %] of the exemplar, not touching its border) cover the most.
    let mut best: Option<(usize, String, Vec<Vec<usize>>, f64)> = None;
    for q in [30, 40, 50, 60, 70] {
        let th = sorted[(sorted.len() - 1) * q / 100];
        for bright in [true, false] {
            let fg: Vec<bool> = lum.iter().map(|&v| if bright { v > th } else { v < th }).collect();
            for r in [0usize, 1, 2] {
                let core = erode(&fg, m, r);
                let mut taken = vec![false; m * m];
                let mut seen = vec![false; m * m];
                let mut kept = Vec::new();
                for c in components(&core, m) {
                    if c.bbox.0 == 0 || c.bbox.1 == 0 || c.bbox.2 + 1 >= m || c.bbox.3 + 1 >= m {
                        continue;
                    }
                    let grown = regrow(&c, &fg, m, r, &taken, &mut seen);
                    let touches = grown.iter().any(|&i| i % m == 0 || i / m == 0 || i % m == m - 1 || i / m == m - 1);
                    if touches || grown.len() < amin || grown.len() > amax {
                        continue;
                    }
                    for &i in &grown {
                        taken[i] = true;
                    }
                    kept.push(grown);
                }
                // Score: the area the usable elements cover (many tiny specks lose to fewer,
                // real elements); at least the minimum count.
                let score = if kept.len() >= MIN_BASES { kept.iter().map(Vec::len).sum::<usize>() } else { kept.len() };
                if best.as_ref().is_none_or(|b| score > b.0) {
                    let name = format!(
                        "luminance {} the {q}th percentile, eroded by {r}",
                        if bright { "above" } else { "below" }
                    );
                    let fraction = fg.iter().filter(|&&f| f).count() as f64 / total;
                    best = Some((score, name, kept, fraction));
                }
            }
        }
    }
    let (_, segmentation, kept, foreground) = best.unwrap_or_default();
    if kept.len() < MIN_BASES {
        return Err(CoreError::Param {
            name: "umbrella",
            message: format!(
                "found {} separate elements in the exemplar, at least {MIN_BASES} are needed: it does not look like a texture of discrete elements",
                kept.len()
            ),
        });
    }
    let elements = elements_of(px, m, kept);
    let groups = cluster(&elements);
    let mut mean_colour = [0f32; 3];
    for p in px {
        for k in 0..3 {
            mean_colour[k] += p[k] as f32 / 255.0;
        }
    }
    mean_colour = mean_colour.map(|v| v / (m * m) as f32);
    let spread = orientation_spread(&elements, m);
    Ok(assemble(px, m, &elements, &groups, Summary { mean_colour, segmentation, foreground, orientation_spread: spread }))
}

/// What [`assemble`] takes as given: the statistics not computed from the elements.
pub(super) struct Summary {
    pub mean_colour: [f32; 3],
    pub segmentation: String,
    pub foreground: f64,
    pub orientation_spread: u32,
}

/// The elements of an `m × m` image from their texels' masks: centre, rim, area, mean colour.
pub(super) fn elements_of(px: &[[u8; 3]], m: usize, masks: Vec<Vec<usize>>) -> Vec<Element> {
    masks
        .into_iter()
        .map(|texels| {
            let mut inside = vec![false; m * m];
            for &i in &texels {
                inside[i] = true;
            }
            let c = deepest(&texels, m);
            let centre = (c % m, c / m);
            let radii = rim(
                &|x, y| x >= 0 && y >= 0 && (x as usize) < m && (y as usize) < m && inside[y as usize * m + x as usize],
                centre,
            );
            let mut mean = [0f32; 3];
            for &i in &texels {
                for k in 0..3 {
                    mean[k] += px[i][k] as f32 / 255.0;
                }
            }
            let area = texels.len();
            mean = mean.map(|v| v / area as f32);
            Element { texels, centre, radii, area, mean }
        })
        .collect()
}

/// The bases of `groups` of `elements` (each group's first is the base, the others its
/// variants) with the size statistics.
pub(super) fn assemble(px: &[[u8; 3]], m: usize, elements: &[Element], groups: &[Vec<usize>], s: Summary) -> Elements {
    let mean_area = elements.iter().map(|e| e.area as f64).sum::<f64>() / elements.len().max(1) as f64;
    let mut scales: Vec<f64> = elements.iter().map(|e| (e.area as f64 / mean_area).sqrt()).collect();
    scales.sort_by(f64::total_cmp);
    let pick = |q: usize| scales.get(scales.len().saturating_sub(1) * q / 100).copied().unwrap_or(1.0);
    let scale_spread = (pick(10), pick(90));
    let bases = groups.iter().map(|g| base(px, m, elements, g)).collect();
    Elements {
        bases,
        found: elements.len(),
        mean_area,
        scale_spread,
        mean_colour: s.mean_colour,
        segmentation: s.segmentation,
        foreground: s.foreground,
        orientation_spread: s.orientation_spread,
        normals: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spikes_are_cut_and_lobes_and_smooth_rims_kept() {
        // A spike two rays wide on a disc of radius 10: cut to 1.5 times the disc.
        let mut radii = [10f32; RAYS];
        radii[5] = 40.0;
        radii[6] = 36.0;
        let cut = despike(radii);
        assert_eq!((cut[5], cut[6]), (15.0, 15.0));
        assert!((0..RAYS).filter(|i| ![5, 6].contains(i)).all(|i| cut[i] == 10.0));
        // A pointed lobe (2.6 times its neighbours) stays, and so does a lobe three rays wide.
        let mut lobe = [10f32; RAYS];
        lobe[5] = 26.0;
        assert_eq!(despike(lobe), lobe);
        radii[7] = 38.0;
        assert_eq!(despike(radii), radii);
        // An ellipse with semi-axes 7 and 3 (the tip is the narrowest part of its profile) stays.
        let ellipse: [f32; RAYS] = std::array::from_fn(|i| {
            let d = ray(i);
            21.0 / ((3.0 * d[0]).powi(2) + (7.0 * d[1]).powi(2)).sqrt()
        });
        assert_eq!(despike(ellipse), ellipse);
        // No radius ever grows.
        for n in 0..200u32 {
            let r: [f32; RAYS] = std::array::from_fn(|i| 0.5 + ((n as usize * 7 + i * i * 13) % 29) as f32);
            assert!(despike(r).iter().zip(&r).all(|(a, b)| a <= b));
        }
    }
}
