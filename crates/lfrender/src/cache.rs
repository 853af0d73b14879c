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
//!
//! Where the light is smooth, the cell's noise is wasted resolution: once filled, each cell's
//! irradiance is shrunk towards the next coarser level's field at its centre as far as its own
//! noise explains their difference (positive-part James–Stein, coarsest level first), so smooth
//! light pools the samples of several levels and edges keep their cells. Its bias is the
//! coarser level's blur where that is below a cell's noise.
//!
//! The glossy lobe is shared too where it is wide: from every view of the grid a point is
//! seen within a small angle (the grid's span over the distance: 3° at 3 m at 512²), and a
//! lobe many times wider than that reflects nearly the same light towards all of them. There a
//! fill sample estimates, with probability `q`, the glossy light leaving towards its own view
//! divided by the lobe's directional albedo `A(μo) = F0·P(μo) + F90·Q(μo)` (the split-sum
//! factorisation of real-time rendering), and a view multiplies the cell's value by its own
//! sample's `A`: Fresnel's angle dependence and a textured F0 stay per sample. The glossy
//! light still changes across the grid, by the lobe's contrast times about `span / width`;
//! a plain mean would give every view the grid's average (a 4 % error at the outer views of
//! a lit rough metal at `glossy_share = 4`). So each cell fits the estimates linearly in the
//! view's position in the grid, `G(u, v) = G₀ + u·∂G/∂u + v·∂G/∂v` (least squares over its
//! samples), and a view reads the fit at its own `(u, v)`: what is left is the curvature of
//! the lobe's light over the grid, second order in `span / width`. Lobes narrower than
//! `glossy_share` times the grid's angle (mirrors, polished surfaces) stay per view, and so do
//! lobes narrower than `glossy_min_width` whatever the grid spans: such a lobe reflects detail
//! that changes within a cell, which the cell's one value blurs (a grid spanning almost no
//! angle, far surfaces at 512², or a single view, would otherwise share mirrors).

use crate::camera::LightFieldCamera;
use crate::util::hash::mix64;
use glam::{DMat3, DVec3, I64Vec3, Vec2, Vec3};
use rayon::prelude::*;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicU64, Ordering};

/// What a shared-shading cache shares, and how finely.
#[derive(Clone, Copy, Debug)]
pub struct CacheParams {
    /// Cell size in pixels of the centre view (rounded up to a power of two).
    pub cell_px: f32,
    /// A glossy lobe at least this many times as wide (`2α`, radians) as the angle the camera
    /// grid spans at a point is shared; narrower ones are traced per view. 0 shares every
    /// glossy lobe at least `glossy_min_width` wide (with that 0 too, mirrors included).
    pub glossy_share: f32,
    /// Lobes narrower than this (`2α`, radians) are never shared, whatever the grid spans.
    pub glossy_min_width: f32,
    /// Vertices of a fill path whose coupled-irradiance estimates the cells keep: 1 is the
    /// first (the camera's) alone; more adds those of its later surface vertices, up to
    /// [`MAX_FILL_VERTICES`] (see [`CacheSums::add_later`]).
    pub fill_vertices: u32,
    /// Light samples a fill path takes at its first vertex (see
    /// [`CacheGrid::fill_light_samples`]).
    pub fill_light_samples: u32,
    /// Shrink each cell's irradiance towards the next coarser level's as far as its own
    /// noise explains their difference ([`CellSums::shrunk`]).
    pub shrink: bool,
    /// A second fill pass whose paths read the first pass's cache at their second surface
    /// (a final gather); its estimates join the first pass's in every cell.
    pub final_gather: bool,
}

/// The most vertices of one fill path that feed the cache.
pub const MAX_FILL_VERTICES: u32 = 8;

/// The grid cells of a scene: where a point's cell is, from the centre camera's footprint.
#[derive(Clone, Copy, Debug)]
pub struct CacheGrid {
    origin: DVec3,
    forward: DVec3,
    /// Cell size per metre of depth: `cell_px / f_px`.
    cell_per_depth: f64,
    /// `glossy_share` times the distance between the grid's outermost cameras (metres).
    shared_lobe_span: f64,
    /// [`CacheParams::glossy_min_width`].
    min_shared_width: f32,
    /// [`CacheParams::fill_vertices`].
    pub fill_vertices: u32,
    /// Light samples at a fill path's first vertex, averaged. The cell's estimate there is
    /// the whole of what a Lambert surface shows, and with many lamps one light sample is much
    /// of its noise (it picks a lamp by power over distance, blind to whether it is hidden);
    /// a shadow ray costs a fraction of the path behind it.
    pub fill_light_samples: u32,
    /// [`CacheParams::shrink`].
    shrink: bool,
}

