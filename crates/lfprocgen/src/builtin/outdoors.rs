//! Openings in the back wall and what lies behind them: the wall's reveal, a window's glass
//! and the outdoor layers it looks out on (sky, woods, buildings, a tree), a door's corridor.

use super::look::Mood;
use super::{Gen, kelvin_rgb};
use crate::openings::{Opening, OpeningKind, REVEAL};
use crate::scene::{Opacity, Shape, Texture, Transform};
use glam::{Quat, Vec3};
use rand::RngExt;
use std::f32::consts::FRAC_PI_2;

impl Gen<'_> {
    /// Up to `scene.windows` windows and, by chance `scene.door`, a door in the back wall,
    /// at random places that keep apart.
    pub(super) fn draw_openings(&mut self, size: Vec3) -> Vec<Opening> {
        let s = self.room;
        let (door, [lo, hi]) = (s.door, s.windows);
        // A window-lit room has a window whatever `scene.windows` says.
        let lo = if self.mood == Mood::Window {
            lo.max(1)
        } else {
            lo
        };
        let hi = hi.max(lo);
        let mut wanted = Vec::new();
        if self.chance(door) {
            let (w, top) = (
                self.between(0.8, 1.0),
                self.between(2.0, 2.2).min(size.y - 0.2),
            );
            wanted.push((OpeningKind::Door, w, 0.0, top));
        }
        for _ in 0..self.rng.random_range(lo..=hi) {
            let sill = self.between(0.5, 1.0);
            let top = (sill + self.between(0.8, 1.6)).min(size.y - 0.25);
            wanted.push((OpeningKind::Window, self.between(0.7, 1.8), sill, top));
        }
        let mut placed: Vec<Opening> = Vec::new();
        for (kind, width, y0, y1) in wanted {
            for _ in 0..20 {
                let x0 = self.between(-size.x / 2.0, size.x / 2.0 - width);
                let o = Opening {
                    kind,
                    x0,
                    x1: x0 + width,
                    y0,
                    y1,
                };
                if o.fits(size.x, &placed) {
                    placed.push(o);
                    break;
                }
            }
        }
        placed
    }

    /// What lies beyond the back wall's openings: their reveals, window panes and bars, a
    /// corridor behind a door, and the outdoors behind the windows.
    pub(super) fn outside(&mut self, size: Vec3, wall: u32) {
        let z = -size.z / 2.0;
        for o in self.openings.clone() {
            self.reveal(&o, z, wall);
            match o.kind {
                OpeningKind::Window => {
                    self.window(&o, z);
                    self.outdoors(&o, z);
                }
                OpeningKind::Door => self.corridor(&o, z, wall),
            }
        }
    }

    /// What a window looks out on: a cloudy sky, a horizon of distant trees, a few buildings
    /// and sometimes a nearer tree, at depths from 0.4 m to 2.2 m beyond the wall, so a ray
    /// through the window meets structure that moves with parallax (something for a depth
    /// method to match) instead of a flat white plane. All of it emits (textured emission)
    /// rather than being lit: out there nothing would light a face turned to the room, and as
    /// emitters they light the room as the daylight did. Each layer is just large enough that
    /// every camera ray through the window meets the sky (the HCI lens sees at most ~0.4 m
    /// sideways per metre).
    fn outdoors(&mut self, o: &Opening, z: f32) {
        let kelvin = self.between(5500.0, 7500.0);
        let sky = Vec3::from(kelvin_rgb(kelvin)) * self.range(self.room.window_light);
        let sky = sky * self.window_factor();
        let face = z - REVEAL;
        let dist = self.between(1.4, 2.2);
        // Half the extent seen around the window at `d` beyond the wall's outer face.
        let margin = |d: f32| 0.5 * (REVEAL + d) + 0.1;
        let (cx, cy, h) = (o.centre_x(), (o.y0 + o.y1) / 2.0, o.y1 - o.y0);
        let size = [o.width() + 2.0 * margin(dist), h + 2.0 * margin(dist)];
        let clouds = self.noise([0.55, 0.68, 0.95], [1.0; 3], 0.3, 0.8);
        let m = self.emitter("sky", sky, clouds);
        let at = Vec3::new(cx, cy, face - dist);
        self.add("outside_sky", Shape::Quad { size }, Transform::at(at), m);
        // The horizon: a band of distant woods from below the view up to a random height.
        let (bottom, horizon) = (cy - size[1] / 2.0, o.y0 + h * self.between(0.05, 0.5));
        let woods = self.noise([0.10, 0.16, 0.07], [0.32, 0.38, 0.2], 0.03, 0.12);
        let radiance = sky * self.between(0.2, 0.4);
        let m = self.emitter("woods", radiance, woods);
        let at = Vec3::new(cx, (bottom + horizon) / 2.0, face - dist + 0.05);
        let size = [size[0], horizon - bottom];
        self.add("outside_woods", Shape::Quad { size }, Transform::at(at), m);
        for _ in 0..self.rng.random_range(1..=3) {
            let d = self.between(0.7, dist - 0.2);
            self.building(o, face - d, margin(d), sky);
        }
        if self.chance(0.6) {
            let front = face - self.between(0.6, 1.2);
            self.tree(o, front, sky);
        }
    }

    /// A building seen through a window, `z` its front, where the view reaches `margin` below
    /// the sill: a facade of lit wall and darker window panes (a checker) from below the view
    /// to a top inside the window's height.
    fn building(&mut self, o: &Opening, z: f32, margin: f32, sky: Vec3) {
        let (width, depth) = (self.between(0.25, 0.8), 0.3);
        let x = self.between(o.x0 - 0.2, o.x1 + 0.2);
        let base = o.y0 - margin;
        let top = o.y0 + (o.y1 - o.y0) * self.between(0.15, 0.9);
        let wall = self.color().map(|c| 0.4 + 0.6 * c);
        let facade = Texture::Checker {
            a: wall,
            b: [0.18, 0.22, 0.3],
            size: self.between(0.03, 0.08),
        };
        let radiance = sky * self.between(0.25, 0.6);
        let m = self.emitter("building", radiance, facade);
        let at = Vec3::new(x, (base + top) / 2.0, z - depth / 2.0);
        let size = Vec3::new(width, top - base, depth);
        self.add(
            "outside_building",
            Shape::Cuboid { size },
            Transform::at(at),
            m,
        );
    }

    /// A nearer tree, `z` the front of its crown: a noisy green sphere on a dark trunk.
    fn tree(&mut self, o: &Opening, z: f32, sky: Vec3) {
        let r = self.between(0.15, 0.35);
        let x = self.between(o.x0, o.x1);
        let y = o.y0 + (o.y1 - o.y0) * self.between(0.2, 0.6);
        let leaves = self.noise([0.06, 0.14, 0.04], [0.25, 0.42, 0.12], 0.02, 0.06);
        let radiance = sky * self.between(0.2, 0.4);
        let m = self.emitter("tree", radiance, leaves);
        let crown = Shape::Sphere {
            radius: r,
            rings: 12,
            segments: 16,
        };
        let centre = Vec3::new(x, y, z - r);
        self.add("outside_tree", crown, Transform::at(centre), m);
        let bark = Texture::constant([0.12, 0.09, 0.07]);
        let m = self.emitter("trunk", sky * 0.2, bark);
        let trunk = Shape::Cylinder {
            radius: 0.03,
            height: y,
            segments: 8,
        };
        let foot = Vec3::new(x, 0.0, centre.z);
        self.add("outside_tree", trunk, Transform::at(foot), m);
    }

    /// The four faces of the wall's thickness around an opening, facing into it.
    fn reveal(&mut self, o: &Opening, z: f32, wall: u32) {
        let zc = z - REVEAL / 2.0;
        let (w, h) = (o.width(), o.y1 - o.y0);
        let yc = (o.y0 + o.y1) / 2.0;
        let faces = [
            (
                [REVEAL, h],
                Vec3::new(o.x0, yc, zc),
                Quat::from_rotation_y(FRAC_PI_2),
            ),
            (
                [REVEAL, h],
                Vec3::new(o.x1, yc, zc),
                Quat::from_rotation_y(-FRAC_PI_2),
            ),
            (
                [w, REVEAL],
                Vec3::new(o.centre_x(), o.y0, zc),
                Quat::from_rotation_x(-FRAC_PI_2),
            ),
            (
                [w, REVEAL],
                Vec3::new(o.centre_x(), o.y1, zc),
                Quat::from_rotation_x(FRAC_PI_2),
            ),
        ];
        for (size, at, rotation) in faces {
            let xf = Transform {
                translation: at,
                rotation,
                scale: Vec3::ONE,
            };
            self.add("outside_reveal", Shape::Quad { size }, xf, wall);
        }
    }

    /// A window's pane (most windows) and glazing bars (some). The pane is thin glass: a smooth
    /// surface of low opacity, which lets the daylight reach the room by direct light sampling
    /// (a dielectric would pass it only along caustic paths) and is a second depth layer of
    /// known coverage over the daylight.
    fn window(&mut self, o: &Opening, z: f32) {
        let (w, h) = (o.width(), o.y1 - o.y0);
        let centre = Vec3::new(o.centre_x(), (o.y0 + o.y1) / 2.0, z - REVEAL / 2.0);
        if self.chance(0.75) {
            let tint = Texture::constant([0.85, 0.9, 0.92]);
            let a = Opacity::constant(self.between(0.08, 0.25));
            let pane = self.standard("window_pane", tint, 0.05, a);
            let pane = self.push_material(pane);
            self.add(
                "outside_pane",
                Shape::Quad { size: [w, h] },
                Transform::at(centre),
                pane,
            );
        }
        if self.chance(0.5) {
            let c = self.color().map(|v| (v + 0.5).min(0.95));
            let m = self.standard(
                "window_bars",
                Texture::constant(c),
                0.5,
                Opacity::constant(1.0),
            );
            let m = self.push_material(m);
            let t = 0.04;
            let bar = |size: Vec3| Shape::Cuboid { size };
            let at = Transform::at(centre + Vec3::Z * (t / 2.0 + 0.005));
            self.add("outside_bar", bar(Vec3::new(t, h, t)), at, m);
            self.add("outside_bar", bar(Vec3::new(w, t, t)), at, m);
        }
    }

    /// A short unlit corridor behind a door: floor, ceiling, side walls and an end wall.
    fn corridor(&mut self, o: &Opening, z: f32, wall: u32) {
        let len = self.between(1.2, 2.5);
        let width = o.width() + self.between(0.4, 1.2);
        let height = o.y1 + self.between(0.2, 0.4);
        let (x, zc, z_end) = (o.centre_x(), z - REVEAL - len / 2.0, z - REVEAL - len);
        let face = |at: Vec3, rotation: Quat| Transform {
            translation: at,
            rotation,
            scale: Vec3::ONE,
        };
        let faces = [
            (
                [width, len],
                face(Vec3::new(x, 0.0, zc), Quat::from_rotation_x(-FRAC_PI_2)),
            ),
            (
                [width, len],
                face(Vec3::new(x, height, zc), Quat::from_rotation_x(FRAC_PI_2)),
            ),
            (
                [len, height],
                face(
                    Vec3::new(x - width / 2.0, height / 2.0, zc),
                    Quat::from_rotation_y(FRAC_PI_2),
                ),
            ),
            (
                [len, height],
                face(
                    Vec3::new(x + width / 2.0, height / 2.0, zc),
                    Quat::from_rotation_y(-FRAC_PI_2),
                ),
            ),
            (
                [width, height],
                face(Vec3::new(x, height / 2.0, z_end), Quat::IDENTITY),
            ),
        ];
        for (size, xf) in faces {
            self.add("outside_corridor", Shape::Quad { size }, xf, wall);
        }
    }
}
