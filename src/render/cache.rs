//! Shared shading: the view-independent light at a surface point, estimated once from the
//! samples of every view of the light field and reused by all of them.
//!
//! The Standard BSDF's diffuse term separates into a factor of the outgoing direction and one
//! of the incident direction: `f_d(wo, wi) = ρ/π' · (1 − E(μo)) · (1 − E(μi))` (the
//! energy-conserving coupling of the glossy layer). So the diffuse light leaving a point is
//! `ρ/π' · (1 − E(μo)) · I(x)` with the *coupled irradiance* `I(x) = ∫ L(x, wi) (1 − E(μi))
//! cos θi dωi`, which depends on the point alone. A first pass (`fill`) estimates `I` at the
//! first non-delta vertex of camera paths of every view and averages the estimates per cell of
//! a world-space hash grid; the second pass renders each view, multiplying the cell's `I` by
//! the sample's own albedo (textures stay exact per sample) and `1 − E(μo)` of its own view,
//! and tracing the glossy lobe per view. Smooth glass and mirrors are delta surfaces: paths
//! continue through them per view and use the cache at their next vertex.
//!
//! Cells are about a pixel footprint wide (`cell_px` pixels of the centre camera at the cell's
//! depth, rounded up to a power of two), keyed by position, the dominant axis of the shading
//! normal and the material. The bias is the blur of `I` over a cell: lighting that changes
//! within a pixel footprint (a contact shadow's edge) is averaged over it, at most ~2 px at
//! `cell_px = 1`; it shrinks with `cell_px`, while the shared samples per cell shrink with it
//! too. Filling bands in parallel and merging them in band order keeps every sum in a fixed
//! order: the cache, and so every image, is byte-identical for any thread count.

use super::sampler::mix64;
use crate::camera::LightFieldCamera;
use glam::{DVec3, I64Vec3, Vec3};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// The grid cells of a scene: where a point's cell is, from the centre camera's footprint.
#[derive(Clone, Copy, Debug)]
pub struct CacheGrid {
    origin: DVec3,
    forward: DVec3,
    /// Cell size per metre of depth: `cell_px / f_px`.
    cell_per_depth: f64,
}

impl CacheGrid {
    /// Cells of `cell_px` pixels of `cam`'s centre view.
    pub fn new(cam: &LightFieldCamera, cell_px: f32) -> Self {
        Self {
            origin: cam.position,
            forward: cam.forward,
            cell_per_depth: cell_px as f64 / cam.f_px(),
        }
    }

    /// The cell of point `p` with shading normal `n` on material `material`.
    pub fn key(&self, p: Vec3, n: Vec3, material: u32) -> u64 {
        let (level, p) = self.cell_coords(p);
        self.cell_key(level, p.floor().as_i64vec3(), n, material)
    }

    /// The level of `p`'s cells and `p` in units of their size.
    fn cell_coords(&self, p: Vec3) -> (i32, DVec3) {
        let p = p.as_dvec3();
        let depth = (p - self.origin).dot(self.forward).abs().max(1e-6);
        let level = (depth * self.cell_per_depth).log2().ceil() as i32;
        (level, p / 2f64.powi(level))
    }

    fn cell_key(&self, level: i32, q: I64Vec3, n: Vec3, material: u32) -> u64 {
        let axis = n.abs().max_position();
        let normal = (axis as u64) << 1 | (n[axis] < 0.0) as u64;
        let mut h = mix64(level as i64 as u64 ^ (normal << 32) ^ ((material as u64) << 40));
        for c in q.to_array() {
            h = mix64(h ^ c as u64);
        }
        h
    }
}

/// Keys are already well-mixed hashes: hashing them again would only cost time.
#[derive(Default)]
pub struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 << 8) | b as u64;
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = v;
    }
}

type KeyMap<V> = HashMap<u64, V, BuildHasherDefault<KeyHasher>>;

/// Sums of coupled-irradiance estimates per cell, for one band of one view or for all.
#[derive(Default)]
pub struct CacheSums {
    cells: KeyMap<(Vec3, u32)>,
}