impl CacheGrid {
    /// The cells and sharing rule of `params` for `cam`'s light field.
    pub fn new(cam: &LightFieldCamera, params: CacheParams) -> Self {
        let [gx, gy] = cam.grid.map(|n| n.saturating_sub(1) as f64);
        Self {
            origin: cam.position,
            forward: cam.forward,
            cell_per_depth: params.cell_px as f64 / cam.f_px(),
            shared_lobe_span: params.glossy_share as f64 * gx.hypot(gy) * cam.baseline_m,
            min_shared_width: params.glossy_min_width,
            fill_vertices: params.fill_vertices.clamp(1, MAX_FILL_VERTICES),
            fill_light_samples: params.fill_light_samples.max(1),
            shrink: params.shrink,
        }
    }

    /// Whether a glossy lobe `width` radians wide (`2α`) at `p` is shared by all views: it is
    /// at least `glossy_share` times the angle the camera grid spans seen from `p`, and at
    /// least `glossy_min_width`.
    pub fn shares_glossy(&self, p: Vec3, width: f32) -> bool {
        // The floor first: it settles a narrow lobe without the square root (once per sample).
        width >= self.min_shared_width
            && width as f64 * (p.as_dvec3() - self.origin).length() >= self.shared_lobe_span
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
        (q.to_array())
            .into_iter()
            .fold(key_prefix(level, n, material), |h, c| mix64(h ^ c as u64))
    }

    /// The keys of the eight cells `base + corner_offset(corner)` ([`Self::cell_key`]'s),
    /// sharing the hashes of their common coordinates: 15 mixes instead of 32.
    fn corner_keys(&self, level: i32, base: I64Vec3, n: Vec3, material: u32) -> [u64; 8] {
        let h = key_prefix(level, n, material);
        let x = [0, 1].map(|o| mix64(h ^ (base.x + o) as u64));
        let xy: [u64; 4] =
            std::array::from_fn(|c| mix64(x[c & 1] ^ (base.y + (c >> 1) as i64) as u64));
        std::array::from_fn(|c| mix64(xy[c & 3] ^ (base.z + (c >> 2) as i64) as u64))
    }
}

/// The hash a cell key starts from: its level, normal side and material.
fn key_prefix(level: i32, n: Vec3, material: u32) -> u64 {
    let axis = n.abs().max_position();
    let normal = (axis as u64) << 1 | (n[axis] < 0.0) as u64;
    mix64(level as i64 as u64 ^ (normal << 32) ^ ((material as u64) << 40))
}

/// Coarser levels a fill sample also goes into: a lookup in a cell no fill sample reached
/// (thin or grazing surfaces, where the fill's sub-pixel positions differ from the render's)
/// then blurs over 2 or 4 cells instead of falling back to a full, noisy path per sample.
pub const COARSER: usize = 2;

/// The offset of corner `0..8` of a cell block along x, y, z (bits 0, 1, 2): one convention
/// for the cells a lookup fetches and the weights it gives them.
fn corner_offset(corner: usize) -> [usize; 3] {
    [corner & 1, (corner >> 1) & 1, corner >> 2]
}

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

/// One fill sample's estimate at its first non-delta vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Estimate {
    /// The coupled irradiance `I`.
    Irradiance(Vec3),
    /// The glossy light leaving towards the sample's view over the lobe's albedo `A(μo)`.
    Glossy(Vec3),
}

/// The glossy term of a cell as a linear function of the view's position `(u, v)` in the
/// grid (view steps from the centre view).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GlossyFit {
    pub centre: Vec3,
    pub du: Vec3,
    pub dv: Vec3,
}

impl GlossyFit {
    /// The glossy term seen from view position `uv`.
    pub fn at(&self, uv: Vec2) -> Vec3 {
        (self.centre + self.du * uv.x + self.dv * uv.y).max(Vec3::ZERO)
    }

    fn scaled(self, w: f32) -> Self {
        Self {
            centre: self.centre * w,
            du: self.du * w,
            dv: self.dv * w,
        }
    }

    fn plus(self, o: Self) -> Self {
        Self {
            centre: self.centre + o.centre,
            du: self.du + o.du,
            dv: self.dv + o.dv,
        }
    }
}

/// The sums of a least-squares fit of `g ≈ c + u·du + v·dv`.
#[derive(Clone, Copy, Default)]
struct GlossySums {
    /// Σ1, Σu, Σv, Σu², Σuv, Σv².
    design: [f32; 6],
    /// Σg, Σg·u, Σg·v.
    g: [Vec3; 3],
}

