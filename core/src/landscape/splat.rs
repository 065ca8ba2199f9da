//! Where each layer of a landscape shows: a [`Splat`] gives every pixel of a window a weight
//! per layer (non-negative, summing to one), from noise ([`NoiseSplat`]: each layer a share of
//! the ground) or from a painted map ([`ImageSplat`]: palette colours or RGBA weights, placed
//! on the texel grid, its boundaries warped by noise). Both are functions of absolute texel
//! coordinates, so every window agrees with every other.

use super::noise::Noise;
use super::texel_centre;
use crate::View;

/// Hash tag of a noise splat's field.
const TAG_SPLAT: u64 = 0x5350_4C41_5400_0001;
/// Hash tags of an image splat's warp (x and y).
const TAG_WARP_X: u64 = 0x5741_5250_5800_0001;
const TAG_WARP_Y: u64 = 0x5741_5250_5900_0001;

/// Largest side of a painted splat, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 4096;
/// Largest painted splat file, in bytes.
pub const MAX_IMAGE_BYTES: usize = 16 << 20;

/// Why a splat cannot be made, naming the field at fault.
#[derive(Debug, thiserror::Error)]
pub enum SplatError {
    /// A field's value is outside what is allowed.
    #[error("'{field}': {message}")]
    Field {
        /// The field, as the configuration spells it.
        field: &'static str,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// The painted map is over the limits.
    #[error("'image': {0}")]
    TooLarge(String),
    /// The painted map is not a decodable image.
    #[error("'image' is not a decodable PNG: {0}")]
    Undecodable(String),
}

/// Per-pixel weights of every layer over a window: `w[p * layers + i]` is layer `i`'s at pixel
/// `p` (row-major); each pixel's weights are non-negative and sum to one. A window whose every
/// pixel has the same weights holds them once (`same`, and `w` empty).
#[derive(Debug, Clone, PartialEq)]
pub struct Weights {
    /// Layers.
    pub layers: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The weights.
    pub w: Vec<f32>,
    /// The weights of every pixel, when they are all the same.
    pub same: Option<Vec<f32>>,
}

impl Weights {
    /// The weights of pixel `p`.
    #[inline]
    pub fn at(&self, p: usize) -> &[f32] {
        match &self.same {
            Some(one) => one,
            None => &self.w[p * self.layers..(p + 1) * self.layers],
        }
    }

    /// Which layers have a weight above zero anywhere in the window.
    pub fn used(&self) -> Vec<bool> {
        let mut used = vec![false; self.layers];
        for px in self.w.chunks_exact(self.layers).chain(self.same.as_deref()) {
            for (u, &v) in used.iter_mut().zip(px) {
                *u |= v > 0.0;
            }
        }
        used
    }

    /// Pixels in the window.
    pub fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// The same weights at every pixel of the window (`raw` normalised as [`Weights::from_fn`]
    /// would).
    fn constant(layers: usize, view: View, raw: &[f32]) -> Weights {
        let one = Weights::from_fn(layers, View::native(crate::Rect::new(0, 0, 1, 1)), |_, px| px.copy_from_slice(raw));
        let (width, height) = (view.rect.width() as usize, view.rect.height() as usize);
        Weights { layers, width, height, w: Vec::new(), same: Some(one.w) }
    }

    /// Weights of `layers` layers from a function of the pixel index writing each pixel's raw
    /// (non-negative) weights; raw weights summing to zero give the first layer.
    fn from_fn(layers: usize, view: View, mut f: impl FnMut(usize, &mut [f32])) -> Weights {
        let (width, height) = (view.rect.width() as usize, view.rect.height() as usize);
        let mut w = vec![0f32; width * height * layers];
        for (p, px) in w.chunks_exact_mut(layers).enumerate() {
            f(p, px);
            let sum: f32 = px.iter().sum();
            if sum > 0.0 && sum.is_finite() {
                px.iter_mut().for_each(|v| *v /= sum);
            } else {
                px.iter_mut().for_each(|v| *v = 0.0);
                px[0] = 1.0;
            }
        }
        Weights { layers, width, height, w, same: None }
    }
}

/// Where each layer shows.
#[derive(Debug, Clone, PartialEq)]
pub enum Splat {
    /// Regions of a noise field.
    Noise(NoiseSplat),
    /// A painted map.
    Image(ImageSplat),
}

impl Splat {
    /// Layers it weighs.
    pub fn layers(&self) -> usize {
        match self {
            Splat::Noise(n) => n.boundaries.len() + 1,
            Splat::Image(i) => i.layers,
        }
    }

