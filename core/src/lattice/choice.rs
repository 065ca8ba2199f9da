//! How a texture says which lattice it has: `auto` (detected, the default), `none`, `[nx, ny]`
//! cells of a rectified exemplar, explicit basis vectors (`[[dy, dx], [dy, dx]]` or `[[dy, dx]]`,
//! exemplar texels) or explicit waves (`{ period, angle }`, one or two). One spelling in
//! configuration files (serde), and on the command line and in upload fields
//! ([`std::str::FromStr`]: the vectors as the same JSON text).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{Lattice, Wave, MIN_ANGLE};
use crate::error::{CoreError, Result};

/// A texture's lattice setting.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum LatticeChoice {
    /// Detected from the exemplar ([`super::detect`]).
    #[default]
    Auto,
    /// No lattice: synthesis is free at every level.
    None,
    /// `nx × ny` cells tiling a rectified, toroidal exemplar (each a power of two).
    Cells(u32, u32),
    /// Explicit waves: `(period in texels, angle of the normal in degrees)`, one or two.
    Waves(Vec<(f64, f64)>),
    /// Explicit basis vectors `[dy, dx]` in exemplar texels: two for a grid (any angle: square,
    /// staggered, diagonal), one for stripes (the translation across them; free along them).
    Vectors(Vec<[f64; 2]>),
}

impl LatticeChoice {
    /// Whether the exemplar must be toroidal (cells tile it).
    pub fn needs_toroidal(&self) -> bool {
        matches!(self, LatticeChoice::Cells(..))
    }

    /// The lattice this setting names explicitly on a `w × h` exemplar (cells, waves or
    /// vectors, checked); `None` for `auto`, whose lattice is detected from the pixels
    /// ([`super::detect`]), and for `none`.
    pub fn explicit(&self, w: u32, h: u32) -> Result<Option<Lattice>> {
        let side = crate::geom::Size::new(w, h).longer();
        Ok(match self {
            LatticeChoice::Auto | LatticeChoice::None => None,
            LatticeChoice::Cells(nx, ny) => Some(Lattice::cells(*nx, *ny, w, h)?),
            LatticeChoice::Waves(w) => {
                // The periods as given, before a wave rounds them to its fixed point.
                if let Some((p, _)) = w.iter().find(|(p, _)| !(2.0..=side as f64).contains(p)) {
                    return Err(CoreError::Param {
                        name: "lattice",
                        message: format!("period {} is outside 2..={side} texels", number(*p)),
                    });
                }
                Some(Lattice::given(w.iter().map(|&(p, a)| Wave::new(p, a)).collect(), side)?)
            }
            LatticeChoice::Vectors(v) => Some(Lattice::given(waves_of(v, side)?, side)?),
        })
    }
}

/// A number as an error message shows it: as given up to three decimals, in scientific
/// notation from a million on (a hostile `1e300` does not come back as 301 digits).
fn number(x: f64) -> String {
    if x.abs() >= 1e6 {
        format!("{x:.3e}")
    } else {
        format!("{}", (x * 1000.0).round() / 1000.0)
    }
}

/// The waves of basis vectors `[dy, dx]`: for one vector `t`, the wave along it of period
/// `|t|`; for two, the reciprocal vectors `kᵢ` (`kᵢ·tⱼ = δᵢⱼ`), each a wave of period `1/|kᵢ|`
/// along it. Zero, too long (beyond the exemplar's side) and collinear vectors (less than
/// [`MIN_ANGLE`] apart) are refused, named.
pub fn waves_of(vectors: &[[f64; 2]], side: u32) -> Result<Vec<Wave>> {
    let bad = |message: String| Err(CoreError::Param { name: "lattice", message });
    let show = |v: &[f64; 2]| format!("[{}, {}]", number(v[0]), number(v[1]));
    if vectors.is_empty() || vectors.len() > 2 {
        return bad(format!("{} basis vectors: give one [dy, dx] (stripes) or two (a grid)", vectors.len()));
    }
    for v in vectors {
        let len = v[0].hypot(v[1]);
        if !len.is_finite() || len < 2.0 {
            return bad(format!("basis vector {} is zero or shorter than 2 texels", show(v)));
        }
        if len > side as f64 {
            return bad(format!("basis vector {} is longer than the {side}-texel exemplar", show(v)));
        }
    }
    let xy = |v: &[f64; 2]| [v[1], v[0]];
    match vectors {
        [t] => {
            let [x, y] = xy(t);
            Ok(vec![Wave::new(x.hypot(y), y.atan2(x).to_degrees())])
        }
        [a, b] => {
            let ([ax, ay], [bx, by]) = (xy(a), xy(b));
            let det = ax * by - ay * bx;
            let sin = det.abs() / (ax.hypot(ay) * bx.hypot(by));
            if sin < MIN_ANGLE.to_radians().sin() {
                return bad(format!(
                    "basis vectors {} and {} are collinear (less than {MIN_ANGLE}° apart)",
                    show(a),
                    show(b)
                ));
            }
            // Rows of B⁻¹ (B's columns a, b): k₁ = (by, −bx)/det, k₂ = (−ay, ax)/det.
            let wave = |k: [f64; 2]| Wave::new(1.0 / k[0].hypot(k[1]), k[1].atan2(k[0]).to_degrees());
            Ok(vec![wave([by / det, -bx / det]), wave([-ay / det, ax / det])])
        }
        _ => unreachable!("one or two vectors, checked above"),
    }
}