impl GlossySums {
    fn one(g: Vec3, uv: Vec2) -> Self {
        let (u, v) = (uv.x, uv.y);
        Self {
            design: [1.0, u, v, u * u, u * v, v * v],
            g: [g, g * u, g * v],
        }
    }

    fn add(&mut self, o: &Self) {
        self.design
            .iter_mut()
            .zip(o.design)
            .for_each(|(a, b)| *a += b);
        self.g.iter_mut().zip(o.g).for_each(|(a, b)| *a += b);
    }

    /// The fit, its slopes shrunk towards 0 by a ridge of [`RIDGE`], so that a cell seen from
    /// a few views only, where the slopes are not determined, keeps the mean.
    fn fit(&self) -> Option<GlossyFit> {
        let [n, su, sv, suu, suv, svv] = self.design.map(f64::from);
        if n == 0.0 {
            return None;
        }
        let m = DMat3::from_cols_array(&[n, su, sv, su, suu + RIDGE, suv, sv, suv, svv + RIDGE]);
        let inv = m.inverse();
        let [c, du, dv] = [0, 1, 2].map(|row| {
            let w = inv.row(row);
            let g = self.g.map(|g| g.as_dvec3());
            (g[0] * w.x + g[1] * w.y + g[2] * w.z).as_vec3()
        });
        Some(GlossyFit { centre: c, du, dv })
    }
}

/// The ridge of the glossy fit's slopes: the weight of one sample at a 9×9 grid's corner.
const RIDGE: f64 = 16.0;

/// Where a fill sample's first vertex lies: what names its cells at every level.
#[derive(Clone, Copy, Debug)]
pub struct Anchor {
    pub p: Vec3,
    /// Shading normal (its dominant axis and side key the cell).
    pub n: Vec3,
    pub material: u32,
}

/// Running sums of one cell: the two estimates, the irradiance's squares (its noise), and
/// the first vertex that filled it with its level above the vertex's own (what finds the cell
/// again from its key, for [`CellSums::shrunk`]).
#[derive(Clone, Copy, Default)]
struct CellSums {
    irradiance: (Vec3, u32),
    squares: Vec3,
    glossy: GlossySums,
    anchor: Option<(Anchor, u8)>,
}

impl CellSums {
    fn add(&mut self, other: &CellSums) {
        self.irradiance.0 += other.irradiance.0;
        self.irradiance.1 += other.irradiance.1;
        self.squares += other.squares;
        self.glossy.add(&other.glossy);
        self.anchor = self.anchor.or(other.anchor);
    }

    /// The cell's mean irradiance shrunk towards `prior`, the next coarser level's field at
    /// the cell's centre (trilinear between its cells, which hold ~4× the samples): by the
    /// positive-part James–Stein factor `1 − v / |m − prior|²`, `v` the variance of the
    /// cell's mean from its own samples. Where the two differ by no more than the cell's noise
    /// (smooth lighting) the cell takes the coarser, less noisy value; where they differ by
    /// far more (a shadow's edge, a lamp's falloff) it keeps its own. So the bias is the
    /// coarser level's blur, and only where that blur is below the cell's noise; it shrinks
    /// with the noise, as the fill grows.
    fn shrunk(&self, mean: Vec3, prior: Vec3) -> Vec3 {
        let n = self.irradiance.1 as f64;
        if n < 2.0 {
            return prior;
        }
        let m = mean.as_dvec3();
        let of_mean = (self.squares.as_dvec3() / n - m * m).max(DVec3::ZERO) / (n - 1.0);
        let d = m - prior.as_dvec3();
        let (dd, v) = (d.length_squared(), of_mean.element_sum());
        let keep = if dd > v { 1.0 - v / dd } else { 0.0 };
        (prior.as_dvec3() + d * keep).as_vec3()
    }

    fn mean(self) -> Cell {
        let (sum, n) = self.irradiance;
        Cell {
            irradiance: (n > 0).then(|| sum / n as f32),
            glossy: self.glossy.fit(),
        }
    }
}

/// Sums of the fill's estimates per cell, for one band of one view or for all.
#[derive(Default)]
pub struct CacheSums {
    cells: KeyMap<CellSums>,
    /// The coupled irradiance estimated at later vertices of fill paths: sum, squares, count.
    later: KeyMap<(Vec3, Vec3, u32)>,
}

