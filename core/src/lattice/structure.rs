//! What structure detection found, as it is stored in an analysis, reported by
//! `GET /textures/{id}` (`structure`) and said in one line by `textile info` and `analyze`.
//! One typed record, written from a [`Detection`] and read back as itself.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::detect::{cell_margin, ridge_margin, Class, Detection, MIN_CONTRAST, MIN_Z};
use super::{milli, Lattice};

/// An exemplar's structure: its class, basis and confidence, and the scores it was decided by.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Structure {
    /// `exact`, `lattice` or `none`.
    pub class: Class,
    /// 0 (none), 1 or 2.
    pub dimensions: usize,
    /// Vectors `[dy, dx]` in exemplar texels: the copies for `exact`, the lattice's
    /// translations for `lattice`.
    pub basis: Vec<[f64; 2]>,
    /// For `lattice`: the decision's margin mapped to `[0, 1]` (½ on the rule).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub confidence: Option<f64>,
    /// For `exact`: the tile's size.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tile: Option<TileSize>,
    /// For `exact`: the structure inside one tile.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner: Option<Box<Structure>>,
    /// What the decision weighed (absent on `inner`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scores: Option<Scores>,
}

/// The size of an exact repeat's tile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TileSize {
    /// Width, when the tile is axis-aligned across.
    pub width: Option<i64>,
    /// Height, when the tile is axis-aligned down.
    pub height: Option<i64>,
    /// Area in texels.
    pub area: Option<i64>,
}

/// The scores of a detection: the best candidate of each kind, found or not (a weak find below
/// the rule is reported so that a user can confirm it with explicit vectors; the modes do not
/// use it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// The exact repeat's Laplacian correlation, if the image is a tile repeated.
    pub repeat: Option<f64>,
    /// The best 1-D candidate.
    pub ridge: Option<Candidate>,
    /// The best 2-D candidate.
    pub cell: Option<Candidate>,
    /// The rule.
    pub thresholds: Thresholds,
}

/// One candidate lattice and how it scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// Its basis, `[dy, dx]`.
    pub basis: Vec<[f64; 2]>,
    /// The shift by a translation against the shift by half of one.
    pub contrast: f64,
    /// The contrast in noise units.
    pub z: f64,
    /// How far it clears the rule (1 on it).
    pub margin: f64,
}

/// The rule's thresholds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Thresholds {
    /// Least Laplacian correlation of an exact copy.
    pub repeat: f64,
    /// Least score, in noise units.
    pub z: f64,
    /// Least contrast.
    pub contrast: f64,
}

impl Structure {
    /// The structure a detection found.
    pub fn of(d: &Detection) -> Structure {
        let r = milli;
        let ridge = d.ridge.map(|q| {
            let (s, c) = q.angle.to_radians().sin_cos();
            Candidate {
                basis: vec![[r(q.period * s), r(q.period * c)]],
                contrast: r(q.contrast),
                z: r(q.z),
                margin: r(ridge_margin(&q)),
            }
        });
        let cell = d.cell.map(|c| Candidate {
            basis: [c.t1, c.t2].iter().map(|t| [r(t[1]), r(t[0])]).collect(),
            contrast: r(c.contrast),
            z: r(c.z),
            margin: r(cell_margin(&c)),
        });
        let scores = Scores {
            repeat: d.repeat.as_ref().map(|rep| rep.score as f64 / 1000.0),
            ridge,
            cell,
            thresholds: Thresholds { repeat: super::exact::COPY_MIN, z: MIN_Z, contrast: MIN_CONTRAST },
        };
        let lattice = lattice_part(&d.lattice);
        match &d.repeat {
            Some(rep) => {
                let (width, height) = rep.axis_size().unwrap_or((None, None));
                Structure {
                    class: Class::Exact,
                    dimensions: rep.basis.len(),
                    basis: rep.basis.iter().map(|v| [v[1] as f64, v[0] as f64]).collect(),
                    confidence: None,
                    tile: Some(TileSize { width, height, area: rep.area() }),
                    inner: Some(Box::new(lattice)),
                    scores: Some(scores),
                }
            }
            None => Structure { scores: Some(scores), ..lattice },
        }
    }
}

/// A lattice (or none) as a structure without scores.
fn lattice_part(l: &Option<Lattice>) -> Structure {
    match l {
        Some(l) => Structure {
            class: Class::Lattice,
            dimensions: l.waves.len(),
            basis: l.basis().iter().map(|v| [milli(v[1]), milli(v[0])]).collect(),
            confidence: Some(l.confidence as f64 / 1000.0),
            tile: None,
            inner: None,
            scores: None,
        },
        None => Structure {
            class: Class::None,
            dimensions: 0,
            basis: Vec::new(),
            confidence: None,
            tile: None,
            inner: None,
            scores: None,
        },
    }
}

/// Vectors as `[a, b] × [c, d]`.
fn vectors(basis: &[[f64; 2]]) -> String {
    let each: Vec<String> = basis.iter().map(|v| format!("[{}, {}]", v[0], v[1])).collect();
    each.join(" × ")
}

/// One line, for `textile info` and `textile analyze`: `exact: a 64×32 tile repeated (copies
/// [dy, dx] [32, 0] × [0, 64], score 1); inside: none`, `lattice, 1-D: basis [dy, dx] [0,
/// 18.03] (confidence 0.69)`, `none (stochastic)`.
impl fmt::Display for Structure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lattice = |s: &Structure| match s.class {
            Class::Lattice => format!(
                "lattice, {}-D: basis [dy, dx] {} (confidence {})",
                s.dimensions,
                vectors(&s.basis),
                s.confidence.unwrap_or(0.0)
            ),
            _ => "none".to_string(),
        };
        match self.class {
            Class::Exact => {
                let tile = match self.tile.as_ref().map(|t| (t.width, t.height)) {
                    Some((Some(w), Some(h))) => format!("a {w}×{h} tile repeated"),
                    Some((Some(w), None)) => format!("repeated every {w} texels across"),
                    Some((None, Some(h))) => format!("repeated every {h} texels down"),
                    _ => "a tile repeated".to_string(),
                };
                let score = self.scores.as_ref().and_then(|s| s.repeat).unwrap_or(0.0);
                let inner = self.inner.as_deref().map_or("none".to_string(), lattice);
                write!(f, "exact: {tile} (copies [dy, dx] {}, score {score}); inside: {inner}", vectors(&self.basis))
            }
            Class::Lattice => f.write_str(&lattice(self)),
            Class::None => f.write_str("none (stochastic)"),
        }
    }
}