impl CacheSums {
    pub fn add(&mut self, key: u64, value: Vec3) {
        let cell = self.cells.entry(key).or_insert((Vec3::ZERO, 0));
        cell.0 += value;
        cell.1 += 1;
    }

    /// Adds `other`'s sums cell by cell (call in a fixed order for reproducible sums).
    pub fn merge(&mut self, other: CacheSums) {
        for (key, (sum, n)) in other.cells {
            let cell = self.cells.entry(key).or_insert((Vec3::ZERO, 0));
            cell.0 += sum;
            cell.1 += n;
        }
    }

    /// The mean per cell.
    pub fn finish(self, grid: CacheGrid) -> RadianceCache {
        let cells = self
            .cells
            .into_iter()
            .map(|(k, (sum, n))| (k, sum / n as f32))
            .collect();
        RadianceCache { grid, cells }
    }
}

/// The filled cache: mean coupled irradiance per cell.
pub struct RadianceCache {
    pub grid: CacheGrid,
    cells: KeyMap<Vec3>,
}

impl RadianceCache {
    pub fn get(&self, key: u64) -> Option<Vec3> {
        self.cells.get(&key).copied()
    }

    /// The coupled irradiance at `p`, interpolated trilinearly between the centres of the
    /// eight cells around it (those that exist). A per-sample nearest cell would make a
    /// pixel's value depend on how its samples fall among cells, which differs from view to
    /// view; the interpolated field is continuous, so views agree to its gradient.
    pub fn lookup(&self, p: Vec3, n: Vec3, material: u32) -> Option<Vec3> {
        let (level, p) = self.grid.cell_coords(p);
        let f = p - DVec3::splat(0.5);
        let base = f.floor();
        let t = (f - base).as_vec3();
        let base = base.as_i64vec3();
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
        for corner in 0..8 {
            let o = I64Vec3::new(corner & 1, (corner >> 1) & 1, corner >> 2);
            let w = [0, 1, 2]
                .map(|a| if o[a] == 1 { t[a] } else { 1.0 - t[a] })
                .iter()
                .product::<f32>();
            if let Some(v) = self.get(self.grid.cell_key(level, base + o, n, material)) {
                sum += w * v;
                weight += w;
            }
        }
        (weight > 1e-3).then(|| sum / weight)
    }

    /// Number of cells (reported with the render).
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> LightFieldCamera {
        LightFieldCamera {
            resolution: [100, 100],
            grid: [1, 1],
            focal_length_mm: 50.0,
            sensor_size_mm: 50.0,
            baseline_m: 0.0,
            focus_distance_m: 1.0,
            position: DVec3::ZERO,
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }

    #[test]
    fn cells_are_a_pixel_footprint_rounded_up_to_a_power_of_two() {
        // f_px = 100: at 2 m depth a pixel is 2 cm, so cells are 2^-5 m = 3.125 cm.
        let grid = CacheGrid::new(&camera(), 1.0);
        let n = Vec3::Z;
        let key = |x: f32| grid.key(Vec3::new(x, 0.01, -2.0), n, 0);
        assert_eq!(key(0.001), key(0.03));
        assert_ne!(key(0.03), key(0.032));
        // Another normal axis, side or material is another cell.
        let p = Vec3::new(0.01, 0.01, -2.0);
        assert_ne!(grid.key(p, n, 0), grid.key(p, -n, 0));
        assert_ne!(grid.key(p, n, 0), grid.key(p, Vec3::X, 0));
        assert_ne!(grid.key(p, n, 0), grid.key(p, n, 1));
    }

    #[test]
    fn sums_average_per_cell_in_any_merge_grouping() {
        let mut a = CacheSums::default();
        a.add(1, Vec3::ONE);
        a.add(2, Vec3::splat(4.0));
        let mut b = CacheSums::default();
        b.add(1, Vec3::splat(3.0));
        a.merge(b);
        let cache = a.finish(CacheGrid::new(&camera(), 1.0));
        assert_eq!(cache.get(1), Some(Vec3::splat(2.0)));
        assert_eq!(cache.get(2), Some(Vec3::splat(4.0)));
        assert_eq!(cache.get(3), None);
        assert_eq!(cache.len(), 2);
    }
}
