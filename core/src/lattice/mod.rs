//! Near-regular textures (design note §1.9): planks at a spacing, bricks in a bond, tiles on a
//! grid. A [`Lattice`] is one or two *waves*: a direction and a period across which the
//! exemplar repeats (one wave: stripes, a 1-D lattice such as planks or the courses of a wall,
//! free along the stripes; two: a 2-D lattice, square, staggered or oblique, with real-valued
//! periods). Its *phase* at a position is where that position falls within each period.
//!
//! Synthesis keeps the lattice by keeping phases: at every level, every synthesized coordinate is snapped to the phase of its output position
//! ([`LevelLattice::snap`]) and second candidates must share their texel's phase
//! ([`LevelLattice::same_phase`]); the mosaic snaps its block offsets to lattice translations.
//! Cells then vary while the grid holds. Lattices are found from the exemplar alone
//! ([`detect`]) or given (`lattice = [nx, ny]` cells, or explicit periods and angles).

mod acf;
mod cell;
mod choice;
mod detect;
mod exact;
mod ridge;
mod structure;

pub use cell::Cell;
pub use choice::{LatticeChoice, SYNTAX};
pub use detect::{cell_margin, detect, ridge_margin, Class, Detection, MIN_CONTRAST, MIN_Z};
pub use exact::{Repeat, COPY_MIN, HALF_MAX};
pub use ridge::Ridge;
pub use structure::{Candidate, Scores, Structure, Thresholds, TileSize};

use serde::{Deserialize, Serialize};

use crate::error::{CoreError, Result};

/// Fixed-point unit of [`Wave`] periods and angles: 1/1024 of a texel or a degree, so that a
/// lattice hashes, compares and serialises exactly.
pub const UNIT: f64 = 1024.0;

/// One direction of repeat: the exemplar's content repeats every `period` texels along the
/// unit normal at `angle` degrees from +x (y down); stripes run perpendicular to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Wave {
    /// Period in 1/1024 texel.
    pub period: u32,
    /// Angle of the normal in 1/1024 degree, in `[0°, 180°)`.
    pub angle: u32,
}

impl Wave {
    /// A wave of `period` texels along the normal at `angle_deg` degrees (folded into
    /// `[0, 180)`, rounded to the fixed-point [`UNIT`]).
    pub fn new(period: f64, angle_deg: f64) -> Wave {
        let a = angle_deg.rem_euclid(180.0);
        let angle = ((a * UNIT).round() as u32) % (180 * UNIT as u32);
        Wave { period: (period * UNIT).round().max(1.0) as u32, angle }
    }

    /// Period in texels.
    pub fn period(&self) -> f64 {
        self.period as f64 / UNIT
    }

    /// Angle of the normal in degrees.
    pub fn angle_deg(&self) -> f64 {
        self.angle as f64 / UNIT
    }

    /// Wave vector `n / period` (cycles per texel): the phase of `p` is `k · p` modulo 1.
    pub fn vector(&self) -> [f64; 2] {
        let t = self.angle_deg().to_radians();
        let p = self.period();
        [t.cos() / p, t.sin() / p]
    }
}

/// Where a lattice came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// Found in the exemplar by [`detect`].
    Detected,
    /// Given: `nx × ny` cells, or explicit periods and angles.
    Given,
}

/// The lattice of a near-regular exemplar: one wave (1-D) or two (2-D).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Lattice {
    /// The waves, one or two, the second at least 20° from the first.
    pub waves: Vec<Wave>,
    /// Detected or given.
    pub origin: Origin,
    /// Detection's confidence in thousandths (the strongest ridge's contrast, see [`detect`]);
    /// 1000 for a given lattice.
    pub confidence: u32,
}

