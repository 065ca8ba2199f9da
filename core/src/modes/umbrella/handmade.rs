//! A hand-made umbrella set (issue 15: "for textures where extraction is not good enough"):
//! JSON naming one image with alpha per base — the element is where alpha ≥ 128 — and, per
//! base, optional variant images (their colour offsets and shapes become the base's variants),
//! with optional arrangement statistics. The images are packed into one atlas and go through
//! the same steps as extracted elements (deepest centre, ray-cast rim, crop, variants), so a
//! hand-made base is used exactly like an extracted one.
//!
//! ```json
//! { "bases": [ { "image": "stone1.png", "variants": ["stone1b.png"] },
//!              { "image": "stone2.png" } ],
//!   "foreground": 0.7, "orientation_spread": 180 }
//! ```

use serde::Deserialize;

use super::extract::{assemble, elements_of, orientation_spread, Elements, Summary, MAX_BASES, MAX_VARIANTS};
use crate::error::{CoreError, Result};

/// Largest side of one element image.
pub const MAX_IMAGE_SIDE: u32 = 256;
/// Fewest texels an element's alpha must cover.
pub const MIN_AREA: usize = 16;
/// Foreground share when the set does not give one.
pub const DEFAULT_FOREGROUND: f64 = 0.6;
/// Empty texels between images in the atlas (more than the crop's 2-texel margin).
const GAP: usize = 4;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SetFile {
    bases: Vec<BaseFile>,
    #[serde(default)]
    foreground: Option<f64>,
    #[serde(default)]
    orientation_spread: Option<u32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BaseFile {
    image: String,
    #[serde(default)]
    variants: Vec<String>,
}

fn bad(message: String) -> CoreError {
    CoreError::Param { name: "set", message }
}

/// One decoded element image: RGB and alpha mask.
struct Picture {
    w: usize,
    h: usize,
    rgb: Vec<[u8; 3]>,
    alpha: Vec<bool>,
}

fn decode(name: &str, bytes: &[u8]) -> Result<Picture> {
    let undecodable = |e: &dyn std::fmt::Display| bad(format!("image '{name}': {e}"));
    // The size from the header first: a huge image is refused before it is decoded.
    let (w, h) = crate::image::reader(bytes).and_then(|r| r.into_dimensions()).map_err(|e| undecodable(&e))?;
    if w > MAX_IMAGE_SIDE || h > MAX_IMAGE_SIDE || w == 0 || h == 0 {
        return Err(bad(format!("image '{name}' is {w}x{h}; an element image is at most {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE}")));
    }
    let img = crate::image::decode_within(bytes, MAX_IMAGE_SIDE, 16 << 20).map_err(|e| undecodable(&e))?;
    if !img.color().has_alpha() {
        return Err(bad(format!("image '{name}' has no alpha channel: the element is where alpha ≥ 128")));
    }
    let rgba = img.to_rgba8();
    let rgb = rgba.pixels().map(|p| [p[0], p[1], p[2]]).collect();
    let alpha: Vec<bool> = rgba.pixels().map(|p| p[3] >= 128).collect();
    let area = alpha.iter().filter(|&&a| a).count();
    if area < MIN_AREA {
        return Err(bad(format!("image '{name}': its alpha covers {area} texels, at least {MIN_AREA} are needed")));
    }
    Ok(Picture { w: w as usize, h: h as usize, rgb, alpha })
}

/// The elements of a hand-made set: `json` is the set file, `read` gives an image's bytes by
/// the name the set uses. Every problem is a parameter error naming the set's part.
pub fn load(json: &[u8], read: &dyn Fn(&str) -> Result<Vec<u8>>) -> Result<Elements> {
    let set: SetFile = serde_json::from_slice(json).map_err(|e| bad(format!("set file: {e}")))?;
    if set.bases.is_empty() || set.bases.len() > MAX_BASES {
        return Err(bad(format!("{} bases; a set has 1 to {MAX_BASES}", set.bases.len())));
    }
    if let Some(f) = set.foreground.filter(|f| !(0.05..=0.95).contains(f)) {
        return Err(bad(format!("foreground {f}: the share of the plane elements cover, 0.05 to 0.95")));
    }
    if let Some(s) = set.orientation_spread.filter(|&s| s > 180) {
        return Err(bad(format!("orientation_spread {s}: degrees either way, 0 to 180")));
    }
    // Every image, each base followed by its variants.
    let mut pictures = Vec::new();
    let mut groups = Vec::new();
    for b in &set.bases {
        if b.variants.len() + 1 > MAX_VARIANTS {
            return Err(bad(format!("base '{}' has {} variants; at most {}", b.image, b.variants.len(), MAX_VARIANTS - 1)));
        }
        let mut group = Vec::new();
        for name in std::iter::once(&b.image).chain(&b.variants) {
            group.push(pictures.len());
            pictures.push(decode(name, &read(name)?)?);
        }
        groups.push(group);
    }
    // Pack them into one square atlas, row by row, with gaps.
    let area: usize = pictures.iter().map(|p| (p.w + GAP) * (p.h + GAP)).sum();
    let widest = pictures.iter().map(|p| p.w + 2 * GAP).max().unwrap_or(1);
    let mut m = ((area as f64).sqrt() * 1.2).ceil() as usize + 2 * GAP;
    let origins = loop {
        m = m.max(widest);
        let (mut x, mut y, mut row) = (GAP, GAP, 0);
        let mut origins = Vec::new();
        for p in &pictures {
            if x + p.w + GAP > m {
                (x, y, row) = (GAP, y + row + GAP, 0);
            }
            origins.push((x, y));
            x += p.w + GAP;
            row = row.max(p.h);
        }
        if y + row + GAP <= m {
            break origins;
        }
        m += m / 4 + 1;
    };
    let mut px = vec![[0u8; 3]; m * m];
    let mut masks = Vec::with_capacity(pictures.len());
    for (p, &(ox, oy)) in pictures.iter().zip(&origins) {
        let mut mask = Vec::new();
        for y in 0..p.h {
            for x in 0..p.w {
                let i = (oy + y) * m + ox + x;
                px[i] = p.rgb[y * p.w + x];
                if p.alpha[y * p.w + x] {
                    mask.push(i);
                }
            }
        }
        masks.push(mask);
    }
    let elements = elements_of(&px, m, masks);
    let mut mean_colour = [0f32; 3];
    let mut n = 0f32;
    for e in &elements {
        for &i in &e.texels {
            for k in 0..3 {
                mean_colour[k] += px[i][k] as f32 / 255.0;
            }
            n += 1.0;
        }
    }
    let summary = Summary {
        mean_colour: mean_colour.map(|v| v / n.max(1.0)),
        segmentation: format!("hand-made set of {} images", pictures.len()),
        foreground: set.foreground.unwrap_or(DEFAULT_FOREGROUND),
        orientation_spread: set.orientation_spread.unwrap_or_else(|| orientation_spread(&elements, m)),
    };
    Ok(assemble(&px, m, &elements, &groups, summary))
}
