//! One umbrella's geometry and colour (design note §5.2, §5.4): the diamond angle that orders
//! directions with only + − ÷, the sector of the rim a point falls in, its barycentrics in that
//! sector's triangle, and the colour there — the base texture at the base vertices' texture
//! coordinates plus the variant's signed vertex colour offsets.

use super::extract::{ray, BaseUmbrella, RAYS};

/// The diamond angle of direction `(x, y)`: a monotone stand-in for `atan2` in `[0, 4)`,
/// bit-exact with only additions, subtractions and one division.
#[inline]
pub fn diamond(x: f32, y: f32) -> f32 {
    if y >= 0.0 {
        if x >= 0.0 {
            if x + y == 0.0 {
                0.0
            } else {
                y / (x + y)
            }
        } else {
            1.0 - x / (y - x)
        }
    } else if x < 0.0 {
        2.0 - y / (-x - y)
    } else {
        3.0 + x / (x - y)
    }
}

/// The diamond angles of the rays, increasing from 0.
pub fn ray_angles() -> [f32; RAYS] {
    std::array::from_fn(|i| {
        let d = ray(i);
        diamond(d[0], d[1])
    })
}

/// Largest `i` with `angles[i] <= a`.
fn sector_at(angles: &[f32; RAYS], a: f32) -> usize {
    let (mut lo, mut hi) = (0usize, RAYS);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if angles[mid] <= a {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Where a point falls in an umbrella's local frame: sector `i` (between rim vertices `i` and
/// `i + 1`) and barycentrics `(α, β, γ)` of the centre and those two vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Sector.
    pub sector: usize,
    /// Weight of the centre.
    pub alpha: f32,
    /// Weight of rim vertex `sector`.
    pub beta: f32,
    /// Weight of rim vertex `sector + 1`.
    pub gamma: f32,
}

/// The sector of local point `(x, y)` (binary search of its diamond angle among the rays').
#[inline]
pub fn sector(angles: &[f32; RAYS], x: f32, y: f32) -> usize {
    sector_at(angles, diamond(x, y))
}

/// Whether local point `(x, y)` lies inside the star-shaped polygon with rim `radii` (vertex
/// `i` at `radii[i]·ray(i)`), and where; the centre counts as inside.
#[inline]
pub fn locate(angles: &[f32; RAYS], rays: &[[f32; 2]; RAYS], radii: &[f32; RAYS], x: f32, y: f32) -> Option<Hit> {
    if x == 0.0 && y == 0.0 {
        return Some(Hit { sector: 0, alpha: 1.0, beta: 0.0, gamma: 0.0 });
    }
    let i = sector(angles, x, y);
    let j = (i + 1) % RAYS;
    let (a, b) = (rays[i].map(|v| v * radii[i]), rays[j].map(|v| v * radii[j]));
    let det = a[0] * b[1] - a[1] * b[0];
    let beta = ((x * b[1] - y * b[0]) / det).max(0.0);
    let gamma = ((a[0] * y - a[1] * x) / det).max(0.0);
    let alpha = 1.0 - beta - gamma;
    (alpha >= 0.0).then_some(Hit { sector: i, alpha, beta, gamma })
}

/// Diamond-angle bins of [`SectorTable`] per unit.
const BINS: usize = 1024;

/// The sector of a direction by table: the sector at the lower edge of its diamond-angle bin,
/// stepped forward while the next ray's angle is still below it — the same answer as
/// [`sector`]'s binary search, with one load and a comparison or two.
#[derive(Debug, Clone)]
pub struct SectorTable {
    angles: [f32; RAYS],
    lut: Vec<u8>,
}

impl Default for SectorTable {
    fn default() -> Self {
        let angles = ray_angles();
        let lut = (0..4 * BINS).map(|b| sector_at(&angles, b as f32 / BINS as f32) as u8).collect();
        SectorTable { angles, lut }
    }
}

impl SectorTable {
    /// The sector of local point `(x, y)`.
    #[inline]
    pub fn sector(&self, x: f32, y: f32) -> usize {
        let a = diamond(x, y);
        let mut i = self.lut[((a * BINS as f32) as usize).min(4 * BINS - 1)] as usize;
        while i + 1 < RAYS && self.angles[i + 1] <= a {
            i += 1;
        }
        i
    }
}

/// A rim prepared for lookups: per sector its two rim vertices and their determinant, computed
/// exactly as [`locate`] computes them, so [`Rim::locate`] gives the same bits.
#[derive(Debug, Clone, PartialEq)]
pub struct Rim {
    tri: [[f32; 5]; RAYS],
}

impl Rim {
    /// The rim with radii `radii` along `rays`.
    pub fn new(rays: &[[f32; 2]; RAYS], radii: &[f32; RAYS]) -> Rim {
        Rim {
            tri: std::array::from_fn(|i| {
                let j = (i + 1) % RAYS;
                let (a, b) = (rays[i].map(|v| v * radii[i]), rays[j].map(|v| v * radii[j]));
                [a[0], a[1], b[0], b[1], a[0] * b[1] - a[1] * b[0]]
            }),
        }
    }

    /// [`locate`] with the sector from `table`.
    #[inline]
    pub fn locate(&self, table: &SectorTable, x: f32, y: f32) -> Option<Hit> {
        if x == 0.0 && y == 0.0 {
            return Some(Hit { sector: 0, alpha: 1.0, beta: 0.0, gamma: 0.0 });
        }
        let i = table.sector(x, y);
        let [a0, a1, b0, b1, det] = self.tri[i];
        let beta = ((x * b1 - y * b0) / det).max(0.0);
        let gamma = ((a0 * y - a1 * x) / det).max(0.0);
        let alpha = 1.0 - beta - gamma;
        (alpha >= 0.0).then_some(Hit { sector: i, alpha, beta, gamma })
    }

    /// Where a point the coverage says is inside falls, for its colour: [`Rim::locate`], and a
    /// point just past the rim (a sub-sample centroid in a concave part, or rounding at the
    /// edge) taken onto it.
    #[inline]
    pub fn locate_clamped(&self, table: &SectorTable, x: f32, y: f32) -> Hit {
        if x == 0.0 && y == 0.0 {
            return Hit { sector: 0, alpha: 1.0, beta: 0.0, gamma: 0.0 };
        }
        let i = table.sector(x, y);
        let [a0, a1, b0, b1, det] = self.tri[i];
        let mut beta = ((x * b1 - y * b0) / det).max(0.0);
        let mut gamma = ((a0 * y - a1 * x) / det).max(0.0);
        let s = beta + gamma;
        if s > 1.0 {
            beta /= s;
            gamma /= s;
        }
        Hit { sector: i, alpha: (1.0 - beta - gamma).max(0.0), beta, gamma }
    }
}

/// Whether every sector of a rim keeps positive orientation (no fold).
pub fn fold_free(rays: &[[f32; 2]; RAYS], radii: &[f32; RAYS]) -> bool {
    (0..RAYS).all(|i| {
        let j = (i + 1) % RAYS;
        let (a, b) = (rays[i].map(|v| v * radii[i]), rays[j].map(|v| v * radii[j]));
        a[0] * b[1] - a[1] * b[0] > 0.0
    })
}

/// The colour at a hit: the base texture at the base vertices' texture coordinates (bilinear,
/// and between mipmap levels when a lookup spans `footprint` > 1 texels of the base), plus
/// `offsets` (centre first, then the rim; already scaled by the colour strength) interpolated
/// over the sector's triangle, clamped to `[0, 1]`.
#[inline]
pub fn colour(base: &BaseUmbrella, rays: &[[f32; 2]; RAYS], offsets: &[[f32; 3]; RAYS + 1], hit: Hit, footprint: f32) -> [f32; 3] {
    let (i, j) = (hit.sector, (hit.sector + 1) % RAYS);
    let (ri, rj) = (base.radii[i], base.radii[j]);
    let u = base.centre[0] + hit.beta * ri * rays[i][0] + hit.gamma * rj * rays[j][0];
    let v = base.centre[1] + hit.beta * ri * rays[i][1] + hit.gamma * rj * rays[j][1];
    let t = texture(base, u, v, footprint);
    let (o0, oi, oj) = (offsets[0], offsets[i + 1], offsets[j + 1]);
    [0, 1, 2].map(|k| (t[k] + hit.alpha * o0[k] + hit.beta * oi[k] + hit.gamma * oj[k]).clamp(0.0, 1.0))
}

/// `log2 v` for `v ≥ 1`, piecewise linear between powers of two (exact at them; plain
/// arithmetic on the bits, so the same on every machine).
#[inline]
fn log2_linear(v: f32) -> f32 {
    let b = v.max(1.0).to_bits();
    let e = ((b >> 23) & 0xFF) as i32 - 127;
    let m = f32::from_bits((b & 0x7F_FFFF) | 0x3F80_0000);
    e as f32 + (m - 1.0)
}

/// The base texture at crop coordinates `(u, v)` for a lookup spanning `footprint` texels:
/// bilinear on the level whose texels are that wide, blended with the next (trilinear).
#[inline]
fn texture(base: &BaseUmbrella, u: f32, v: f32, footprint: f32) -> [f32; 3] {
    let lod = log2_linear(footprint).min(base.mips.len() as f32);
    let l = lod as usize;
    let level = |l: usize| -> [f32; 3] {
        if l == 0 {
            return bilinear(base.w, base.h, &base.texture, u, v);
        }
        let m = &base.mips[l - 1];
        let s = 1.0 / (1u32 << l) as f32;
        bilinear(m.w, m.h, &m.texels, u * s, v * s)
    };
    let a = level(l);
    let f = lod - l as f32;
    if f <= 0.0 || l >= base.mips.len() {
        return a;
    }
    let b = level(l + 1);
    [0, 1, 2].map(|k| a[k] + (b[k] - a[k]) * f)
}

/// Bilinear sample of a `w × h` texture at `(u, v)` (texel centres at `+0.5`), clamped to it.
#[inline]
fn bilinear(w: u32, h: u32, texels: &[[f32; 3]], u: f32, v: f32) -> [f32; 3] {
    let (w, h) = (w as i32, h as i32);
    let (fx, fy) = (u - 0.5, v - 0.5);
    // ⌊·⌋ by conversion (crop coordinates are small; `f32::floor` is a call without SSE4.1).
    let floor = |v: f32| {
        let t = v as i32;
        t - ((t as f32) > v) as i32
    };
    let (x0, y0) = (floor(fx), floor(fy));
    let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
    // Texels widened to four lanes, so that the arithmetic is one vector operation per step
    // (lane by lane the same operations, so the same bits).
    let at = |x: i32, y: i32| {
        let t = texels[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
        [t[0], t[1], t[2], 0.0]
    };
    let (a, b, c, d) = (at(x0, y0), at(x0 + 1, y0), at(x0, y0 + 1), at(x0 + 1, y0 + 1));
    let (sx, sy) = (1.0 - tx, 1.0 - ty);
    let mut out = [0f32; 4];
    for k in 0..4 {
        out[k] = (a[k] * sx + b[k] * tx) * sy + (c[k] * sx + d[k] * tx) * ty;
    }
    [out[0], out[1], out[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_diamond_angle_is_monotone_around_the_circle() {
        let mut last = -1.0f32;
        for i in 0..3600 {
            let a = std::f64::consts::TAU * i as f64 / 3600.0;
            let d = diamond(a.cos() as f32, a.sin() as f32);
            assert!((0.0..4.0).contains(&d) && d > last, "step {i}: {d} after {last}");
            last = d;
        }
    }

    #[test]
    fn points_inside_a_disc_are_found_and_outside_are_not() {
        let (angles, rays) = (ray_angles(), std::array::from_fn(ray));
        let radii = [10.0f32; RAYS];
        for i in 0..360 {
            let a = (i as f32).to_radians();
            let inner = locate(&angles, &rays, &radii, 9.0 * a.cos(), 9.0 * a.sin()).expect("inside");
            assert!((inner.alpha + inner.beta + inner.gamma - 1.0).abs() < 1e-5);
            assert!(locate(&angles, &rays, &radii, 10.5 * a.cos(), 10.5 * a.sin()).is_none());
        }
        assert!(fold_free(&rays, &radii));
    }

    #[test]
    fn the_sector_table_and_prepared_rims_give_the_same_bits() {
        let (angles, rays) = (ray_angles(), std::array::from_fn(ray));
        let table = SectorTable::default();
        let radii: [f32; RAYS] = std::array::from_fn(|i| 4.0 + (i * 7 % 5) as f32);
        let rim = Rim::new(&rays, &radii);
        for i in 0..20000 {
            let t = i as f32 * 0.000314;
            let (x, y) = (7.3 * (t * 37.0).cos() * (t * 3.0).sin(), 7.3 * (t * 37.0).sin());
            assert_eq!(table.sector(x, y), sector(&angles, x, y), "{x},{y}");
            assert_eq!(rim.locate(&table, x, y), locate(&angles, &rays, &radii, x, y), "{x},{y}");
        }
        // Exactly on the rays, too.
        for r in rays {
            assert_eq!(table.sector(r[0], r[1]), sector(&angles, r[0], r[1]));
        }
    }
}