impl Lattice {
    /// A lattice of `nx × ny` cells over a `w × h` exemplar: `nx` must divide the width and
    /// `ny` the height, so that cells are whole texels.
    pub fn cells(nx: u32, ny: u32, w: u32, h: u32) -> Result<Lattice> {
        for (n, side) in [(nx, w), (ny, h)] {
            if n == 0 || n > side || !side.is_multiple_of(n) {
                return Err(CoreError::Param {
                    name: "lattice",
                    message: format!(
                        "{nx}x{ny} does not divide the {w}x{h} exemplar into whole cells: \
                         each count must divide its side ({w} across, {h} down)"
                    ),
                });
            }
        }
        let mut waves = Vec::new();
        if nx > 1 {
            waves.push(Wave::new(w as f64 / nx as f64, 0.0));
        }
        if ny > 1 {
            waves.push(Wave::new(h as f64 / ny as f64, 90.0));
        }
        Lattice::given(waves, crate::geom::Size::new(w, h).longer())
    }

    /// A lattice of the given waves (`(period, angle°)`): one or two, periods from 2 texels to
    /// `side` (the exemplar's longer side), two waves at least 20° apart.
    pub fn given(waves: Vec<Wave>, side: u32) -> Result<Lattice> {
        let bad = |message: String| Err(CoreError::Param { name: "lattice", message });
        if waves.is_empty() || waves.len() > 2 {
            return bad(format!("{} periods: give one (stripes) or two (a grid)", waves.len()));
        }
        for w in &waves {
            if w.period() < 2.0 || w.period() > side as f64 {
                return bad(format!("period {:.2} is outside 2..={side} texels", w.period()));
            }
        }
        if let [a, b] = waves[..] {
            let d = (a.angle_deg() - b.angle_deg()).rem_euclid(180.0);
            if d.min(180.0 - d) < MIN_ANGLE {
                return bad(format!(
                    "the two directions {:.1}° and {:.1}° are less than {MIN_ANGLE}° apart",
                    a.angle_deg(),
                    b.angle_deg()
                ));
            }
        }
        Ok(Lattice { waves, origin: Origin::Given, confidence: 1000 })
    }

    /// Whether the lattice is 1-D (stripes).
    pub fn is_stripes(&self) -> bool {
        self.waves.len() == 1
    }

    /// The lattice's basis vectors in texels: for two waves the primitive translations `a, b`
    /// (`kᵢ·a, kᵢ·b` whole numbers), reduced to the shortest pair; for one wave the single
    /// translation across the stripes.
    pub fn basis(&self) -> Vec<[f64; 2]> {
        match self.waves[..] {
            [w] => {
                let [kx, ky] = w.vector();
                let q = kx * kx + ky * ky;
                vec![[kx / q, ky / q]]
            }
            [w1, w2] => {
                let ([a, b], [c, d]) = (w1.vector(), w2.vector());
                let det = a * d - b * c;
                // Columns of K⁻¹: k₁·u = 1, k₂·u = 0 and k₁·v = 0, k₂·v = 1.
                let (u, v) = ([d / det, -c / det], [-b / det, a / det]);
                reduce(u, v).to_vec()
            }
            _ => Vec::new(),
        }
    }

    /// The whole lattice's constants: every wave held (mosaic's block offsets).
    pub fn whole(&self) -> LevelLattice {
        let active: Vec<[f64; 2]> = self.waves.iter().map(|w| w.vector()).collect();
        LevelLattice::new(&active, self.waves.iter().map(|w| w.period()).fold(0.0, f64::max))
    }

    /// The lattice's constants for the synthesis level of stride `h`, on an exemplar whose
    /// longer side is `side`. Stripes hold at every level: their free axis is where the cells vary, and held
    /// only from half a period up (LH05's rule) plank gaps and brick columns wander at the finer
    /// levels — texq `lattice` 0.35 planks, 0.56 cobblestones, 0.54 brick, against 1.02, 0.92,
    /// 0.78 held at every level, nn_err no worse (bench/README.md). A grid's only freedom is
    /// which cell goes where, so held at every level the correction copies the exemplar's own
    /// arrangement; a grid wave that repeats `n` times across the exemplar holds from the stride
    /// `period / min(n, 8)` up (at least half a period): the more cells there are to choose
    /// from, the finer the levels that keep them in phase (8 × 8 square tiles: lattice 0.96,
    /// copy_frac 0.30; from half a period up 0.24; the 2 × 4 rectified corkboard keeps LH05's
    /// half a period, finer it is a tiling).
    pub fn level(&self, h: i64, side: u32) -> LevelLattice {
        if self.is_stripes() {
            return self.whole();
        }
        let holds = |w: &&Wave| w.period() <= h as f64 * (side as f64 / w.period()).floor().clamp(2.0, 8.0);
        let held: Vec<[f64; 2]> = self.waves.iter().filter(holds).map(|w| w.vector()).collect();
        let longest = self.waves.iter().filter(holds).map(|w| w.period()).fold(0.0, f64::max);
        LevelLattice::new(&held, longest)
    }