impl fmt::Display for LatticeChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LatticeChoice::Auto => f.write_str("auto"),
            LatticeChoice::None => f.write_str("none"),
            LatticeChoice::Cells(nx, ny) => write!(f, "{nx},{ny}"),
            LatticeChoice::Waves(w) => {
                let parts: Vec<String> = w.iter().map(|(p, a)| format!("{p}@{a}")).collect();
                f.write_str(&parts.join(","))
            }
            LatticeChoice::Vectors(v) => {
                let parts: Vec<String> = v.iter().map(|[dy, dx]| format!("[{dy},{dx}]")).collect();
                write!(f, "[{}]", parts.join(","))
            }
        }
    }
}

/// The command-line spelling's grammar, for errors.
pub const SYNTAX: &str = "auto, none, NX,NY (cells of a rectified exemplar), [[DY,DX],[DY,DX]] or [[DY,DX]] \
     (basis vectors in texels) or PERIOD@ANGLE[,PERIOD@ANGLE] (texels, degrees)";

impl FromStr for LatticeChoice {
    type Err = String;

    /// `auto`, `none`, `NX,NY` or `PERIOD@ANGLE[,PERIOD@ANGLE]`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let s = s.trim();
        let bad = || format!("lattice {s:?}: expected {SYNTAX}");
        match s {
            "auto" => return Ok(LatticeChoice::Auto),
            "none" => return Ok(LatticeChoice::None),
            _ => {}
        }
        if s.starts_with('[') {
            let v: Vec<[f64; 2]> = serde_json::from_str(s).map_err(|_| bad())?;
            if v.iter().flatten().any(|c| !c.is_finite()) {
                return Err(bad());
            }
            return Ok(LatticeChoice::Vectors(v));
        }
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.iter().all(|p| p.contains('@')) {
            let waves = parts
                .iter()
                .map(|p| {
                    let (per, ang) = p.split_once('@').ok_or_else(bad)?;
                    let num = |v: &str| v.parse::<f64>().ok().filter(|x| x.is_finite()).ok_or_else(bad);
                    Ok((num(per)?, num(ang)?))
                })
                .collect::<std::result::Result<Vec<_>, String>>()?;
            return Ok(LatticeChoice::Waves(waves));
        }
        match parts[..] {
            [a, b] => match (a.parse::<u32>(), b.parse::<u32>()) {
                (Ok(nx), Ok(ny)) if nx > 0 && ny > 0 => Ok(LatticeChoice::Cells(nx, ny)),
                _ => Err(bad()),
            },
            _ => Err(bad()),
        }
    }
}

/// One wave as configuration files write it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct WaveSpec {
    /// Period in texels.
    period: f64,
    /// Angle of the normal in degrees (0: stripes run down, 90: across).
    angle: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Spelling {
    Word(String),
    Cells([u32; 2]),
    Vectors(Vec<[f64; 2]>),
    Waves(Vec<WaveSpec>),
}

