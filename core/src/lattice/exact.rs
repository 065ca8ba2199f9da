//! Exact repeats (the lattice design note, §2.1): an exemplar that is a smaller tile
//! repeated pixel for pixel — a "seamless" texture tiled 2×2, a crop holding 1.3 copies of a
//! 100 px tile, a material laid as a checkerboard of two blocks. Its copies are lags `d` at which
//! the 3×3 Laplacian of the luma correlates with itself at [`COPY_MIN`] or more over the
//! overlap (Pearson, no window), while at `d/2` it does not (below [`HALF_MAX`]: a repeat, not
//! a long streak). Lags are proposed by the luma's autocorrelation (its local maxima, which a
//! copy always is) and confirmed on the full-resolution Laplacian, so the test costs a few
//! passes over the image. The shortest copies, Gauss-reduced, are the tile's basis.
//!
//! What it is for: a texel's copy is the same content, so it must not be its second coherence
//! candidate ([`Repeat::is_copy`]), and the tile's size is what a user should be told.

/// Least Laplacian correlation of a copy. Tilings score 1.000; the best non-tiling measured in
/// the design note scored 0.93 (a grating whose artist reused its halves).
pub const COPY_MIN: f64 = 0.95;

/// Largest Laplacian correlation at half a copy's lag.
pub const HALF_MAX: f64 = 0.5;

/// Least luma autocorrelation of a lag proposed as a copy.
const PROPOSE_MIN: f64 = 0.3;

/// Lags proposed at most (the highest).
const PROPOSED: usize = 48;

/// Shortest copy lag, in texels.
const MIN_LAG: i64 = 3;

/// Least overlap of a copy's two ends: a share of the image, and a pixel count.
const MIN_OVERLAP_SHARE: f64 = 0.10;
const MIN_OVERLAP_PIXELS: usize = 1024;

/// The exact repeat of an exemplar: the translations that map it onto itself.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Repeat {
    /// One or two basis vectors `(dx, dy)` in texels, Gauss-reduced (shortest first).
    pub basis: Vec<[i64; 2]>,
    /// The lowest Laplacian correlation of the basis vectors, in thousandths.
    pub score: u32,
}

impl Repeat {
    /// Whether the lag `d = (dx, dy)` is a copy: an integer combination of the basis.
    pub fn is_copy(&self, d: (i64, i64)) -> bool {
        if d == (0, 0) {
            return true;
        }
        match self.basis[..] {
            [[ax, ay]] => {
                // Parallel to a, and a whole multiple of it.
                ax * d.1 == ay * d.0 && {
                    let (num, den) = if ax != 0 { (d.0, ax) } else { (d.1, ay) };
                    den != 0 && num % den == 0
                }
            }
            [[ax, ay], [bx, by]] => {
                let det = ax * by - ay * bx;
                det != 0 && (d.0 * by - d.1 * bx) % det == 0 && (ax * d.1 - ay * d.0) % det == 0
            }
            _ => false,
        }
    }

    /// The tile's area in texels (`|det|`), or `None` for copies along one direction only.
    pub fn area(&self) -> Option<i64> {
        match self.basis[..] {
            [[ax, ay], [bx, by]] => Some((ax * by - ay * bx).abs()),
            _ => None,
        }
    }

    /// The tile's width and height when its basis is along the axes (`(w, 0)` and `(0, h)`, in
    /// either order); for copies along one axis only, that axis's period and `None`.
    pub fn axis_size(&self) -> Option<(Option<i64>, Option<i64>)> {
        let along = |v: &[i64; 2]| match v {
            [x, 0] => Some((Some(x.abs()), None)),
            [0, y] => Some((None, Some(y.abs()))),
            _ => None,
        };
        match &self.basis[..] {
            [a] => along(a),
            [a, b] => match (along(a)?, along(b)?) {
                ((Some(w), None), (None, Some(h))) | ((None, Some(h)), (Some(w), None)) => Some((Some(w), Some(h))),
                _ => None,
            },
            _ => None,
        }
    }

