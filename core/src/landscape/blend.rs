//! How a landscape's layers join where the splat gives several of them weight: the
//! [`Blend::Height`] rule (the taller material wins, so stones poke through grass) or a
//! [`Blend::Linear`] cross-fade; then [`mix`] weighs the layers' pixels of any map with the
//! weights that came out.

use super::splat::Weights;

/// A layer's height at each pixel, in `[0, 1]`.
pub type Heights = Vec<f32>;

/// How weights are made from the splat and the layers' heights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Blend {
    /// Each layer with splat weight scores its height plus that weight; layers within `depth`
    /// of the highest score mix in proportion to how far within they are, elsewhere the
    /// highest wins (`depth` 0: always the highest, the first of equals).
    Height {
        /// Width of the mixing band, in the units of the scores (0–1).
        depth: f32,
    },
    /// The splat's weights as they are.
    Linear,
}

impl Blend {
    /// Whether the blend reads the layers' heights.
    pub fn needs_heights(&self) -> bool {
        matches!(self, Blend::Height { .. })
    }

    /// The weights the layers' pixels are mixed with: from the splat's, and (for
    /// [`Blend::Height`]) each used layer's heights over the same pixels. A layer without splat
    /// weight at a pixel takes no part there, whatever its height.
    pub fn weights(&self, splat: &Weights, heights: &[Option<Heights>]) -> Weights {
        let Blend::Height { depth } = *self else { return splat.clone() };
        if splat.used().iter().filter(|u| **u).count() < 2 {
            return splat.clone();
        }
        let mut out = splat.clone();
        let layers = splat.layers;
        for (p, px) in out.w.chunks_exact_mut(layers).enumerate() {
            let score = |i: usize| px[i] + heights[i].as_ref().map_or(0.0, |h| h[p]);
            let mut best = None::<(usize, f32)>;
            for i in (0..layers).filter(|&i| px[i] > 0.0) {
                let s = score(i);
                if best.is_none_or(|(_, b)| s > b) {
                    best = Some((i, s));
                }
            }
            let Some((top, high)) = best else { continue };
            let mut raw = [0f32; super::MAX_LAYERS];
            let mut sum = 0.0;
            if depth > 0.0 {
                for i in (0..layers).filter(|&i| px[i] > 0.0) {
                    raw[i] = (score(i) - (high - depth)).max(0.0);
                    sum += raw[i];
                }
            }
            if sum > 0.0 {
                for (v, r) in px.iter_mut().zip(raw) {
                    *v = r / sum;
                }
            } else {
                px.iter_mut().for_each(|v| *v = 0.0);
                px[top] = 1.0;
            }
        }
        out
    }
}

/// Heights from a grey map's pixels (RGB bytes, the red channel).
pub fn grey_heights(rgb: &[u8]) -> Heights {
    rgb.chunks_exact(3).map(|c| c[0] as f32 / 255.0).collect()
}

/// Heights from colour: the luma (Rec. 601) of RGB bytes, for a layer without a height map.
pub fn luma_heights(rgb: &[u8]) -> Heights {
    rgb.chunks_exact(3).map(|c| (0.299 * c[0] as f32 + 0.587 * c[1] as f32 + 0.114 * c[2] as f32) / 255.0).collect()
}

/// The layers' pixels (RGB bytes, one image per used layer, `None` for layers without weight
/// anywhere) weighed by `weights`. A pixel of one layer alone is that layer's pixel, byte for
/// byte.
pub fn mix(weights: &Weights, images: &[Option<&[u8]>]) -> Vec<u8> {
    let mut out = vec![0u8; 3 * weights.pixels()];
    for (p, dst) in out.chunks_exact_mut(3).enumerate() {
        let w = weights.at(p);
        if let Some(i) = w.iter().position(|&v| v == 1.0) {
            if let Some(img) = images[i] {
                dst.copy_from_slice(&img[3 * p..3 * p + 3]);
            }
            continue;
        }
        let mut acc = [0f32; 3];
        for (i, img) in images.iter().enumerate() {
            if let Some(img) = img.filter(|_| w[i] > 0.0) {
                for c in 0..3 {
                    acc[c] += w[i] * img[3 * p + c] as f32;
                }
            }
        }
        for c in 0..3 {
            dst[c] = acc[c].round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn weights(w: &[f32]) -> Weights {
        Weights { layers: 2, width: w.len() / 2, height: 1, w: w.to_vec(), same: None }
    }

    #[test]
    fn the_taller_layer_wins_beyond_the_depth_and_they_mix_within() {
        let splat = weights(&[0.5, 0.5, 0.5, 0.5, 1.0, 0.0]);
        let heights = vec![Some(vec![0.9, 0.50, 0.1]), Some(vec![0.2, 0.45, 0.99])];
        let w = Blend::Height { depth: 0.2 }.weights(&splat, &heights);
        assert_eq!(w.at(0), &[1.0, 0.0], "0.7 higher: the first alone");
        assert!((w.at(1)[0] - 0.2 / 0.35).abs() < 1e-6, "within the depth: {:?}", w.at(1));
        assert_eq!(w.at(2), &[1.0, 0.0], "no splat weight, no part, however tall");
        assert_eq!(Blend::Linear.weights(&splat, &heights), splat);
    }

    #[test]
    fn a_pixel_of_one_layer_is_copied_and_others_are_weighed() {
        let w = weights(&[1.0, 0.0, 0.25, 0.75]);
        let (a, b) = ([10u8, 20, 30, 100, 100, 100], [0u8, 0, 0, 200, 0, 40]);
        assert_eq!(mix(&w, &[Some(&a), Some(&b)]), vec![10, 20, 30, 175, 25, 55]);
    }
}
