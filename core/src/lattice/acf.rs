//! The autocorrelation detection reads a lattice from, and the noise its scores are measured
//! in.
//!
//! `A` is the luma's normalised autocorrelation, Hann-windowed, zero-padded and unbiased (each
//! lag divided by the window's own autocorrelation there), `A(0) = 1`. The lattice is looked
//! for in the luma minus its Gaussian blur of σ = side/8 ([`highpass`]): slow lighting is no
//! structure, and it would widen the central peak the noise is measured from.
//!
//! **Noise.** Bartlett's formula gives the variance of an autocorrelation estimate at a lag
//! away from the peaks as `Σ_u A(u)² / N` over the lags `u` where `A` is still correlated (here
//! the disc of radius `r0`, the first radius whose ring mean falls under 0.05). With the 2-D
//! Hann window the image's `m²` samples count as `N = (Σw²)² / Σw⁴ = ((3/8)² / (35/128))² · m²
//! ≈ 0.2645 · m²` effective ones (`design/lattice.md` §2 states it for the unwindowed
//! estimate, `N = m²`). That standard deviation, [`Autocorrelation::sigma`], is one noise
//! unit.

use rustfft::num_complex::Complex;
use rustfft::FftPlannerScalar;

/// Effective share of the samples the 2-D Hann window leaves: `((3/8)² / (35/128))²`.
const HANN_EFFECTIVE: f64 = 0.2645;

/// Ring mean of `A` under which lags are taken as uncorrelated (the radius `r0`).
const CORRELATED: f64 = 0.05;

/// The normalised autocorrelation of an image, at lags in `(-n/2, n/2)` (stored wrapped).
pub(super) struct Autocorrelation {
    /// Image side.
    pub(super) m: usize,
    /// Padded side (`2m`, up to a power of two).
    pub(super) n: usize,
    /// Values at integer lags, row-major, negative lags wrapped.
    pub(super) a: Vec<f64>,
    /// One noise unit: the standard deviation of `A` at a lag off the lattice (module comment).
    pub(super) sigma: f64,
    /// Radius within which `A` is correlated with the origin's peak, in texels.
    pub(super) r0: f64,
}

impl Autocorrelation {
    /// The autocorrelations of the `m × m` images `images`, in order (they share the window's
    /// own autocorrelation, which unbiases them).
    pub(super) fn of_all<const K: usize>(images: [&[f64]; K], m: usize) -> [Autocorrelation; K] {
        let n = (2 * m).next_power_of_two();
        let hann: Vec<f64> =
            (0..m)
                .map(|i| {
                    if m > 1 {
                        0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / (m - 1) as f64).cos()
                    } else {
                        1.0
                    }
                })
                .collect();
        let window = |x: usize, y: usize| hann[x] * hann[y];
        let power = |f: &dyn Fn(usize, usize) -> f64| {
            let mut buf = vec![Complex::new(0.0, 0.0); n * n];
            for y in 0..m {
                for x in 0..m {
                    buf[y * n + x] = Complex::new(f(x, y), 0.0);
                }
            }
            fft2(&mut buf, n, false);
            for c in buf.iter_mut() {
                *c = Complex::new(c.norm_sqr(), 0.0);
            }
            fft2(&mut buf, n, true);
            buf.into_iter().map(|c| c.re).collect::<Vec<f64>>()
        };
        let weight = power(&window);
        images.map(|luma| {
            let mean = luma.iter().sum::<f64>() / luma.len().max(1) as f64;
            let signal = power(&|x, y| (luma[y * m + x] - mean) * window(x, y));
            let mut a: Vec<f64> = signal.iter().zip(&weight).map(|(s, w)| s / w.max(1e-9)).collect();
            let zero = a[0].max(1e-12);
            a.iter_mut().for_each(|v| *v /= zero);
            let mut acf = Autocorrelation { m, n, a, sigma: 1.0, r0: 1.0 };
            (acf.sigma, acf.r0) = acf.bartlett();
            acf
        })
    }

    /// `A` at the integer lag `(x, y)`.
    #[inline]
    pub(super) fn grid(&self, x: i64, y: i64) -> f64 {
        let n = self.n as i64;
        self.a[(y.rem_euclid(n) * n + x.rem_euclid(n)) as usize]
    }

    /// `A` at the real-valued lag `(x, y)`, bilinear.
    #[inline]
    pub(super) fn at(&self, x: f64, y: f64) -> f64 {
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        (self.grid(x0, y0) * (1.0 - fx) + self.grid(x0 + 1, y0) * fx) * (1.0 - fy)
            + (self.grid(x0, y0 + 1) * (1.0 - fx) + self.grid(x0 + 1, y0 + 1) * fx) * fy
    }

    /// The highest `A` within `radius` of the lag `p` (and at `p` itself): a lattice point of a
    /// real, slightly drifting lattice is a peak near where the basis puts it.
    pub(super) fn near(&self, p: [f64; 2], radius: f64) -> f64 {
        let ri = radius.ceil() as i64;
        let (cx, cy) = (p[0].round() as i64, p[1].round() as i64);
        let mut best = self.at(p[0], p[1]);
        for dy in -ri..=ri {
            for dx in -ri..=ri {
                let (x, y) = (cx + dx, cy + dy);
                if (x as f64 - p[0]).hypot(y as f64 - p[1]) <= radius {
                    best = best.max(self.grid(x, y));
                }
            }
        }
        best
    }

    /// Whether the two copies at lag `p` overlap enough for `A` to be read there: a fifth of
    /// the image.
    pub(super) fn usable(&self, p: [f64; 2]) -> bool {
        let m = self.m as f64;
        (1.0 - p[0].abs() / m).max(0.0) * (1.0 - p[1].abs() / m).max(0.0) >= 0.2
    }

    /// Mean of `A` along the line at distance `t` along the normal at `angle` degrees, over
    /// `|s| ≤ half`.
    pub(super) fn line(&self, angle: f64, t: f64, half: i64) -> f64 {
        let (s, c) = angle.to_radians().sin_cos();
        let sum: f64 = (-half..=half).map(|k| self.at(t * c - k as f64 * s, t * s + k as f64 * c)).sum();
        sum / (2 * half + 1) as f64
    }

    /// Bartlett's noise of the estimate and the correlation radius `r0` (module comment).
    fn bartlett(&self) -> (f64, f64) {
        let half = (self.m / 2) as i64;
        let mut r0 = half.max(1);
        for r in 1..half {
            let ring: f64 = (0..64)
                .map(|i| {
                    let t = i as f64 * std::f64::consts::PI / 32.0;
                    self.at(r as f64 * t.cos(), r as f64 * t.sin())
                })
                .sum();
            if ring / 64.0 < CORRELATED {
                r0 = r;
                break;
            }
        }
        let mut sum = 0.0;
        for y in -r0..=r0 {
            for x in -r0..=r0 {
                if x * x + y * y <= r0 * r0 {
                    sum += self.grid(x, y).powi(2);
                }
            }
        }
        ((sum / (HANN_EFFECTIVE * (self.m * self.m) as f64)).sqrt().max(1e-6), r0 as f64)
    }
}