    /// The weights over `view` (the landscape's pixels and zoom) under `seed`, repeating every
    /// `period` texels when given (see [`Splat::check_period`]).
    pub fn weights(&self, view: View, seed: u64, period: Option<i64>) -> Weights {
        match self {
            Splat::Noise(n) => n.weights(view, seed, period),
            Splat::Image(i) => i.weights(view, seed, period),
        }
    }

    /// Whether the splat can repeat every `period` texels; if not, why.
    pub fn check_period(&self, period: i64) -> Result<(), String> {
        match self {
            Splat::Noise(_) => Ok(()),
            Splat::Image(i) => i.check_period(period),
        }
    }
}

/// Regions of fractal noise: the noise's value, mapped through its own distribution to a
/// uniform `u` in `[0, 1]`, is cut at the layers' cumulative shares, so each layer covers its
/// share of the ground; within `transition` (in the same units: about that fraction of the
/// ground lies in transitions) of a cut, the two layers mix.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseSplat {
    feature: f64,
    octaves: u32,
    boundaries: Vec<f64>,
    transition: f64,
    /// Quantiles of the noise's values, 0 % to 100 % in [`QUANTILES`] steps.
    quantiles: Vec<f64>,
}

/// Steps of a noise splat's quantile table.
const QUANTILES: usize = 128;