    /// The lattice as `GET /textures/{id}` reports it (`exemplar.lattice`): `kind`
    /// (`stripes` or `grid`), `waves` (period in texels, angle of the normal in degrees),
    /// `basis` (translation vectors in texels, each `[dy, dx]` as `structure.basis` and the
    /// `lattice` setting give them), `confidence` (0–1), `origin`.
    pub fn summary(&self) -> serde_json::Value {
        let r = milli;
        serde_json::json!({
            "kind": if self.is_stripes() { "stripes" } else { "grid" },
            "waves": self.waves.iter().map(|w| serde_json::json!({"period": r(w.period()), "angle": r(w.angle_deg())})).collect::<Vec<_>>(),
            "basis": self.basis().iter().map(|v| [r(v[1]), r(v[0])]).collect::<Vec<_>>(),
            "confidence": self.confidence as f64 / 1000.0,
            "origin": self.origin,
        })
    }

    /// Feed the lattice to a hasher (exemplar and analysis identity).
    pub fn hash_into(&self, h: &mut blake3::Hasher) {
        h.update(b"lattice-waves");
        for w in &self.waves {
            h.update(&w.period.to_le_bytes());
            h.update(&w.angle.to_le_bytes());
        }
    }
}

/// `v` rounded to thousandths for reports (and never `-0`).
pub(crate) fn milli(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0 + 0.0
}

/// Least angle between two waves, in degrees.
pub const MIN_ANGLE: f64 = 20.0;

/// Largest phase difference, in texels along a wave, that [`LevelLattice::same_phase`] accepts:
/// below a texel, so a lattice of whole-texel cells asks for exactly the same phase.
pub const PHASE_TOLERANCE: f64 = 0.75;

/// The shortest basis of the lattice spanned by `u, v` (Lagrange–Gauss reduction).
pub(super) fn reduce(mut u: [f64; 2], mut v: [f64; 2]) -> [[f64; 2]; 2] {
    let dot = |a: [f64; 2], b: [f64; 2]| a[0] * b[0] + a[1] * b[1];
    for _ in 0..64 {
        if dot(u, u) > dot(v, v) {
            std::mem::swap(&mut u, &mut v);
        }
        let m = (dot(u, v) / dot(u, u)).round();
        if m == 0.0 {
            break;
        }
        v = [v[0] - m * u[0], v[1] - m * u[1]];
    }
    [u, v]
}

/// `x` wrapped into `[-½, ½)`.
#[inline]
fn wrap_half(x: f64) -> f64 {
    x - (x + 0.5).floor()
}

/// A lattice as synthesis applies it: its wave vectors, with what snapping needs precomputed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelLattice {
    /// Active wave vectors (the first `count`).
    k: [[f64; 2]; 2],
    count: usize,
    /// Maps phase errors to the texel move that cancels them.
    solve: [[f64; 2]; 2],
    /// Half the longest period of the lattice, rounded up: the farthest a snap moves.
    pub reach: i64,
}

impl LevelLattice {
    /// No constraint.
    pub const FREE: LevelLattice = LevelLattice { k: [[0.0; 2]; 2], count: 0, solve: [[0.0; 2]; 2], reach: 0 };

