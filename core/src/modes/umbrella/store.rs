//! The stored extraction's file format: what [`extract`](super::extract) found for an exemplar
//! — its base umbrellas and arrangement statistics, or why it found none — kept beside the
//! texture's analysis (`<texture>.umbrella`, [`super::prepared`]), so that it is computed once
//! per exemplar, not per process. Layout: a [`crate::prepare::envelope`] (magic, format
//! version, body, BLAKE3 checksum) around a JSON body (the exemplar's extraction id — content
//! hash and extraction version — then the outcome; base textures and masks as base64 of bytes,
//! exact since textures are 8-bit texels / 255). Every way a file can be wrong is an
//! [`AnalysisFileProblem`].

use std::sync::Arc;

use base64::Engine;
use serde::{Deserialize, Serialize};

use super::extract::{mipmap, BaseUmbrella, Elements, Variant, RAYS};
use crate::error::AnalysisFileProblem;
use crate::prepare::{envelope, open_envelope};

/// First bytes of every stored extraction.
pub const MAGIC: &[u8; 8] = b"TXTLUMB\0";
/// Layout version.
pub const FORMAT_VERSION: u32 = 1;

/// What extraction gave for an exemplar: the elements, or why there are none.
pub type Outcome = std::result::Result<Arc<Elements>, String>;

#[derive(Serialize, Deserialize)]
struct Body {
    id: String,
    outcome: std::result::Result<StoredElements, String>,
}

#[derive(Serialize, Deserialize)]
struct StoredElements {
    bases: Vec<StoredBase>,
    found: usize,
    mean_area: f64,
    scale_spread: (f64, f64),
    mean_colour: [f32; 3],
    segmentation: String,
    foreground: f64,
    orientation_spread: u32,
}

#[derive(Serialize, Deserialize)]
struct StoredBase {
    w: u32,
    h: u32,
    /// RGB8 texels, base64.
    texture: String,
    /// One byte (0 or 1) per texel, base64.
    alpha: String,
    centre: [f32; 2],
    radii: Vec<f32>,
    variants: Vec<StoredVariant>,
    source: [u32; 2],
}

#[derive(Serialize, Deserialize)]
struct StoredVariant {
    radii: Vec<f32>,
    colour: Vec<[f32; 3]>,
}

fn b64() -> base64::engine::GeneralPurpose {
    base64::engine::general_purpose::STANDARD
}

fn to_stored(e: &Elements) -> StoredElements {
    StoredElements {
        bases: e
            .bases
            .iter()
            .map(|b| StoredBase {
                w: b.w,
                h: b.h,
                texture: b64().encode(
                    b.texture.iter().flat_map(|t| t.map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8)).collect::<Vec<_>>(),
                ),
                alpha: b64().encode(b.alpha.iter().map(|&a| a as u8).collect::<Vec<_>>()),
                centre: b.centre,
                radii: b.radii.to_vec(),
                variants: b
                    .variants
                    .iter()
                    .map(|v| StoredVariant { radii: v.radii.to_vec(), colour: v.colour.to_vec() })
                    .collect(),
                source: b.source,
            })
            .collect(),
        found: e.found,
        mean_area: e.mean_area,
        scale_spread: e.scale_spread,
        mean_colour: e.mean_colour,
        segmentation: e.segmentation.clone(),
        foreground: e.foreground,
        orientation_spread: e.orientation_spread,
    }
}

fn corrupt(what: impl std::fmt::Display) -> AnalysisFileProblem {
    AnalysisFileProblem::Corrupt(what.to_string())
}

fn from_stored(s: StoredElements) -> std::result::Result<Elements, AnalysisFileProblem> {
    let mut bases = Vec::with_capacity(s.bases.len());
    for b in s.bases {
        let n = b.w as usize * b.h as usize;
        let texture = b64().decode(&b.texture).map_err(corrupt)?;
        let alpha = b64().decode(&b.alpha).map_err(corrupt)?;
        if n == 0 || n > 1 << 20 || texture.len() != 3 * n || alpha.len() != n {
            return Err(corrupt(format!("base of {}x{} with {} texture bytes", b.w, b.h, texture.len())));
        }
        let rays = |v: &[f32]| -> std::result::Result<[f32; RAYS], AnalysisFileProblem> {
            let r: [f32; RAYS] = v.try_into().map_err(|_| corrupt(format!("{} radii, not {RAYS}", v.len())))?;
            // A rim is positive and finite (lookups divide by it).
            if r.iter().all(|x| x.is_finite() && *x > 0.0 && *x < 4096.0) {
                Ok(r)
            } else {
                Err(corrupt("rim radius out of range"))
            }
        };
        let mut variants = Vec::with_capacity(b.variants.len());
        for v in &b.variants {
            let colour: [[f32; 3]; RAYS + 1] =
                v.colour.as_slice().try_into().map_err(|_| corrupt(format!("{} vertex colours", v.colour.len())))?;
            variants.push(Variant { radii: rays(&v.radii)?, colour });
        }
        if variants.is_empty() {
            return Err(corrupt("a base without variants"));
        }
        let texture: Vec<[f32; 3]> = texture.chunks_exact(3).map(|c| [c[0], c[1], c[2]].map(|v| v as f32 / 255.0)).collect();
        let alpha: Vec<bool> = alpha.iter().map(|&a| a != 0).collect();
        bases.push(BaseUmbrella {
            w: b.w,
            h: b.h,
            mips: mipmap(b.w, b.h, &texture, &alpha),
            texture,
            alpha,
            centre: b.centre,
            radii: rays(&b.radii)?,
            variants,
            source: b.source,
        });
    }
    if bases.is_empty() {
        return Err(corrupt("no bases"));
    }
    Ok(Elements {
        bases,
        found: s.found,
        mean_area: s.mean_area,
        scale_spread: s.scale_spread,
        mean_colour: s.mean_colour,
        segmentation: s.segmentation,
        foreground: s.foreground,
        orientation_spread: s.orientation_spread.min(180),
        normals: false,
    })
}

/// The file's bytes for extraction id `id` and its outcome.
pub fn to_bytes(id: &str, outcome: &Outcome) -> Vec<u8> {
    let body = Body { id: id.to_string(), outcome: outcome.as_ref().map(|e| to_stored(e)).map_err(Clone::clone) };
    envelope(MAGIC, FORMAT_VERSION, &serde_json::to_vec(&body).unwrap_or_default())
}

/// Parse a stored extraction: its id and outcome.
pub fn from_bytes(bytes: &[u8]) -> std::result::Result<(String, Outcome), AnalysisFileProblem> {
    let body: Body = serde_json::from_slice(open_envelope(MAGIC, FORMAT_VERSION, bytes)?)
        .map_err(|e| corrupt(format!("body: {e}")))?;
    let outcome = match body.outcome {
        Ok(s) => Ok(Arc::new(from_stored(s)?)),
        Err(why) => Err(why),
    };
    Ok((body.id, outcome))
}