    /// The repeat's period along the unit normal `n`: the shortest nonzero projection of a
    /// short copy on it (`None` if no copy has one, as across copies along one direction).
    pub fn period_along(&self, n: [f64; 2]) -> Option<f64> {
        let mut vs: Vec<[i64; 2]> = self.basis.clone();
        if let [a, b] = self.basis[..] {
            vs.push([a[0] + b[0], a[1] + b[1]]);
            vs.push([a[0] - b[0], a[1] - b[1]]);
        }
        vs.iter().map(|v| (v[0] as f64 * n[0] + v[1] as f64 * n[1]).abs()).filter(|p| *p > 0.5).min_by(f64::total_cmp)
    }

    /// Feed the repeat to a hasher (exemplar and analysis identity).
    pub fn hash_into(&self, h: &mut blake3::Hasher) {
        h.update(b"repeat");
        for v in &self.basis {
            h.update(&v[0].to_le_bytes());
            h.update(&v[1].to_le_bytes());
        }
    }
}

/// The 3×3 Laplacian of the luma of an `m × m` image (0 on the border row and column).
fn laplacian(pixels: &[[u8; 3]], m: usize) -> Vec<f64> {
    let luma: Vec<f64> =
        pixels.iter().map(|p| 0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64).collect();
    let mut out = vec![0.0; m * m];
    for y in 1..m.saturating_sub(1) {
        for x in 1..m - 1 {
            let i = y * m + x;
            let ring: f64 =
                [i - m - 1, i - m, i - m + 1, i - 1, i + 1, i + m - 1, i + m, i + m + 1].iter().map(|&j| luma[j]).sum();
            out[i] = ring - 8.0 * luma[i];
        }
    }
    out
}

/// Pearson correlation of `lap` with itself at the lag `(dx, dy)` over the interior overlap,
/// or `None` where the overlap is too small.
fn correlation(lap: &[f64], m: usize, (dx, dy): (i64, i64)) -> Option<f64> {
    let mi = m as i64;
    let (x0, x1) = (1.max(1 - dx), (mi - 1).min(mi - 1 - dx));
    let (y0, y1) = (1.max(1 - dy), (mi - 1).min(mi - 1 - dy));
    if x1 <= x0 || y1 <= y0 {
        return None;
    }
    let count = ((x1 - x0) * (y1 - y0)) as usize;
    if count < MIN_OVERLAP_PIXELS || (count as f64) < MIN_OVERLAP_SHARE * (m * m) as f64 {
        return None;
    }
    let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for y in y0..y1 {
        let ra = (y * mi) as usize;
        let rb = ((y + dy) * mi + dx) as usize;
        for x in x0 as usize..x1 as usize {
            let (a, b) = (lap[ra + x], lap[rb + x]);
            sa += a;
            sb += b;
            saa += a * a;
            sbb += b * b;
            sab += a * b;
        }
    }
    let n = count as f64;
    let cov = sab - sa * sb / n;
    let va = saa - sa * sa / n;
    let vb = sbb - sb * sb / n;
    if va <= 1e-9 || vb <= 1e-9 {
        return None; // a flat overlap says nothing
    }
    Some(cov / (va * vb).sqrt())
}

/// A luma autocorrelation as [`find`] reads it: the values at integer lags of an image of side
/// `m`, zero-padded to `n`, row-major with negative lags wrapped.
pub(super) struct Lags<'a> {
    /// The image's side.
    pub m: usize,
    /// The padded side.
    pub n: usize,
    /// The values.
    pub a: &'a [f64],
}

