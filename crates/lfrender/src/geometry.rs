//! Triangles in a BVH (built by obvhs, traversed in the SIMD layout of [`super::wide`]) and the
//! three ray queries the renderer needs: closest hit with stochastic transparency, every hit
//! along a ray (for the depth slices), and shadow transmittance.

use super::build_boxes::build_boxes;
use super::material::RenderMaterial;
use super::sampler::RayKey;
use super::wide::{Kernel, WideBvh};
use crate::scene::shapes::MeshTri;
use anyhow::{Result, bail};
use glam::{Vec2, Vec3, Vec3A};
use obvhs::triangle::Triangle;

/// Intersection data of one triangle.
#[derive(Clone, Copy)]
struct IsectTri {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
    /// Unit geometric normal: every path vertex asks for it several times (emission, shading
    /// frame, ray offsets), and 64 bytes keep one triangle in one cache line.
    n: Vec3A,
}

/// Relative distance within which two hits on one object are one surface (two triangles
/// meeting the ray at their shared edge report one crossing twice).
const SAME_SURFACE: f32 = 1e-5;

/// Shading data of one triangle.
#[derive(Clone, Copy, Debug)]
pub struct TriShading {
    pub n: [Vec3; 3],
    pub uv: [Vec2; 3],
    pub material: u32,
    pub object: u32,
}

/// A ray–triangle intersection: distance and barycentrics of `v1`, `v2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub tri: u32,
    pub b: Vec2,
}

/// A triangle with its object and material, as handed to [`Geometry::build`].
pub struct SceneTri {
    pub tri: MeshTri,
    pub material: u32,
    pub object: u32,
}

/// The scene's triangles and their BVH.
pub struct Geometry {
    bvh: WideBvh,
    isect: Vec<IsectTri>,
    pub shading: Vec<TriShading>,
    /// Opacity per triangle when uniform over it, NaN when it comes from a texture: the
    /// closest-hit test reads 4 bytes instead of the shading record and the material.
    tri_opacity: Vec<f32>,
}

impl Geometry {
    /// Builds the BVH; rejects non-finite vertices, naming the object.
    pub fn build(
        tris: &[SceneTri],
        object_names: &[String],
        mats: &[RenderMaterial],
    ) -> Result<Self> {
        if let Some(bad) = tris.iter().find(|t| !t.tri.p.iter().all(|p| p.is_finite())) {
            bail!(
                "object {:?} has non-finite vertex coordinates",
                object_names[bad.object as usize]
            );
        }
        if tris.is_empty() {
            bail!("the scene has no geometry");
        }
        let prims: Vec<Triangle> = tris
            .iter()
            .map(|t| {
                let [v0, v1, v2] = t.tri.p.map(Vec3A::from);
                Triangle { v0, v1, v2 }
            })
            .collect();
        let edges: Vec<[Vec3A; 3]> = (prims.iter())
            .map(|t| [t.v0, t.v1 - t.v0, t.v2 - t.v0])
            .collect();
        let bvh = WideBvh::new(&edges, &build_boxes(&prims), Kernel::from_env()?)?;
        let isect: Vec<IsectTri> = (edges.iter())
            .map(|&[v0, e1, e2]| {
                let n = e1.cross(e2).normalize_or_zero();
                IsectTri { v0, e1, e2, n }
            })
            .collect();
        let shading: Vec<TriShading> = (tris.iter())
            .map(|t| TriShading {
                n: t.tri.n,
                uv: t.tri.uv,
                material: t.material,
                object: t.object,
            })
            .collect();
        let tri_opacity = shading
            .iter()
            .map(|s| {
                mats[s.material as usize]
                    .uniform_opacity
                    .unwrap_or(f32::NAN)
            })
            .collect();
        Ok(Self {
            bvh,
            isect,
            shading,
            tri_opacity,
        })
    }

    pub fn triangle_count(&self) -> usize {
        self.isect.len()
    }

