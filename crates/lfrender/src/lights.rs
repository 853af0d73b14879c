//! Area lights: emissive triangles for next-event estimation, and the matching pdf for MIS
//! when a BSDF-sampled path hits one. Punctual lights (point, spot, directional) have no area:
//! a path can never hit them, so they are reached by next-event estimation alone, without MIS.
//!
//! Emissive triangles are grouped into clusters, one per emissive object. A light sample first
//! picks a cluster in proportion to its power over the squared distance from the shading point
//! (clamped to the cluster's bounding radius), then a triangle of it in proportion to power,
//! then a uniform point. Power alone would almost never pick a lamp bulb for the shade around
//! it, next to ceiling panels of thirty times its power (README, Validation: direct light).
//! Every cluster keeps a positive probability everywhere, so the estimate stays unbiased; only
//! the variance moves.

use super::geometry::Geometry;
use super::material::RenderMaterial;
use crate::scene::Light;
use glam::{Vec2, Vec3};

/// A sampled point on a light.
pub struct LightSample {
    /// The triangle the point lies on.
    pub tri: u32,
    pub p: Vec3,
    pub n: Vec3,
    pub emission: Vec3,
    /// Area-measure pdf, including the probability of choosing the triangle.
    pub pdf_area: f32,
}

/// Most clusters a scene gets: choosing one costs a pass over all of them per light sample,
/// so scenes with more emissive objects merge neighbours in scene order (still unbiased, just
/// less selective).
const MAX_CLUSTERS: usize = 64;

/// Marks a triangle that emits nothing in [`Lights::slot`].
const NOT_EMISSIVE: u32 = u32::MAX;

/// Emissive triangles of one object (or of neighbouring objects, past [`MAX_CLUSTERS`]).
struct Cluster {
    /// Range of the cluster's triangles in [`Lights::tris`].
    start: u32,
    end: u32,
    power: f32,
    centre: Vec3,
    /// Squared bounding radius, the least squared distance the importance divides by: closer
    /// than that the inverse-square law says nothing about a light's extent.
    radius2: f32,
}

impl Cluster {
    /// Unnormalised probability of choosing this cluster for a shading point at `p`.
    fn importance(&self, p: Vec3) -> f32 {
        self.power / p.distance_squared(self.centre).max(self.radius2)
    }
}

/// Object, triangle and power of an emitting triangle.
type Emitting = (u32, u32, f32);

/// Emissive triangles grouped into clusters, sampled as the module describes.
pub struct Lights {
    clusters: Vec<Cluster>,
    /// Emissive triangles, cluster after cluster.
    tris: Vec<u32>,
    /// Per emissive triangle: cumulative probability within its cluster.
    cdf: Vec<f32>,
    /// Per emissive triangle: probability within its cluster, and its cluster.
    pmf: Vec<f32>,
    cluster: Vec<u32>,
    /// Per triangle of the scene: its index in `tris`, or [`NOT_EMISSIVE`].
    slot: Vec<u32>,
}

impl Lights {
    /// Collects the emitting triangles, one cluster per object (by object order past
    /// [`MAX_CLUSTERS`]).
    pub fn new(geo: &Geometry, mats: &[RenderMaterial]) -> Self {
        let mut emitting: Vec<Emitting> = (0..geo.shading.len() as u32)
            .filter_map(|tri| {
                let s = &geo.shading[tri as usize];
                let e = mats[s.material as usize]
                    .emission
                    .dot(Vec3::splat(1.0 / 3.0));
                let power = area(&geo.vertices(tri)) * e;
                (power > 0.0).then_some((s.object, tri, power))
            })
            .collect();
        emitting.sort_by_key(|&(object, tri, _)| (object, tri));
        let objects: Vec<&[Emitting]> = emitting.chunk_by(|a, b| a.0 == b.0).collect();
        let mut lights = Self {
            clusters: Vec::new(),
            tris: Vec::new(),
            cdf: Vec::new(),
            pmf: Vec::new(),
            cluster: Vec::new(),
            slot: vec![NOT_EMISSIVE; geo.shading.len()],
        };
        for group in objects.chunks(objects.len().div_ceil(MAX_CLUSTERS).max(1)) {
            lights.push_cluster(geo, group.iter().flat_map(|o| o.iter()));
        }
        lights
    }

