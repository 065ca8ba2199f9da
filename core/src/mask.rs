//! The randomness mask over the exemplar, `R_E` (design note §1.9): a greyscale image the size
//! of the exemplar, white where synthesis may move content freely, black where it must keep
//! the exemplar as it is (the windows of a facade, a logo). Jitter at level `l` is scaled by
//! the mask's minimum over the `h_l × h_l` box around the coordinate being jittered, so a
//! coarse jump never starts inside a kept element. The per-level minima are computed once.

use std::sync::Arc;

use crate::error::{CoreError, Result};

/// A prepared randomness mask: `m × m` values (0 keep … 255 free) and their per-level box
/// minima.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RandomnessMask {
    /// Exemplar side.
    pub side: u32,
    /// Row-major values, `side × side`.
    pub values: Vec<u8>,
    /// Per level `l = 0..=L`: the minimum over the box `[u − h_l/2, u + h_l/2)` per axis
    /// (`h_l = m / 2^l`; the texel itself at `l = L`), wrapped or clamped at the edges.
    levels: Arc<Vec<Vec<u8>>>,
    /// Content hash (hex), part of the analysis id.
    pub hash: String,
}

impl RandomnessMask {
    /// A mask of `side × side` values for an exemplar that wraps (`toroidal`) or not.
    pub fn new(side: u32, values: Vec<u8>, toroidal: bool) -> Result<RandomnessMask> {
        let m = side as usize;
        if !side.is_power_of_two() || values.len() != m * m {
            return Err(CoreError::Param {
                name: "randomness_mask",
                message: format!("must have {side}×{side} values (the exemplar's size), not {}", values.len()),
            });
        }
        let levels = side.trailing_zeros();
        let rows: Vec<MinTable> = values.chunks_exact(m).map(|r| MinTable::new(r, toroidal)).collect();
        let per_level = (0..=levels)
            .map(|l| {
                let h = m >> l;
                // Rows first, then columns of the row minima.
                let mut across = vec![0u8; m * m];
                for (y, t) in rows.iter().enumerate() {
                    for x in 0..m {
                        across[x * m + y] = t.centred(x, h);
                    }
                }
                let mut out = vec![0u8; m * m];
                for (x, col) in across.chunks_exact(m).enumerate() {
                    let t = MinTable::new(col, toroidal);
                    for y in 0..m {
                        out[y * m + x] = t.centred(y, h);
                    }
                }
                out
            })
            .collect();
        let mut hasher = blake3::Hasher::new();
        hasher.update(b"randomness-mask");
        hasher.update(&side.to_le_bytes());
        hasher.update(&values);
        let hash = hasher.finalize().to_hex()[..16].to_string();
        Ok(RandomnessMask { side, values, levels: Arc::new(per_level), hash })
    }

    /// The mask's minimum around exemplar texel `(x, y)` at level `l` (0 keep … 255 free).
    #[inline]
    pub fn at(&self, l: u32, x: u32, y: u32) -> u8 {
        self.levels[l as usize][(y * self.side + x) as usize]
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
    /// line when it does not wrap.
    fn centred(&self, u: usize, h: usize) -> u8 {
        let n = self.mins[0].len() as i64;
        let k = h.trailing_zeros() as usize;
        let start = u as i64 - (h / 2) as i64;
        if self.toroidal {
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
        let m = 16u32;
        let values: Vec<u8> = (0..m * m).map(|i| ((i * 97 + 13) % 251) as u8).collect();
        for toroidal in [true, false] {
            let mask = RandomnessMask::new(m, values.clone(), toroidal).unwrap();
            for l in 0..=4u32 {
                let h = (m >> l) as i64;
                for y in 0..m as i64 {
                    for x in 0..m as i64 {
                        let mut best = 255u8;
                        for dy in -h / 2..(h - h / 2) {
                            for dx in -h / 2..(h - h / 2) {
                                let at = |v: i64| {
                                    if toroidal {
                                        v.rem_euclid(m as i64)
                                    } else {
                                        v.clamp(0, m as i64 - 1)
                                    }
                                };
                                best = best.min(values[(at(y + dy) * m as i64 + at(x + dx)) as usize]);
                            }
                        }
                        assert_eq!(mask.at(l, x as u32, y as u32), best, "l {l} ({x}, {y}) toroidal {toroidal}");
                    }
                }
            }
        }
        assert!(RandomnessMask::new(m, vec![0; 10], true).is_err());
    }
}
