//! Reproducible sample values: one Owen-scrambled Sobol sequence per (seed, scene, view,
//! pixel), indexed by the pixel's sample number.
//!
//! Deriving the sequence from the pixel — not from the thread or the order of work — is what
//! makes the output byte-identical for any thread count. Sobol points (the `sobol_burley`
//! crate: Burley's hash-based Owen scrambling) stratify every dimension of the path across a
//! pixel's samples, where independent random numbers clump: the light sample, the lobe choice
//! and direction, Russian roulette and stochastic transparency all converge faster. Dimensions
//! come in sets of four, each set with its own scramble and shuffle (Burley's padding, as
//! Cycles does), so a path may draw any number of them; every vertex starts at a fixed
//! dimension ([`Sampler::start_vertex`]) so that a dimension means the same decision in every
//! sample of the pixel.

use crate::util::hash::{mix64, unit_float};
use glam::Vec2;

/// Dimensions reserved per path vertex: the light sample (choice and point), the continuation
/// choice, the lobe choice and direction, Russian roulette and the next ray's transparency
/// phase, padded to whole sets of four.
pub const VERTEX_DIMS: u32 = 12;

/// Dimensions of the camera ray (pixel position, transparency phase), before the path's.
const CAMERA_DIMS: u32 = 4;

/// Longest Sobol sequence `sobol_burley` provides; later samples continue in a fresh scramble.
const SEQUENCE: u32 = 1 << 16;

/// What decides which semi-transparent surfaces a ray passes (stochastic transparency): a
/// surface of opacity `a` is kept when `fract(h(hash, surface) + phase) < a`. `hash` is the
/// same for every sample of a pixel and `phase` a stratified dimension, so for every surface
/// the kept fraction of a pixel's samples is `a` to within one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayKey {
    pub hash: u64,
    pub phase: f32,
}

impl RayKey {
    /// A 64-bit value distinct per camera sample (the hash is the pixel's, the phase the
    /// sample's): the key of side streams such as hidden slice surfaces' shading.
    #[inline]
    pub fn stream(self) -> u64 {
        self.hash ^ (self.phase.to_bits() as u64) << 32
    }

    /// The uniform number that surface `id` is tested with.
    #[inline]
    pub fn uniform(self, id: u32) -> f32 {
        (unit_float(mix64(self.hash ^ id as u64)) + self.phase).fract()
    }
}

/// A pixel's sampler: sample `index`, next dimension `dim`, and the 4-D set of values that
/// `dim` falls in (computed once per set: `sobol_burley` evaluates four dimensions at the cost
/// of one).
pub struct Sampler {
    seed: u64,
    index: u32,
    dim: u32,
    strata: [u32; 2],
    /// Which set `values` holds (`u32::MAX`: none).
    set: u32,
    values: [f32; 4],
}

impl Sampler {
    /// The sequence of pixel `(x, y)` of `view` in scene `scene`, with `spp` pixel strata.
    pub fn new(seed: u64, scene: u64, view: u32, x: u32, y: u32, spp: u32) -> Self {
        let key = mix64(mix64(mix64(seed) ^ scene) ^ view as u64);
        let pixel = (y as u64) << 32 | x as u64;
        Self::with_seed(mix64(key ^ pixel), strata(spp))
    }

    /// An independent sequence keyed by a 64-bit value (side computations that must not shift
    /// the pixel's own values, such as shading hidden slice surfaces).
    pub fn from_key(key: u64) -> Self {
        Self::with_seed(mix64(!key), [1, 1])
    }

    fn with_seed(seed: u64, strata: [u32; 2]) -> Self {
        Self {
            seed,
            index: 0,
            dim: 0,
            strata,
            set: u32::MAX,
            values: [0.0; 4],
        }
    }

    /// Starts sample `index` of the pixel at its first dimension.
    #[inline]
    pub fn start_sample(&mut self, index: u32) {
        (self.index, self.dim, self.set) = (index, 0, u32::MAX);
    }

