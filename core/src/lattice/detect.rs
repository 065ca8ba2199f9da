//! Finding an exemplar's lattice from its pixels alone (after Liu, Lin & Hays 2004: the
//! lattice from the autocorrelation's peaks). The luma's normalised autocorrelation `A`
//! (Hann-windowed, zero-padded, unbiased) of a near-regular texture has peaks on its lattice
//! translations, and they line up in *ridges*: lines of lags `t·n + s·n⊥` along which `A` stays
//! high, one family per direction of repeat (a plank floor: one; tiles, bricks: two). A ridge's
//! *value* is the mean of `A` along the line `t·n` (over `|s| ≤ side/6`), its *contrast* the
//! value minus the value at half the period, where a repeat has its opposite phase.
//!
//! The rule that decides, measured on the development set and the shared materials
//! (`bench/README.md`, "Lattice detection"): a wave of period `t` from 6 texels to a quarter of
//! the side (a repeat seen at least four times, its second harmonic within half the side) whose ridge has value at least
//! [`RIDGE_MIN_VALUE`] and contrast at least [`RIDGE_MIN_CONTRAST`]; the strongest such ridge is
//! the first wave. The second, if any, comes from the first's crest lines: a peak passing the same
//! rule along the crest through the origin is the repeat along the rows, the best peak along the
//! next crest their stagger (square tiles 0, a running bond half a brick). Stochastic exemplars
//! have no such ridge (gravel 0.04, grass 0.02, granite 0.02, leaves 0.05 in value), the
//! near-regular ones do (brick 0.57, planks 0.64, cobblestones 0.14).
//!
//! Deterministic on every machine: scalar (no SIMD) FFTs in `f64` and results rounded to the
//! fixed point of [`Wave`].

use rustfft::num_complex::Complex;
use rustfft::FftPlannerScalar;

use super::exact::{self, Repeat};
use super::{Lattice, Origin, Wave, MIN_ANGLE};

/// Least ridge value (mean autocorrelation along the ridge) of a detected wave.
pub const RIDGE_MIN_VALUE: f64 = 0.12;

/// Least ridge contrast (value minus the value at half the period) of a detected wave.
pub const RIDGE_MIN_CONTRAST: f64 = 0.15;

/// Shortest period detected, in texels: finer repeats are texture, not lattice.
const MIN_PERIOD: f64 = 6.0;

/// Degrees within which a fitted angle is taken to be the multiple of 45° it is near.
const AXIS_SNAP: f64 = 1.0;

/// Share of the fitted ridge's value the axis must keep to be taken instead.
const AXIS_SNAP_VALUE: f64 = 0.97;

/// Share of a ridge's value a sub-multiple must reach to be taken as the fundamental: the
/// unbiased autocorrelation is noisier at long lags, where a multiple can come out higher
/// (boards every 19.3 with random fill: 0.45 at 19.3, 0.59 at 58).
const FUNDAMENTAL_SHARE: f64 = 0.7;

/// Side from which [`RIDGE_MIN_VALUE`] holds as it is.
const SMALL_SIDE: usize = 128;

/// Largest side analysed at full resolution; larger exemplars are box-reduced first.
const DETECT_SIDE: usize = 256;

/// One ridge of the autocorrelation: a direction of repeat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ridge {
    /// Angle of the normal, degrees in `[0, 180)`.
    pub angle: f64,
    /// Period in texels.
    pub period: f64,
    /// Mean autocorrelation along the ridge.
    pub value: f64,
    /// Value minus the value at half the period.
    pub contrast: f64,
}

/// What detection found: the exemplar's class ([`Detection::class`]), its exact repeat if it is
/// a tile repeated, the lattice the modes keep (for a tiling, the structure found *inside* one
/// tile), and the strongest ridges it weighed (its scores).
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// The translations that map the image onto itself, if it is a tile repeated.
    pub repeat: Option<Repeat>,
    /// The lattice, or `None` for a stochastic exemplar (or a tiling of stochastic content).
    pub lattice: Option<Lattice>,
    /// The lattice's waves as ridges (found, or for a rejected exemplar the strongest ridge and
    /// the strongest at least 20° from it: how close it came).
    pub ridges: Vec<Ridge>,
}

