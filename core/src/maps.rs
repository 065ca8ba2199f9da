//! Material maps (issue 39): images of the same surface as the exemplar, co-registered with it
//! — a tangent-space normal map, height, specular, roughness, ambient occlusion, metallic or any
//! named extra map. Modes that synthesize exemplar coordinates look every map up at the same
//! coordinates (`Source::with_map` in `modes`), so all maps of a tile agree texel for
//! texel; where a mode blends texels, normals are blended as vectors and renormalised
//! ([`renormalise`]). Also here: what a request asks for ([`MapChoice`]) and the synthesized
//! coordinates themselves ([`UvWindow`], `map=uv`).
//!
//! Normals are stored and served in glTF's convention: OpenGL, +Y up (green high where the
//! surface faces the top of the image), `rgb = (n + 1) / 2 · 255`, unit length.

use serde::{Deserialize, Serialize};

use crate::cache::{Pyramid, Stack};
use crate::error::{CoreError, Result};
use crate::image::box_stack;
use crate::stack::low_pass;

/// The maps every material tool knows by name (any other valid name is an extra map).
pub const STANDARD: &[&str] = &["normal", "height", "specular", "roughness", "ao", "metallic"];
/// What `map=` may name besides a texture's maps: the colour, and the coordinates.
pub const BUILT_IN: &[&str] = &["albedo", "uv"];

/// Fixed point of `map=uv`: coordinates are in `1/UV_SCALE` exemplar texel (so a 512² exemplar
/// spans 0..32768 of a 16-bit channel, and magnified pixels down to 1/32 texel are exact).
pub const UV_SCALE: u32 = 64;

/// How a normal map encodes +Y.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NormalConvention {
    /// +Y up: green high where the surface faces the top of the image (glTF, Blender, Unity).
    #[serde(rename = "opengl")]
    OpenGl,
    /// +Y down: green high where the surface faces the bottom (Direct3D engines, Unreal).
    #[serde(rename = "directx")]
    DirectX,
}

/// One prepared map: texels the size of the exemplar (and of its high-resolution image).
#[derive(Debug, Clone, PartialEq)]
pub struct MaterialMap {
    /// Its name (`normal`, `height`, … or an extra map's).
    pub name: String,
    /// Width in texels, the exemplar's.
    pub width: u32,
    /// Height in texels, the exemplar's.
    pub height: u32,
    /// Row-major RGB texels, `width × height` like the exemplar's (grey maps in all three).
    pub texels: Vec<[u8; 3]>,
    /// Its version twice as wide and high when the exemplar has one ([`Exemplar::hires`]).
    pub hires: Option<Vec<[u8; 3]>>,
    /// Whether it is the normal map (OpenGL convention, unit vectors).
    pub normal: bool,
    /// Hash of everything above: part of its tiles' ETags, and of no other map's.
    pub hash: String,
}

impl MaterialMap {
    /// Map `name` from its `width × height` texels, prepared like the exemplar's (and its
    /// version twice as large when the exemplar has one): a normal map is converted to the
    /// OpenGL convention from `convention` (required) and renormalised.
    pub fn new(
        name: &str,
        (width, height): (u32, u32),
        texels: Vec<[u8; 3]>,
        hires: Option<Vec<[u8; 3]>>,
        convention: Option<NormalConvention>,
    ) -> Result<Self> {
        check_name(name)?;
        if texels.len() != width as usize * height as usize {
            return Err(CoreError::Map {
                name: name.to_string(),
                message: format!("has {} texels, not {width}x{height}", texels.len()),
            });
        }
        let normal = name == "normal";
        let convention = match (normal, convention) {
            (true, Some(c)) => Some(c),
            (true, None) => {
                return Err(CoreError::Map {
                    name: name.to_string(),
                    message: "needs normal_convention: \"opengl\" (+Y up, glTF's) or \"directx\" (+Y down)".into(),
                })
            }
            (false, _) => None,
        };
        if normal {
            check_normals(name, &texels)?;
        }
        let fix = |px: Vec<[u8; 3]>| match convention {
            Some(c) => px.into_iter().map(|t| unit(t, c == NormalConvention::DirectX)).collect(),
            None => px,
        };
        let (texels, hires) = (fix(texels), hires.map(fix));
        let mut h = blake3::Hasher::new();
        h.update(name.as_bytes());
        h.update(&[normal as u8]);
        h.update(texels.as_flattened());
        if let Some(hi) = &hires {
            h.update(hi.as_flattened());
        }
        let hash = h.finalize().to_hex()[..16].to_string();
        Ok(MaterialMap { name: name.to_string(), width, height, texels, hires, normal, hash })
    }

    /// Its size `(width, height)` for indexing.
    pub fn dims(&self) -> (usize, usize) {
        (self.width as usize, self.height as usize)
    }

    /// The centred `2^k × 2^k` box means of the map, per texel, for every `k` (see
    /// [`box_stack`]), derived on first use and kept in `cache` within its bytes.
    pub fn box_stack(&self, cache: &Pyramid) -> Stack {
        cache.derived(&format!("boxes|map|{}", self.hash), || box_stack(&self.texels, self.dims()))
    }