impl CacheSums {
    /// Adds one estimate, made from view position `uv` at `anchor`, to the cells `keys` of
    /// its point ([`CacheGrid::keys`]).
    pub fn add(&mut self, keys: &[u64], estimate: Estimate, uv: Vec2, anchor: Anchor) {
        let mut one = CellSums::default();
        match estimate {
            Estimate::Irradiance(v) => (one.irradiance, one.squares) = ((v, 1), v * v),
            Estimate::Glossy(g) => one.glossy = GlossySums::one(g, uv),
        }
        for (k, &key) in keys.iter().enumerate() {
            one.anchor = Some((anchor, k as u8));
            self.cells.entry(key).or_default().add(&one);
        }
    }

    /// Adds a coupled irradiance `estimate` made at a later vertex of a fill path (one the
    /// path reached by a bounce) to the cells `keys` of that vertex. `I(x)` does not depend
    /// on where the light leaving `x` goes, so such an estimate is as good a sample of a
    /// cell's `I` as a camera path's first vertex makes: the bounces of the fill paths the
    /// cache traces anyway, free samples (the way neural radiance caches train on every
    /// vertex of a path, Müller et al. 2021). Only cells some first vertex filled keep them
    /// ([`Self::merge_view`]): the others no view ever reads.
    pub fn add_later(&mut self, keys: &[u64], estimate: Vec3) {
        for &key in keys {
            let (sum, squares, n) = self.later.entry(key).or_default();
            (*sum, *squares, *n) = (*sum + estimate, *squares + estimate * estimate, *n + 1);
        }
    }

    /// Adds one view's band sums, in band order: first their cells, then their later-vertex
    /// estimates, into the cells that exist by then (some first vertex of this view or an
    /// earlier one filled them). The estimates of cells no view has filled yet are dropped at
    /// once: most lie where no camera looks (under furniture, beside and behind the grid, in
    /// cells as fine as the centre camera's pixels there), and keeping them until the end
    /// held 2.7 GB at 512². The same sums for any thread count.
    pub fn merge_view(&mut self, bands: Vec<CacheSums>) {
        let mut later = Vec::with_capacity(bands.len());
        for band in bands {
            for (key, sums) in band.cells {
                self.cells.entry(key).or_default().add(&sums);
            }
            later.push(band.later);
        }
        for (key, (sum, squares, n)) in later.into_iter().flatten() {
            if let Some(cell) = self.cells.get_mut(&key) {
                cell.irradiance.0 += sum;
                cell.irradiance.1 += n;
                cell.squares += squares;
            }
        }
    }

    /// The means per cell, their irradiance shrunk towards the next coarser level's
    /// ([`CellSums::shrunk`]) if the grid says so. The sums stay: a final gather reads this
    /// cache and adds its estimates to them.
    pub fn finish(&self, grid: CacheGrid) -> RadianceCache {
        let means = (self.cells.iter())
            .map(|(&k, sums)| (k, sums.mean()))
            .collect();
        let mut cache = RadianceCache::new(grid, means);
        if grid.shrink {
            cache.shrink(&self.cells);
        }
        cache
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

/// The means of one filled cell (`None` where no fill sample made that estimate).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Cell {
    /// Coupled irradiance `I`.
    pub irradiance: Option<Vec3>,
    /// Glossy light over the lobe's albedo (only where the lobe is shared).
    pub glossy: Option<GlossyFit>,
}

/// A lookup's result: the coupled irradiance, and the glossy term where cells have one.
#[derive(Clone, Copy, Debug)]
pub struct Cached {
    pub irradiance: Vec3,
    pub glossy: Option<GlossyFit>,
}

/// The last [`MEMO`] corner sets a thread looked up, replaced round-robin: a composited
/// camera ray alternates between the layers it passes (a lampshade, the bulb behind it), so
/// one remembered set would be evicted at every lookup. The ids are kept apart from the
/// cells, so a search does not step over 8 × 56 bytes of cells per set.
struct CornerMemo {
    ids: [Option<Corners>; MEMO],
    cells: [[Option<Cell>; 8]; MEMO],
    next: usize,
}

/// Corner sets remembered per thread. A pixel's samples straddle up to eight sets (cells
/// are ~1.8 pixels wide), its composited layers and per-view bounces add more: at 128² 4
/// sets missed 39 % of the lookups, 8 sets 29 %, 16 sets 25 % (4 Dec 2026).
const MEMO: usize = 8;

thread_local! {
    static LAST_CORNERS: std::cell::RefCell<CornerMemo> = const {
        std::cell::RefCell::new(CornerMemo {
            ids: [None; MEMO],
            cells: [[None; 8]; MEMO],
            next: 0,
        })
    };
}

/// The filled cache: the mean estimates per cell.
pub struct RadianceCache {
    pub grid: CacheGrid,
    cells: KeyMap<Cell>,
    /// Unique in the process (see [`Corners`]).
    id: u64,
}

impl RadianceCache {
    fn new(grid: CacheGrid, cells: KeyMap<Cell>) -> Self {
        let id = Self::next_id();
        Self { grid, cells, id }
    }