/// The luma minus its Gaussian blur of σ = side/8 (three box passes each way, mirrored edges,
/// running sums).
pub(super) fn highpass(luma: &[f64], m: usize) -> Vec<f64> {
    let sigma = m as f64 / 8.0;
    let w = ((4.0 * sigma * sigma + 1.0).sqrt().round() as usize) | 1;
    let r = (w / 2) as i64;
    let mm = m as i64;
    let mirror = |i: i64| -> usize {
        let mut j = i;
        // Mirrored until inside (a box wider than the image reflects more than once).
        while j < 0 || j >= mm {
            j = if j < 0 { -j - 1 } else { 2 * mm - j - 1 };
        }
        j as usize
    };
    // One box pass along a line read through `get`, written through `put`.
    let pass = |line: &mut dyn FnMut(usize) -> f64, out: &mut [f64]| {
        let mut sum: f64 = (-r..=r).map(|d| line(mirror(d))).sum();
        for (i, o) in out.iter_mut().enumerate() {
            *o = sum / w as f64;
            let i = i as i64;
            sum += line(mirror(i + r + 1)) - line(mirror(i - r));
        }
    };
    let mut b = luma.to_vec();
    let mut out = vec![0.0; m];
    for _ in 0..3 {
        for y in 0..m {
            pass(&mut |x| b[y * m + x], &mut out);
            b[y * m..(y + 1) * m].copy_from_slice(&out);
        }
        for x in 0..m {
            pass(&mut |y| b[y * m + x], &mut out);
            for (y, v) in out.iter().enumerate() {
                b[y * m + x] = *v;
            }
        }
    }
    luma.iter().zip(&b).map(|(l, v)| l - v).collect()
}

/// The 2×2 box reduction of an `m × m` image.
pub(super) fn halve(v: &[f64], m: usize) -> Vec<f64> {
    let h = m / 2;
    let mut out = vec![0.0; h * h];
    for y in 0..h {
        for x in 0..h {
            let i = 2 * y * m + 2 * x;
            out[y * h + x] = 0.25 * (v[i] + v[i + 1] + v[i + m] + v[i + m + 1]);
        }
    }
    out
}

/// The vertex of the parabola through `f(x − h), f(x), f(x + h)` (`x` where it is not a
/// maximum), kept within `h` of `x`.
pub(super) fn parabola_peak(x: f64, h: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (a, b, c) = (f(x - h), f(x), f(x + h));
    let d = a - 2.0 * b + c;
    if d >= 0.0 {
        return x;
    }
    x + (0.5 * (a - c) / d).clamp(-1.0, 1.0) * h
}

/// In-place 2-D FFT of an `n × n` row-major buffer (inverse unnormalised).
fn fft2(buf: &mut [Complex<f64>], n: usize, inverse: bool) {
    let mut planner = FftPlannerScalar::new();
    let fft = if inverse { planner.plan_fft_inverse(n) } else { planner.plan_fft_forward(n) };
    for row in buf.chunks_exact_mut(n) {
        fft.process(row);
    }
    let mut col = vec![Complex::new(0.0, 0.0); n];
    for x in 0..n {
        for y in 0..n {
            col[y] = buf[y * n + x];
        }
        fft.process(&mut col);
        for y in 0..n {
            buf[y * n + x] = col[y];
        }
    }
}