    fn new(active: &[[f64; 2]], longest: f64) -> LevelLattice {
        let reach = (longest / 2.0).ceil() as i64 + 1;
        match *active {
            [k] => {
                let q = k[0] * k[0] + k[1] * k[1];
                LevelLattice { k: [k, [0.0; 2]], count: 1, solve: [[k[0] / q, 0.0], [k[1] / q, 0.0]], reach }
            }
            [k1, k2] => {
                let det = k1[0] * k2[1] - k1[1] * k2[0];
                let solve = [[k2[1] / det, -k1[1] / det], [-k2[0] / det, k1[0] / det]];
                LevelLattice { k: [k1, k2], count: 2, solve, reach }
            }
            _ => LevelLattice::FREE,
        }
    }

    /// A grid's two basis translations in whole texels, when the level holds a grid whose
    /// translations are whole (a rectified lattice of cells); `None` otherwise.
    pub fn grid_translations(&self) -> Option<[(i64, i64); 2]> {
        if self.count != 2 {
            return None;
        }
        let whole = |x: f64| (x - x.round()).abs() < 1e-6;
        let (a, b) = ((self.solve[0][0], self.solve[1][0]), (self.solve[0][1], self.solve[1][1]));
        (whole(a.0) && whole(a.1) && whole(b.0) && whole(b.1))
            .then(|| [(a.0.round() as i64, a.1.round() as i64), (b.0.round() as i64, b.1.round() as i64)])
    }

    /// Whether this level is free of the lattice.
    pub fn is_free(&self) -> bool {
        self.count == 0
    }

    /// The texel move that puts a coordinate `u` on the phase of position `p`: the nearest
    /// `δ` (rounded to whole texels) with `kᵢ·(u + δ) ≡ kᵢ·p (mod 1)` for every active wave.
    #[inline]
    pub fn snap(&self, u: (i64, i64), p: (i64, i64)) -> (i64, i64) {
        if self.count == 0 {
            return (0, 0);
        }
        let (dx, dy) = ((p.0 - u.0) as f64, (p.1 - u.1) as f64);
        let e0 = wrap_half(self.k[0][0] * dx + self.k[0][1] * dy);
        let e1 = if self.count == 2 { wrap_half(self.k[1][0] * dx + self.k[1][1] * dy) } else { 0.0 };
        let mx = self.solve[0][0] * e0 + self.solve[0][1] * e1;
        let my = self.solve[1][0] * e0 + self.solve[1][1] * e1;
        (mx.round() as i64, my.round() as i64)
    }

    /// `d` moved to the nearest lattice translation (rounded to whole texels).
    #[inline]
    pub fn translation(&self, d: (i64, i64)) -> (i64, i64) {
        let (mx, my) = self.snap(d, (0, 0));
        (d.0 + mx, d.1 + my)
    }

    /// Whether `d` is a lattice translation within [`PHASE_TOLERANCE`] texels along every
    /// active wave.
    #[inline]
    pub fn same_phase(&self, d: (i64, i64)) -> bool {
        (0..self.count).all(|i| {
            let [kx, ky] = self.k[i];
            let q = (kx * kx + ky * ky).sqrt();
            wrap_half(kx * d.0 as f64 + ky * d.1 as f64).abs() <= PHASE_TOLERANCE * q
        })
    }
}

