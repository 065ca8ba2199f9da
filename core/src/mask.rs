//! The randomness mask over the exemplar, `R_E` (design note §1.9): a greyscale image the size
//! of the exemplar, white where synthesis may move content freely, black where it must keep
//! the exemplar as it is (the windows of a facade, a logo). Jitter at level `l` is scaled by
//! the mask's minimum over the `h_l × h_l` box around the coordinate being jittered, so a
//! coarse jump never starts inside a kept element. The per-level minima are computed once.

use std::sync::Arc;

use crate::error::{CoreError, Result};

/// A prepared randomness mask: `w × h` values (0 keep … 255 free) and their per-level box
/// minima.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RandomnessMask {
    /// Exemplar width.
    pub width: u32,
    /// Exemplar height.
    pub height: u32,
    /// Row-major values, `width × height`.
    pub values: Vec<u8>,
    /// Per level `l = 0..=L`: the minimum over the box `[u − h_l/2, u + h_l/2)` per axis
    /// (`h_l = 2^(L−l)`; the texel itself at `l = L`), wrapped or clamped at the edges.
    levels: Arc<Vec<Vec<u8>>>,
    /// Content hash (hex), part of the analysis id.
    pub hash: String,
}

impl RandomnessMask {
    /// A mask of `width × height` values for an exemplar that wraps (`toroidal`) or not.
    pub fn new(width: u32, height: u32, values: Vec<u8>, toroidal: bool) -> Result<RandomnessMask> {
        let (w, h) = (width as usize, height as usize);
        if w == 0 || h == 0 || values.len() != w * h {
            return Err(CoreError::Param {
                name: "randomness_mask",
                message: format!("must have {width}×{height} values (the exemplar's size), not {}", values.len()),
            });
        }
        let levels = crate::geom::levels_for(width, height);
        let rows: Vec<MinTable> = values.chunks_exact(w).map(|r| MinTable::new(r, toroidal)).collect();
        let per_level = (0..=levels)
            .map(|l| {
                let span = 1usize << (levels - l);
                // Rows first (stored transposed), then columns of the row minima.
                let mut across = vec![0u8; w * h];
                for (y, t) in rows.iter().enumerate() {
                    for x in 0..w {
                        across[x * h + y] = t.centred(x, span);
                    }
                }
                let mut out = vec![0u8; w * h];
                for (x, col) in across.chunks_exact(h).enumerate() {
                    let t = MinTable::new(col, toroidal);
                    for y in 0..h {
                        out[y * w + x] = t.centred(y, span);
                    }
                }
                out
            })
            .collect();
        let mut hasher = blake3::Hasher::new();
        hasher.update(b"randomness-mask");
        hasher.update(&width.to_le_bytes());
        if height != width {
            hasher.update(&height.to_le_bytes());
        }
        hasher.update(&values);
        let hash = hasher.finalize().to_hex()[..16].to_string();
        Ok(RandomnessMask { width, height, values, levels: Arc::new(per_level), hash })
    }

    /// The mask's minimum around exemplar texel `(x, y)` at level `l` (0 keep … 255 free).
    #[inline]
    pub fn at(&self, l: u32, x: u32, y: u32) -> u8 {
        self.levels[l as usize][(y * self.width + x) as usize]
    }
}

/// Minima of a line over windows of power-of-two lengths (a sparse table): `mins[k][i]` is the
/// minimum of `[i, i + 2^k)`, wrapped around (`toroidal`) or cut at the end.
struct MinTable {
    mins: Vec<Vec<u8>>,
    toroidal: bool,
}

impl MinTable {
    fn new(line: &[u8], toroidal: bool) -> MinTable {
        let n = line.len();
        let mut mins = vec![line.to_vec()];
        let mut w = 1;
        while w < n {
            let prev = &mins[mins.len() - 1];
            let next = (0..n)
                .map(|i| {
                    let j = i + w;
                    let other = if toroidal { prev[j % n] } else { prev[j.min(n - 1)] };
                    prev[i].min(other)
                })
                .collect();
            mins.push(next);
            w *= 2;
        }
        MinTable { mins, toroidal }
    }

    /// The minimum over `[u − h/2, u + h/2)` (`h` a power of two), wrapped, or clamped to the
    /// line when it does not wrap (a window at least as long as a wrapping line: all of it).
    fn centred(&self, u: usize, h: usize) -> u8 {
        let n = self.mins[0].len() as i64;
        let k = h.trailing_zeros() as usize;
        let start = u as i64 - (h / 2) as i64;
        if self.toroidal {
            if h as i64 >= n {
                return self.mins[0].iter().copied().min().unwrap_or(255);
            }
            return self.mins[k][start.rem_euclid(n) as usize];
        }
        let (s, e) = (start.max(0), (start + h as i64).min(n));
        let len = (e - s) as u64;
        let k = 63 - len.leading_zeros() as usize;
        self.mins[k][s as usize].min(self.mins[k][(e - (1 << k)) as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_minima_equal_a_direct_box_minimum() {
        for (w, hh) in [(16u32, 16u32), (12, 7)] {
            check_minima(w, hh);
        }
        assert!(RandomnessMask::new(16, 16, vec![0; 10], true).is_err());
    }

    fn check_minima(m: u32, rows: u32) {
        let values: Vec<u8> = (0..m * rows).map(|i| ((i * 97 + 13) % 251) as u8).collect();
        let levels = crate::geom::levels_for(m, rows);
        for toroidal in [true, false] {
            let mask = RandomnessMask::new(m, rows, values.clone(), toroidal).unwrap();
            for l in 0..=levels {
                let h = 1i64 << (levels - l);
                for y in 0..rows as i64 {
                    for x in 0..m as i64 {
                        let mut best = 255u8;
                        for dy in -h / 2..(h - h / 2) {
                            for dx in -h / 2..(h - h / 2) {
                                let at = |v: i64, n: i64| if toroidal { v.rem_euclid(n) } else { v.clamp(0, n - 1) };
                                best = best
                                    .min(values[(at(y + dy, rows as i64) * m as i64 + at(x + dx, m as i64)) as usize]);
                            }
                        }
                        assert_eq!(mask.at(l, x as u32, y as u32), best, "l {l} ({x}, {y}) toroidal {toroidal}");
                    }
                }
            }
        }
    }
}