    /// The map low-passed `steps` stack levels (see [`crate::stack::low_pass`]), with the
    /// addressing of a `toroidal` exemplar or not, as a one-level stack kept in `cache`.
    pub fn low_pass(&self, cache: &Pyramid, toroidal: bool, steps: u32) -> Stack {
        cache.derived(&format!("low|map|{}|{toroidal}|{steps}", self.hash), || {
            vec![low_pass(&self.texels, self.dims(), toroidal, steps)]
        })
    }

    /// The map's mean colour (rounded to nearest).
    pub fn mean(&self) -> [u8; 3] {
        crate::image::mean_colour(&self.texels)
    }
}

/// Check a map name: 1–32 of `a-z 0-9 _`, and not one `map=` gives itself ([`BUILT_IN`]).
pub fn check_name(name: &str) -> Result<()> {
    let ok = !name.is_empty()
        && name.len() <= 32
        && name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_');
    if !ok {
        return Err(CoreError::Map {
            name: crate::error::clip(name),
            message: "a map name must be 1-32 of a-z 0-9 _".into(),
        });
    }
    if BUILT_IN.contains(&name) {
        return Err(CoreError::Map { name: name.into(), message: "is built in: name the map otherwise".into() });
    }
    Ok(())
}

/// What an image shows: the colour, one of the texture's maps, or the coordinates.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub enum MapChoice {
    /// The exemplar's colours (`map=albedo`, the default).
    #[default]
    Albedo,
    /// The map of this name.
    Map(String),
    /// The synthesized exemplar coordinates (`map=uv`).
    Uv,
}

impl MapChoice {
    /// As `map=` spells it.
    pub fn name(&self) -> &str {
        match self {
            MapChoice::Albedo => "albedo",
            MapChoice::Map(m) => m,
            MapChoice::Uv => "uv",
        }
    }
}

/// The exemplar coordinates a mode shows at each pixel of a window, in `1/UV_SCALE` texel.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UvWindow {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major `[u, v]`.
    pub uv: Vec<[u16; 2]>,
}

/// Decode an encoded normal (`c / 127.5 − 1` per channel).
fn decode(c: [u8; 3]) -> [f64; 3] {
    c.map(|v| v as f64 / 127.5 - 1.0)
}

/// Largest share of a normal map's texels that may be wrong — pointing sideways or into the
/// surface (`z ≤ 0`), or longer than [`LONGEST_NORMAL`] — before the map is refused.
const MAX_WRONG_NORMALS: f64 = 0.01;
/// Longest encoded normal accepted: a unit vector is 1 within rounding; box-filtered maps hold
/// shorter ones (down to 0.08 in the development set's), never longer (at most 1.07).
const LONGEST_NORMAL: f64 = 1.25;