    /// Moves to the dimensions of path vertex `depth` (after the camera ray's).
    #[inline]
    pub fn start_vertex(&mut self, depth: u32) {
        self.dim = CAMERA_DIMS + depth * VERTEX_DIMS;
    }

    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        let (set, within) = (self.dim / 4, self.dim % 4);
        self.dim += 1;
        if set != self.set {
            let scramble = mix64(self.seed ^ (set as u64) << 32 ^ (self.index / SEQUENCE) as u64);
            self.values = sobol_burley::sample_4d(self.index % SEQUENCE, 0, scramble as u32);
            self.set = set;
        }
        self.values[within as usize]
    }

    /// An independent sequence for extra samples of this sample's vertex `depth` (its light
    /// samples beyond the first): keyed by the pixel, the sample and the vertex.
    pub fn side(&self, depth: u32) -> Sampler {
        Self::from_key(mix64(self.seed ^ (self.index as u64) << 32 ^ depth as u64))
    }

    /// The next dimension to be drawn, for [`Self::resume_at`].
    #[inline]
    pub fn dimension(&self) -> u32 {
        self.dim
    }

    /// Continues at dimension `dim` (a branch of the path drew others in between).
    #[inline]
    pub fn resume_at(&mut self, dim: u32) {
        self.dim = dim;
    }

    #[inline]
    pub fn next2(&mut self) -> Vec2 {
        Vec2::new(self.next_f32(), self.next_f32())
    }

    /// The transparency key of the next ray: a hash of the pixel and the dimension (the same
    /// in every sample), and a stratified phase.
    #[inline]
    pub fn next_key(&mut self) -> RayKey {
        let hash = mix64(self.seed ^ 0x5EED_0000_0000 ^ self.dim as u64);
        RayKey {
            hash,
            phase: self.next_f32(),
        }
    }

    /// Starts sample `s` and returns its jittered position inside the unit pixel: stratum `s`
    /// of the `nx × ny` grid, so every stratum holds exactly one sample for any spp.
    #[inline]
    pub fn pixel_offset(&mut self, s: u32) -> Vec2 {
        self.start_sample(s);
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

    /// Every dimension — in the first set, in padded sets, far along the path — puts exactly
    /// one of a pixel's first 16 samples in each sixteenth of [0, 1) (the Sobol net property
    /// that independent random numbers lack), and two pixels get different points.
    #[test]
    fn every_dimension_is_stratified_across_a_pixels_samples() {
        for dim in [0, 3, 5, 13, 50, 200, 300] {
            let mut seen = [0u32; 16];
            let mut first = Vec::new();
            for (x, seen) in [(4, Some(&mut seen)), (5, None)] {
                let mut s = Sampler::new(1, 2, 3, x, 5, 16);
                let mut values = Vec::new();
                for i in 0..16 {
                    s.start_sample(i);
                    s.dim = dim;
                    values.push(s.next_f32());
                }
                if let Some(seen) = seen {
                    values.iter().for_each(|v| seen[(v * 16.0) as usize] += 1);
                    first = values;
                } else {
                    assert_ne!(first, values, "dim {dim}: pixels share their points");
                }
            }
            assert_eq!(seen, [1; 16], "dim {dim}");
        }
    }

    /// Stochastic transparency: of a pixel's 16 camera rays, the share that keeps a surface of
    /// opacity `a` is `a` to within one ray, for every surface (each hashes to its own offset).
    #[test]
    fn transparency_keeps_the_opacity_share_of_samples() {
        for id in [0, 7, 123_456] {
            for a in [0.1f32, 0.25, 0.5, 0.8] {
                let mut s = Sampler::new(9, 0, 40, 17, 3, 16);
                let kept = (0..16)
                    .filter(|&i| {
                        s.pixel_offset(i);
                        s.next_key().uniform(id) < a
                    })
                    .count();
                let want = a * 16.0;
                assert!(
                    (kept as f32 - want).abs() <= 1.0,
                    "id {id}, a {a}: {kept}/16"
                );
            }
        }
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
