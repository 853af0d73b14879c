//! The built-in procedural scene generator: a deep closed room with ceiling lights, filled with
//! boxes, tables, spheres, cylinders, semi-transparent and glass panes and grid cut-outs.
//!
//! Everything is drawn from one RNG stream per (seed, scene index), so a scene is a pure
//! function of the config.

use super::{
    Material, Object, Opacity, SceneDesc, Shape, SliceRange, SurfaceModel, Texture, Transform,
};
use crate::camera::LightFieldCamera;
use crate::config::Config;
use crate::render::sampler::mix64;
use glam::{DVec3, Quat, Vec3};
use rand::RngExt;
use rand_pcg::Pcg32;
use std::f32::consts::{FRAC_PI_2, TAU};

/// Generates scene `index` of the dataset described by `cfg`. The camera's baseline, focus and
/// the slice range are provisional until the renderer frames the scene.
pub fn generate(cfg: &Config, index: u64) -> SceneDesc {
    let mut g = Gen {
        rng: Pcg32::new(mix64(cfg.dataset.seed ^ mix64(index)), 0x5CE7E),
        cfg,
        materials: Vec::new(),
        objects: Vec::new(),
    };
    let s = &cfg.scene;
    let size = Vec3::new(
        g.range(s.room_width),
        g.range(s.room_height),
        g.range(s.room_depth),
    );
    g.room(size);
    g.lights(size);
    let camera = g.camera(size);
    for _ in 0..s.objects {
        g.furniture(size, &camera);
    }
    SceneDesc {
        generator: format!("lfgen {}", env!("CARGO_PKG_VERSION")),
        name: format!("scene_{index:04}"),
        index,
        seed: cfg.dataset.seed,
        camera,
        slices: SliceRange {
            z_near: 0.1,
            z_far: 100.0,
            count: cfg.render.slices,
            spacing: cfg.render.slice_spacing,
        },
        environment: s.environment.map(|v| v as f32),
        exposure: cfg.render.exposure as f32,
        materials: g.materials,
        objects: g.objects,
        lights: Vec::new(),
        sources: Vec::new(),
    }
}

struct Gen<'a> {
    rng: Pcg32,
    cfg: &'a Config,
    materials: Vec<Material>,
    objects: Vec<Object>,
}