/// Refuse a normal map that is not one: more than [`MAX_WRONG_NORMALS`] of its texels point
/// sideways or down, or are far too long (an all-black image decodes to `(−1, −1, −1)`, into
/// the surface). The development set's normal maps have none such.
fn check_normals(name: &str, texels: &[[u8; 3]]) -> Result<()> {
    let wrong = texels
        .iter()
        .filter(|&&c| {
            let n = decode(c);
            n[2] <= 0.0 || (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt() > LONGEST_NORMAL
        })
        .count();
    let share = wrong as f64 / texels.len().max(1) as f64;
    if share > MAX_WRONG_NORMALS {
        return Err(CoreError::Map {
            name: name.to_string(),
            message: format!(
                "is not a tangent-space normal map: {:.0} % of its texels point sideways or into the surface, \
                 or are longer than a unit vector (at most {:.0} % may)",
                share * 100.0,
                MAX_WRONG_NORMALS * 100.0
            ),
        });
    }
    Ok(())
}

/// Encode a unit vector, rounding each channel.
fn encode(n: [f64; 3]) -> [u8; 3] {
    n.map(|v| ((v + 1.0) * 127.5).round().clamp(0.0, 255.0) as u8)
}

/// The unit normal of encoded `c` (green flipped for a DirectX map); straight up when `c` has
/// no direction.
fn unit(c: [u8; 3], flip_g: bool) -> [u8; 3] {
    let mut n = decode(c);
    if flip_g {
        n[1] = -n[1];
    }
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len < 1e-6 {
        return [128, 128, 255];
    }
    encode(n.map(|v| v / len))
}

/// How far from unit length an encoded unit vector may be after rounding each channel
/// (`√3 · 0.5 / 127.5`): normals within it are left exactly as they are.
const ROUNDING: f64 = 0.0068;

/// Renormalise blended normals in place (RGB bytes): every pixel further from unit length than
/// rounding leaves a unit vector is made unit length again, so blending two normals gives the
/// normalised mean vector, and a copied texel stays byte for byte.
pub fn renormalise(pixels: &mut [u8]) {
    // In integers: a channel `v` decodes to `d / 255` with `d = 2v − 255`, so `|n| = √s / 255`
    // with `s = Σ d²`, and `||n| − 1| > ROUNDING` is `s` outside these bounds — which lie well
    // between integers, so the test decides exactly as the square root would, without one.
    let (lo, hi) = (65025.0 * (1.0 - ROUNDING) * (1.0 - ROUNDING), 65025.0 * (1.0 + ROUNDING) * (1.0 + ROUNDING));
    for px in pixels.chunks_exact_mut(3) {
        let s: i32 = px.iter().map(|&v| (2 * v as i32 - 255) * (2 * v as i32 - 255)).sum();
        if (s as f64) < lo || (s as f64) > hi {
            let c = [px[0], px[1], px[2]];
            px.copy_from_slice(&unit(c, false));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_low_pass_is_the_one_asked_for_whatever_was_asked_before() {
        let m = 16usize;
        let texels: Vec<[u8; 3]> =
            (0..m * m).map(|i| [(i * 37 % 251) as u8, (i % m * 16) as u8, (i / m * 16) as u8]).collect();
        let map = MaterialMap::new("height", (16, 16), texels.clone(), None, None).unwrap();
        let cache = Pyramid::new(1 << 20);
        for (toroidal, steps) in [(true, 2), (false, 2), (true, 1), (true, 2)] {
            assert_eq!(
                &map.low_pass(&cache, toroidal, steps)[0][..],
                &low_pass(&texels, (m, m), toroidal, steps)[..],
                "{toroidal} {steps}"
            );
        }
    }

    #[test]
    fn maps_that_are_not_normal_maps_are_refused() {
        let flat = vec![[128, 128, 255]; 64 * 64];
        assert!(MaterialMap::new("normal", (64, 64), flat, None, Some(NormalConvention::OpenGl)).is_ok());
        // All black (the hostile run's upload), all white, and pointing down.
        for c in [[0, 0, 0], [255, 255, 255], [128, 128, 20]] {
            let e = MaterialMap::new("normal", (64, 64), vec![c; 64 * 64], None, Some(NormalConvention::OpenGl))
                .unwrap_err();
            assert!(e.to_string().contains("normal") && e.to_string().contains("100 %"), "{c:?}: {e}");
        }
        // A few wrong texels are tolerated; a height map is not checked as one.
        let mut few = vec![[128, 128, 255]; 64 * 64];
        few[..30].fill([0, 0, 0]);
        assert!(MaterialMap::new("normal", (64, 64), few, None, Some(NormalConvention::DirectX)).is_ok());
        assert!(MaterialMap::new("height", (64, 64), vec![[0, 0, 0]; 64 * 64], None, None).is_ok());
    }

    #[test]
    fn the_integer_test_of_unit_length_decides_as_the_square_root_does() {
        for r in 0..=255u8 {
            for g in 0..=255u8 {
                for b in (0..=255u8).step_by(3) {
                    let n = decode([r, g, b]);
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    let mut px = [r, g, b];
                    renormalise(&mut px);
                    let kept = px == [r, g, b];
                    assert!(kept || (len - 1.0).abs() > ROUNDING, "{r} {g} {b}: |n| = {len} changed");
                    assert!(
                        !kept || (len - 1.0).abs() <= ROUNDING || unit([r, g, b], false) == [r, g, b],
                        "{r} {g} {b} kept"
                    );
                }
            }
        }
    }

    #[test]
    fn unit_normals_survive_renormalisation_byte_for_byte_and_are_unit_length() {
        for r in (0..=255u8).step_by(5) {
            for g in (0..=255u8).step_by(7) {
                for b in [0u8, 60, 128, 200, 255] {
                    let u = unit([r, g, b], false);
                    let n = decode(u);
                    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                    assert!((len - 1.0).abs() <= 1.0 / 127.0, "{u:?}: |n| = {len}");
                    let mut px = u.to_vec();
                    renormalise(&mut px);
                    assert_eq!(px, u.to_vec(), "{u:?} changed");
                }
            }
        }
    }

    #[test]
    fn directx_normals_flip_green_and_blends_renormalise() {
        assert_eq!(unit([128, 200, 220], true)[1], 255 - unit([128, 200, 220], false)[1]);
        // The mean of two opposite tilts is straight up.
        let (a, b) = (unit([228, 128, 200], false), unit([28, 128, 200], false));
        let mut mean: Vec<u8> = (0..3).map(|i| (a[i] as u16 + b[i] as u16).div_ceil(2) as u8).collect();
        renormalise(&mut mean);
        assert_eq!(mean, [128, 128, 255]);
    }

    #[test]
    fn map_names_are_checked() {
        for bad in ["", "Normal", "uv", "albedo", "a-b", &"x".repeat(33)] {
            assert!(check_name(bad).is_err(), "{bad}");
        }
        for good in ["normal", "ao", "detail_2"] {
            assert!(check_name(good).is_ok(), "{good}");
        }
    }
}
