//! Fixed sets of the renderer's kinds of rays, for measuring its ray queries (`lfgen bench
//! speed`): camera rays, the incoherent bounces from their first surfaces, and shadow rays
//! from those surfaces to a light. They are drawn from a fixed seed, so every binary traces
//! the same rays, and built before any timing starts.

use super::RenderScene;
use super::bsdf::{Frame, cosine_sample_hemisphere};
use super::geometry::Hit;
use super::sampler::{RayKey, Sampler};
use glam::Vec3;

/// Seed of the probes' random numbers.
const PROBE_SEED: u64 = 0xBE7C;

/// The rays of one probe.
pub struct ProbeRays {
    /// Origin and direction of each camera ray.
    pub camera: Vec<(Vec3, Vec3)>,
    /// Cosine-distributed rays from the camera rays' first surfaces (the path's bounces).
    pub bounces: Vec<(Vec3, Vec3)>,
    /// Origin, unit direction and length of a shadow ray from each first surface to a sampled
    /// point on a light; empty when the scene has no emissive surface.
    pub shadows: Vec<(Vec3, Vec3, f32)>,
}

impl RenderScene {
    /// The probe of `camera` (origins and directions): its rays, its first surfaces' bounces
    /// and shadow rays.
    pub fn probe_rays(&self, camera: Vec<(Vec3, Vec3)>) -> ProbeRays {
        let surfaces = self.first_surfaces(&camera);
        let bounces = (surfaces.iter().enumerate())
            .map(|(i, &(p, n))| {
                let u = probe_sampler(i, 0).next2();
                (
                    p,
                    Frame::from_normal(n).to_world(cosine_sample_hemisphere(u)),
                )
            })
            .collect();
        let shadows = match self.lights.is_empty() {
            true => Vec::new(),
            false => (surfaces.iter().enumerate())
                .map(|(i, &(p, _))| {
                    let mut s = probe_sampler(i, 1);
                    let (u, uv) = (s.next_f32(), s.next2());
                    let light = self
                        .lights
                        .sample(&self.geometry, &self.materials, p, u, uv);
                    let to = light.p - p;
                    (p, to.normalize(), to.length() * (1.0 - 1e-4))
                })
                .collect(),
        };
        ProbeRays {
            camera,
            bounces,
            shadows,
        }
    }

    /// The closest hit of a probe ray, its stochastic opacity drawn for repetition `k` (the
    /// camera path's query).
    pub fn probe_closest(&self, origin: Vec3, dir: Vec3, k: u32) -> Option<Hit> {
        let key = RayKey {
            hash: u64::from(k),
            phase: 0.0,
        };
        (self.geometry).closest(&self.materials, origin, dir, f32::INFINITY, key)
    }

    /// The transmittance of a probe's shadow ray (the light sample's query).
    pub fn probe_shadow(&self, origin: Vec3, dir: Vec3, length: f32) -> Vec3 {
        (self.geometry)
            .transmittance(&self.materials, origin, dir, length, false)
            .0
    }

    /// Where the camera rays first meet an opaque-enough surface, each lifted off it along its
    /// normal turned towards the camera: the origins of the secondary rays.
    fn first_surfaces(&self, camera: &[(Vec3, Vec3)]) -> Vec<(Vec3, Vec3)> {
        let geo = &self.geometry;
        camera
            .iter()
            .filter_map(|&(o, d)| {
                let hit = self.probe_closest(o, d, 0)?;
                let n = geo.geometric_normal(hit.tri);
                let n = if n.dot(d) > 0.0 { -n } else { n };
                let p = o + d * hit.t;
                Some((p + n * 1e-4 * p.abs().max_element().max(1.0), n))
            })
            .collect()
    }
}

/// The probe's random numbers for surface `i`, stream `stream`.
fn probe_sampler(i: usize, stream: u32) -> Sampler {
    let mut s = Sampler::new(PROBE_SEED, 0, stream, i as u32, 0, 1);
    s.start_sample(0);
    s
}