/// The exact repeat of the `m × m` exemplar `pixels`, whose luma autocorrelation (possibly of
/// the image reduced by `scale`) is `a`; `None` if it is no tiling.
pub(super) fn find(pixels: &[[u8; 3]], m: usize, a: &Lags, scale: usize) -> Option<Repeat> {
    let lap = laplacian(pixels, m);
    // Proposals: local maxima of the autocorrelation in the half plane, highest first.
    let (ma, n) = (a.m as i64, a.n as i64);
    let at = |x: i64, y: i64| a.a[(y.rem_euclid(n) * n + x.rem_euclid(n)) as usize];
    let mut proposed: Vec<(f64, i64, i64)> = Vec::new();
    for y in 0..ma {
        for x in (1 - ma)..ma {
            if y == 0 && x <= 0 {
                continue;
            }
            // Where the two ends barely overlap the estimate is noise (and unbounded).
            let overlap = ((ma - x.abs()) * (ma - y)) as f64 / (ma * ma) as f64;
            let v = at(x, y);
            if overlap < MIN_OVERLAP_SHARE
                || v < PROPOSE_MIN
                || (x * x + y * y) * ((scale * scale) as i64) < MIN_LAG * MIN_LAG
            {
                continue;
            }
            let peak = (-1..=1).all(|j| (-1..=1).all(|i| (i, j) == (0, 0) || at(x + i, y + j) <= v));
            if peak {
                proposed.push((v, x, y));
            }
        }
    }
    proposed.sort_by(|p, q| q.0.total_cmp(&p.0).then((p.1, p.2).cmp(&(q.1, q.2))));
    proposed.truncate(PROPOSED);
    // Confirmed copies at full resolution (around each proposal when the image was reduced).
    let s = scale as i64;
    let reach = if s > 1 { s } else { 0 };
    let mut copies: Vec<([i64; 2], f64)> = Vec::new();
    for &(_, px, py) in &proposed {
        let best = (-reach..=reach)
            .flat_map(|j| (-reach..=reach).map(move |i| (px * s + i, py * s + j)))
            .filter_map(|d| correlation(&lap, m, d).map(|c| (d, c)))
            .max_by(|p, q| p.1.total_cmp(&q.1));
        let Some(((dx, dy), c)) = best else { continue };
        if c < COPY_MIN || dx * dx + dy * dy < MIN_LAG * MIN_LAG {
            continue;
        }
        // Half the lag must not correlate: a copy, not a streak.
        let half = correlation(&lap, m, (dx.div_euclid(2), dy.div_euclid(2))).unwrap_or(0.0);
        if half >= HALF_MAX {
            continue;
        }
        if !copies.iter().any(|(v, _)| *v == [dx, dy]) {
            copies.push(([dx, dy], c));
        }
    }
    basis(&copies)
}

/// The Gauss-reduced basis of the shortest two independent copies (or the shortest one).
fn basis(copies: &[([i64; 2], f64)]) -> Option<Repeat> {
    let len = |v: [i64; 2]| v[0] * v[0] + v[1] * v[1];
    let mut sorted: Vec<&([i64; 2], f64)> = copies.iter().collect();
    sorted.sort_by_key(|(v, _)| (len(*v), v[1], v[0]));
    let &&(a, ca) = sorted.first()?;
    let second = sorted.iter().find(|(v, _)| a[0] * v[1] - a[1] * v[0] != 0);
    let Some(&&(b, cb)) = second else {
        return Some(Repeat { basis: vec![canonical(a)], score: (ca.min(1.0) * 1000.0).round() as u32 });
    };
    let (mut u, mut v) = (a, b);
    let dot = |p: [i64; 2], q: [i64; 2]| p[0] * q[0] + p[1] * q[1];
    for _ in 0..64 {
        if len(u) > len(v) {
            std::mem::swap(&mut u, &mut v);
        }
        let k = (dot(u, v) as f64 / len(u) as f64).round() as i64;
        if k == 0 {
            break;
        }
        v = [v[0] - k * u[0], v[1] - k * u[1]];
    }
    let score = (ca.min(cb).min(1.0) * 1000.0).round() as u32;
    Some(Repeat { basis: vec![canonical(u), canonical(v)], score })
}

/// `v` or `−v`, whichever points down (or right, along a row): one spelling per translation.
fn canonical(v: [i64; 2]) -> [i64; 2] {
    if v[1] < 0 || (v[1] == 0 && v[0] < 0) {
        [-v[0], -v[1]]
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_are_integer_combinations_of_the_basis() {
        let r = Repeat { basis: vec![[128, 128], [128, -128]], score: 1000 };
        assert!(r.is_copy((256, 0)) && r.is_copy((128, -128)) && r.is_copy((0, 0)));
        assert!(!r.is_copy((128, 0)) && !r.is_copy((0, 128)) && !r.is_copy((1, 1)));
        let one = Repeat { basis: vec![[43, 0]], score: 1000 };
        assert!(one.is_copy((86, 0)) && one.is_copy((-43, 0)));
        assert!(!one.is_copy((43, 1)) && !one.is_copy((20, 0)));
        assert_eq!(Repeat { basis: vec![[0, 32], [64, 0]], score: 1000 }.axis_size(), Some((Some(64), Some(32))));
        assert_eq!(r.axis_size(), None);
        assert_eq!(r.area(), Some(32768));
        assert_eq!(r.period_along([1.0, 0.0]), Some(128.0));
    }
}
