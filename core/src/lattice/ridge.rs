//! 1-D lattices: the ridges of the autocorrelation. A wave of period `t` along the normal `n`
//! (planks, courses of a wall) makes `A` high along whole lines `k·t·n + s·n⊥` and low half
//! way between them. A ridge's *value* `R(t)` is the mean of `A` along the line (over
//! `|s| ≤ side/6`); its *contrast* is the comb of its first two repeats, the lesser over
//! `k = 1, 2` of `R(k·t) − ½(R((k − ½)·t) + R((k + ½)·t))`: does the shift by the period (and
//! by twice it) predict the image better than the shift by half of it? A half period fails at
//! `k = 1`, a double one at the half-way points. Its *score* `z` is that contrast in noise
//! units: a line mean over `L` lags of which about `L / (2·r0)` are independent, three of them.

use rayon::prelude::*;

use super::acf::{parabola_peak, Autocorrelation};

/// Shortest period detected, in texels: finer repeats are texture, not lattice.
pub(super) const MIN_PERIOD: f64 = 6.0;

/// Degrees within which a fitted angle is taken to be the multiple of 45° it is near.
const AXIS_SNAP: f64 = 1.0;

/// Share of the fitted ridge's value the axis must keep to be taken instead.
const AXIS_SNAP_VALUE: f64 = 0.97;

/// Share of a ridge's contrast a sub-multiple must reach to be taken as the fundamental: an
/// odd multiple `3t` has a comb too (its half period is in opposite phase as well).
const FUNDAMENTAL_SHARE: f64 = 0.7;

/// One ridge of the autocorrelation: a direction of repeat and how well it predicts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ridge {
    /// Angle of the normal, degrees in `[0, 180)`.
    pub angle: f64,
    /// Period in texels.
    pub period: f64,
    /// Mean autocorrelation along the ridge.
    pub value: f64,
    /// The comb: the shift by the period against the shift by half of it (module comment).
    pub contrast: f64,
    /// The contrast in noise units.
    pub z: f64,
}

impl Autocorrelation {
    /// Half the length of a ridge's line, in lags.
    fn half_line(&self) -> i64 {
        (self.m / 6) as i64
    }

    /// Half the length of the line a ridge is scored on: long, so that a straight joint
    /// across the image counts for all of its length and short broken ripples do not.
    fn half_score_line(&self) -> i64 {
        (self.m / 3) as i64
    }

    /// `R(t)` along the normal at `angle`.
    fn ridge(&self, angle: f64, t: f64) -> f64 {
        self.line(angle, t, self.half_line())
    }

    /// The ridge at `angle`, `t`, scored (module comment).
    pub(super) fn ridge_at(&self, angle: f64, t: f64) -> Ridge {
        let r = |x: f64| self.line(angle, x, self.half_score_line());
        let comb = |k: f64| r(k * t) - 0.5 * (r((k - 0.5) * t) + r((k + 0.5) * t));
        let contrast = comb(1.0).min(comb(2.0));
        let length = (2 * self.half_score_line() + 1) as f64;
        let line_noise = self.sigma * ((2.0 * self.r0 + 1.0) / length).min(1.0).sqrt();
        let z = contrast / (line_noise * 1.5f64.sqrt());
        Ridge { angle, period: t, value: r(t), contrast, z }
    }

    /// Longest period scored: its comb's second repeat, `2.5·t`, within 0.45 of the side.
    pub(super) fn longest_period(&self) -> f64 {
        0.45 * self.m as f64 / 2.5
    }

    /// Every local maximum of every direction's ridge profile, 1° and half a texel apart, from
    /// [`MIN_PERIOD`] to [`Autocorrelation::longest_period`], scored.
    pub(super) fn ridges(&self) -> Vec<Ridge> {
        let steps = (self.longest_period() / 0.5).floor() as usize + 1;
        let per_angle: Vec<Vec<Ridge>> = (0..180)
            .into_par_iter()
            .map(|deg| {
                let angle = deg as f64;
                let profile: Vec<f64> = (0..=steps).map(|i| self.ridge(angle, i as f64 * 0.5)).collect();
                // Peaks of the profile above its value half a period before: only those can
                // have a comb (scored on long lines, the costly part).
                (1..steps)
                    .filter(|&i| {
                        let t = i as f64 * 0.5;
                        t >= MIN_PERIOD
                            && profile[i] >= profile[i - 1]
                            && profile[i] >= profile[i + 1]
                            && profile[i] > self.ridge(angle, t / 2.0)
                    })
                    .map(|i| self.ridge_at(angle, i as f64 * 0.5))
                    .collect()
            })
            .collect();
        per_angle.into_iter().flatten().collect()
    }

    /// `r`, or the shortest of its sub-multiples `t/k` that `passes` and has nearly its
    /// contrast: an odd multiple `3t` has a comb too.
    pub(super) fn fundamental(&self, r: Ridge, passes: impl Fn(&Ridge) -> bool) -> Ridge {
        // Only odd sub-multiples: `t`'s comb is its shift against the shift by `t/2`, so a
        // ridge that passes has no period `t/2` (nor `t/4`).
        for k in [5, 3] {
            // The sub-multiple's own peak, within a texel of `t / k` (a narrow joint's peak
            // falls between the samples of `r`'s half-texel scan).
            let t = (-4..=4)
                .map(|i| r.period / k as f64 + i as f64 * 0.25)
                .max_by(|a, b| self.ridge(r.angle, *a).total_cmp(&self.ridge(r.angle, *b)))
                .unwrap_or(r.period / k as f64);
            if t < MIN_PERIOD {
                continue;
            }
            let sub = self.ridge_at(r.angle, t);
            if passes(&sub) && sub.contrast >= FUNDAMENTAL_SHARE * r.contrast {
                return sub;
            }
        }
        r
    }

    /// `r`, or its double if that passes too: then `r` is half the period (its half-way
    /// points are in phase with the double's repeats), up to the longest period scored.
    pub(super) fn doubled(&self, mut r: Ridge, passes: impl Fn(&Ridge) -> bool) -> Ridge {
        while 2.0 * r.period <= self.longest_period() {
            let t = parabola_peak(2.0 * r.period, 0.5, |t| self.ridge(r.angle, t));
            let double = self.ridge_at(r.angle, t);
            if !passes(&double) {
                break;
            }
            r = double;
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

    /// A ridge's angle to a tenth of a degree and its period to a fraction of a texel: the
    /// angle maximising its value, then the period fitted through the parabolic peaks of its
    /// harmonics `k·t` within half the side; scored again there.
    pub(super) fn refine(&self, r: Ridge) -> Ridge {
        // The angle: of the value-maximising one on long lines (a third of the side each way,
        // where short ones barely turn) and the one the crests' slope gives, the better.
        let long = |a: f64| self.line(a, r.period, (self.m / 3) as i64);
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
        self.ridge_at(angle.rem_euclid(180.0), period)
    }
}
