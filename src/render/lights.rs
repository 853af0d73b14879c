//! Area lights: emissive triangles sampled in proportion to their power, for next-event
//! estimation, and the matching pdf for MIS when a BSDF-sampled path hits one.

use super::geometry::Geometry;
use super::material::RenderMaterial;
use glam::{Vec2, Vec3};

/// A sampled point on a light.
pub struct LightSample {
    pub p: Vec3,
    pub n: Vec3,
    pub emission: Vec3,
    /// Area-measure pdf, including the probability of choosing the triangle.
    pub pdf_area: f32,
}

/// Power-proportional distribution over emissive triangles.
pub struct Lights {
    tris: Vec<u32>,
    cdf: Vec<f32>,
    /// Selection probability per triangle (BVH order), 0 for non-emitters.
    pmf: Vec<f32>,
}

impl Lights {
    pub fn new(geo: &Geometry, mats: &[RenderMaterial]) -> Self {
        let mut tris = Vec::new();
        let mut weights = Vec::new();
        for (i, s) in geo.shading.iter().enumerate() {
            let e = mats[s.material as usize].emission;
            if e.max_element() > 0.0 {
                tris.push(i as u32);
                weights.push(area(&geo.vertices(i as u32)) * e.dot(Vec3::splat(1.0 / 3.0)));
            }
        }
        let total: f32 = weights.iter().sum();
        let mut pmf = vec![0.0; geo.shading.len()];
        let mut acc = 0.0;
        let cdf = tris
            .iter()
            .zip(&weights)
            .map(|(&t, w)| {
                pmf[t as usize] = w / total;
                acc += w / total;
                acc
            })
            .collect();
        Self { tris, cdf, pmf }
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// Samples a point on a light with one number for the triangle and two for the point.
    pub fn sample(&self, geo: &Geometry, mats: &[RenderMaterial], u: f32, uv: Vec2) -> LightSample {
        let k = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.tris.len() - 1);
        let tri = self.tris[k];
        let v = geo.vertices(tri);
        let (su, sv) = if uv.x + uv.y > 1.0 {
            (1.0 - uv.x, 1.0 - uv.y)
        } else {
            (uv.x, uv.y)
        };
        let p = v[0] + (v[1] - v[0]) * su + (v[2] - v[0]) * sv;
        let emission = mats[geo.shading[tri as usize].material as usize].emission;
        LightSample {
            p,
            n: geo.geometric_normal(tri),
            emission,
            pdf_area: self.pmf[tri as usize] / area(&v),
        }
    }

    /// Solid-angle pdf with which [`Self::sample`] would pick this point of triangle `tri`,
    /// seen from distance `dist` at cosine `cos_light`.
    pub fn pdf(&self, geo: &Geometry, tri: u32, dist: f32, cos_light: f32) -> f32 {
        let pmf = self.pmf[tri as usize];
        if pmf == 0.0 || cos_light <= 0.0 {
            return 0.0;
        }
        pmf / area(&geo.vertices(tri)) * dist * dist / cos_light
    }
}

fn area(v: &[Vec3; 3]) -> f32 {
    0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()
}