    /// A process-unique id ([`Corners`]).
    fn next_id() -> u64 {
        static NEXT_ID: AtomicU64 = AtomicU64::new(0);
        NEXT_ID.fetch_add(1, Ordering::Relaxed)
    }

    /// Shrinks every cell's irradiance towards the next coarser level's field
    /// ([`CellSums::shrunk`]), coarsest level first, so each level leans on a coarser one
    /// that has already leant on its own: smooth light pools the samples of several levels.
    /// Each cell depends only on its own sums and the coarser levels, so the result does not
    /// depend on an order within a level.
    fn shrink(&mut self, sums: &KeyMap<CellSums>) {
        let level = |s: &CellSums| s.anchor.map(|(at, k)| self.grid.level(at.p) + k as i32);
        let mut order: Vec<(i32, u64)> = (sums.iter())
            .filter_map(|(&key, s)| Some((level(s)?, key)))
            .collect();
        order.sort_unstable_by(|a, b| b.cmp(a));
        for same in order.chunk_by(|a, b| a.0 == b.0) {
            let shrunk: Vec<(u64, Vec3)> = (same.par_iter())
                .filter_map(|&(level, key)| {
                    let s = &sums[&key];
                    let mean = self.cells[&key].irradiance?;
                    let (at, _) = s.anchor?;
                    let centre = (cell_units(at.p, level).floor() + 0.5) * 2f64.powi(level);
                    let prior = self.interpolate(level + 1, centre.as_vec3(), at.n, at.material)?;
                    Some((key, s.shrunk(mean, prior.irradiance)))
                })
                .collect();
            for (key, irradiance) in shrunk {
                self.cells.get_mut(&key).expect("a filled cell").irradiance = Some(irradiance);
            }
            // Lookups remember cells per cache id: the changed cells are a new cache.
            self.id = Self::next_id();
        }
    }

    pub fn get(&self, key: u64) -> Option<Cell> {
        self.cells.get(&key).copied()
    }

    /// The cached light at `p`, interpolated trilinearly between the centres of the eight
    /// cells around it (those that exist). A per-sample nearest cell would make a pixel's
    /// value depend on how its samples fall among cells, which differs from view to view;
    /// the interpolated field is continuous, so views agree to its gradient.
    pub fn lookup(&self, p: Vec3, n: Vec3, material: u32) -> Option<Cached> {
        let level = self.grid.level(p);
        (0..=COARSER as i32).find_map(|k| self.interpolate(level + k, p, n, material))
    }

    /// The trilinear interpolation at one level, `None` where no cell around `p` has an
    /// irradiance; the glossy term from the cells that have one.
    fn interpolate(&self, level: i32, p: Vec3, n: Vec3, material: u32) -> Option<Cached> {
        let f = cell_units(p, level) - DVec3::splat(0.5);
        let base = f.floor();
        let t = (f - base).as_vec3();
        self.with_corners(level, base.as_i64vec3(), n, material, |corners| {
            let (mut irradiance, mut glossy) = ((Vec3::ZERO, 0.0), (GlossyFit::default(), 0.0));
            for (corner, cell) in corners.iter().enumerate() {
                let Some(cell) = cell else { continue };
                let o = corner_offset(corner);
                let w = [0, 1, 2]
                    .map(|a| if o[a] == 1 { t[a] } else { 1.0 - t[a] })
                    .iter()
                    .product::<f32>();
                if let Some(i) = cell.irradiance {
                    irradiance = (irradiance.0 + w * i, irradiance.1 + w);
                }
                if let Some(g) = cell.glossy {
                    glossy = (glossy.0.plus(g.scaled(w)), glossy.1 + w);
                }
            }
            let enough = |w: f32| w > 1e-3;
            Some(Cached {
                irradiance: enough(irradiance.1).then(|| irradiance.0 / irradiance.1)?,
                glossy: enough(glossy.1).then(|| glossy.0.scaled(1.0 / glossy.1)),
            })
        })
    }

