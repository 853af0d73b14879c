//! The room's shell: floor, walls and ceiling with their openings, skirting boards, the
//! ceiling lights, and the camera that looks down the room.

use super::{Gen, SKIRTING};
use crate::camera::LightFieldCamera;
use crate::openings::skirting_runs;
use crate::scene::{Opacity, Shape, Texture, Transform};
use crate::textures::generators::Family;
use glam::{DVec3, Quat, Vec3};
use std::f32::consts::{FRAC_PI_2, PI};

impl Gen<'_> {
    /// Floor, four walls and ceiling as separate surfaces with library textures, and skirting.
    pub(super) fn room(&mut self, size: Vec3) {
        let floor_tex = self.library(&[
            Family::Planks,
            Family::Parquet,
            Family::Tiles,
            Family::Carpet,
            Family::Concrete,
            Family::Marble,
        ]);
        let wall_families = [
            Family::Paint,
            Family::Plaster,
            Family::Stripes,
            Family::Motif,
            Family::Bricks,
            Family::Tiles,
        ];
        let wall_tex = self.library(&wall_families);
        let ceiling_tex = self.library(&[Family::Paint, Family::Plaster, Family::Concrete]);
        let floor_tex = self.surface(floor_tex, true);
        let wall_tex = self.surface(wall_tex, true);
        let ceiling_tex = self.surface(ceiling_tex, true);
        let floor = self.standard("floor", floor_tex, 0.6, Opacity::constant(1.0));
        let floor = self.push_material(floor);
        let walls = self.standard("walls", wall_tex, 0.85, Opacity::constant(1.0));
        let walls = self.push_material(walls);
        // An accent back wall in one room out of three.
        let back = if self.chance(1.0 / 3.0) {
            let t = self.library(&wall_families);
            let t = self.surface(t, true);
            let m = self.standard("back_wall", t, 0.85, Opacity::constant(1.0));
            self.push_material(m)
        } else {
            walls
        };
        let ceiling = self.standard("ceiling", ceiling_tex, 0.9, Opacity::constant(1.0));
        let ceiling = self.push_material(ceiling);
        let (w, h, d) = (size.x, size.y, size.z);
        let quad = |centre: Vec3, rot: Quat| Transform {
            translation: centre,
            rotation: rot,
            scale: Vec3::ONE,
        };
        let faces = [
            (
                "floor",
                [w, d],
                quad(Vec3::ZERO, Quat::from_rotation_x(-FRAC_PI_2)),
                floor,
            ),
            (
                "ceiling",
                [w, d],
                quad(Vec3::Y * h, Quat::from_rotation_x(FRAC_PI_2)),
                ceiling,
            ),
            (
                "wall_front",
                [w, h],
                quad(Vec3::new(0.0, h / 2.0, d / 2.0), Quat::from_rotation_y(PI)),
                walls,
            ),
            (
                "wall_left",
                [d, h],
                quad(
                    Vec3::new(-w / 2.0, h / 2.0, 0.0),
                    Quat::from_rotation_y(FRAC_PI_2),
                ),
                walls,
            ),
            (
                "wall_right",
                [d, h],
                quad(
                    Vec3::new(w / 2.0, h / 2.0, 0.0),
                    Quat::from_rotation_y(-FRAC_PI_2),
                ),
                walls,
            ),
        ];
        for (name, size, xf, m) in faces {
            self.add(name, Shape::Quad { size }, xf, m);
        }
        self.openings = self.draw_openings(size);
        let holes = self.openings.iter().map(|o| o.hole(h)).collect();
        let back_xf = quad(Vec3::new(0.0, h / 2.0, -d / 2.0), Quat::IDENTITY);
        self.add(
            "wall_back",
            Shape::Wall {
                size: [w, h],
                holes,
            },
            back_xf,
            back,
        );
        self.outside(size, back);
        if self.chance(0.7) {
            self.skirting(size);
        }
    }

    /// Skirting boards along the four walls.
    fn skirting(&mut self, size: Vec3) {
        let c = self.color();
        let m = self.standard(
            "skirting",
            Texture::constant(c),
            0.4,
            Opacity::constant(1.0),
        );
        let m = self.push_material(m);
        let [sh, st] = SKIRTING;
        let (w, d) = (size.x, size.z);
        let back = skirting_runs(w, &self.openings).into_iter().map(|[a, b]| {
            (
                Vec3::new(b - a, sh, st),
                Vec3::new((a + b) / 2.0, sh / 2.0, -d / 2.0 + st / 2.0),
            )
        });
        let boards = [
            (
                Vec3::new(w, sh, st),
                Vec3::new(0.0, sh / 2.0, d / 2.0 - st / 2.0),
            ),
            (
                Vec3::new(st, sh, d - 2.0 * st),
                Vec3::new(-w / 2.0 + st / 2.0, sh / 2.0, 0.0),
            ),
            (
                Vec3::new(st, sh, d - 2.0 * st),
                Vec3::new(w / 2.0 - st / 2.0, sh / 2.0, 0.0),
            ),
        ];
        for (size, at) in boards.into_iter().chain(back) {
            self.add("skirting", Shape::Cuboid { size }, Transform::at(at), m);
        }
    }

    /// Ceiling area lights along the room, of random colour temperature and intensity, as
    /// bright as the room's mood has them (off, they stay as plain panels).
    pub(super) fn lights(&mut self, size: Vec3) {
        let n = self.room.lights;
        for i in 0..n {
            let kelvin = self.between(2700.0, 6500.0);
            let power = 6.0 + 10.0 * self.unit();
            let factor = self.panel_factor(i);
            let emission = self.light_rgb(kelvin, power * factor);
            let mut m = self.standard(
                &format!("light_{i}"),
                Texture::constant([0.8; 3]),
                1.0,
                Opacity::constant(1.0),
            );
            m.emission = emission;
            let m = self.push_material(m);
            let z = -size.z / 2.0 + size.z * (i as f32 + 0.5) / n as f32;
            // The 2.4 m panel stays 5 cm clear of the side walls.
            let x = (self.unit() - 0.5) * (size.x - 2.5).max(0.0);
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
    pub(super) fn camera(&mut self, size: Vec3) -> LightFieldCamera {
        let rig = self.rig.clone();
        let yaw = (self.unit() - 0.5) * 0.2;
        let pitch = -0.1 - 0.12 * self.unit();
        let forward =
            DVec3::new(-(yaw.sin() as f64), pitch.sin() as f64, -(yaw.cos() as f64)).normalize();
        let up = (DVec3::Y - forward * forward.y).normalize();
        LightFieldCamera {
            position: DVec3::new(
                0.0,
                1.2 + 0.4 * self.unit() as f64,
                size.z as f64 / 2.0 - 0.2,
            ),
            forward,
            up,
            ..rig
        }
    }
}
