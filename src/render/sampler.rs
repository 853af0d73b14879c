//! Reproducible random numbers: one PCG stream per (seed, scene, view, pixel).
//!
//! Deriving the stream from the pixel — not from the thread or the order of work — is what makes
//! the output byte-identical for any thread count.

use glam::Vec2;
use rand::RngExt;
use rand_pcg::Pcg32;

/// SplitMix64 finaliser: a cheap, well-mixed 64-bit hash.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform float in [0, 1) from a hash value.
#[inline]
pub fn unit_float(h: u64) -> f32 {
    (h >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
}

/// Per-pixel sampler: stratified pixel positions plus a PCG stream for everything else.
pub struct Sampler {
    rng: Pcg32,
    strata: [u32; 2],
}

impl Sampler {
    /// The stream of pixel `(x, y)` of `view` in scene `scene`.
    pub fn new(seed: u64, scene: u64, view: u32, x: u32, y: u32, spp: u32) -> Self {
        let key = mix64(mix64(mix64(seed) ^ scene) ^ view as u64);
        let pixel = (y as u64) << 32 | x as u64;
        Self {
            rng: Pcg32::new(mix64(key ^ pixel), key | 1),
            strata: strata(spp),
        }
    }

    /// An independent stream keyed by a 64-bit value (side computations that must not shift
    /// the pixel's own stream, such as shading hidden slice surfaces).
    pub fn from_key(key: u64) -> Self {
        Self {
            rng: Pcg32::new(mix64(key), mix64(!key) | 1),
            strata: [1, 1],
        }
    }

    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        self.rng.random::<f32>()
    }

    #[inline]
    pub fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }

    /// A fresh 64-bit key (per-ray decisions that must not depend on traversal order).
    #[inline]
    pub fn next_key(&mut self) -> u64 {
        self.rng.random::<u64>()
    }

    /// Jittered position of sample `s` inside the unit pixel (`nx × ny` strata).
    #[inline]
    pub fn pixel_offset(&mut self, s: u32) -> Vec2 {
        let [nx, ny] = self.strata;
        let cell = Vec2::new((s % nx) as f32, ((s / nx) % ny) as f32);
        (cell + self.next2()) / Vec2::new(nx as f32, ny as f32)
    }
}

/// The `nx × ny = spp` grid of pixel strata closest to square: `nx` is the largest divisor of
/// `spp` not above its square root. Exactly `spp` cells, so every cell gets one sample; a
/// rounded square root instead left cells empty (spp 8 → 3 × 3 with one never sampled, so
/// every pixel integrated 8/9 of its area).
fn strata(spp: u32) -> [u32; 2] {
    let spp = spp.max(1);
    let nx = (1..=spp.isqrt())
        .rev()
        .find(|d| spp.is_multiple_of(*d))
        .unwrap_or(1);
    [nx, spp / nx]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<f32> = (0..8)
            .scan(Sampler::new(1, 2, 3, 4, 5, 16), |s, _| Some(s.next_f32()))
            .collect();
        let b: Vec<f32> = (0..8)
            .scan(Sampler::new(1, 2, 3, 4, 5, 16), |s, _| Some(s.next_f32()))
            .collect();
        let c: Vec<f32> = (0..8)
            .scan(Sampler::new(1, 2, 3, 5, 4, 16), |s, _| Some(s.next_f32()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn stratified_offsets_cover_every_stratum_once() {
        for (spp, grid) in [
            (16, [4, 4]),
            (8, [2, 4]),
            (32, [4, 8]),
            (7, [1, 7]),
            (1, [1, 1]),
        ] {
            assert_eq!(strata(spp), grid, "spp {spp}");
            let mut s = Sampler::new(0, 0, 0, 0, 0, spp);
            let [nx, ny] = grid;
            let mut seen = vec![0u32; spp as usize];
            for i in 0..spp {
                let p = s.pixel_offset(i);
                assert!(p.x >= 0.0 && p.x < 1.0 && p.y >= 0.0 && p.y < 1.0);
                let cell = (p.y * ny as f32) as usize * nx as usize + (p.x * nx as f32) as usize;
                seen[cell] += 1;
            }
            assert_eq!(
                seen,
                vec![1; spp as usize],
                "spp {spp}: a stratum is empty or doubled"
            );
        }
    }
}
