//! Unidirectional path tracing with next-event estimation, MIS (power heuristic), Russian
//! roulette and stochastic transparency. Punctual lights are sampled at every vertex, all of
//! them, deterministically (no random numbers, so scenes without them draw the same streams).

use super::RenderScene;
use super::bsdf::{Frame, power_heuristic};
use super::geometry::Hit;
use super::sampler::Sampler;
use glam::Vec3;

/// Path-tracing limits.
#[derive(Clone, Copy, Debug)]
pub struct PathSettings {
    pub max_depth: u32,
    pub rr_depth: u32,
}

/// Offset for spawning rays off a surface, relative to the scene scale.
const RAY_EPS: f32 = 1e-4;

/// How the path arrived at the current vertex (for MIS on emitters).
#[derive(Clone, Copy)]
struct Arrival {
    pdf: f32,
    is_delta: bool,
}

impl RenderScene {
    /// Radiance arriving along `dir` at `origin`, given the first surface already chosen
    /// (`first`, from the caller's traversal; `None` means the ray escaped).
    pub fn radiance(
        &self,
        settings: &PathSettings,
        origin: Vec3,
        dir: Vec3,
        first: Option<Hit>,
        sampler: &mut Sampler,
    ) -> Vec3 {
        let (mut origin, mut dir, mut hit) = (origin, dir, first);
        let mut radiance = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        let mut arrival = Arrival {
            pdf: 0.0,
            is_delta: true,
        };
        for depth in 0..settings.max_depth {
            let Some(h) = hit else {
                radiance += beta * self.environment;
                break;
            };
            let p = origin + dir * h.t;
            radiance += beta * self.emitted(&h, dir, arrival);
            let s = &self.geometry.shading[h.tri as usize];
            let mat = &self.materials[s.material as usize];
            let bsdf = mat.surface(self.geometry.uv(&h));
            let wo = -dir.normalize();
            let frame = Frame::from_normal(self.shading_normal(&h, wo, mat.glass_ior.is_some()));
            let wo_l = frame.to_local(wo);
            // At the last vertex no BSDF-sampled ray follows to pick up the other MIS share of
            // the direct light, so the light sample takes all of it (and the ray is not traced).
            let last = depth + 1 == settings.max_depth;
            if !bsdf.is_delta() && !self.lights.is_empty() {
                let ld = self.direct_light(p, &h, &frame, wo_l, &bsdf, last, sampler);
                radiance += beta * ld;
            }
            if !bsdf.is_delta() && !self.punctual_lights.is_empty() {
                radiance += beta * self.punctual_light(p, &h, &frame, wo_l, &bsdf);
            }
            if last {
                break;
            }
            let Some(bs) = bsdf.sample(wo_l, sampler.next_f32(), sampler.next2()) else {
                break;
            };
            if bs.pdf <= 0.0 {
                break;
            }
            beta *= bs.f * bs.wi.z.abs() / bs.pdf;
            arrival = Arrival {
                pdf: bs.pdf,
                is_delta: bs.is_delta,
            };
            if depth + 1 >= settings.rr_depth {
                let survive = beta.max_element().min(0.95);
                if sampler.next_f32() >= survive {
                    break;
                }
                beta /= survive;
            }
            dir = frame.to_world(bs.wi);
            origin = self.spawn(p, h.tri, dir);
            hit = self.geometry.closest(
                &self.materials,
                origin,
                dir,
                f32::INFINITY,
                sampler.next_key(),
            );
        }
        radiance
    }

    /// Emission picked up at a hit, MIS-weighted against light sampling unless the path
    /// arrived by a delta lobe (or from the camera).
    fn emitted(&self, h: &Hit, dir: Vec3, arrival: Arrival) -> Vec3 {
        let mat = &self.materials[self.geometry.shading[h.tri as usize].material as usize];
        if !mat.is_emissive() {
            return Vec3::ZERO;
        }
        let ng = self.geometry.geometric_normal(h.tri);
        let dist = dir.length() * h.t;
        let cos_light = -dir.normalize().dot(ng);
        if cos_light <= 0.0 {
            return Vec3::ZERO;
        }
        if arrival.is_delta {
            return mat.emission;
        }
        let light_pdf = self.lights.pdf(&self.geometry, h.tri, dist, cos_light);
        mat.emission * power_heuristic(arrival.pdf, light_pdf)
    }

