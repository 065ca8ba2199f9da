//! What the umbrella mode shows of a material map (issue 39): the same umbrellas, placed
//! where the colour's are, their bases' textures re-cut from the map at the crops the colour's
//! were cut from ([`Elements::of_map`]). Colour offsets, shadows and the colour calibrations
//! of the gaps are the colour's alone; a tangent-space normal turns with its umbrella
//! ([`Elements::oriented`]), so a rotated patch's normals match its rotated height.

use super::extract::{mipmap, BaseUmbrella, Elements, Variant, RAYS};

impl Elements {
    /// These elements showing `texels` — an `m × m` map co-registered with the exemplar they
    /// were extracted from — instead of its colours: each base's crop re-cut from the map (its
    /// origin is where the base's centre, `source`, lands at `centre`), mipmapped under the same
    /// alpha, its variants' colour offsets dropped (they are the colour's; their morph targets,
    /// geometry, stay). `normals`: the map is a normal map ([`Elements::oriented`]).
    pub fn of_map(&self, texels: &[[u8; 3]], m: usize, normals: bool) -> Elements {
        let at = |x: i64, y: i64| {
            let (x, y) = (x.clamp(0, m as i64 - 1) as usize, y.clamp(0, m as i64 - 1) as usize);
            texels.get(y * m + x).copied().unwrap_or_default().map(|c| c as f32 / 255.0)
        };
        let bases = self
            .bases
            .iter()
            .map(|b| {
                let x0 = b.source[0] as i64 - (b.centre[0] - 0.5).round() as i64;
                let y0 = b.source[1] as i64 - (b.centre[1] - 0.5).round() as i64;
                let texture: Vec<[f32; 3]> =
                    (0..b.h as i64).flat_map(|y| (0..b.w as i64).map(move |x| (x0 + x, y0 + y))).map(|(x, y)| at(x, y)).collect();
                let variants = b.variants.iter().map(|v| Variant { radii: v.radii, colour: [[0.0; 3]; RAYS + 1] }).collect();
                BaseUmbrella { mips: mipmap(b.w, b.h, &texture, &b.alpha), texture, variants, ..b.clone() }
            })
            .collect();
        let n = texels.len().max(1) as f64;
        let mean_colour = std::array::from_fn(|k| (texels.iter().map(|t| t[k] as f64).sum::<f64>() / n / 255.0) as f32);
        Elements { bases, mean_colour, normals, ..self.clone() }
    }

    /// What a texel `c` of these elements' textures shows in an umbrella turned by `(cos, sin)`
    /// (texture to plane, image axes) and magnified `1 / inv_scale` times: itself, or for a
    /// normal map (OpenGL convention, +Y up the image) the surface's normal after the same
    /// turn and magnification — its slopes turned with the umbrella and divided by the
    /// magnification (heights stay), unit length.
    #[inline]
    pub fn oriented(&self, c: [f32; 3], cos: f32, sin: f32, inv_scale: f32) -> [f32; 3] {
        if !self.normals {
            return c;
        }
        // The plane's image vector is R·t for the texture's t = (nx, −ny); back with y up.
        let (nx, ny, nz) = (2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, 2.0 * c[2] - 1.0);
        let (x, y) = ((cos * nx + sin * ny) * inv_scale, (cos * ny - sin * nx) * inv_scale);
        let len = (x * x + y * y + nz * nz).sqrt().max(1e-6);
        [(x / len + 1.0) * 0.5, (y / len + 1.0) * 0.5, (nz / len + 1.0) * 0.5]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exemplar::{Exemplar, ExemplarOptions};

    #[test]
    fn a_map_equal_to_the_exemplar_gives_the_same_bases_and_normals_turn_with_the_umbrella() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars/gravel.png");
        let ex = Exemplar::from_bytes(&std::fs::read(path).unwrap(), &ExemplarOptions::default()).unwrap();
        let (el, _) = super::super::elements(&ex).unwrap();
        let same = el.of_map(&ex.pixels, ex.width as usize, false);
        for (a, b) in el.bases.iter().zip(&same.bases) {
            assert_eq!(a.texture, b.texture, "the re-cut crop is the colour's crop");
            assert!(b.variants.iter().all(|v| v.colour == [[0.0; 3]; RAYS + 1]));
        }
        let normals = Elements { normals: true, ..same };
        // A quarter turn clockwise on screen (y down): a normal facing +x (east) faces south,
        // −y in the +Y-up convention.
        let (c, s) = (0.0f32, 1.0f32);
        let east = [1.0, 0.5, 0.5];
        let turned = normals.oriented(east, c, s, 1.0);
        assert!((turned[0] - 0.5).abs() < 1e-6 && turned[1].abs() < 1e-6, "{turned:?}");
        assert_eq!(el.oriented(east, c, s, 2.0), east, "colours do not turn");
    }
}
