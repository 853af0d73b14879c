//! Area lights: emissive triangles sampled in proportion to their power, for next-event
//! estimation, and the matching pdf for MIS when a BSDF-sampled path hits one. Punctual
//! lights (point, spot, directional) have no area: a path can never hit them, so they are
//! reached by next-event estimation alone, without MIS.

use super::geometry::Geometry;
use super::material::RenderMaterial;
use crate::scene::Light;
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

/// A point, spot or directional light ready for shading (units: see [`crate::scene::light`]).
#[derive(Clone, Debug)]
pub struct PunctualLight {
    kind: PunctualKind,
    /// Intensity (point, spot) or irradiance (directional), linear RGB.
    color: Vec3,
}

#[derive(Clone, Debug)]
enum PunctualKind {
    /// A point light, or a spot light when it has a cone.
    Point {
        position: Vec3,
        range: Option<f32>,
        cone: Option<Cone>,
    },
    /// Unit direction towards the light.
    Directional { to_light: Vec3 },
}

/// A spot light's cone: attenuation `clamp(cos θ · scale + offset, 0, 1)²` at angle θ from
/// `axis` (`KHR_lights_punctual`), 1 inside the inner cone and 0 outside the outer one.
#[derive(Clone, Copy, Debug)]
struct Cone {
    axis: Vec3,
    scale: f32,
    offset: f32,
}

impl Cone {
    fn new(axis: Vec3, inner: f32, outer: f32) -> Self {
        let (cos_inner, cos_outer) = (inner.cos(), outer.cos());
        let scale = 1.0 / (cos_inner - cos_outer).max(1e-3);
        Self {
            axis,
            scale,
            offset: -cos_outer * scale,
        }
    }

    /// Attenuation towards unit direction `dir` (from the light).
    fn attenuation(&self, dir: Vec3) -> f32 {
        let a = (dir.dot(self.axis) * self.scale + self.offset).clamp(0.0, 1.0);
        a * a
    }
}

/// Light arriving at a point from a punctual light.
pub struct Incident {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Distance to the light (infinite for a directional light).
    pub dist: f32,
    /// Irradiance on a surface facing the light (multiply by the BSDF and the cosine).
    pub irradiance: Vec3,
}

impl PunctualLight {
    pub fn new(light: &Light) -> Self {
        match *light {
            Light::Point {
                position,
                intensity,
                range,
            } => Self {
                kind: PunctualKind::Point {
                    position,
                    range,
                    cone: None,
                },
                color: Vec3::from(intensity),
            },
            Light::Spot {
                position,
                direction,
                intensity,
                inner_cone,
                outer_cone,
                range,
            } => Self {
                kind: PunctualKind::Point {
                    position,
                    range,
                    cone: Some(Cone::new(direction, inner_cone, outer_cone)),
                },
                color: Vec3::from(intensity),
            },
            Light::Directional {
                direction,
                irradiance,
            } => Self {
                kind: PunctualKind::Directional {
                    to_light: -direction,
                },
                color: Vec3::from(irradiance),
            },
        }
    }

    /// What this light sends to `p`; `None` where it sends nothing (outside a spot's cone or
    /// beyond the range).
    pub fn incident(&self, p: Vec3) -> Option<Incident> {
        match self.kind {
            PunctualKind::Directional { to_light } => Some(Incident {
                wi: to_light,
                dist: f32::INFINITY,
                irradiance: self.color,
            }),
            PunctualKind::Point {
                position,
                range,
                cone,
            } => {
                let to_light = position - p;
                let dist2 = to_light.length_squared();
                let dist = dist2.sqrt();
                if dist <= 0.0 {
                    return None;
                }
                let wi = to_light / dist;
                let mut falloff = 1.0 / dist2;
                if let Some(cone) = cone {
                    falloff *= cone.attenuation(-wi);
                }
                if let Some(r) = range {
                    // The window glTF recommends, so the light ends smoothly at `range`.
                    falloff *= (1.0 - (dist / r).powi(4)).clamp(0.0, 1.0);
                }
                (falloff > 0.0).then(|| Incident {
                    wi,
                    dist,
                    irradiance: self.color * falloff,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot(inner: f32, outer: f32) -> PunctualLight {
        PunctualLight::new(&Light::Spot {
            position: Vec3::ZERO,
            direction: Vec3::NEG_Z,
            intensity: [4.0; 3],
            inner_cone: inner,
            outer_cone: outer,
            range: None,
        })
    }

    #[test]
    fn point_light_falls_off_with_the_square_of_the_distance() {
        let l = PunctualLight::new(&Light::Point {
            position: Vec3::new(0.0, 2.0, 0.0),
            intensity: [8.0, 4.0, 2.0],
            range: None,
        });
        let inc = l.incident(Vec3::ZERO).unwrap();
        assert_eq!(inc.wi, Vec3::Y);
        assert_eq!(inc.dist, 2.0);
        assert_eq!(inc.irradiance, Vec3::new(2.0, 1.0, 0.5));
    }

    #[test]
    fn spot_cone_follows_khr_lights_punctual() {
        let l = spot(0.2, 0.4);
        let at = |angle: f32| {
            let p = Vec3::new(angle.sin(), 0.0, -angle.cos());
            l.incident(p).map_or(0.0, |i| i.irradiance.x / 4.0)
        };
        assert_eq!(at(0.0), 1.0);
        assert!((at(0.19) - 1.0).abs() < 1e-6);
        assert_eq!(at(0.41), 0.0);
        // Halfway in cos between the cones: (1/2)².
        let mid = (0.5 * (0.2f32.cos() + 0.4f32.cos())).acos();
        assert!((at(mid) - 0.25).abs() < 1e-4, "{}", at(mid));
        assert!(at(0.3) < at(0.25) && at(0.35) < at(0.3));
    }

    #[test]
    fn directional_light_and_range() {
        let sun = PunctualLight::new(&Light::Directional {
            direction: Vec3::NEG_Y,
            irradiance: [3.0; 3],
        });
        let inc = sun.incident(Vec3::new(5.0, 0.0, 1.0)).unwrap();
        assert_eq!(
            (inc.wi, inc.dist, inc.irradiance),
            (Vec3::Y, f32::INFINITY, Vec3::splat(3.0))
        );
        let ranged = PunctualLight::new(&Light::Point {
            position: Vec3::ZERO,
            intensity: [1.0; 3],
            range: Some(2.0),
        });
        assert!(ranged.incident(Vec3::new(0.0, 0.0, 2.5)).is_none());
        let near = ranged.incident(Vec3::new(0.0, 0.0, 1.0)).unwrap();
        assert!((near.irradiance.x - (1.0 - 1.0 / 16.0)).abs() < 1e-6);
    }
}