impl NoiseSplat {
    /// A noise splat: `shares` of the ground per layer (positive, normalised), the noise's
    /// `feature` size in texels (its coarsest octave), `octaves`, and the `transition` width.
    pub fn new(shares: &[f64], feature: f64, octaves: u32, transition: f64) -> Result<NoiseSplat, SplatError> {
        let field = |field, message: String| SplatError::Field { field, message };
        if shares.len() < 2 || shares.len() > super::MAX_LAYERS {
            return Err(field("shares", format!("one per layer, 2 to {} layers", super::MAX_LAYERS)));
        }
        if shares.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(field("shares", "every share must be a positive number".into()));
        }
        if !(feature.is_finite() && (4.0..=65536.0).contains(&feature)) {
            return Err(field("feature", format!("{feature} texels is outside [4, 65536]")));
        }
        if !(1..=8).contains(&octaves) {
            return Err(field("octaves", format!("{octaves} is outside [1, 8]")));
        }
        if !(transition.is_finite() && (0.0..=0.5).contains(&transition)) {
            return Err(field("transition", format!("{transition} is outside [0, 0.5]")));
        }
        let total: f64 = shares.iter().sum();
        let mut acc = 0.0;
        let boundaries = shares[..shares.len() - 1]
            .iter()
            .map(|s| {
                acc += s / total;
                acc
            })
            .collect();
        // The distribution of fractal noise does not depend on its seed: one sample of it, on a
        // grid that strides across many cells, serves every seed.
        let noise = Noise::new(TAG_SPLAT, 0, feature, octaves);
        let step = feature * 0.377;
        let mut values: Vec<f64> = (0..256 * 256)
            .map(|k| noise.at((k % 256) as f64 * step + 0.31, (k / 256) as f64 * step + 0.73, None))
            .collect();
        values.sort_by(f64::total_cmp);
        let quantiles = (0..=QUANTILES).map(|q| values[(q * (values.len() - 1)) / QUANTILES]).collect();
        Ok(NoiseSplat { feature, octaves, boundaries, transition, quantiles })
    }

    /// `u` in `[0, 1]`: where `v` falls in the noise's distribution.
    fn uniform(&self, v: f64) -> f64 {
        let q = &self.quantiles;
        let k = q.partition_point(|&x| x <= v);
        if k == 0 {
            return 0.0;
        }
        if k > QUANTILES {
            return 1.0;
        }
        let (a, b) = (q[k - 1], q[k]);
        let f = if b > a { (v - a) / (b - a) } else { 0.0 };
        ((k - 1) as f64 + f) / QUANTILES as f64
    }

    fn weights(&self, view: View, seed: u64, period: Option<i64>) -> Weights {
        let grid = Noise::new(TAG_SPLAT, seed, self.feature, self.octaves).grid(view, period);
        let layers = self.boundaries.len() + 1;
        // A window whose values all lie between two cuts, clear of their transitions, is one
        // layer's alone: no pixel need be looked at.
        let (lo, hi) = grid.range();
        // With a margin well beyond what rounding a pixel's value can move it, so that every
        // pixel's own evaluation would give the same.
        let (ulo, uhi) = (self.uniform(lo) - 1e-6, self.uniform(hi) + 1e-6);
        let half = self.transition / 2.0;
        let band = self.boundaries.partition_point(|&b| b + half <= ulo);
        let clear = self.boundaries.get(band).is_none_or(|&b| uhi < b - half)
            && (band == 0 || self.boundaries[band - 1] + half <= ulo);
        if clear {
            let mut raw = vec![0f32; layers];
            raw[band] = 1.0;
            return Weights::constant(layers, view, &raw);
        }
        let field = grid.pixels();
        let t = self.transition;
        Weights::from_fn(layers, view, |p, px| {
            let u = self.uniform(field[p] as f64);
            // How far past each cut: 1 beyond it, 0 before it, smooth within the transition.
            let past = |b: f64| -> f64 {
                if t <= 0.0 {
                    return if u >= b { 1.0 } else { 0.0 };
                }
                let x = ((u - b) / t + 0.5).clamp(0.0, 1.0);
                x * x * (3.0 - 2.0 * x)
            };
            let mut before = 1.0;
            for (i, w) in px.iter_mut().enumerate() {
                let after = self.boundaries.get(i).map_or(0.0, |&b| past(b));
                *w = (before - after).max(0.0) as f32;
                before = after;
            }
        })
    }
}

/// How a painted map says which layer a pixel is.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// Each layer is a colour; a pixel is the layer of the nearest colour.
    Palette(Vec<[u8; 3]>),
    /// Up to four layers are the R, G, B and A channels' weights.
    Channels,
}

/// What a landscape shows outside its painted map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outside {
    /// The map again, edge to edge.
    Repeat,
    /// One layer (its index).
    Layer(usize),
}

/// Where a painted map lies on the texel grid, and how its edges are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    /// Texels one map pixel covers.
    pub texels_per_pixel: f64,
    /// Texel of the map's top-left corner.
    pub origin: (f64, f64),
    /// Outside the map.
    pub outside: Outside,
    /// Amplitude in texels of the noise that moves the sampling point, so that pixel
    /// boundaries wander instead of showing as stairs (0: none).
    pub warp: f64,
}

/// A painted map: per pixel, the weights of the layers, sampled bilinearly at the (warped)
/// texel a landscape pixel shows.
#[derive(Debug, Clone, PartialEq)]
pub struct ImageSplat {
    width: usize,
    height: usize,
    layers: usize,
    /// Per map pixel, `layers` weights in 0–255.
    cells: Vec<u8>,
    place: Placement,
}

