//! How a texture says which lattice it has: `auto` (detected, the default), `none`, `[nx, ny]`
//! cells of a rectified exemplar, or explicit waves (`{ period, angle }`, one or two). One
//! spelling in configuration files (serde) and on the command line ([`std::str::FromStr`]).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{Lattice, Wave};
use crate::error::Result;

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
}

impl LatticeChoice {
    /// Whether the exemplar must be toroidal (cells tile it).
    pub fn needs_toroidal(&self) -> bool {
        matches!(self, LatticeChoice::Cells(..))
    }

    /// The lattice this setting gives the `side × side` exemplar `pixels`.
    pub fn resolve(&self, pixels: &[[u8; 3]], side: u32) -> Result<Option<Lattice>> {
        Ok(match self {
            LatticeChoice::Auto => super::detect(pixels, side).lattice,
            LatticeChoice::None => None,
            LatticeChoice::Cells(nx, ny) => Some(Lattice::cells(*nx, *ny, side)?),
            LatticeChoice::Waves(w) => Some(Lattice::given(w.iter().map(|&(p, a)| Wave::new(p, a)).collect(), side)?),
        })
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
        }
    }
}

/// The command-line spelling's grammar, for errors.
pub const SYNTAX: &str =
    "auto, none, NX,NY (cells of a rectified exemplar) or PERIOD@ANGLE[,PERIOD@ANGLE] (texels, degrees)";

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
        }
        .serialize(s)
    }
}

impl<'de> Deserialize<'de> for LatticeChoice {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let bad = || {
            serde::de::Error::custom("lattice: expected \"auto\", \"none\", [nx, ny] or [{ period = P, angle = A }, …]")
        };
        match Spelling::deserialize(d).map_err(|_| bad())? {
            Spelling::Word(w) if w == "auto" => Ok(LatticeChoice::Auto),
            Spelling::Word(w) if w == "none" => Ok(LatticeChoice::None),
            Spelling::Word(_) => Err(bad()),
            Spelling::Cells([nx, ny]) => Ok(LatticeChoice::Cells(nx, ny)),
            Spelling::Waves(w) => Ok(LatticeChoice::Waves(w.into_iter().map(|w| (w.period, w.angle)).collect())),
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