impl Gen<'_> {
    fn range(&mut self, [a, b]: [f64; 2]) -> f32 {
        self.rng.random_range(a..=b) as f32
    }

    fn unit(&mut self) -> f32 {
        self.rng.random::<f32>()
    }

    fn chance(&mut self, p: f64) -> bool {
        self.rng.random::<f64>() < p
    }

    fn color(&mut self) -> [f32; 3] {
        let base = 0.15 + 0.6 * self.unit();
        [0, 1, 2].map(|_| (base * (0.6 + 0.8 * self.unit())).min(0.9))
    }

    fn texture(&mut self) -> Texture {
        let (a, b) = (self.color(), self.color());
        match self.rng.random_range(0..4) {
            0 => Texture::constant(a),
            1 => Texture::Checker {
                a,
                b,
                size: 0.05 + 0.3 * self.unit(),
            },
            2 => Texture::Stripes {
                a,
                b,
                width: 0.02 + 0.15 * self.unit(),
            },
            _ => Texture::Noise {
                a,
                b,
                scale: 0.03 + 0.3 * self.unit(),
                seed: self.rng.random(),
            },
        }
    }

    fn material(&mut self, name: &str, opacity: Opacity, model: SurfaceModel) -> u32 {
        let metallic = if self.chance(0.1) { 1.0 } else { 0.0 };
        let m = Material {
            name: name.into(),
            model,
            base_color: if model == SurfaceModel::Standard {
                self.texture()
            } else {
                Texture::constant([0.95; 3])
            },
            roughness: 0.15 + 0.8 * self.unit(),
            metallic,
            opacity,
            emission: [0.0; 3],
        };
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    /// A random material for an object: opaque, semi-transparent or glass.
    fn object_material(&mut self, name: &str) -> u32 {
        let s = &self.cfg.scene;
        let (glass, semi, range) = (s.glass, s.semi_transparent, s.opacity_range);
        if self.chance(glass) {
            return self.material(
                name,
                Opacity::constant(1.0),
                SurfaceModel::Glass { ior: 1.5 },
            );
        }
        let a = if self.chance(semi) {
            self.range(range)
        } else {
            1.0
        };
        self.material(name, Opacity::constant(a), SurfaceModel::Standard)
    }

    fn add(&mut self, name: &str, shape: Shape, transform: Transform, material: u32) {
        self.objects.push(Object {
            name: name.into(),
            shape,
            transform,
            material,
        });
    }

    fn room(&mut self, size: Vec3) {
        let m = self.material("room", Opacity::constant(1.0), SurfaceModel::Standard);
        self.add("room", Shape::Room { size }, Transform::at(Vec3::ZERO), m);
    }

    fn lights(&mut self, size: Vec3) {
        for i in 0..self.cfg.scene.lights {
            let warmth = self.unit();
            let power = 8.0 + 8.0 * self.unit();
            let emission = [
                power,
                power * (0.85 + 0.1 * warmth),
                power * (0.65 + 0.3 * warmth),
            ];
            self.materials.push(Material {
                name: format!("light_{i}"),
                model: SurfaceModel::Standard,
                base_color: Texture::constant([0.8; 3]),
                roughness: 1.0,
                metallic: 0.0,
                opacity: Opacity::constant(1.0),
                emission,
            });
            let m = (self.materials.len() - 1) as u32;
            let z = -size.z / 2.0 + size.z * (i as f32 + 0.5) / self.cfg.scene.lights as f32;
            let x = (self.unit() - 0.5) * size.x * 0.5;
            let mut xf = Transform::at(Vec3::new(x, size.y - 0.02, z));
            xf.rotation = Quat::from_rotation_x(FRAC_PI_2);
            self.add(
                &format!("light_{i}"),
                Shape::Quad { size: [2.4, 1.2] },
                xf,
                m,
            );
        }
    }

    /// The centre camera: near the front wall at eye height, looking into the room.
    fn camera(&mut self, size: Vec3) -> LightFieldCamera {
        let c = &self.cfg.camera;
        let yaw = (self.unit() - 0.5) * 0.2;
        let pitch = -0.05 - 0.1 * self.unit();
        let forward =
            DVec3::new(-(yaw.sin() as f64), pitch.sin() as f64, -(yaw.cos() as f64)).normalize();
        let up = (DVec3::Y - forward * forward.y).normalize();
        LightFieldCamera {
            resolution: c.resolution,
            grid: c.grid,
            focal_length_mm: c.focal_length_mm,
            sensor_size_mm: c.sensor_size_mm,
            baseline_m: c.baseline_mm / 1000.0,
            focus_distance_m: c.focus_distance_m,
            position: DVec3::new(
                0.0,
                1.2 + 0.4 * self.unit() as f64,
                size.z as f64 / 2.0 - 0.2,
            ),
            forward,
            up,
        }
    }

    /// One random piece of furniture standing on the floor inside the camera's view.
    ///
    /// The HCI lens sees only ~20° across, so objects are spread over the frustum's width at
    /// their distance (plus a margin for partial occluders at the image border), from 2.5 m
    /// in front of the camera to the back wall.
    fn furniture(&mut self, room: Vec3, cam: &LightFieldCamera) {
        let half_fov = (cam.sensor_size_mm / 2.0 / cam.focal_length_mm) as f32;
        let cam_z = cam.position.z as f32;
        let dist = 2.5 + self.unit() * (cam_z + room.z / 2.0 - 3.0);
        let half_width = (half_fov * dist + 0.3).min(room.x / 2.0 - 0.3);
        let at = Vec3::new((2.0 * self.unit() - 1.0) * half_width, 0.0, cam_z - dist);
        let yaw = self.unit() * TAU;
        let name = format!("object_{}", self.objects.len());
        let cutout = self.cfg.scene.cutout;
        match self.rng.random_range(0..6) {
            _ if self.chance(cutout) => self.grid_panel(&name, at, yaw),
            0 => self.block(&name, at, yaw),
            1 => self.table(&name, at, yaw),
            2 => self.ball(&name, at),
            3 => self.column(&name, at),
            _ => self.pane(&name, at, yaw),
        }
    }

    fn block(&mut self, name: &str, at: Vec3, yaw: f32) {
        let size = Vec3::new(
            0.2 + 0.8 * self.unit(),
            0.2 + 1.2 * self.unit(),
            0.2 + 0.6 * self.unit(),
        );
        let m = self.object_material(name);
        self.add(
            name,
            Shape::Cuboid { size },
            Transform::at(at + Vec3::Y * size.y / 2.0).rotated_y(yaw),
            m,
        );
    }

    fn table(&mut self, name: &str, at: Vec3, yaw: f32) {
        let (w, d, h) = (
            0.6 + 0.8 * self.unit(),
            0.4 + 0.5 * self.unit(),
            0.45 + 0.35 * self.unit(),
        );
        let top = self.object_material(name);
        let legs = self.object_material(name);
        let rot = Quat::from_rotation_y(yaw);
        let top_xf = Transform::at(at + Vec3::Y * (h - 0.02)).rotated_y(yaw);
        self.add(
            name,
            Shape::Cuboid {
                size: Vec3::new(w, 0.04, d),
            },
            top_xf,
            top,
        );
        for (sx, sz) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
            let off = rot * Vec3::new(sx * (w / 2.0 - 0.05), 0.0, sz * (d / 2.0 - 0.05));
            let leg = Shape::Cylinder {
                radius: 0.025,
                height: h - 0.04,
                segments: 12,
            };
            self.add(&format!("{name}_leg"), leg, Transform::at(at + off), legs);
        }
    }

    fn ball(&mut self, name: &str, at: Vec3) {
        let r = 0.1 + 0.3 * self.unit();
        let h = 0.3 * self.unit();
        let m = self.object_material(name);
        self.add(
            name,
            Shape::Sphere {
                radius: r,
                rings: 24,
                segments: 48,
            },
            Transform::at(at + Vec3::Y * (h + r)),
            m,
        );
        if h > 0.05 {
            let stand = self.object_material(name);
            let shape = Shape::Cylinder {
                radius: r * 0.3,
                height: h + 0.01,
                segments: 16,
            };
            self.add(&format!("{name}_stand"), shape, Transform::at(at), stand);
        }
    }

    fn column(&mut self, name: &str, at: Vec3) {
        let shape = Shape::Cylinder {
            radius: 0.05 + 0.2 * self.unit(),
            height: 0.3 + 1.5 * self.unit(),
            segments: 32,
        };
        let m = self.object_material(name);
        self.add(name, shape, Transform::at(at), m);
    }

    /// A standing pane: semi-transparent sheet, or a thin glass slab.
    fn pane(&mut self, name: &str, at: Vec3, yaw: f32) {
        let (w, h) = (0.3 + 0.6 * self.unit(), 0.4 + 1.0 * self.unit());
        let centre = at + Vec3::Y * (h / 2.0 + 0.05 * self.unit());
        let xf = Transform::at(centre).rotated_y(yaw * 0.3);
        if self.chance(0.3) {
            let m = self.material(
                name,
                Opacity::constant(1.0),
                SurfaceModel::Glass { ior: 1.5 },
            );
            self.add(
                name,
                Shape::Cuboid {
                    size: Vec3::new(w, h, 0.01),
                },
                xf,
                m,
            );
        } else {
            let a = self.range(self.cfg.scene.opacity_range);
            let m = self.material(name, Opacity::constant(a), SurfaceModel::Standard);
            self.add(name, Shape::Quad { size: [w, h] }, xf, m);
        }
    }

    /// A panel with a grid / woven alpha pattern (mesh screens, lattices).
    fn grid_panel(&mut self, name: &str, at: Vec3, yaw: f32) {
        let (w, h) = (0.3 + 0.6 * self.unit(), 0.5 + 1.0 * self.unit());
        let opacity = Opacity::Grid {
            value: 1.0,
            period: 0.01 + 0.08 * self.unit(),
            bar: 0.15 + 0.4 * self.unit(),
        };
        let m = self.material(name, opacity, SurfaceModel::Standard);
        let xf = Transform::at(at + Vec3::Y * h / 2.0).rotated_y(yaw * 0.3);
        self.add(name, Shape::Quad { size: [w, h] }, xf, m);
    }
}
