//! The Gaussian stack (design note §1.2a): one full `w × h` image per synthesis level, blurred
//! more at coarser levels with an à-trous binomial filter, in exact u16 fixed point (value·256).
//! Edges are handled by an addressing rule: wrap for toroidal exemplars, mirror otherwise. Also
//! one level of it alone ([`low_pass`]): what `synth` blends seams with, for maps as for colour.

/// Exemplar texel address for a possibly out-of-range index `i` (wrap or mirror, §1.2a).
#[inline]
pub fn addr(i: i64, m: i64, toroidal: bool) -> usize {
    if toroidal {
        i.rem_euclid(m) as usize
    } else {
        let j = i.rem_euclid(2 * m);
        (if j < m { j } else { 2 * m - 1 - j }) as usize
    }
}

const TAPS: [u32; 5] = [1, 4, 6, 4, 1];

/// Build the stack for a `w × h` exemplar: `L + 1` levels ([`crate::geom::levels_for`]),
/// index `l` = level `l` (0 = coarsest, the exact mean colour; `L` = the exemplar itself).
pub fn build_stack(pixels: &[[u8; 3]], (w, h): (usize, usize), toroidal: bool) -> Vec<Vec<[u16; 3]>> {
    let levels = crate::geom::levels_for(w as u32, h as u32) as usize;
    let mut stack = vec![Vec::new(); levels + 1];
    stack[levels] = pixels.iter().map(|p| p.map(|v| (v as u16) << 8)).collect();
    for l in (1..=levels).rev() {
        stack[l - 1] = blur(&stack[l], (w, h), 1 << (levels - l), toroidal);
    }
    // Level 0 is the exact mean colour (LH05).
    let n = (w * h) as u64;
    let mut sum = [0u64; 3];
    for p in pixels {
        for c in 0..3 {
            sum[c] += p[c] as u64;
        }
    }
    let mean = sum.map(|s| (((s << 8) + n / 2) / n) as u16);
    stack[0] = vec![mean; w * h];
    stack
}

/// One step of the à-trous filter at stride `h`: the next coarser stack level.
fn blur(src: &[[u16; 3]], (w, hh): (usize, usize), h: i64, toroidal: bool) -> Vec<[u16; 3]> {
    let pass = |src: &[[u16; 3]], horizontal: bool| -> Vec<[u16; 3]> {
        let mut out = vec![[0u16; 3]; w * hh];
        for y in 0..hh {
            for x in 0..w {
                let mut acc = [0u32; 3];
                for (k, &t) in TAPS.iter().enumerate() {
                    let off = (k as i64 - 2) * h;
                    let (sx, sy) = if horizontal {
                        (addr(x as i64 + off, w as i64, toroidal), y)
                    } else {
                        (x, addr(y as i64 + off, hh as i64, toroidal))
                    };
                    let p = src[sy * w + sx];
                    for c in 0..3 {
                        acc[c] += t * p[c] as u32;
                    }
                }
                out[y * w + x] = acc.map(|s| ((s + 8) >> 4) as u16);
            }
        }
        out
    };
    pass(&pass(src, true), false)
}

/// Stack level `L − steps` of a `w × h` image, 8-bit: what [`build_stack`] gives there,
/// without the coarser levels.
pub fn low_pass(pixels: &[[u8; 3]], dims: (usize, usize), toroidal: bool, steps: u32) -> Vec<[u8; 3]> {
    let steps = steps.min(crate::geom::levels_for(dims.0 as u32, dims.1 as u32));
    let mut level: Vec<[u16; 3]> = pixels.iter().map(|p| p.map(|v| (v as u16) << 8)).collect();
    for s in 0..steps {
        level = blur(&level, dims, 1 << s, toroidal);
    }
    level.iter().map(|c| c.map(to_u8)).collect()
}

/// Round a stack value (value·256) to 8 bits.
#[inline]
pub fn to_u8(v: u16) -> u8 {
    ((v as u32 + 128) >> 8).min(255) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn addressing_wraps_or_mirrors() {
        assert_eq!(addr(-1, 8, true), 7);
        assert_eq!(addr(-1, 8, false), 0);
        assert_eq!(addr(8, 8, false), 7);
        assert_eq!(addr(17, 8, false), 1);
    }

    #[test]
    fn a_low_pass_is_the_stack_level_it_names() {
        let m = 16usize;
        let px: Vec<[u8; 3]> =
            (0..m * m).map(|i| [(i * 37 % 251) as u8, (i * 11 % 256) as u8, (i / m * 16) as u8]).collect();
        for toroidal in [false, true] {
            let stack = build_stack(&px, (m, m), toroidal);
            for steps in 0..=3u32 {
                let level: Vec<[u8; 3]> = stack[4 - steps as usize].iter().map(|c| c.map(to_u8)).collect();
                assert_eq!(low_pass(&px, (m, m), toroidal, steps), level, "toroidal {toroidal}, {steps} steps");
            }
        }
    }

    #[test]
    fn flat_exemplar_gives_flat_stack() {
        let px = vec![[7u8, 8, 9]; 32 * 32];
        let s = build_stack(&px, (32, 32), false);
        assert_eq!(s.len(), 6);
        for level in &s {
            assert!(level.iter().all(|p| *p == [7 << 8, 8 << 8, 9 << 8]));
        }
    }
}