/// An exemplar's structure class.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    /// A tile repeated pixel for pixel.
    Exact,
    /// A near-regular lattice (1-D or 2-D).
    Lattice,
    /// Stochastic.
    None,
}

impl Class {
    /// `exact`, `lattice` or `none`.
    pub fn name(self) -> &'static str {
        match self {
            Class::Exact => "exact",
            Class::Lattice => "lattice",
            Class::None => "none",
        }
    }
}

impl Detection {
    /// Exact if the image is a tile repeated, else lattice if one was found, else none.
    pub fn class(&self) -> Class {
        match (&self.repeat, &self.lattice) {
            (Some(_), _) => Class::Exact,
            (None, Some(_)) => Class::Lattice,
            (None, None) => Class::None,
        }
    }

    /// The structure as `GET /textures/{id}` reports it (`structure`): `class`,
    /// `basis` (vectors `[dy, dx]` in exemplar texels: the copies for `exact`, the lattice's
    /// translations for `lattice`), `dimensions`, `scores`, and for `exact` the `tile` (its
    /// size when axis-aligned, its area) and the structure `inner` to one tile.
    pub fn summary(&self) -> serde_json::Value {
        let r = super::milli;
        let ridges: Vec<serde_json::Value> = self
            .ridges
            .iter()
            .map(|q| serde_json::json!({"period": r(q.period), "angle": r(q.angle), "value": r(q.value), "contrast": r(q.contrast)}))
            .collect();
        let lattice_part = |l: &Option<Lattice>| match l {
            Some(l) => serde_json::json!({
                "class": "lattice",
                "dimensions": l.waves.len(),
                "basis": l.basis().iter().map(|v| [r(v[1]), r(v[0])]).collect::<Vec<_>>(),
                "confidence": l.confidence as f64 / 1000.0,
            }),
            None => serde_json::json!({"class": "none", "dimensions": 0, "basis": []}),
        };
        let thresholds = serde_json::json!({
            "repeat": super::exact::COPY_MIN, "ridge_value": RIDGE_MIN_VALUE, "ridge_contrast": RIDGE_MIN_CONTRAST,
        });
        match &self.repeat {
            Some(rep) => {
                let (w, h) = rep.axis_size().unwrap_or((None, None));
                serde_json::json!({
                    "class": "exact",
                    "dimensions": rep.basis.len(),
                    "basis": rep.basis.iter().map(|v| [v[1], v[0]]).collect::<Vec<_>>(),
                    "tile": {"width": w, "height": h, "area": rep.area()},
                    "scores": {"repeat": rep.score as f64 / 1000.0, "ridges": ridges, "thresholds": thresholds},
                    "inner": lattice_part(&self.lattice),
                })
            }
            None => {
                let mut v = lattice_part(&self.lattice);
                v["scores"] = serde_json::json!({"repeat": null, "ridges": ridges, "thresholds": thresholds});
                v
            }
        }
    }
}

/// One line saying what a structure summary ([`Detection::summary`]) holds, for `textile info`
/// and `textile analyze`: `exact: a 64×32 tile repeated (copies [dy, dx] [32, 0] × [0, 64],
/// score 1.000); inside: none`, `lattice, 1-D: basis [dy, dx] [0, 18.03] (confidence 0.69)`,
/// `none (stochastic)`.
pub fn describe(summary: &serde_json::Value) -> String {
    let vecs = |v: &serde_json::Value| {
        let each: Vec<String> = v.as_array().into_iter().flatten().map(|b| b.to_string().replace(',', ", ")).collect();
        each.join(" × ")
    };
    let lattice = |v: &serde_json::Value| match v["class"].as_str() {
        Some("lattice") => format!(
            "lattice, {}-D: basis [dy, dx] {} (confidence {})",
            v["dimensions"],
            vecs(&v["basis"]),
            v["confidence"]
        ),
        _ => "none".to_string(),
    };
    match summary["class"].as_str() {
        Some("exact") => {
            let t = &summary["tile"];
            let tile = match (t["width"].as_i64(), t["height"].as_i64()) {
                (Some(w), Some(h)) => format!("a {w}×{h} tile repeated"),
                (Some(w), None) => format!("repeated every {w} texels across"),
                (None, Some(h)) => format!("repeated every {h} texels down"),
                _ => "a tile repeated".to_string(),
            };
            format!(
                "exact: {tile} (copies [dy, dx] {}, score {}); inside: {}",
                vecs(&summary["basis"]),
                summary["scores"]["repeat"],
                lattice(&summary["inner"])
            )
        }
        Some("lattice") => lattice(summary),
        _ => "none (stochastic)".to_string(),
    }
}