    /// The kernel the BVH's queries run (the same bits whichever it is).
    pub fn kernel(&self) -> Kernel {
        self.bvh.kernel()
    }

    /// Interpolated UV of a hit.
    #[inline]
    pub fn uv(&self, hit: &Hit) -> Vec2 {
        let s = &self.shading[hit.tri as usize];
        s.uv[0] * (1.0 - hit.b.x - hit.b.y) + s.uv[1] * hit.b.x + s.uv[2] * hit.b.y
    }

    /// Geometric (winding) normal, unit length.
    #[inline]
    pub fn geometric_normal(&self, tri: u32) -> Vec3 {
        Vec3::from(self.isect[tri as usize].n)
    }

    /// Interpolated shading normal.
    #[inline]
    pub fn shading_normal(&self, hit: &Hit) -> Vec3 {
        let s = &self.shading[hit.tri as usize];
        let n = s.n[0] * (1.0 - hit.b.x - hit.b.y) + s.n[1] * hit.b.x + s.n[2] * hit.b.y;
        n.try_normalize()
            .unwrap_or_else(|| self.geometric_normal(hit.tri))
    }

    /// Distance along `dir` from `origin` to the plane of triangle `tri` (None when parallel).
    #[inline]
    pub fn plane_distance(&self, tri: u32, origin: Vec3, dir: Vec3) -> Option<f32> {
        let t = &self.isect[tri as usize];
        let n = Vec3::from(t.e1.cross(t.e2));
        let denom = n.dot(dir);
        (denom.abs() > 1e-12 * n.length() * dir.length())
            .then(|| n.dot(Vec3::from(t.v0) - origin) / denom)
    }

