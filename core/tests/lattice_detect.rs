//! Structure detection (issue 69) on lattices made in code with real texture in each cell —
//! cells filled from the gravel material at a random offset each, joints from the cliff rock
//! (both 256², so that no fill repeats within the image), so no two cells are alike and
//! nothing is flat — and on the stochastic exemplars of
//! the development set and the materials. Each made lattice's basis must come back within half
//! a texel (up to sign and reduction); a tile repeated must come back `exact` with its tile;
//! every stochastic exemplar must come back `none`.

mod common;

use textile_core::lattice::{detect, Class, Detection};
use textile_core::{Exemplar, ExemplarOptions};

const SIDE: u32 = 256;

/// An exemplar image by name, from the embedded set (`config/exemplars`).
fn load(name: &str) -> Exemplar {
    let bytes = std::fs::read(common::embedded_exemplar(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    Exemplar::from_bytes(&bytes, &ExemplarOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A small integer hash of a cell, for its fill's offset and tint.
fn cell_hash(i: i64, j: i64) -> u64 {
    let mut h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (j as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^ (h >> 32)
}

/// Textures to fill cells and joints with.
struct Fill {
    stone: Exemplar,
    joint: Exemplar,
}

impl Fill {
    fn new() -> Fill {
        Fill { stone: load("test/gravel_material.png"), joint: load("test/cliff_rock.png") }
    }

    /// The stone texture at `(x, y)` seen through cell `(i, j)`: gravel at the cell's own
    /// offset, with the cell's own brightness.
    fn stone(&self, x: i64, y: i64, cell: (i64, i64)) -> [u8; 3] {
        let h = cell_hash(cell.0, cell.1);
        let m = self.stone.width as i64;
        let (ox, oy) = ((h % 97) as i64, ((h >> 8) % 89) as i64);
        let p = self.stone.pixels[((y + oy).rem_euclid(m) * m + (x + ox).rem_euclid(m)) as usize];
        let gain = 0.85 + 0.3 * ((h >> 16) % 100) as f64 / 100.0;
        p.map(|c| (40.0 + 0.75 * c as f64 * gain).min(255.0) as u8)
    }

    /// The joint texture at `(x, y)`: rock, dark.
    fn joint(&self, x: i64, y: i64) -> [u8; 3] {
        let m = self.joint.width as i64;
        self.joint.pixels[(y.rem_euclid(m) * m + x.rem_euclid(m)) as usize].map(|c| (c as f64 * 0.3) as u8)
    }
}

/// A `SIDE²` image of `f(x, y)` evaluated at pixel centres, after turning the plane by
/// `degrees` about the image's centre.
fn image(degrees: f64, f: impl Fn(f64, f64) -> [u8; 3]) -> Vec<[u8; 3]> {
    let (s, c) = degrees.to_radians().sin_cos();
    let half = SIDE as f64 / 2.0;
    (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = ((i % SIDE) as f64 + 0.5 - half, (i / SIDE) as f64 + 0.5 - half);
            f(c * x + s * y + half, -s * x + c * y + half)
        })
        .collect()
}

/// `v` turned by `degrees` the way [`image`] turns the plane (its content).
fn turned(v: [f64; 2], degrees: f64) -> [f64; 2] {
    let (s, c) = degrees.to_radians().sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// Boards across x every `t` texels (joints 2 texels wide); boards are free along y.
fn boards(fill: &Fill, t: f64) -> Vec<[u8; 3]> {
    image(0.0, |x, y| {
        let i = (x / t).floor() as i64;
        if x - i as f64 * t < 2.0 {
            fill.joint(x as i64, y as i64)
        } else {
            fill.stone(x as i64, y as i64, (i, 0))
        }
    })
}

/// Bricks `l` long and `h` high, each course shifted by half a brick, turned by `degrees`.
fn running_bond(fill: &Fill, l: f64, h: f64, degrees: f64) -> Vec<[u8; 3]> {
    image(degrees, |x, y| {
        let row = (y / h).floor();
        let u = x - row * l / 2.0;
        let i = (u / l).floor();
        if y - row * h < 2.5 || u - i * l < 2.5 {
            fill.joint(x as i64, y as i64)
        } else {
            fill.stone(x as i64, y as i64, (i as i64, row as i64))
        }
    })
}

/// Tiles `w × h` on a square grid.
fn stack_bond(fill: &Fill, w: f64, h: f64) -> Vec<[u8; 3]> {
    image(0.0, |x, y| {
        let (i, j) = ((x / w).floor(), (y / h).floor());
        if x - i * w < 2.0 || y - j * h < 2.0 {
            fill.joint(x as i64, y as i64)
        } else {
            fill.stone(x as i64, y as i64, (i as i64, j as i64))
        }
    })
}

/// A tread plate: lugs (bright ellipses along alternate diagonals) on the lattice of
/// `a = (p, p)` and `b = (p, −p)`, on a plate of texture.
fn tread(fill: &Fill, p: f64) -> Vec<[u8; 3]> {
    image(0.0, |x, y| {
        // Lattice coordinates: x = p(u + v), y = p(u − v).
        let (u, v) = ((x / p + y / p) / 2.0, (x / p - y / p) / 2.0);
        let (fu, fv) = (u - u.round(), v - v.round());
        // Offset from the nearest lug centre, in texels, and its long axis along a diagonal.
        let (dx, dy) = (p * (fu + fv), p * (fu - fv));
        let (along, across) = ((dx + dy) / 2f64.sqrt(), (dx - dy) / 2f64.sqrt());
        let on_lug = (along / (0.45 * p)).powi(2) + (across / (0.15 * p)).powi(2) <= 1.0;
        let base = fill.stone(x as i64, y as i64, (0, 0));
        if on_lug {
            base.map(|c| c.saturating_add(90))
        } else {
            base.map(|c| (c as f64 * 0.7) as u8)
        }
    })
}

/// A tile of `w × h` random texture (gravel under grass) repeated on the lattice of `a` and
/// `b` (whole texels) over the whole image.
fn tiled(fill: &Fill, a: [i64; 2], b: [i64; 2]) -> Vec<[u8; 3]> {
    let det = (a[0] * b[1] - a[1] * b[0]) as f64;
    (0..SIDE as i64 * SIDE as i64)
        .map(|i| {
            let (x, y) = (i % SIDE as i64, i / SIDE as i64);
            // The representative of (x, y) in the tile: subtract whole multiples of a and b.
            let u = ((x * b[1] - y * b[0]) as f64 / det).floor() as i64;
            let v = ((a[0] * y - a[1] * x) as f64 / det).floor() as i64;
            let (rx, ry) = (x - u * a[0] - v * b[0], y - u * a[1] - v * b[1]);
            let g = fill.stone(rx, ry, (0, 0));
            let k = fill.joint(rx * 3 + 7, ry * 2 + 1);
            [g[0] / 2 + k[0], g[1] / 2 + k[1], g[2] / 2 + k[2]]
        })
        .collect()
}

/// Whether the lattices spanned by `found` and by `want` are the same within `tol` texels:
/// the same dimension, and each basis vector of either within `tol` of a whole combination of
/// the other's (for one vector: of its multiples).
fn same_lattice(found: &[[f64; 2]], want: &[[f64; 2]], tol: f64) -> bool {
    let on = |v: [f64; 2], basis: &[[f64; 2]]| -> bool {
        match basis {
            [a] => {
                let k = ((v[0] * a[0] + v[1] * a[1]) / (a[0] * a[0] + a[1] * a[1])).round();
                k != 0.0 && (v[0] - k * a[0]).hypot(v[1] - k * a[1]) <= tol
            }
            [a, b] => {
                let det = a[0] * b[1] - a[1] * b[0];
                let (p, q) = (((v[0] * b[1] - v[1] * b[0]) / det).round(), ((a[0] * v[1] - a[1] * v[0]) / det).round());
                (v[0] - p * a[0] - q * b[0]).hypot(v[1] - p * a[1] - q * b[1]) <= tol
            }
            _ => false,
        }
    };
    found.len() == want.len() && found.iter().all(|v| on(*v, want)) && want.iter().all(|v| on(*v, found))
}

/// Detection of a made image, with its report for failures.
fn found(px: &[[u8; 3]]) -> (Detection, Vec<[f64; 2]>) {
    let d = detect(px, SIDE, SIDE);
    let basis = d.lattice.as_ref().map(|l| l.basis()).unwrap_or_default();
    (d, basis)
}

#[test]
fn boards_at_fractional_spacings_are_one_dimensional() {
    let fill = Fill::new();
    for t in [19.3, 28.4] {
        let (d, basis) = found(&boards(&fill, t));
        assert_eq!(d.class(), Class::Lattice, "boards every {t}: {:?}", (d.ridge, d.cell));
        assert!(same_lattice(&basis, &[[t, 0.0]], 0.5), "boards every {t}: found {basis:?}");
    }
}

#[test]
fn a_running_bond_is_two_dimensional_with_its_stagger() {
    let fill = Fill::new();
    let (l, h) = (61.3, 28.4);
    for degrees in [0.0, 7.0] {
        let (d, basis) = found(&running_bond(&fill, l, h, degrees));
        let want = [turned([l, 0.0], degrees), turned([l / 2.0, h], degrees)];
        assert_eq!(d.class(), Class::Lattice, "bond at {degrees}°: {:?}", (d.ridge, d.cell));
        assert!(same_lattice(&basis, &want, 0.5), "bond at {degrees}°: found {basis:?}, want {want:?}");
    }
}

#[test]
fn a_stack_bond_and_a_diagonal_tread_are_two_dimensional() {
    let fill = Fill::new();
    let (d, basis) = found(&stack_bond(&fill, 21.7, 33.1));
    assert!(
        same_lattice(&basis, &[[21.7, 0.0], [0.0, 33.1]], 0.5),
        "stack bond: found {basis:?} ({:?})",
        (d.ridge, d.cell)
    );
    let p = 17.5;
    let (d, basis) = found(&tread(&fill, p));
    assert!(same_lattice(&basis, &[[p, p], [p, -p]], 0.5), "tread: found {basis:?} ({:?})", (d.ridge, d.cell));
}

#[test]
fn a_tile_repeated_is_exact_with_its_tile() {
    let fill = Fill::new();
    for (a, b) in [([128, 0], [0, 128]), ([96, 0], [40, 80])] {
        let d = detect(&tiled(&fill, a, b), SIDE, SIDE);
        assert_eq!(d.class(), Class::Exact, "{a:?} × {b:?}: {:?}", d.repeat);
        let rep = d.repeat.expect("a repeat");
        let got: Vec<[f64; 2]> = rep.basis.iter().map(|v| [v[0] as f64, v[1] as f64]).collect();
        let want = [[a[0] as f64, a[1] as f64], [b[0] as f64, b[1] as f64]];
        assert!(same_lattice(&got, &want, 0.01), "{a:?} × {b:?}: found {got:?}");
        assert_eq!(rep.score, 1000);
        assert!(d.lattice.is_none(), "random texture has no lattice inside its tile: {:?}", d.lattice);
    }
    // The shared planks material: two blocks as a checkerboard, boards every 42.67 inside.
    let planks = load("test/planks.png");
    let d = detect(&planks.pixels, planks.width, planks.height);
    let rep = d.repeat.clone().expect("planks repeat");
    let got: Vec<[f64; 2]> = rep.basis.iter().map(|v| [v[0] as f64, v[1] as f64]).collect();
    assert!(same_lattice(&got, &[[128.0, 128.0], [128.0, -128.0]], 0.01), "planks: {got:?}");
    let inner = d.lattice.expect("boards inside").basis();
    assert!(same_lattice(&inner, &[[128.0 / 3.0, 0.0]], 0.5), "planks' boards: {inner:?}");
}

#[test]
fn stochastic_exemplars_have_no_structure() {
    for name in [
        "gravel.png",
        "grass.png",
        "test/slime.png",
        "test/cliff_rock.png",
        "materials/flagstones/albedo.png",
        "materials/forest_floor/albedo.png",
        "test/gravel_material.png",
    ] {
        let ex = load(name);
        let d = detect(&ex.pixels, ex.width, ex.height);
        assert_eq!(d.class(), Class::None, "{name}: {:?} {:?} {:?}", d.repeat, d.lattice, (d.ridge, d.cell));
    }
}