impl ImageSplat {
    /// Decode a painted map (PNG bytes) for `layers` layers read by `key`.
    pub fn decode(bytes: &[u8], layers: usize, key: &Key, place: Placement) -> Result<ImageSplat, SplatError> {
        let field = |field, message: String| SplatError::Field { field, message };
        if bytes.len() > MAX_IMAGE_BYTES {
            return Err(SplatError::TooLarge(format!(
                "{} bytes is over the {} MiB a splat may have",
                bytes.len(),
                MAX_IMAGE_BYTES >> 20
            )));
        }
        if !(2..=super::MAX_LAYERS).contains(&layers) {
            return Err(field("layers", format!("{layers} layers; a landscape has 2 to {}", super::MAX_LAYERS)));
        }
        match key {
            Key::Channels if layers > 4 => {
                return Err(field("key", format!("RGBA weights carry at most 4 layers, not {layers}; use a palette")))
            }
            Key::Palette(p) if p.len() != layers => {
                return Err(field("palette", format!("{} colours for {layers} layers; one per layer", p.len())))
            }
            _ => {}
        }
        if !(place.texels_per_pixel.is_finite() && (0.0625..=65536.0).contains(&place.texels_per_pixel)) {
            return Err(field("texels_per_pixel", format!("{} is outside [1/16, 65536]", place.texels_per_pixel)));
        }
        if !(place.origin.0.is_finite() && place.origin.1.is_finite())
            || place.origin.0.abs().max(place.origin.1.abs()) > 1e12
        {
            return Err(field("origin", "must be two finite texel coordinates within ±10^12".into()));
        }
        if !(place.warp.is_finite() && (0.0..=4096.0).contains(&place.warp)) {
            return Err(field("warp", format!("{} texels is outside [0, 4096]", place.warp)));
        }
        if let Outside::Layer(i) = place.outside {
            if i >= layers {
                return Err(field("outside", format!("layer {i} does not exist")));
            }
        }
        let format = image::guess_format(bytes).map_err(|e| SplatError::Undecodable(e.to_string()))?;
        if format != image::ImageFormat::Png {
            return Err(SplatError::Undecodable(format!("it is {format:?}; a splat is a PNG")));
        }
        let img = crate::image::decode_within(bytes, MAX_IMAGE_SIDE, 4 * 4096 * 4096 * 2).map_err(|e| match e {
            image::ImageError::Limits(_) => {
                SplatError::TooLarge(format!("over {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE} pixels"))
            }
            e => SplatError::Undecodable(e.to_string()),
        })?;
        if img.width().max(img.height()) > MAX_IMAGE_SIDE {
            return Err(SplatError::TooLarge(format!(
                "{}x{} pixels is over {MAX_IMAGE_SIDE}x{MAX_IMAGE_SIDE}",
                img.width(),
                img.height()
            )));
        }
        let rgba = img.to_rgba8();
        let (width, height) = (rgba.width() as usize, rgba.height() as usize);
        let mut cells = vec![0u8; width * height * layers];
        for (px, out) in rgba.pixels().zip(cells.chunks_exact_mut(layers)) {
            match key {
                Key::Channels => out.copy_from_slice(&px.0[..layers]),
                Key::Palette(p) => {
                    let d = |c: &[u8; 3]| (0..3).map(|k| (c[k] as i32 - px.0[k] as i32).pow(2)).sum::<i32>();
                    let best = (0..layers).min_by_key(|&i| (d(&p[i]), i)).unwrap_or(0);
                    out[best] = 255;
                }
            }
        }
        Ok(ImageSplat { width, height, layers, cells, place })
    }

    fn check_period(&self, period: i64) -> Result<(), String> {
        let tpp = self.place.texels_per_pixel;
        let (ew, eh) = (self.width as f64 * tpp, self.height as f64 * tpp);
        let fits = |e: f64| e.fract() == 0.0 && e > 0.0 && (period as f64 % e) == 0.0;
        match self.place.outside {
            Outside::Layer(_) => Err("a painted splat shown once (outside = a layer) does not repeat; use \
                                      outside = \"repeat\" for world="
                .into()),
            Outside::Repeat if !(fits(ew) && fits(eh)) => Err(format!(
                "the painted splat repeats every {ew}x{eh} texels, which does not divide the period of {period} texels"
            )),
            Outside::Repeat => Ok(()),
        }
    }

