//! Shared fixtures for the core tests: the embedded default exemplars (`config/exemplars`) and
//! exemplars made in code, analysed once per test binary. Nothing here reads outside the
//! repository: a bare clone runs every test.
#![allow(dead_code)]

use std::path::PathBuf;
use std::sync::OnceLock;

use textile_core::{Analysis, Exemplar, ExemplarOptions, NoProgress};

/// Path of an embedded default exemplar in `config/exemplars`.
pub fn embedded_exemplar(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../config/exemplars").join(name)
}

pub fn analyse(path: &PathBuf, opts: ExemplarOptions) -> Analysis {
    let bytes = std::fs::read(path).expect("read exemplar");
    let ex = Exemplar::from_bytes(&bytes, &opts).expect("decode exemplar");
    Analysis::build(&ex, &NoProgress)
}

/// A seamless (toroidal) `side × side` exemplar made in code: waves with integer frequencies
/// over the period plus value noise on a lattice that wraps, so every texel has the same kind of
/// neighbourhood across the wrap-around seam as inside.
pub fn toroidal_exemplar(side: u32, salt: u64) -> Exemplar {
    let n = side as i64;
    let cell = 8;
    let lattice = |i: i64, j: i64, c: u64| {
        let (i, j) = (i.rem_euclid(n / cell), j.rem_euclid(n / cell));
        let z = textile_core::hash::hash(0x5EED, salt, i, j, c as i64);
        (z >> 56) as f64 / 255.0
    };
    let noise = |x: i64, y: i64, c: u64| {
        let (i, j) = (x / cell, y / cell);
        let (fx, fy) = ((x % cell) as f64 / cell as f64, (y % cell) as f64 / cell as f64);
        let top = lattice(i, j, c) * (1.0 - fx) + lattice(i + 1, j, c) * fx;
        let bottom = lattice(i, j + 1, c) * (1.0 - fx) + lattice(i + 1, j + 1, c) * fx;
        top * (1.0 - fy) + bottom * fy
    };
    let tau = std::f64::consts::TAU / n as f64;
    let px: Vec<[u8; 4]> = (0..n * n)
        .map(|k| {
            let (x, y) = (k % n, k / n);
            let r = 110.0 + 50.0 * (tau * (3 * x + y) as f64).sin() + 80.0 * noise(x, y, 0);
            let g = 100.0 + 40.0 * (tau * (x - 2 * y) as f64).cos() + 90.0 * noise(x, y, 1);
            let b = 40.0 + 160.0 * noise(x, y, 2);
            [r.clamp(0.0, 255.0) as u8, g.clamp(0.0, 255.0) as u8, b.clamp(0.0, 255.0) as u8, 255]
        })
        .collect();
    Exemplar::from_rgba(side, side, &px, &ExemplarOptions::default())
}

/// A 64×64 crop of the gravel exemplar (non-toroidal).
pub fn small_exemplar() -> &'static Exemplar {
    static E: OnceLock<Exemplar> = OnceLock::new();
    E.get_or_init(|| {
        let bytes = std::fs::read(embedded_exemplar("gravel.png")).expect("read gravel");
        let img = image::load_from_memory(&bytes).expect("decode").to_rgba8();
        let small = image::imageops::crop_imm(&img, 0, 0, 64, 64).to_image();
        let px: Vec<[u8; 4]> = small.pixels().map(|p| p.0).collect();
        Exemplar::from_rgba(64, 64, &px, &ExemplarOptions::default())
    })
}

/// The analysis of [`small_exemplar`].
pub fn small() -> &'static Analysis {
    static A: OnceLock<Analysis> = OnceLock::new();
    A.get_or_init(|| Analysis::build(small_exemplar(), &NoProgress))
}

/// The `w × h` part of `img` at `(x, y)`.
pub fn crop(img: &textile_core::RgbWindow, x: u32, y: u32, w: u32, h: u32) -> textile_core::RgbWindow {
    let mut pixels = Vec::new();
    for j in y..y + h {
        let s = 3 * (j * img.width + x) as usize;
        pixels.extend_from_slice(&img.pixels[s..s + 3 * w as usize]);
    }
    textile_core::RgbWindow { width: w, height: h, pixels }
}
