//! Hashing to integers and to uniform floats. One definition, because a scene's procedural
//! textures, its random layout and the renderer's sample streams must all agree bit for bit
//! across re-renders of a saved `scene.json`.

/// SplitMix64 finaliser: a cheap, well-mixed 64-bit hash.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform float in [0, 1) from the top 24 bits of a hash value (every value exact in f32).
#[inline]
pub fn unit_float(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_float_spans_zero_to_just_below_one() {
        assert_eq!(unit_float(0), 0.0);
        assert_eq!(unit_float(u64::MAX), 1.0 - 1.0 / (1u64 << 24) as f32);
        // Known SplitMix64 output for seed 0 (the reference implementation's first value).
        assert_eq!(mix64(0), 0xE220_A839_7B1D_CDAF);
    }
}