    /// The layer a map cell (or the ground outside the map) gives all its weight to, if one.
    fn sole(&self, cx: i64, cy: i64) -> Option<usize> {
        let (mw, mh) = (self.width as i64, self.height as i64);
        let inside = (0..mw).contains(&cx) && (0..mh).contains(&cy);
        if let (false, Outside::Layer(l)) = (inside, self.place.outside) {
            return Some(l);
        }
        let c = (cy.rem_euclid(mh) * mw + cx.rem_euclid(mw)) as usize * self.layers;
        let cell = &self.cells[c..c + self.layers];
        let mut nonzero = cell.iter().enumerate().filter(|(_, v)| **v > 0);
        match (nonzero.next(), nonzero.next()) {
            (Some((l, _)), None) => Some(l),
            _ => None,
        }
    }

    /// The layer every pixel of the window is wholly, if one: when every map cell the window's
    /// samples can reach (warp included) gives all its weight to that layer. Its pixels'
    /// own evaluation gives exactly that weight (one cell's one layer, normalised, is 1).
    fn sole_over(&self, view: View) -> Option<usize> {
        let p = &self.place;
        let zoom = view.zoom_out as i64 - view.zoom_in as i64;
        let r = view.rect;
        let edge = |x0: i64, n: i64, origin: f64| {
            let lo = (texel_centre(x0, 0, zoom) - p.warp - 1.0 - origin) / p.texels_per_pixel - 0.5;
            let hi = (texel_centre(x0, (n - 1) as usize, zoom) + p.warp + 1.0 - origin) / p.texels_per_pixel - 0.5;
            (lo.floor() as i64, hi.floor() as i64 + 1)
        };
        let (x0, x1) = edge(r.x0, r.width(), p.origin.0);
        let (y0, y1) = edge(r.y0, r.height(), p.origin.1);
        // A window over many cells is decided pixel by pixel.
        if (x1 - x0 + 1).saturating_mul(y1 - y0 + 1) > 4096 {
            return None;
        }
        let first = self.sole(x0, y0)?;
        for cy in y0..=y1 {
            for cx in x0..=x1 {
                if self.sole(cx, cy) != Some(first) {
                    return None;
                }
            }
        }
        Some(first)
    }

    fn weights(&self, view: View, seed: u64, period: Option<i64>) -> Weights {
        if let Some(l) = self.sole_over(view) {
            let mut raw = vec![0f32; self.layers];
            raw[l] = 1.0;
            return Weights::constant(self.layers, view, &raw);
        }
        let p = &self.place;
        let zoom = view.zoom_out as i64 - view.zoom_in as i64;
        let warp = |tag| {
            (p.warp > 0.0).then(|| Noise::new(tag, seed, (4.0 * p.texels_per_pixel).max(4.0), 2).window(view, period))
        };
        let (wx, wy) = (warp(TAG_WARP_X), warp(TAG_WARP_Y));
        let (w, h) = (view.rect.width() as usize, view.rect.height() as usize);
        let (mw, mh) = (self.width as i64, self.height as i64);
        let q = |t: f64, origin: f64| (t - origin) / p.texels_per_pixel - 0.5;
        // Unwarped, a pixel's place in the map is its column's and its row's: found once each.
        let (cols, rows): (Vec<Axis>, Vec<Axis>) = match (&wx, &wy) {
            (Some(_), _) | (_, Some(_)) => (Vec::new(), Vec::new()),
            _ => (
                (0..w).map(|i| Axis::at(q(texel_centre(view.rect.x0, i, zoom), p.origin.0), mw)).collect(),
                (0..h).map(|j| Axis::at(q(texel_centre(view.rect.y0, j, zoom), p.origin.1), mh)).collect(),
            ),
        };
        Weights::from_fn(self.layers, view, |i, px| {
            let (ax, ay) = match (&wx, &wy) {
                (Some(wx), Some(wy)) => {
                    let x = texel_centre(view.rect.x0, i % w, zoom) + (2.0 * wx[i] as f64 - 1.0) * p.warp;
                    let y = texel_centre(view.rect.y0, i / w, zoom) + (2.0 * wy[i] as f64 - 1.0) * p.warp;
                    (Axis::at(q(x, p.origin.0), mw), Axis::at(q(y, p.origin.1), mh))
                }
                _ => (cols[i % w], rows[i / w]),
            };
            for (b, fy) in [(0, 1.0 - ay.f), (1, ay.f)] {
                for (a, fx) in [(0, 1.0 - ax.f), (1, ax.f)] {
                    let f = fx * fy;
                    match (ax.inside[a] && ay.inside[b], p.outside) {
                        (false, Outside::Layer(l)) => px[l] += f as f32,
                        _ => {
                            let c = (ay.cell[b] * self.width + ax.cell[a]) * self.layers;
                            for (v, &cell) in px.iter_mut().zip(&self.cells[c..c + self.layers]) {
                                *v += (f * cell as f64) as f32;
                            }
                        }
                    }
                }
            }
        })
    }
}