    /// Appends one cluster.
    fn push_cluster<'a>(&mut self, geo: &Geometry, emitting: impl Iterator<Item = &'a Emitting>) {
        let index = self.clusters.len() as u32;
        let start = self.tris.len() as u32;
        let (mut lo, mut hi, mut power) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0.0);
        for &(_, tri, w) in emitting {
            for v in geo.vertices(tri) {
                (lo, hi) = (lo.min(v), hi.max(v));
            }
            power += w;
            self.slot[tri as usize] = self.tris.len() as u32;
            self.tris.push(tri);
            self.pmf.push(w);
            self.cluster.push(index);
        }
        let mut acc = 0.0;
        for p in &mut self.pmf[start as usize..] {
            *p /= power;
            acc += *p;
            self.cdf.push(acc);
        }
        self.clusters.push(Cluster {
            start,
            end: self.tris.len() as u32,
            power,
            centre: 0.5 * (lo + hi),
            radius2: (0.25 * (hi - lo).length_squared()).max(f32::MIN_POSITIVE),
        });
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The sum of every cluster's importance for a shading point at `p`.
    fn total_importance(&self, p: Vec3) -> f32 {
        self.clusters.iter().map(|c| c.importance(p)).sum()
    }

    /// Probability of choosing cluster `c` for a shading point at `p`.
    fn cluster_probability(&self, c: &Cluster, p: Vec3) -> f32 {
        match self.clusters.len() {
            1 => 1.0,
            _ => c.importance(p) / self.total_importance(p),
        }
    }

    /// Picks a cluster for a shading point at `p` with `u` in [0, 1); returns it, its
    /// probability (as [`Self::cluster_probability`] computes it) and `u` rescaled to [0, 1)
    /// within its share, for choosing the triangle. Each importance is computed once (a
    /// division per cluster, up to [`MAX_CLUSTERS`] per light sample) and summed in the order
    /// [`Self::total_importance`] sums it, so the probability is bit for bit the same.
    fn pick_cluster(&self, p: Vec3, u: f32) -> (&Cluster, f32, f32) {
        let [only] = &self.clusters[..] else {
            let mut weight = [0.0; MAX_CLUSTERS];
            for (w, c) in weight.iter_mut().zip(&self.clusters) {
                *w = c.importance(p);
            }
            let weight = &weight[..self.clusters.len()];
            let total: f32 = weight.iter().sum();
            let mut rest = u * total;
            for (c, &w) in self.clusters.iter().zip(weight) {
                if rest < w {
                    return (c, w / total, (rest / w).min(ONE_BELOW));
                }
                rest -= w;
            }
            // Rounding left `u` past the last share.
            let (last, w) = (self.clusters.last().unwrap(), weight[weight.len() - 1]);
            return (last, w / total, ONE_BELOW);
        };
        (only, 1.0, u)
    }

    /// Samples a point on a light for a shading point at `from`, with one number for the
    /// cluster and triangle and two for the point.
    pub fn sample(
        &self,
        geo: &Geometry,
        mats: &[RenderMaterial],
        from: Vec3,
        u: f32,
        uv: Vec2,
    ) -> LightSample {
        let (c, probability, u) = self.pick_cluster(from, u);
        let cdf = &self.cdf[c.start as usize..c.end as usize];
        let k = c.start as usize + cdf.partition_point(|&x| x <= u).min(cdf.len() - 1);
        let tri = self.tris[k];
        let v = geo.vertices(tri);
        let (su, sv) = if uv.x + uv.y > 1.0 {
            (1.0 - uv.x, 1.0 - uv.y)
        } else {
            (uv.x, uv.y)
        };
        let p = v[0] + (v[1] - v[0]) * su + (v[2] - v[0]) * sv;
        let s = &geo.shading[tri as usize];
        let uv = s.uv[0] * (1.0 - su - sv) + s.uv[1] * su + s.uv[2] * sv;
        let emission = mats[s.material as usize].emitted(uv);
        LightSample {
            tri,
            p,
            n: geo.geometric_normal(tri),
            emission,
            pdf_area: probability * self.pmf[k] / area(&v),
        }
    }

    /// Solid-angle pdf with which [`Self::sample`], called for a shading point at `from`,
    /// would pick this point of triangle `tri`, seen from distance `dist` at cosine
    /// `cos_light`.
    pub fn pdf(&self, geo: &Geometry, tri: u32, from: Vec3, dist: f32, cos_light: f32) -> f32 {
        let k = self.slot[tri as usize];
        if k == NOT_EMISSIVE || cos_light <= 0.0 {
            return 0.0;
        }
        let c = &self.clusters[self.cluster[k as usize] as usize];
        let pmf = self.cluster_probability(c, from) * self.pmf[k as usize];
        pmf / area(&geo.vertices(tri)) * dist * dist / cos_light
    }
}

/// The largest f32 below 1: keeps a rescaled random number inside [0, 1).
const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

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