impl std::fmt::Display for Lattice {
    /// `grid of [dy, dx] [0.00, 20.50] × [14.00, 10.25] texels, detected, confidence 0.62`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let z = |x: f64| if x.abs() < 0.005 { 0.0 } else { x }; // no "-0.00"
        let vecs: Vec<String> = self.basis().iter().map(|v| format!("[{:.2}, {:.2}]", z(v[1]), z(v[0]))).collect();
        let kind = if self.is_stripes() { "stripes every" } else { "grid of" };
        let origin = match self.origin {
            Origin::Detected => "detected",
            Origin::Given => "given",
        };
        write!(
            f,
            "{kind} [dy, dx] {} texels, {origin}, confidence {:.2}",
            vecs.join(" × "),
            self.confidence as f64 / 1000.0
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_must_divide_the_side() {
        assert!(Lattice::cells(2, 4, 128, 128).is_ok());
        assert!(Lattice::cells(1, 64, 128, 128).is_ok());
        for (nx, ny) in [(3, 4), (0, 2), (2, 256), (2, 6)] {
            let e = Lattice::cells(nx, ny, 128, 128).unwrap_err().to_string();
            assert!(e.contains("lattice") && e.contains(&format!("{nx}x{ny}")), "{e}");
        }
    }

    #[test]
    fn cells_are_two_waves() {
        let l = Lattice::cells(2, 4, 128, 128).unwrap();
        let b = l.basis();
        assert!(b[0][0].abs() < 1e-9 && (b[0][1] - 32.0).abs() < 1e-9 && (b[1][0] - 64.0).abs() < 1e-9, "{b:?}");
        assert_eq!(l.whole().count, 2);
        assert_eq!(Lattice::cells(1, 4, 128, 128).unwrap().whole().count, 1);
        // A grid wave repeating n times holds from period / n up (n from 2 to 8): the 64-texel
        // one (n = 2) from stride 32, the 32-texel one (n = 4) from stride 8, none below.
        assert_eq!([32, 16, 8, 4].map(|h| l.level(h, 128).count), [2, 1, 1, 0]);
    }

    #[test]
    fn snapping_lands_on_the_phase_of_the_position() {
        // A staggered lattice: a = (20.5, 0), b = (10.25, 14).
        let (a, b) = ([20.5, 0.0], [10.25, 14.0]);
        // Its waves: normals of the lines through b (and through a).
        let w1 = Wave::new(14.0, 90.0);
        let n2 = (-b[1], b[0]);
        let len = f64::hypot(n2.0, n2.1);
        let w2 = Wave::new((a[0] * n2.0 + a[1] * n2.1).abs() / len, f64::atan2(n2.1, n2.0).to_degrees());
        let lat = Lattice::given(vec![w1, w2], 256).unwrap();
        let basis = lat.basis();
        for v in &basis {
            let on =
                |t: [f64; 2]| ((t[0] - v[0]).hypot(t[1] - v[1]) < 0.01) || ((t[0] + v[0]).hypot(t[1] + v[1]) < 0.01);
            let ab = [a[0] - b[0], a[1] - b[1]];
            assert!(on(a) || on(b) || on(ab), "{basis:?}");
        }
        let lv = lat.whole();
        for (u, p) in [((3, 9), (100, 40)), ((-50, 7), (0, 0)), ((17, 17), (-300, 1000))] {
            let (mx, my) = lv.snap(u, p);
            assert!(mx.abs() <= 12 && my.abs() <= 8, "{mx},{my}");
            let moved = (u.0 + mx - p.0, u.1 + my - p.1);
            assert!(lv.same_phase(moved), "{u:?} {p:?} -> {moved:?}");
        }
        assert_eq!(lv.translation((41, 0)), (41, 0));
        assert!(lv.same_phase((-10, -14)));
        assert!(!lv.same_phase((5, 0)));
    }

    #[test]
    fn stripes_leave_the_other_axis_free() {
        let lat = Lattice::given(vec![Wave::new(42.7, 0.0)], 256).unwrap();
        let lv = lat.level(1, 256);
        assert_eq!(lv.snap((10, 5), (10, 99)), (0, 0));
        assert_eq!(lv.snap((10, 5), (31, 5)), (21, 0));
        assert!(lv.same_phase((85, 13)) && !lv.same_phase((21, 0)));
    }

    #[test]
    fn given_lattices_are_checked() {
        assert!(Lattice::given(vec![], 128).is_err());
        assert!(Lattice::given(vec![Wave::new(1.0, 0.0)], 128).is_err());
        assert!(Lattice::given(vec![Wave::new(10.0, 0.0), Wave::new(10.0, 10.0)], 128).is_err());
        assert!(Lattice::given(vec![Wave::new(10.0, 170.0), Wave::new(10.0, 5.0)], 128).is_err());
        assert!(Lattice::given(vec![Wave::new(10.0, 0.0), Wave::new(10.0, 45.0)], 128).is_ok());
    }
}