/// Where a sample falls along one axis of a painted map: the two cells it lies between
/// (wrapped into the map), whether each is inside it, and how far past the first.
#[derive(Debug, Clone, Copy)]
struct Axis {
    cell: [usize; 2],
    inside: [bool; 2],
    f: f64,
}

impl Axis {
    /// At `q` map pixels (pixel centres at whole numbers) along an axis of `n` pixels.
    fn at(q: f64, n: i64) -> Axis {
        let i = q.floor() as i64;
        Axis {
            cell: [i.rem_euclid(n) as usize, (i + 1).rem_euclid(n) as usize],
            inside: [(0..n).contains(&i), (0..n).contains(&(i + 1))],
            f: q - q.floor(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Rect;

    fn png(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
        let img = image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)));
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).expect("png");
        out.into_inner()
    }

    #[test]
    fn noise_shares_are_the_ground_each_layer_covers() {
        let s = NoiseSplat::new(&[1.0, 3.0], 64.0, 4, 0.1).expect("splat");
        let w = s.weights(View::native(Rect::new(1000, -3000, 1024, 1024)), 5, None);
        let first: f32 = (0..w.pixels()).map(|p| w.at(p)[0]).sum::<f32>() / w.pixels() as f32;
        assert!((first - 0.25).abs() < 0.08, "first layer covers {first}");
        for p in 0..w.pixels() {
            assert!((w.at(p).iter().sum::<f32>() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn a_painted_map_weighs_by_palette_and_says_what_is_wrong() {
        let bytes = png(8, 8, |x, _| if x < 4 { [200, 0, 0, 255] } else { [0, 0, 200, 255] });
        let place = Placement { texels_per_pixel: 16.0, origin: (0.0, 0.0), outside: Outside::Layer(1), warp: 0.0 };
        let key = Key::Palette(vec![[255, 0, 0], [0, 0, 255]]);
        let s = ImageSplat::decode(&bytes, 2, &key, place).expect("splat");
        let w = s.weights(View::native(Rect::new(0, 0, 128, 128)), 0, None);
        assert_eq!(w.at(10 * 128 + 10), &[1.0, 0.0]);
        assert_eq!(w.at(10 * 128 + 120), &[0.0, 1.0]);
        let mid = w.at(10 * 128 + 64);
        assert!(mid[0] > 0.0 && mid[1] > 0.0, "a soft edge: {mid:?}");
        assert!(s.check_period(1024).is_err());
        assert!(matches!(ImageSplat::decode(b"not a png", 2, &key, place), Err(SplatError::Undecodable(_))));
        let e = ImageSplat::decode(&bytes, 5, &Key::Channels, place).unwrap_err();
        assert!(e.to_string().contains("at most 4"), "{e}");
    }
}