    /// Area and vertices of a triangle (light sampling).
    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        let t = &self.isect[tri as usize];
        [t.v0, t.v0 + t.e1, t.v0 + t.e2].map(Vec3::from)
    }

    /// Opacity of the surface at a hit (cut-outs and semi-transparency).
    #[inline]
    fn opacity(&self, mats: &[RenderMaterial], hit: &Hit) -> f32 {
        let m = &mats[self.shading[hit.tri as usize].material as usize];
        m.uniform_opacity
            .unwrap_or_else(|| m.opacity.eval(self.uv(hit)))
    }

    /// The opacity stochastic transparency tests a hit with (a triangle's uniform opacity
    /// where it has one).
    #[inline]
    pub fn hit_opacity(&self, mats: &[RenderMaterial], hit: &Hit) -> f32 {
        let uniform = self.tri_opacity[hit.tri as usize];
        match uniform.is_nan() {
            true => self.opacity(mats, hit),
            false => uniform,
        }
    }

    /// Whether the stochastic-transparency test keeps this hit. The decision hashes the ray's
    /// `key` with the triangle, so the same ray sees the same surfaces whichever query asks.
    #[inline]
    pub fn accepts(&self, mats: &[RenderMaterial], hit: &Hit, key: RayKey) -> bool {
        let a = self.hit_opacity(mats, hit);
        a >= 1.0 || (a > 0.0 && key.uniform(hit.tri) < a)
    }

    /// Closest hit that passes the stochastic-transparency test for `key`.
    pub fn closest(
        &self,
        mats: &[RenderMaterial],
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
        key: RayKey,
    ) -> Option<Hit> {
        self.closest_where(origin, dir, 0.0, tmax, |hit| self.accepts(mats, hit, key))
    }

    /// The first surface with any opacity behind `after` (from the origin for `None`): the
    /// next layer of a ray that composites semi-transparent surfaces. Hits within
    /// [`SAME_SURFACE`] behind `after` are skipped: one crossing reported twice.
    pub fn next_layer(
        &self,
        mats: &[RenderMaterial],
        origin: Vec3,
        dir: Vec3,
        after: Option<&Hit>,
    ) -> Option<Hit> {
        let tmin = after.map_or(0.0, |h| h.t + SAME_SURFACE * h.t.max(1.0));
        let visible = |hit: &Hit| self.hit_opacity(mats, hit) > 0.0;
        self.closest_where(origin, dir, tmin, f32::INFINITY, visible)
    }

    /// Closest hit in `(tmin, tmax]` that `accept` keeps.
    fn closest_where(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: f32,
        accept: impl Fn(&Hit) -> bool,
    ) -> Option<Hit> {
        (self.bvh).closest(origin.into(), dir.into(), tmin, tmax, accept)
    }

    /// Every surface along the ray up to `tmax`, sorted front to back, into `out` (cleared).
    /// Reports of one surface twice (two triangles of an object meeting the ray at a shared
    /// edge) keep the first.
    pub fn all_hits(&self, origin: Vec3, dir: Vec3, tmax: f32, out: &mut Vec<Hit>) {
        out.clear();
        self.bvh.each_hit(origin.into(), dir.into(), tmax, |hit| {
            out.push(*hit);
            true
        });
        out.sort_unstable_by(|a, b| a.t.total_cmp(&b.t).then(a.tri.cmp(&b.tri)));
        out.dedup_by(|b, a| {
            let (sa, sb) = (&self.shading[a.tri as usize], &self.shading[b.tri as usize]);
            sa.object == sb.object && (b.t - a.t) <= SAME_SURFACE * a.t.max(1.0)
        });
    }

    /// Fraction of light passing from `origin` along `dir` to distance `tmax`: the product of
    /// `1 - opacity` over semi-transparent surfaces; opaque surfaces block. Smooth glass blocks
    /// too, unless `through_glass`: then each glass interface passes its tint times
    /// `1 − Fresnel` along the straight line (no refraction; see `GlassLight::Shadows`). Also
    /// says whether the segment crossed glass. `dir` is a unit vector (shadow rays).
    pub fn transmittance(
        &self,
        mats: &[RenderMaterial],
        origin: Vec3,
        dir: Vec3,
        tmax: f32,
        through_glass: bool,
    ) -> (Vec3, bool) {
        let (mut tr, mut crossed_glass) = (Vec3::ONE, false);
        self.bvh.each_hit(origin.into(), dir.into(), tmax, |hit| {
            let m = &mats[self.shading[hit.tri as usize].material as usize];
            crossed_glass |= m.glass_ior.is_some();
            let passed = match m.glass_ior {
                Some(ior) if through_glass => self.glass_transmittance(m, hit, dir, ior),
                Some(_) => Vec3::ZERO,
                None => Vec3::splat(1.0 - self.opacity(mats, hit)),
            };
            if passed == Vec3::ZERO {
                tr = Vec3::ZERO;
                return false;
            }
            tr *= passed;
            true
        });
        (tr, crossed_glass)
    }

    /// What one glass interface passes of light crossing it along unit `dir`: its tint times
    /// `1 − F`, with F the Fresnel reflectance for the side the ray enters from (total internal
    /// reflection passes nothing).
    fn glass_transmittance(&self, m: &RenderMaterial, hit: &Hit, dir: Vec3, ior: f32) -> Vec3 {
        let cos = dir.dot(self.geometric_normal(hit.tri));
        let eta = if cos < 0.0 { ior } else { 1.0 / ior };
        let (reflected, _) = super::bsdf::fresnel_dielectric(cos.abs(), eta);
        m.base_color.eval(self.uv(hit)) * (1.0 - reflected).max(0.0)
    }

    /// GT coverage of a hit: opacity, times the Fresnel reflectance for glass (the part of the
    /// pixel's light that does not come from behind the surface).
    #[inline]
    pub fn coverage(&self, mats: &[RenderMaterial], hit: &Hit, dir: Vec3) -> f32 {
        let m = &mats[self.shading[hit.tri as usize].material as usize];
        let a = self.opacity(mats, hit);
        match m.glass_ior {
            Some(ior) => {
                let cos = dir.normalize().dot(self.geometric_normal(hit.tri)).abs();
                a * super::bsdf::fresnel_dielectric(cos, ior).0
            }
            None => a,
        }
    }
}
