//! Smooth multi-octave value noise on the landscape's texel grid, from the coordinate hash: the
//! same value for a texel in every window, process and thread count. With a period the lattice
//! of every octave is fitted to it (a whole number of cells across), so the noise repeats
//! exactly, at any period.

use crate::hash::{hash_keyed, key};

/// Fractal value noise in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    key: u64,
    /// Cell side of the coarsest octave, in texels.
    feature: f64,
    octaves: u32,
}

impl Noise {
    /// Noise of `octaves` octaves (each half the cell and half the amplitude of the one before)
    /// whose coarsest cells are `feature` texels across, under a hash `tag` and `seed`.
    pub fn new(tag: u64, seed: u64, feature: f64, octaves: u32) -> Noise {
        Noise { key: key(tag, seed), feature: feature.max(1.0), octaves: octaves.clamp(1, 8) }
    }

    /// The cell side of octave `o`, fitted to `period` texels when one is given.
    fn cell(&self, o: u32, period: Option<i64>) -> (f64, Option<i64>) {
        let c = self.feature / f64::from(1u32 << o);
        match period {
            Some(p) => {
                let n = ((p as f64 / c).round() as i64).max(1);
                (p as f64 / n as f64, Some(n))
            }
            None => (c, None),
        }
    }

    /// The value at texel point `(x, y)`, repeating every `period` texels when given.
    pub fn at(&self, x: f64, y: f64, period: Option<i64>) -> f64 {
        // Texel centres are exact binary fractions, so wrapping first makes the repeat exact.
        let (x, y) = match period {
            Some(p) => (x.rem_euclid(p as f64), y.rem_euclid(p as f64)),
            None => (x, y),
        };
        let (mut sum, mut amp, mut total) = (0.0, 1.0, 0.0);
        for o in 0..self.octaves {
            let (c, n) = self.cell(o, period);
            sum += amp * self.octave(o, x / c, y / c, n);
            total += amp;
            amp *= 0.5;
        }
        sum / total
    }

    /// One octave: lattice values at integer points, joined by a quintic fade.
    fn octave(&self, o: u32, gx: f64, gy: f64, n: Option<i64>) -> f64 {
        let (ix, iy) = (gx.floor(), gy.floor());
        let (fx, fy) = (fade(gx - ix), fade(gy - iy));
        let (ix, iy) = (ix as i64, iy as i64);
        let v = |a: i64, b: i64| {
            let (a, b) = match n {
                Some(n) => (a.rem_euclid(n), b.rem_euclid(n)),
                None => (a, b),
            };
            (hash_keyed(self.key, o as i64, a, b) >> 11) as f64 / (1u64 << 53) as f64
        };
        let top = v(ix, iy) + (v(ix + 1, iy) - v(ix, iy)) * fx;
        let bottom = v(ix, iy + 1) + (v(ix + 1, iy + 1) - v(ix, iy + 1)) * fx;
        top + (bottom - top) * fy
    }

    /// Values over a window's pixels (row-major), computed exactly at pixels whose coordinates
    /// are multiples of [`STRIDE`] and joined bilinearly between (the noise varies over many
    /// pixels at any zoom a landscape is served at), so a tile costs a sixteenth of the
    /// lookups. The grid is fixed to absolute pixel coordinates: any window equals the same
    /// area cut from any other.
    pub fn window(&self, view: crate::View, period: Option<i64>) -> Vec<f32> {
        self.grid(view, period).pixels()
    }

    /// The exact values under a window ([`Noise::window`] before joining them).
    pub fn grid(&self, view: crate::View, period: Option<i64>) -> Grid {
        let zoom = view.zoom_out as i64 - view.zoom_in as i64;
        let st = STRIDE as i64;
        let r = view.rect;
        let (gx0, gy0) = (r.x0.div_euclid(st), r.y0.div_euclid(st));
        let gw = ((r.x0 + r.width() - 1).div_euclid(st) - gx0 + 2) as usize;
        let gh = ((r.y0 + r.height() - 1).div_euclid(st) - gy0 + 2) as usize;
        let mut values = vec![0f64; gw * gh];
        for gj in 0..gh {
            let y = super::texel_centre((gy0 + gj as i64) * st, 0, zoom);
            for gi in 0..gw {
                let x = super::texel_centre((gx0 + gi as i64) * st, 0, zoom);
                values[gj * gw + gi] = self.at(x, y, period);
            }
        }
        Grid { values, gw, gx0, gy0, rect: r }
    }
}

/// Noise values at every [`STRIDE`]-th pixel under a window, and the window.
#[derive(Debug, Clone)]
pub struct Grid {
    values: Vec<f64>,
    gw: usize,
    gx0: i64,
    gy0: i64,
    rect: crate::Rect,
}

impl Grid {
    /// The least and the greatest value: every pixel's lies between (bilinear joins never
    /// leave the range of their corners).
    pub fn range(&self) -> (f64, f64) {
        self.values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)))
    }

    /// Every pixel's value, row-major.
    pub fn pixels(&self) -> Vec<f32> {
        let (st, s) = (STRIDE as i64, STRIDE as f64);
        let r = self.rect;
        let (w, h) = (r.width() as usize, r.height() as usize);
        let mut out = Vec::with_capacity(w * h);
        for j in 0..h {
            let py = r.y0 + j as i64;
            let (gj, fy) = ((py.div_euclid(st) - self.gy0) as usize, py.rem_euclid(st) as f64 / s);
            for i in 0..w {
                let px = r.x0 + i as i64;
                let (gi, fx) = ((px.div_euclid(st) - self.gx0) as usize, px.rem_euclid(st) as f64 / s);
                let at = |a: usize, b: usize| self.values[(gj + b) * self.gw + gi + a];
                let top = at(0, 0) + (at(1, 0) - at(0, 0)) * fx;
                let bottom = at(0, 1) + (at(1, 1) - at(0, 1)) * fx;
                out.push((top + (bottom - top) * fy) as f32);
            }
        }
        out
    }
}

/// Pixels between exact evaluations in [`Noise::window`].
pub const STRIDE: usize = 4;

fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Rect, View};

    #[test]
    fn noise_is_smooth_bounded_and_periodic_when_asked() {
        let n = Noise::new(1, 7, 100.0, 4);
        for i in 0..200 {
            let (x, y) = (i as f64 * 13.75 - 900.0, i as f64 * -7.25 + 40.5);
            let v = n.at(x, y, None);
            assert!((0.0..=1.0).contains(&v));
            assert!((n.at(x + 0.5, y, None) - v).abs() < 0.05, "smooth");
            let p = Some(1024);
            assert_eq!(n.at(x, y, p), n.at(x + 1024.0, y - 2048.0, p), "periodic");
        }
        assert_ne!(n.at(3.0, 4.0, None), Noise::new(1, 8, 100.0, 4).at(3.0, 4.0, None), "seeded");
    }

    #[test]
    fn a_window_is_the_same_wherever_it_is_cut_from() {
        let n = Noise::new(1, 3, 64.0, 3);
        let big = n.window(View::native(Rect::new(-9, 15, 32, 32)), None);
        let small = n.window(View::native(Rect::new(7, 31, 16, 16)), None);
        for j in 0..16 {
            for i in 0..16 {
                assert_eq!(small[j * 16 + i], big[(j + 16) * 32 + i + 16]);
            }
        }
    }
}
