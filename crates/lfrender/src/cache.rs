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

use crate::camera::LightFieldCamera;
use crate::util::hash::mix64;
use glam::{DVec3, I64Vec3, Vec3};
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};

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

    /// The cells of point `p` with shading normal `n` on material `material`: at the level
    /// of its depth, then [`COARSER`] levels of twice, four times… the size (a lookup that
    /// finds no filled cell at its own level takes the next coarser one instead).
    pub fn keys(&self, p: Vec3, n: Vec3, material: u32) -> [u64; COARSER + 1] {
        let level = self.level(p);
        std::array::from_fn(|k| {
            let level = level + k as i32;
            let q = cell_units(p, level).floor().as_i64vec3();
            self.cell_key(level, q, n, material)
        })
    }

    /// The level of the cells at `p`'s depth.
    fn level(&self, p: Vec3) -> i32 {
        let depth = (p.as_dvec3() - self.origin)
            .dot(self.forward)
            .abs()
            .max(1e-6);
        (depth * self.cell_per_depth).log2().ceil() as i32
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

/// Coarser levels a fill sample also goes into: a lookup in a cell no fill sample reached
/// (thin or grazing surfaces, where the fill's sub-pixel positions differ from the render's)
/// then blurs over 2 or 4 cells instead of falling back to a full, noisy path per sample.
pub const COARSER: usize = 2;

/// `p` in units of the cell size of `level`.
fn cell_units(p: Vec3, level: i32) -> DVec3 {
    p.as_dvec3() / 2f64.powi(level)
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
    /// Adds one estimate to the cells `keys` of its point ([`CacheGrid::keys`]).
    pub fn add(&mut self, keys: &[u64], value: Vec3) {
        for &key in keys {
            let cell = self.cells.entry(key).or_insert((Vec3::ZERO, 0));
            cell.0 += value;
            cell.1 += 1;
        }
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
        static NEXT_ID: AtomicU64 = AtomicU64::new(0);
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        RadianceCache { grid, cells, id }
    }
}

/// What identifies the eight cells of a lookup (`RadianceCache::corners`); the cache's id
/// tells two caches apart (a thread renders one scene's views after another's, and a new
/// cache may reuse a dropped one's memory).
#[derive(Clone, Copy, PartialEq)]
struct Corners {
    cache: u64,
    level: i32,
    base: I64Vec3,
    normal: u8,
    material: u32,
}

thread_local! {
    static LAST_CORNERS: std::cell::RefCell<Option<(Corners, [Option<Vec3>; 8])>> =
        const { std::cell::RefCell::new(None) };
}

/// The filled cache: mean coupled irradiance per cell.
pub struct RadianceCache {
    pub grid: CacheGrid,
    cells: KeyMap<Vec3>,
    /// Unique in the process (see [`Corners`]).
    id: u64,
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
        let level = self.grid.level(p);
        (0..=COARSER as i32).find_map(|k| self.interpolate(level + k, p, n, material))
    }

    /// The trilinear interpolation at one level, `None` where no cell around `p` is filled.
    fn interpolate(&self, level: i32, p: Vec3, n: Vec3, material: u32) -> Option<Vec3> {
        let f = cell_units(p, level) - DVec3::splat(0.5);
        let base = f.floor();
        let t = (f - base).as_vec3();
        let corners = self.corners(level, base.as_i64vec3(), n, material);
        let (mut sum, mut weight) = (Vec3::ZERO, 0.0);
        for (corner, value) in corners.iter().enumerate() {
            let o = [corner & 1, (corner >> 1) & 1, corner >> 2];
            let w = [0, 1, 2]
                .map(|a| if o[a] == 1 { t[a] } else { 1.0 - t[a] })
                .iter()
                .product::<f32>();
            if let Some(v) = value {
                sum += w * *v;
                weight += w;
            }
        }
        (weight > 1e-3).then(|| sum / weight)
    }

    /// The eight cells around a lookup. The samples of a pixel (and of its neighbours) mostly
    /// fall between the same eight cells, so the last eight are kept per thread: at 512²
    /// the table is far larger than the CPU caches, and eight random reads per sample cost
    /// more than the rest of the sample.
    fn corners(&self, level: i32, base: I64Vec3, n: Vec3, material: u32) -> [Option<Vec3>; 8] {
        let axis = n.abs().max_position();
        let id = Corners {
            cache: self.id,
            level,
            base,
            normal: (axis as u8) << 1 | (n[axis] < 0.0) as u8,
            material,
        };
        LAST_CORNERS.with(|last| {
            let mut last = last.borrow_mut();
            if let Some((seen, values)) = &*last
                && *seen == id
            {
                return *values;
            }
            let values = std::array::from_fn(|corner| {
                let c = corner as i64;
                let o = I64Vec3::new(c & 1, (c >> 1) & 1, c >> 2);
                self.get(self.grid.cell_key(level, base + o, n, material))
            });
            *last = Some((id, values));
            values
        })
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
        let key = |x: f32| grid.keys(Vec3::new(x, 0.01, -2.0), n, 0)[0];
        assert_eq!(key(0.001), key(0.03));
        assert_ne!(key(0.03), key(0.032));
        // The coarser levels: 6.25 cm and 12.5 cm.
        let coarse = |x: f32| grid.keys(Vec3::new(x, 0.01, -2.0), n, 0);
        assert_eq!(coarse(0.001)[1], coarse(0.06)[1]);
        assert_ne!(coarse(0.06)[1], coarse(0.063)[1]);
        assert_eq!(coarse(0.001)[2], coarse(0.12)[2]);
        // Another normal axis, side or material is another cell.
        let p = Vec3::new(0.01, 0.01, -2.0);
        let k = |n: Vec3, m: u32| grid.keys(p, n, m)[0];
        assert_ne!(k(n, 0), k(-n, 0));
        assert_ne!(k(n, 0), k(Vec3::X, 0));
        assert_ne!(k(n, 0), k(n, 1));
    }

    #[test]
    fn sums_average_per_cell_in_any_merge_grouping() {
        let mut a = CacheSums::default();
        a.add(&[1], Vec3::ONE);
        a.add(&[2, 5], Vec3::splat(4.0));
        let mut b = CacheSums::default();
        b.add(&[1], Vec3::splat(3.0));
        a.merge(b);
        let cache = a.finish(CacheGrid::new(&camera(), 1.0));
        assert_eq!(cache.get(1), Some(Vec3::splat(2.0)));
        assert_eq!(cache.get(2), Some(Vec3::splat(4.0)));
        assert_eq!(cache.get(3), None);
        assert_eq!(cache.get(5), Some(Vec3::splat(4.0)));
        assert_eq!(cache.len(), 3);
    }
}
