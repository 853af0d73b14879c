//! The room's materials: library textures and patterns, the standard, glass, cut-out and
//! semi-transparent variants a scene's shares ask for, and emitters (lamp bulbs, the outdoor
//! backdrop). Every material a scene uses is pushed here, so its index is its place in
//! `SceneDesc::materials`.

use super::{Gen, kelvin_rgb};
use crate::furniture::Role;
use crate::scene::{Material, Opacity, SurfaceModel, Texture};
use crate::textures::generators::{FAMILIES, Family};
use glam::Vec3;
use rand::RngExt;

impl Gen<'_> {
    /// A texture of the procedural library from one of `families`, untinted.
    pub(super) fn library(&mut self, families: &[Family]) -> Texture {
        let family = families[self.rng.random_range(0..families.len())];
        let f = FAMILIES
            .iter()
            .position(|&x| x == family)
            .expect("a family") as u32;
        let per_family = (self.room.textures / FAMILIES.len() as u32).max(1);
        Texture::Library {
            seed: self.room.texture_seed,
            index: f + FAMILIES.len() as u32 * self.rng.random_range(0..per_family),
            tint: [1.0; 3],
        }
    }

    /// The simple procedural textures (checker, stripes, noise) or a plain colour.
    fn pattern(&mut self) -> Texture {
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

    pub(super) fn push_material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }

    pub(super) fn standard(
        &mut self,
        name: &str,
        base_color: Texture,
        roughness: f32,
        opacity: Opacity,
    ) -> Material {
        Material {
            name: name.into(),
            model: SurfaceModel::Standard,
            base_color,
            roughness,
            metallic: 0.0,
            opacity,
            emission: [0.0; 3],
            emission_map: None,
        }
    }

    fn glass(&mut self, name: &str) -> u32 {
        let tint = 0.85 + 0.13 * self.unit();
        let m = Material {
            name: name.into(),
            model: SurfaceModel::Glass {
                ior: self.between(1.45, 1.55),
            },
            base_color: Texture::constant([tint, tint, (tint + 0.05).min(0.98)]),
            roughness: 0.0,
            metallic: 0.0,
            opacity: Opacity::constant(1.0),
            emission: [0.0; 3],
            emission_map: None,
        };
        self.push_material(m)
    }

    /// The material of `role` for piece `name`. Roles that are solid surfaces are randomised
    /// by the scene's shares: plain or low-contrast, glossy or metallic (`look`), then glass,
    /// semi-transparent with random opacity, or a grid cut-out.
    pub(super) fn role_material(&mut self, name: &str, role: Role) -> u32 {
        let name = format!("{name}_{role:?}").to_lowercase();
        let (texture, roughness, metallic) = match role {
            Role::Glass => return self.glass(&name),
            Role::Mesh => return self.mesh(&name),
            Role::Leaf => return self.leaf(&name),
            Role::Sheer => return self.sheer(&name),
            Role::Bulb => return self.bulb(&name),
            Role::Rug => {
                let t = self.library(&[Family::Carpet, Family::Weave, Family::Motif]);
                let m = self.standard(&name, t, 0.95, Opacity::constant(1.0));
                return self.push_material(m);
            }
            Role::Wood => (
                self.library(&[Family::Wood, Family::Planks, Family::Parquet]),
                self.between(0.3, 0.8),
                0.0,
            ),
            Role::Fabric => {
                let t = match self.chance(0.6) {
                    true => self.library(&[
                        Family::Carpet,
                        Family::Weave,
                        Family::Stripes,
                        Family::Motif,
                    ]),
                    false => self.pattern(),
                };
                (t, self.between(0.7, 1.0), 0.0)
            }
            Role::Metal => (
                Texture::constant(self.color()),
                self.between(0.15, 0.5),
                1.0,
            ),
            Role::Paint => (self.pattern(), self.between(0.3, 0.9), 0.0),
            Role::Ceramic => {
                let t = match self.chance(0.4) {
                    true => self.library(&[Family::Marble, Family::Granite]),
                    false => Texture::constant(self.color()),
                };
                (t, self.between(0.05, 0.35), 0.0)
            }
            Role::Book => (Texture::constant(self.color()), self.between(0.4, 0.8), 0.0),
            Role::Picture => {
                let all = FAMILIES;
                (self.library(&all), 0.6, 0.0)
            }
        };
        let texture = match role {
            Role::Picture => texture,
            _ => self.surface(texture, role == Role::Paint),
        };
        let (roughness, metallic) = match role {
            Role::Metal => (roughness, metallic),
            _ => self.finish(roughness, metallic),
        };
        let mut m = self.standard(&name, texture, roughness, Opacity::constant(1.0));
        m.metallic = metallic;
        self.randomised(m)
    }

    /// Adds the solid material `m`, made glass, a grid cut-out or semi-transparent by the
    /// scene's shares. Materials that already see through, or glow, are kept as they are.
    pub(super) fn randomised(&mut self, mut m: Material) -> u32 {
        if m.opacity.uniform() != Some(1.0) || m.is_emissive() || m.model != SurfaceModel::Standard
        {
            return self.push_material(m);
        }
        let s = self.room;
        let (glass, semi, cutout, range) = (s.glass, s.semi_transparent, s.cutout, s.opacity_range);
        if self.chance(glass) {
            return self.glass(&m.name);
        }
        if self.chance(cutout) {
            m.opacity = self.grid();
        } else if self.chance(semi) {
            m.opacity = Opacity::constant(self.range(range));
        }
        self.push_material(m)
    }

    fn grid(&mut self) -> Opacity {
        Opacity::Grid {
            value: 1.0,
            period: 0.005 + 0.05 * self.unit(),
            bar: 0.15 + 0.4 * self.unit(),
        }
    }

    /// Woven or grid cut-out (mesh chair backs, screens).
    fn mesh(&mut self, name: &str) -> u32 {
        let (c, o) = (Texture::constant(self.color()), self.grid());
        let m = self.standard(name, c, 0.6, o);
        self.push_material(m)
    }

    /// Leaves: green-ish, one leaf silhouette per unit of UV (a unit quad is one leaf).
    fn leaf(&mut self, name: &str) -> u32 {
        let g = 0.15 + 0.35 * self.unit();
        let c = [g * self.between(0.3, 0.7), g, g * self.between(0.1, 0.4)];
        let period = [1.0, 1.0];
        let m = self.standard(name, Texture::constant(c), 0.5, Opacity::Leaves { period });
        self.push_material(m)
    }

    /// Thin cloth: a light colour with low opacity.
    fn sheer(&mut self, name: &str) -> u32 {
        let c = self.color().map(|v| (v + 0.4).min(0.95));
        let a = self.between(0.3, 0.6);
        let m = self.standard(name, Texture::constant(c), 0.9, Opacity::constant(a));
        self.push_material(m)
    }

    /// A lamp bulb: a small emitter of random colour temperature.
    fn bulb(&mut self, name: &str) -> u32 {
        let rgb = kelvin_rgb(self.between(2400.0, 4000.0));
        let mut m = self.standard(
            name,
            Texture::constant([0.9; 3]),
            1.0,
            Opacity::constant(1.0),
        );
        m.emission = rgb.map(|c| c * 40.0);
        self.push_material(m)
    }

    /// Value noise between `a` and `b` with a feature size drawn from `[lo, hi]` metres.
    pub(super) fn noise(&mut self, a: [f32; 3], b: [f32; 3], lo: f32, hi: f32) -> Texture {
        Texture::Noise {
            a,
            b,
            scale: self.between(lo, hi),
            seed: self.rng.random(),
        }
    }

    /// An emissive material radiating `radiance × map(uv)`.
    pub(super) fn emitter(&mut self, name: &str, radiance: Vec3, map: Texture) -> u32 {
        let mut m = self.standard(
            name,
            Texture::constant([0.8; 3]),
            1.0,
            Opacity::constant(1.0),
        );
        m.emission = radiance.to_array();
        m.emission_map = Some(map);
        self.push_material(m)
    }
}