impl Serialize for LatticeChoice {
    fn serialize<S: Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            LatticeChoice::Auto => Spelling::Word("auto".into()),
            LatticeChoice::None => Spelling::Word("none".into()),
            LatticeChoice::Cells(nx, ny) => Spelling::Cells([*nx, *ny]),
            LatticeChoice::Waves(w) => {
                Spelling::Waves(w.iter().map(|&(period, angle)| WaveSpec { period, angle }).collect())
            }
            LatticeChoice::Vectors(v) => Spelling::Vectors(v.clone()),
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for LatticeChoice {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let bad = || {
            serde::de::Error::custom(
                "lattice: expected \"auto\", \"none\", [nx, ny], [[dy, dx], [dy, dx]] or [{ period = P, angle = A }, …]",
            )
        };
        match Spelling::deserialize(d).map_err(|_| bad())? {
            Spelling::Word(w) if w == "auto" => Ok(LatticeChoice::Auto),
            Spelling::Word(w) if w == "none" => Ok(LatticeChoice::None),
            Spelling::Word(_) => Err(bad()),
            Spelling::Cells([nx, ny]) => Ok(LatticeChoice::Cells(nx, ny)),
            Spelling::Waves(w) => Ok(LatticeChoice::Waves(w.into_iter().map(|w| (w.period, w.angle)).collect())),
            Spelling::Vectors(v) => Ok(LatticeChoice::Vectors(v)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_line_spellings() {
        assert_eq!("auto".parse(), Ok(LatticeChoice::Auto));
        assert_eq!(" none ".parse(), Ok(LatticeChoice::None));
        assert_eq!("2,4".parse(), Ok(LatticeChoice::Cells(2, 4)));
        assert_eq!("42.7@0".parse(), Ok(LatticeChoice::Waves(vec![(42.7, 0.0)])));
        assert_eq!("20@0, 14@90".parse(), Ok(LatticeChoice::Waves(vec![(20.0, 0.0), (14.0, 90.0)])));
        for bad in ["", "2", "2,x", "0,4", "1@", "@3", "2,4,8", "nan@0", "automatic"] {
            let e = bad.parse::<LatticeChoice>().unwrap_err();
            assert!(e.contains("expected"), "{bad}: {e}");
        }
        for c in [LatticeChoice::Auto, LatticeChoice::Cells(2, 4), LatticeChoice::Waves(vec![(42.5, 0.0), (9.0, 90.0)])]
        {
            assert_eq!(c.to_string().parse(), Ok(c));
        }
    }

    #[test]
    fn basis_vectors_become_the_same_lattice() {
        assert_eq!("[[28.4, 30.65], [0, 61.3]]".parse(), Ok(LatticeChoice::Vectors(vec![[28.4, 30.65], [0.0, 61.3]])));
        assert_eq!(read_json("[[19.3, 0]]"), LatticeChoice::Vectors(vec![[19.3, 0.0]]));
        // A running bond's basis comes back (as [x, y] translations) from its waves.
        let lat = LatticeChoice::Vectors(vec![[28.4, 30.65], [0.0, 61.3]]).explicit(256, 256).unwrap().unwrap();
        let want = [[30.65, 28.4], [61.3, 0.0]];
        for t in lat.basis() {
            let k: Vec<f64> = lat.waves.iter().map(|w| w.vector()).map(|k| k[0] * t[0] + k[1] * t[1]).collect();
            assert!(k.iter().all(|p| (p - p.round()).abs() < 1e-3), "{t:?}: {k:?}");
        }
        for t in want {
            for w in &lat.waves {
                let p = w.vector()[0] * t[0] + w.vector()[1] * t[1];
                assert!((p - p.round()).abs() < 1e-3, "{t:?} off the lattice");
            }
        }
        // Stripes: one vector, across them.
        let one = LatticeChoice::Vectors(vec![[0.0, 19.3]]).explicit(128, 128).unwrap().unwrap();
        assert!((one.waves[0].period() - 19.3).abs() < 1e-3 && one.waves[0].angle_deg().abs() < 1e-3);
        // Zero, too long, collinear: refused, naming the vectors.
        for (v, says) in [
            (vec![[0.0, 0.0]], "[0, 0]"),
            (vec![[0.0, 300.0]], "longer than"),
            (vec![[10.0, 10.0], [20.0, 21.0]], "collinear"),
            (vec![[1.0, 1.0], [2.0, 2.0], [3.0, 0.0]], "3 basis vectors"),
        ] {
            let e = LatticeChoice::Vectors(v).explicit(256, 256).unwrap_err().to_string();
            assert!(e.contains(says) && e.contains("lattice"), "{e}");
        }
        assert!("[[1, x]]".parse::<LatticeChoice>().unwrap_err().contains("expected"));
    }

    fn read_json(s: &str) -> LatticeChoice {
        serde_json::from_str(s).unwrap()
    }

    #[test]
    fn file_spellings() {
        let read = |s: &str| serde_json::from_str::<LatticeChoice>(s);
        assert_eq!(read("\"auto\"").unwrap(), LatticeChoice::Auto);
        assert_eq!(read("[2, 4]").unwrap(), LatticeChoice::Cells(2, 4));
        assert_eq!(read("[{\"period\": 42.7, \"angle\": 0}]").unwrap(), LatticeChoice::Waves(vec![(42.7, 0.0)]));
        for bad in ["\"sometimes\"", "[1]", "[{\"period\": 3}]", "7"] {
            assert!(read(bad).unwrap_err().to_string().contains("lattice"), "{bad}");
        }
        let c = LatticeChoice::Waves(vec![(42.5, 0.0)]);
        assert_eq!(read(&serde_json::to_string(&c).unwrap()).unwrap(), c);
    }
}