    /// Calls `f` with the eight cells around a lookup. The samples of a pixel (and of its
    /// neighbours) mostly fall between the same eight cells, so the last few sets are kept per
    /// thread: at 512² the table (~40 MB) is far larger than the CPU caches, and the eight
    /// hash probes of a miss are most of a lookup's cost (lookups are ~13 % of a default
    /// scene's time). `f` reads the kept set in place rather than copying it out.
    fn with_corners<R>(
        &self,
        level: i32,
        base: I64Vec3,
        n: Vec3,
        material: u32,
        f: impl FnOnce(&[Option<Cell>; 8]) -> R,
    ) -> R {
        let axis = n.abs().max_position();
        let id = Corners {
            cache: self.id,
            level,
            base,
            normal: (axis as u8) << 1 | (n[axis] < 0.0) as u8,
            material,
        };
        LAST_CORNERS.with(|memo| {
            let mut memo = memo.borrow_mut();
            let seen = memo.ids.iter().position(|seen| *seen == Some(id));
            let slot = seen.unwrap_or_else(|| {
                let slot = memo.next;
                let keys = self.grid.corner_keys(level, base, n, material);
                memo.cells[slot] = keys.map(|key| self.get(key));
                memo.ids[slot] = Some(id);
                memo.next = (slot + 1) % MEMO;
                slot
            });
            f(&memo.cells[slot])
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

    const PARAMS: CacheParams = CacheParams {
        cell_px: 1.0,
        glossy_share: 4.0,
        glossy_min_width: 0.0,
        fill_vertices: 1,
        fill_light_samples: 1,
        shrink: false,
        final_gather: false,
    };

    /// Where the estimates of a test with made-up keys lie: anywhere (`PARAMS` shrinks
    /// nothing, and only shrinking reads it).
    const NOWHERE: Anchor = Anchor {
        p: Vec3::ZERO,
        n: Vec3::Z,
        material: 0,
    };

    #[test]
    fn cells_are_a_pixel_footprint_rounded_up_to_a_power_of_two() {
        // f_px = 100: at 2 m depth a pixel is 2 cm, so cells are 2^-5 m = 3.125 cm.
        let grid = CacheGrid::new(&camera(), PARAMS);
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
    fn a_lookups_eight_keys_are_the_keys_of_its_eight_cells() {
        let grid = CacheGrid::new(&camera(), PARAMS);
        let (n, base) = (Vec3::new(0.2, -0.9, 0.1), I64Vec3::new(-1, 7, -300));
        let keys = grid.corner_keys(-4, base, n, 3);
        for (corner, key) in keys.into_iter().enumerate() {
            let o = I64Vec3::from_array(corner_offset(corner).map(|b| b as i64));
            assert_eq!(key, grid.cell_key(-4, base + o, n, 3), "corner {corner}");
        }
    }

    #[test]
    fn sums_average_per_cell_in_any_merge_grouping() {
        let i = Estimate::Irradiance;
        let mut a = CacheSums::default();
        a.add(&[1], i(Vec3::ONE), Vec2::ZERO, NOWHERE);
        a.add(&[2, 5], i(Vec3::splat(4.0)), Vec2::ZERO, NOWHERE);
        let mut b = CacheSums::default();
        b.add(&[1], i(Vec3::splat(3.0)), Vec2::ONE, NOWHERE);
        let mut all = CacheSums::default();
        all.merge_view(vec![a, b]);
        let cache = all.finish(CacheGrid::new(&camera(), PARAMS));
        let cell = |i: f32| Cell {
            irradiance: Some(Vec3::splat(i)),
            glossy: None,
        };
        assert_eq!(cache.get(1), Some(cell(2.0)));
        assert_eq!(cache.get(2), Some(cell(4.0)));
        assert_eq!(cache.get(3), None);
        assert_eq!(cache.get(5), Some(cell(4.0)));
        assert_eq!(cache.len(), 3);
    }

    #[test]
    fn later_vertex_estimates_join_only_the_cells_first_vertices_filled() {
        let i = Estimate::Irradiance;
        // View 0: one band fills cell 1, another makes later estimates in cells 1 and 2.
        let mut a = CacheSums::default();
        a.add(&[1], i(Vec3::ONE), Vec2::ZERO, NOWHERE);
        let mut b = CacheSums::default();
        b.add_later(&[1, 2], Vec3::splat(4.0));
        let mut all = CacheSums::default();
        all.merge_view(vec![b, a]);
        // View 1 fills cell 2 (view 0's estimate there is gone) and adds one there itself.
        let mut c = CacheSums::default();
        c.add_later(&[2, 3], Vec3::splat(5.0));
        c.add(&[2], i(Vec3::splat(2.0)), Vec2::ZERO, NOWHERE);
        all.merge_view(vec![c]);
        let cache = all.finish(CacheGrid::new(&camera(), PARAMS));
        let irradiance = |key| cache.get(key).and_then(|c| c.irradiance);
        assert_eq!(irradiance(1), Some(Vec3::splat(2.5)));
        assert_eq!(irradiance(2), Some(Vec3::splat(3.5)));
        assert_eq!((cache.get(3), cache.len()), (None, 2));
    }

    #[test]
    fn the_glossy_term_is_fitted_linearly_in_the_view_position() {
        // g = 5 + 2u − v (red), seen from every view of a 9×9 grid, in two merged halves.
        let truth = |u: f32, v: f32| Vec3::new(5.0 + 2.0 * u - v, 1.0, 0.0);
        let (mut a, mut b) = (CacheSums::default(), CacheSums::default());
        for (k, (u, v)) in (-4..=4)
            .flat_map(|u| (-4..=4).map(move |v| (u, v)))
            .enumerate()
        {
            let (u, v) = (u as f32, v as f32);
            let half = if k % 2 == 0 { &mut a } else { &mut b };
            half.add(
                &[7],
                Estimate::Glossy(truth(u, v)),
                Vec2::new(u, v),
                NOWHERE,
            );
        }
        let mut all = CacheSums::default();
        all.merge_view(vec![a, b]);
        let fit = all
            .finish(CacheGrid::new(&camera(), PARAMS))
            .get(7)
            .unwrap();
        assert_eq!(fit.irradiance, None);
        let fit = fit.glossy.unwrap();
        // Σu² = 9 · 2 · (1 + 4 + 9 + 16) = 540: the ridge of 16 shrinks the slopes by 3 %.
        let shrink = 540.0 / (540.0 + 16.0);
        assert!((fit.centre - Vec3::new(5.0, 1.0, 0.0)).abs().max_element() < 1e-4);
        assert!((fit.du.x - 2.0 * shrink).abs() < 1e-4 && fit.du.y.abs() < 1e-5);
        assert!((fit.dv.x + shrink).abs() < 1e-4);
        let corner = fit.at(Vec2::new(4.0, -4.0));
        assert!((corner.x - (5.0 + 12.0 * shrink)).abs() < 1e-3, "{corner}");
        // Seen from a single view the slopes are undetermined: the ridge keeps the mean.
        let mut one = CacheSums::default();
        one.add(
            &[1],
            Estimate::Glossy(Vec3::ONE),
            Vec2::new(3.0, 3.0),
            NOWHERE,
        );
        one.add(
            &[1],
            Estimate::Glossy(Vec3::splat(3.0)),
            Vec2::new(3.0, 3.0),
            NOWHERE,
        );
        let fit = one
            .finish(CacheGrid::new(&camera(), PARAMS))
            .get(1)
            .unwrap();
        let g = fit.glossy.unwrap().at(Vec2::new(3.0, 3.0));
        assert!((g - Vec3::splat(2.0)).abs().max_element() < 0.2, "{g}");
    }

    #[test]
    fn a_lobe_is_shared_where_it_is_wide_against_the_grid_seen_from_the_point() {
        // A 3×3 grid, 1 cm apart: the outer cameras are 2√2 cm apart.
        let cam = LightFieldCamera {
            grid: [3, 3],
            baseline_m: 0.01,
            ..camera()
        };
        let grid = CacheGrid::new(&cam, PARAMS);
        let span = 0.02 * std::f32::consts::SQRT_2;
        // At 2 m the grid spans `span / 2` radians: shared from 4× that.
        let p = Vec3::new(0.0, 0.0, -2.0);
        assert!(grid.shares_glossy(p, 4.0 * span / 2.0 * 1.001));
        assert!(!grid.shares_glossy(p, 4.0 * span / 2.0 * 0.999));
        // Twice as far, half the angle.
        assert!(grid.shares_glossy(2.0 * p, 4.0 * span / 4.0 * 1.001));
        // 0 shares every lobe.
        let all = CacheGrid::new(
            &cam,
            CacheParams {
                glossy_share: 0.0,
                ..PARAMS
            },
        );
        assert!(all.shares_glossy(p, 0.0));
    }

    #[test]
    fn a_lobe_narrower_than_the_floor_stays_per_view_whatever_the_grid() {
        // A single view spans no angle: without the floor every lobe, mirrors too, is shared.
        let grid = |glossy_min_width| {
            let params = CacheParams {
                glossy_min_width,
                ..PARAMS
            };
            CacheGrid::new(&camera(), params)
        };
        let p = Vec3::new(0.0, 0.0, -3.0);
        assert!(grid(0.0).shares_glossy(p, 0.08));
        assert!(
            !grid(0.1).shares_glossy(p, 0.08),
            "roughness 0.2: 2α = 0.08 rad"
        );
        assert!(!grid(0.1).shares_glossy(p, 0.0999));
        assert!(grid(0.1).shares_glossy(p, 0.1));
        // Beside a grid's own rule: the floor only removes lobes from the shared set.
        let cam = LightFieldCamera {
            grid: [9, 9],
            baseline_m: 0.01,
            ..camera()
        };
        let nine = CacheGrid::new(
            &cam,
            CacheParams {
                glossy_min_width: 0.1,
                ..PARAMS
            },
        );
        // At 2 m the grid's rule asks for 4 × 8√2 cm / 2 m = 0.226 rad, above the floor.
        let near = Vec3::new(0.0, 0.0, -2.0);
        let rule = 4.0 * 0.08 * std::f32::consts::SQRT_2 / 2.0;
        assert!(!nine.shares_glossy(near, rule * 0.999));
        assert!(nine.shares_glossy(near, rule * 1.001));
        // At 8 m it asks for 0.057 rad: the floor decides.
        assert!(!nine.shares_glossy(4.0 * near, 0.08));
        assert!(nine.shares_glossy(4.0 * near, 0.1));
    }

    /// Shrinking against independent truth: a lit plane whose irradiance steps from 1 to 3 at
    /// x = 0.25 m (a cell boundary at every level), its cells filled with noisy estimates
    /// (uniform ±0.5, 16 per finest cell). Away from the step the cells pool their coarser
    /// levels' samples, so they scatter far less about the truth; at the step, where the
    /// levels differ by far more than a cell's noise, every cell keeps its own value instead
    /// of the coarser levels' blur of the two sides.
    #[test]
    fn shrinking_pools_smooth_light_and_keeps_edges() {
        // Uniform numbers in [0, 1) from the crate's own hash.
        let uniform = |i: u64| (mix64(i) >> 40) as f32 / (1u64 << 24) as f32;
        let truth = |x: f32| if x < 0.25 { 1.0 } else { 3.0 };
        let n = Vec3::Z;
        let fill = |shrink: bool| {
            let grid = CacheGrid::new(&camera(), CacheParams { shrink, ..PARAMS });
            let mut sums = CacheSums::default();
            // 16 × 16 finest cells of 3.125 cm, 16 samples each on average.
            for k in 0..16 * 16 * 16 {
                let [x, y, noise] = [0, 1, 2].map(|d| uniform(3 * k + d));
                let p = Vec3::new(0.5 * x, 0.5 * y, -2.0);
                let i = truth(p.x) + noise - 0.5;
                let at = Anchor { p, n, material: 0 };
                let estimate = Estimate::Irradiance(Vec3::splat(i));
                sums.add(&grid.keys(p, n, 0), estimate, Vec2::ZERO, at);
            }
            let mut all = CacheSums::default();
            all.merge_view(vec![sums]);
            let cache = all.finish(grid);
            // The finest cells' errors, away from the step and beside it.
            let (mut smooth, mut edge) = (Vec::new(), Vec::new());
            for iy in 0..16 {
                for ix in 0..16 {
                    let p = Vec3::new(
                        0.015625 + ix as f32 * 0.03125,
                        0.015625 + iy as f32 * 0.03125,
                        -2.0,
                    );
                    let cell = cache.get(grid.keys(p, n, 0)[0]).expect("every cell filled");
                    let err = (cell.irradiance.unwrap().x - truth(p.x)) as f64;
                    match ix {
                        7 | 8 => edge.push(err),
                        _ => smooth.push(err),
                    }
                }
            }
            let rms = |e: &[f64]| (e.iter().map(|e| e * e).sum::<f64>() / e.len() as f64).sqrt();
            let worst = |e: &[f64]| e.iter().fold(0.0f64, |m, e| m.max(e.abs()));
            (rms(&smooth), worst(&edge))
        };
        let (plain, plain_edge) = fill(false);
        let (shrunk, shrunk_edge) = fill(true);
        lfformat::note!(
            "rms {plain:.4} → {shrunk:.4}, worst at the step {plain_edge:.3} → {shrunk_edge:.3}"
        );
        // 16 samples of variance 1/12: the plain cells' rms is about 0.072.
        assert!((0.05..0.1).contains(&plain), "plain rms {plain}");
        assert!(shrunk < 0.7 * plain, "rms {shrunk} shrunk vs {plain} plain");
        // The coarser levels put the cells beside the step ~0.5–1 off; shrunk, they stay
        // within a few times their own noise.
        assert!(plain_edge < 0.3, "plain edge error {plain_edge}");
        assert!(shrunk_edge < 0.3, "shrunk edge error {shrunk_edge}");
    }
}