/// Detect the structure of the `w × h` exemplar `pixels` (see the module comment): its exact
/// repeat first, then the lattice, inside one tile for a tiling. A non-square exemplar is
/// looked at through its largest centred square: a lattice or a repeat is the same
/// everywhere in the image, and the square keeps the autocorrelation's lags isotropic.
pub fn detect(pixels: &[[u8; 3]], w: u32, h: u32) -> Detection {
    let (square, side) = crate::geom::centred_square(pixels, (w as usize, h as usize));
    detect_square(&square, side as u32)
}

/// [`detect`] on a `side × side` image.
fn detect_square(pixels: &[[u8; 3]], side: u32) -> Detection {
    let mut m = side as usize;
    let mut luma: Vec<f64> =
        pixels.iter().map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect();
    let mut scale = 1.0;
    while m > DETECT_SIDE {
        luma = halve(&luma, m);
        m /= 2;
        scale *= 2.0;
    }
    let a = Autocorrelation::new(&luma, m);
    let lags = exact::Lags { m: a.m, n: a.n, a: &a.a };
    let repeat = exact::find(pixels, side as usize, &lags, scale as usize);
    // A tiling's own period is no lattice: inside one tile, a wave must repeat at least twice.
    let inside = |r: &Ridge| {
        repeat.as_ref().is_none_or(|rep| {
            let (s, c) = r.angle.to_radians().sin_cos();
            rep.period_along([c, s]).is_none_or(|p| r.period * scale <= 0.5 * p + 0.5)
        })
    };
    let scan = a.scan();
    let Some(first) =
        scan.iter().copied().filter(|r| accepted(r, m) && inside(r)).max_by(|x, y| x.contrast.total_cmp(&y.contrast))
    else {
        return Detection { repeat, lattice: None, ridges: strongest(&scan) };
    };
    let first = a.refine(a.fundamental(first));
    let mut ridges = vec![first];
    if let Some(s) = a.along_crests(first).map(|r| a.refine_second(r)).filter(|r| inside(r)) {
        ridges.push(s);
    }
    let waves = ridges.iter().map(|r| Wave::new(r.period * scale, r.angle)).collect();
    let confidence = (first.contrast.clamp(0.0, 1.0) * 1000.0).round() as u32;
    Detection { repeat, lattice: Some(Lattice { waves, origin: Origin::Detected, confidence }), ridges }
}

/// Whether a ridge passes the rule.
///
/// The value threshold holds from a 128² image up; a smaller image's chance peaks are higher
/// (their noise falls as one over the side), so below it the threshold rises in proportion:
/// the 64² bark tile's strongest ridge (0.195) and the 32² leaves tile's (0.170) are chance.
fn accepted(r: &Ridge, m: usize) -> bool {
    let noise = (SMALL_SIDE as f64 / m.max(1) as f64).max(1.0);
    r.value >= RIDGE_MIN_VALUE * noise && r.contrast >= RIDGE_MIN_CONTRAST
}

/// The strongest ridge, and the strongest at least [`MIN_ANGLE`] from it (what a rejected
/// exemplar came closest to).
fn strongest(scan: &[Ridge]) -> Vec<Ridge> {
    let key = |r: &&Ridge| r.value.min(r.contrast);
    let Some(first) = scan.iter().max_by(|x, y| key(x).total_cmp(&key(y))).copied() else { return Vec::new() };
    let second = scan
        .iter()
        .filter(|r| {
            let d = (r.angle - first.angle).rem_euclid(180.0);
            d.min(180.0 - d) >= MIN_ANGLE
        })
        .max_by(|x, y| key(x).total_cmp(&key(y)))
        .copied();
    std::iter::once(first).chain(second).collect()
}