    /// One light sample with a shadow ray through semi-transparent surfaces, MIS-weighted
    /// against BSDF sampling unless `alone` (no BSDF sample follows).
    #[allow(clippy::too_many_arguments)]
    fn direct_light(
        &self,
        p: Vec3,
        h: &Hit,
        frame: &Frame,
        wo_l: Vec3,
        bsdf: &super::bsdf::SurfaceParams,
        alone: bool,
        sampler: &mut Sampler,
    ) -> Vec3 {
        let ls = self.lights.sample(
            &self.geometry,
            &self.materials,
            sampler.next_f32(),
            sampler.next2(),
        );
        let to_light = ls.p - p;
        let dist = to_light.length();
        let wi = to_light / dist;
        let cos_light = -wi.dot(ls.n);
        if cos_light <= 0.0 || dist <= 0.0 {
            return Vec3::ZERO;
        }
        let wi_l = frame.to_local(wi);
        let (f, bsdf_pdf) = bsdf.eval(wo_l, wi_l);
        if f == Vec3::ZERO {
            return Vec3::ZERO;
        }
        let origin = self.spawn(p, h.tri, wi);
        let tmax = (ls.p - origin).length() * (1.0 - 1e-3);
        let tr = self
            .geometry
            .transmittance(&self.materials, origin, wi, tmax);
        if tr <= 0.0 {
            return Vec3::ZERO;
        }
        let light_pdf = ls.pdf_area * dist * dist / cos_light;
        let weight = match alone {
            true => 1.0,
            false => power_heuristic(light_pdf, bsdf_pdf),
        };
        f * ls.emission * (tr * wi_l.z.abs() * weight / light_pdf)
    }

    /// Light from every punctual light, each with a shadow ray through semi-transparent
    /// surfaces. A delta light has no MIS partner: no BSDF sample can hit it.
    fn punctual_light(
        &self,
        p: Vec3,
        h: &Hit,
        frame: &Frame,
        wo_l: Vec3,
        bsdf: &super::bsdf::SurfaceParams,
    ) -> Vec3 {
        let mut sum = Vec3::ZERO;
        for light in &self.punctual_lights {
            let Some(inc) = light.incident(p) else {
                continue;
            };
            let wi_l = frame.to_local(inc.wi);
            let (f, _) = bsdf.eval(wo_l, wi_l);
            if f == Vec3::ZERO {
                continue;
            }
            let origin = self.spawn(p, h.tri, inc.wi);
            let tmax = match inc.dist.is_finite() {
                true => (p + inc.wi * inc.dist - origin).length() * (1.0 - 1e-3),
                false => f32::INFINITY,
            };
            let tr = self
                .geometry
                .transmittance(&self.materials, origin, inc.wi, tmax);
            sum += f * inc.irradiance * (tr * wi_l.z.abs());
        }
        sum
    }

    /// Shading normal; opaque surfaces are two-sided, so it is turned towards the viewer.
    /// Glass keeps its outward orientation so the BSDF knows inside from outside.
    fn shading_normal(&self, h: &Hit, wo: Vec3, is_glass: bool) -> Vec3 {
        let ng = self.geometry.geometric_normal(h.tri);
        let ns = self.geometry.shading_normal(h);
        if is_glass {
            return if ns.dot(ng) > 0.0 { ns } else { ng };
        }
        let ng = if ng.dot(wo) < 0.0 { -ng } else { ng };
        let ns = if ns.dot(ng) < 0.0 { -ns } else { ns };
        if ns.dot(wo) > 0.0 { ns } else { ng }
    }

    /// Ray origin just off the surface, on the side `dir` leaves to.
    fn spawn(&self, p: Vec3, tri: u32, dir: Vec3) -> Vec3 {
        let ng = self.geometry.geometric_normal(tri);
        let eps = RAY_EPS * p.abs().max_element().max(1.0);
        p + ng * eps.copysign(ng.dot(dir))
    }
}