/// The 2×2 box reduction of an `m × m` image.
fn halve(v: &[f64], m: usize) -> Vec<f64> {
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

/// The normalised autocorrelation of an image, at lags in `(-n/2, n/2)` (stored wrapped).
struct Autocorrelation {
    /// Exemplar side.
    m: usize,
    /// Padded side (`2m`, up to a power of two).
    n: usize,
    /// Values at integer lags, row-major, negative lags wrapped.
    a: Vec<f64>,
}

impl Autocorrelation {
    fn new(luma: &[f64], m: usize) -> Autocorrelation {
        let n = (2 * m).next_power_of_two();
        let mean = luma.iter().sum::<f64>() / luma.len().max(1) as f64;
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
        let signal = power(&|x, y| (luma[y * m + x] - mean) * window(x, y));
        let weight = power(&window);
        let mut a: Vec<f64> = signal.iter().zip(&weight).map(|(s, w)| s / w.max(1e-9)).collect();
        let zero = a[0].max(1e-12);
        a.iter_mut().for_each(|v| *v /= zero);
        Autocorrelation { m, n, a }
    }

    /// `A` at the real-valued lag `(x, y)`, bilinear.
    #[inline]
    fn at(&self, x: f64, y: f64) -> f64 {
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let n = self.n as i64;
        let g = |xx: i64, yy: i64| self.a[(yy.rem_euclid(n) * n + xx.rem_euclid(n)) as usize];
        let (x0, y0) = (x0 as i64, y0 as i64);
        (g(x0, y0) * (1.0 - fx) + g(x0 + 1, y0) * fx) * (1.0 - fy)
            + (g(x0, y0 + 1) * (1.0 - fx) + g(x0 + 1, y0 + 1) * fx) * fy
    }

    /// Mean of `A` along the ridge line at distance `t` along the normal at `angle` degrees.
    fn ridge(&self, angle: f64, t: f64) -> f64 {
        self.ridge_over(angle, t, (self.m / 6) as i64)
    }

    /// [`Autocorrelation::ridge`] over `|s| ≤ half`.
    fn ridge_over(&self, angle: f64, t: f64, half: i64) -> f64 {
        let (s, c) = angle.to_radians().sin_cos();
        let sum: f64 = (-half..=half).map(|k| self.at(t * c - k as f64 * s, t * s + k as f64 * c)).sum();
        sum / (2 * half + 1) as f64
    }

    /// Every local maximum of every direction's ridge profile, 1° and half a texel apart.
    fn scan(&self) -> Vec<Ridge> {
        let steps = (self.m as f64 / 4.0 / 0.5).floor() as usize + 1;
        let mut out = Vec::new();
        for deg in 0..180 {
            let angle = deg as f64;
            let profile: Vec<f64> = (0..=steps).map(|i| self.ridge(angle, i as f64 * 0.5)).collect();
            for i in 1..steps {
                let t = i as f64 * 0.5;
                if t < MIN_PERIOD || profile[i] < profile[i - 1] || profile[i] < profile[i + 1] {
                    continue;
                }
                let contrast = profile[i] - self.ridge(angle, t / 2.0);
                out.push(Ridge { angle, period: t, value: profile[i], contrast });
            }
        }
        out
    }

    /// `r`, or the shortest of its sub-multiples `t/k` that is itself an accepted ridge nearly
    /// as strong: an odd harmonic `3t` has the contrast of `t` (its half period is in
    /// opposite phase too).
    fn fundamental(&self, r: Ridge) -> Ridge {
        for k in (2..=5).rev() {
            // The sub-multiple's own peak, within a texel of `t / k` (a narrow joint's peak
            // falls between the samples of `r`'s half-texel scan).
            let t = (-4..=4)
                .map(|i| r.period / k as f64 + i as f64 * 0.25)
                .max_by(|a, b| self.ridge(r.angle, *a).total_cmp(&self.ridge(r.angle, *b)))
                .unwrap_or(r.period / k as f64);
            if t < MIN_PERIOD {
                continue;
            }
            let value = self.ridge(r.angle, t);
            let sub = Ridge { angle: r.angle, period: t, value, contrast: value - self.ridge(r.angle, t / 2.0) };
            if accepted(&sub, self.m) && value >= FUNDAMENTAL_SHARE * r.value {
                return sub;
            }
        }
        r
    }

    /// The angle a ridge's crest line has: at each point `s` along the ridge the parabolic
    /// peak of `A` across it, and the weighted slope of the line through those crests
    /// corrects `angle` (twice).
    fn crest_slope(&self, mut angle: f64, period: f64) -> f64 {
        for _ in 0..2 {
            let (s_, c_) = angle.to_radians().sin_cos();
            let reach = (self.m as f64 / 3.0).min((self.m as f64 / 2.0 - period).max(0.0));
            let (mut sw, mut ss, mut st, mut sss, mut sst) = (0.0, 0.0, 0.0, 0.0, 0.0);
            let mut s = -reach.floor();
            while s <= reach {
                let across = |t: f64| self.at(t * c_ - s * s_, t * s_ + s * c_);
                let centre = (-2..=2)
                    .map(|d| period.round() + d as f64)
                    .max_by(|x, y| across(*x).total_cmp(&across(*y)))
                    .unwrap_or(period);
                let t = parabola_peak(centre, 1.0, across);
                let w = across(t).max(0.0).powi(2);
                (sw, ss, st, sss, sst) = (sw + w, ss + w * s, st + w * t, sss + w * s * s, sst + w * s * t);
                s += 1.0;
            }
            let den = sw * sss - ss * ss;
            if sw <= 0.0 || den.abs() < 1e-9 {
                break;
            }
            angle -= ((sw * sst - ss * st) / den).atan().to_degrees();
        }
        angle
    }

    /// The second wave, from the first one's crest lines (Liu, Lin & Hays's lattice from
    /// peaks): along the crest through the origin, lags `s·n⊥`, a repeat `P` shows as a peak
    /// with the rule's contrast (a plank floor has none: its crest is flat); along the next
    /// crest, `t·n + s·n⊥`, the shift `σ` of its best peak is the stagger (0 for square
    /// tiles, `P/2` for a running bond). The lattice of `P·n⊥` and `t·n + σ·n⊥` has the
    /// first wave and, as its other reciprocal vector, `n⊥/P − σ/(P·t)·n`, taken shortest.
    fn along_crests(&self, first: Ridge) -> Option<Ridge> {
        let (sn, cn) = first.angle.to_radians().sin_cos();
        let (n, perp) = ([cn, sn], [-sn, cn]);
        let crest =
            |k: f64, s: f64| self.at(k * first.period * n[0] + s * perp[0], k * first.period * n[1] + s * perp[1]);
        let reach = self.m as f64 / 4.0;
        // The first peak along the crest through the origin that passes the rule.
        let steps = (reach / 0.5).floor() as usize;
        let profile: Vec<f64> = (0..=steps + 1).map(|i| crest(0.0, i as f64 * 0.5)).collect();
        let peak = (1..=steps).find(|&i| {
            let t = i as f64 * 0.5;
            t >= MIN_PERIOD
                && profile[i] >= profile[i - 1]
                && profile[i] >= profile[i + 1]
                && accepted(
                    &Ridge { angle: 0.0, period: t, value: profile[i], contrast: profile[i] - crest(0.0, t / 2.0) },
                    self.m,
                )
        })?;
        let big_p = parabola_peak(peak as f64 * 0.5, 0.5, |s| crest(0.0, s));
        // Its harmonics within half the side refine it.
        let (mut num, mut den) = (0.0, 0.0);
        let mut k = 1.0;
        while k * big_p <= self.m as f64 / 2.0 {
            let t = parabola_peak((k * if den > 0.0 { num / den } else { big_p } * 2.0).round() / 2.0, 0.5, |s| {
                crest(0.0, s)
            });
            num += k * t;
            den += k * k;
            k += 1.0;
        }
        let big_p = if den > 0.0 { num / den } else { big_p };
        // The stagger: the best peak along the next crest, within half a repeat of its foot.
        let shifts = (-(big_p.floor() as i64)..=(big_p.floor() as i64)).map(|i| i as f64 * 0.5);
        let best = shifts.max_by(|x, y| crest(1.0, *x).total_cmp(&crest(1.0, *y))).unwrap_or(0.0);
        let sigma = parabola_peak(best, 0.5, |s| crest(1.0, s));
        // The other reciprocal vector, reduced against the first wave (k1 = n / t).
        let k1 = [n[0] / first.period, n[1] / first.period];
        let mut k2 = [
            perp[0] / big_p - sigma / (big_p * first.period) * n[0],
            perp[1] / big_p - sigma / (big_p * first.period) * n[1],
        ];
        let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
        let j = (dot(k2, k1) / dot(k1, k1)).round();
        k2 = [k2[0] - j * k1[0], k2[1] - j * k1[1]];
        let len = dot(k2, k2).sqrt();
        let angle = k2[1].atan2(k2[0]).to_degrees().rem_euclid(180.0);
        let gap = (angle - first.angle).rem_euclid(180.0);
        if gap.min(180.0 - gap) < MIN_ANGLE {
            return None; // a stagger this steep is beyond what the waves can hold apart
        }
        let value = profile[peak];
        Some(Ridge { angle, period: 1.0 / len, value, contrast: value - crest(0.0, big_p / 2.0) })
    }

    /// The second wave, as read off the crests, refined on its own ridge ([`Autocorrelation::refine`])
    /// where that ridge is at least as strong: a stagger read off one crest is off by a few
    /// tenths of a texel, the wave's own harmonics pin it (a diagonal tread: 24.16 at 43.8° from
    /// the crest, 24.75 at 45.0° refined). The refined wave stays within a texel and two degrees
    /// of the crest's, or the crest's is kept.
    fn refine_second(&self, r: Ridge) -> Ridge {
        let refined = self.refine(r);
        let turn = (refined.angle - r.angle).rem_euclid(180.0);
        let close = turn.min(180.0 - turn) <= 2.0 && (refined.period - r.period).abs() <= 1.0;
        if close && refined.value >= self.ridge(r.angle, r.period) {
            Ridge { contrast: r.contrast, ..refined }
        } else {
            r
        }
    }

    /// A ridge's angle to a tenth of a degree and its period to a fraction of a texel: the
    /// angle maximising its value, then the period fitted through the parabolic peaks of its
    /// harmonics `k·t` within half the side.
    fn refine(&self, r: Ridge) -> Ridge {
        // The angle: of the value-maximising one on long lines (a third of the side each way,
        // where short ones barely turn) and the one the crests' slope gives, the better.
        let long = |a: f64| self.ridge_over(a, r.period, (self.m / 3) as i64);
        let searched = (-15..=15)
            .map(|i| r.angle + i as f64 * 0.1)
            .max_by(|x, y| long(*x).total_cmp(&long(*y)))
            .unwrap_or(r.angle);
        let sloped = self.crest_slope(r.angle, r.period);
        let angle = if long(sloped) > long(searched) { sloped } else { searched };
        // Photographs of floors and walls are taken square to them: an angle within a degree
        // of a multiple of 45° whose ridge is as strong as the fitted one's, within the fit's
        // noise, is that multiple (a tenth of a degree is a texel of drift every 570).
        let axis = (angle / 45.0).round() * 45.0;
        let angle =
            if (angle - axis).abs() <= AXIS_SNAP && long(axis) >= AXIS_SNAP_VALUE * long(angle) { axis } else { angle };
        let (mut num, mut den) = (0.0, 0.0);
        let mut k = 1.0;
        while k * r.period <= self.m as f64 / 2.0 {
            let guess = if den > 0.0 { k * num / den } else { k * r.period };
            // The integer lag nearest the harmonic, moved to the sampled maximum around it.
            let centre = (-2..=2)
                .map(|d| guess.round() + d as f64)
                .map(|t| (t, self.ridge(angle, t)))
                .max_by(|x, y| x.1.total_cmp(&y.1))
                .map_or(guess.round(), |(t, _)| t);
            let t = parabola_peak(centre, 1.0, |t| self.ridge(angle, t));
            num += k * t;
            den += k * k;
            k += 1.0;
        }
        let period = if den > 0.0 { num / den } else { r.period };
        Ridge { angle: angle.rem_euclid(180.0), period, value: self.ridge(angle, period), contrast: r.contrast }
    }
}

/// The vertex of the parabola through `f(x − h), f(x), f(x + h)` (`x` where it is not a
/// maximum), kept within `h` of `x`.
fn parabola_peak(x: f64, h: f64, f: impl Fn(f64) -> f64) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A synthetic near-regular image: `f(x, y)` sampled on `side²`.
    fn image(side: u32, f: impl Fn(f64, f64) -> f64) -> Vec<[u8; 3]> {
        (0..side * side)
            .map(|i| {
                let v = f((i % side) as f64, (i / side) as f64).clamp(0.0, 255.0) as u8;
                [v, v, v]
            })
            .collect()
    }

    /// A little hashed noise, so that no image is exactly periodic.
    fn noise(x: f64, y: f64) -> f64 {
        let h = crate::hash::hash_keyed(7, x as i64, y as i64, 0);
        (h % 41) as f64 - 20.0
    }

    fn angle_gap(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(180.0);
        d.min(180.0 - d)
    }

    #[test]
    fn stripes_with_a_fractional_period() {
        let px = image(256, |x, y| if (x / 23.4).fract() < 0.15 { 40.0 } else { 170.0 + noise(x, y) });
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("stripes detected");
        assert_eq!(lat.waves.len(), 1, "{d:?}");
        let w = lat.waves[0];
        assert!((w.period() - 23.4).abs() < 0.1, "{d:?}");
        assert!(angle_gap(w.angle_deg(), 0.0) < 0.5, "{d:?}");
    }

    #[test]
    fn oblique_stripes() {
        let (c, s) = 33f64.to_radians().sin_cos();
        let px = image(256, |x, y| if ((x * s + y * c) / 19.3).fract() < 0.2 { 40.0 } else { 170.0 + noise(x, y) });
        let d = detect(&px, 256, 256);
        let w = d.lattice.clone().expect("stripes detected").waves[0];
        assert!((w.period() - 19.3).abs() < 0.1 && angle_gap(w.angle_deg(), 33.0) < 0.3, "{d:?}");
    }

    /// The wave of `lat` nearest `angle`, as (period, angle).
    fn wave_near(lat: &Lattice, angle: f64) -> (f64, f64) {
        let w =
            lat.waves.iter().min_by(|a, b| angle_gap(a.angle_deg(), angle).total_cmp(&angle_gap(b.angle_deg(), angle)));
        w.map_or((f64::NAN, f64::NAN), |w| (w.period(), w.angle_deg()))
    }

    #[test]
    fn square_tiles_with_a_fractional_pitch() {
        let p = 21.5;
        let px = image(
            256,
            |x, y| {
                if (x / p).fract() < 0.12 || (y / p).fract() < 0.12 {
                    50.0
                } else {
                    160.0 + noise(x, y)
                }
            },
        );
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("tiles detected");
        assert_eq!(lat.waves.len(), 2, "{d:?}");
        for a in [0.0, 90.0] {
            let (period, angle) = wave_near(&lat, a);
            assert!((period - p).abs() < 0.5 && angle_gap(angle, a) < 1.0, "{a}: {d:?}");
        }
    }

    #[test]
    fn running_bond() {
        // Courses 16 texels high, bricks 32 long, each course shifted by half a brick: the
        // lattice of (32, 0) and (16, 16).
        let px = image(256, |x, y| {
            let course = (y / 16.0).floor();
            let along = x + 16.0 * course.rem_euclid(2.0);
            if (y / 16.0).fract() < 0.15 || (along / 32.0).fract() < 0.08 {
                45.0
            } else {
                165.0 + noise(x, y)
            }
        });
        let d = detect(&px, 256, 256);
        let lat = d.lattice.clone().expect("bond detected");
        let (period, angle) = wave_near(&lat, 90.0);
        assert!((period - 16.0).abs() < 0.5 && angle_gap(angle, 90.0) < 1.0, "{d:?}");
        assert_eq!(lat.waves.len(), 2, "the bond's second wave: {d:?}");
        // Whichever second wave was found, the half-brick shift is a translation of the lattice.
        let k: Vec<[f64; 2]> = lat.waves.iter().map(|w| w.vector()).collect();
        for t in [[32.0, 0.0], [16.0, 16.0]] {
            for kv in &k {
                let phase = kv[0] * t[0] + kv[1] * t[1];
                assert!((phase - phase.round()).abs() < 0.05, "{t:?} is off the lattice {kv:?}: {d:?}");
            }
        }
    }

    #[test]
    fn noise_has_no_lattice() {
        let px = image(128, |x, y| 128.0 + 3.0 * noise(x, y));
        assert_eq!(detect(&px, 128, 128).lattice, None);
    }
}
