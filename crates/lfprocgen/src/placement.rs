//! Collision-free placement of pieces in a room: oriented footprints tested with the
//! separating-axis theorem, height intervals so a picture can hang above a low cabinet, and
//! surfaces on which accessories stand.
//!
//! World frame of the built-in rooms: floor at y = 0, x ∈ [−W/2, W/2], z ∈ [−D/2, D/2], the
//! camera near +D/2 looking towards −Z.

pub use crate::scene::PlacementReport;
use glam::{Vec2, Vec3};

/// An oriented rectangle on the floor plan (x, z): `centre`, half extents along the piece's
/// local X and Z, and the yaw that turned it (as [`glam::Quat::from_rotation_y`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub centre: Vec2,
    pub half: Vec2,
    pub yaw: f32,
}

impl Footprint {
    /// The piece's local X and Z axes on the floor plan.
    fn axes(&self) -> [Vec2; 2] {
        let (s, c) = self.yaw.sin_cos();
        // Rotation about +Y maps X to (cos, −sin) and Z to (sin, cos) in (x, z).
        [Vec2::new(c, -s), Vec2::new(s, c)]
    }

    /// World (x, z) of the local point `p` (piece frame).
    pub fn to_world(&self, p: Vec2) -> Vec2 {
        let [ax, az] = self.axes();
        self.centre + ax * p.x + az * p.y
    }

    /// Local (x, z) of the world point `p`.
    pub fn to_local(&self, p: Vec2) -> Vec2 {
        let [ax, az] = self.axes();
        let d = p - self.centre;
        Vec2::new(d.dot(ax), d.dot(az))
    }

    pub fn corners(&self) -> [Vec2; 4] {
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(sx, sz)| self.to_world(Vec2::new(sx, sz) * self.half))
    }

    /// Half the extent of the rectangle projected on the unit `axis`.
    fn radius_on(&self, axis: Vec2) -> f32 {
        let [ax, az] = self.axes();
        self.half.x * ax.dot(axis).abs() + self.half.y * az.dot(axis).abs()
    }

    /// Whether the rectangles come closer than `gap` (separating-axis test on the four edge
    /// normals, which is exact for two rectangles).
    pub fn overlaps(&self, other: &Footprint, gap: f32) -> bool {
        let d = other.centre - self.centre;
        self.axes()
            .into_iter()
            .chain(other.axes())
            .all(|axis| d.dot(axis).abs() < self.radius_on(axis) + other.radius_on(axis) + gap)
    }

    /// Whether every corner lies in the rectangle `min..max` (axis-aligned).
    pub fn inside(&self, min: Vec2, max: Vec2) -> bool {
        self.corners()
            .iter()
            .all(|c| c.cmpge(min).all() && c.cmple(max).all())
    }

    /// Whether `inner` lies entirely within this rectangle.
    pub fn contains(&self, inner: &Footprint) -> bool {
        inner.corners().iter().all(|&c| {
            let l = self.to_local(c);
            l.abs().cmple(self.half + 1e-4).all()
        })
    }
}

/// Which bodies can collide: floor covers (rugs) only with each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    Solid,
    Cover,
}

/// A placed piece's volume: footprint times a height interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Body {
    pub footprint: Footprint,
    pub y: [f32; 2],
    pub layer: Layer,
}

impl Body {
    pub fn collides(&self, other: &Body, gap: f32) -> bool {
        self.layer == other.layer
            && self.y[0] < other.y[1] - 1e-3
            && other.y[0] < self.y[1] - 1e-3
            && self.footprint.overlaps(&other.footprint, gap)
    }
}

/// A horizontal surface of a placed piece, in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldSurface {
    pub area: Footprint,
    pub y: f32,
    pub clearance: f32,
    /// Index of the body that carries it (an accessory may touch its host).
    pub host: usize,
}

/// The room and everything placed in it so far.
#[derive(Clone, Debug)]
pub struct Layout {
    pub room: Vec3,
    pub bodies: Vec<Body>,
    pub surfaces: Vec<WorldSurface>,
    /// Free space kept between pieces (metres).
    pub gap: f32,
}

impl Layout {
    pub fn new(room: Vec3) -> Self {
        Self {
            room,
            bodies: Vec::new(),
            surfaces: Vec::new(),
            gap: 0.02,
        }
    }

    /// Whether `body` stays inside the room (walls and ceiling, with a small margin).
    pub fn in_room(&self, body: &Body) -> bool {
        let h = Vec2::new(self.room.x, self.room.z) / 2.0 - 0.005;
        body.footprint.inside(-h, h) && body.y[0] >= 0.0 && body.y[1] <= self.room.y - 0.05
    }

    /// Whether `body` fits: inside the room and clear of every placed body but `host`.
    pub fn fits(&self, body: &Body, host: Option<usize>) -> bool {
        self.in_room(body)
            && self
                .bodies
                .iter()
                .enumerate()
                .all(|(i, b)| Some(i) == host || !b.collides(body, self.gap))
    }

    /// Adds `body`; returns its index.
    pub fn add(&mut self, body: Body) -> usize {
        self.bodies.push(body);
        self.bodies.len() - 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fp(x: f32, z: f32, hx: f32, hz: f32, yaw: f32) -> Footprint {
        Footprint {
            centre: Vec2::new(x, z),
            half: Vec2::new(hx, hz),
            yaw,
        }
    }

    #[test]
    fn sat_separates_rotated_rectangles_that_bounding_circles_would_not() {
        // Two long thin boards side by side, 0.1 apart: their bounding circles overlap.
        let a = fp(0.0, 0.0, 1.0, 0.05, 0.0);
        let b = fp(0.0, 0.2, 1.0, 0.05, 0.0);
        assert!(!a.overlaps(&b, 0.0));
        assert!(a.overlaps(&b, 0.11));
        // A diamond whose corner pokes into a square.
        let sq = fp(0.0, 0.0, 0.5, 0.5, 0.0);
        let diamond = fp(1.15, 0.0, 0.5, 0.5, std::f32::consts::FRAC_PI_4);
        assert!(
            sq.overlaps(&diamond, 0.0),
            "corner at x = 1.15 − 0.707 < 0.5"
        );
        let far = fp(1.25, 0.0, 0.5, 0.5, std::f32::consts::FRAC_PI_4);
        assert!(!sq.overlaps(&far, 0.0));
        // A thin board lying across the diagonal beyond the square's corner.
        let c = fp(1.0, 1.0, 0.5, 0.1, std::f32::consts::FRAC_PI_4);
        assert!(!sq.overlaps(&c, 0.0));
    }

    #[test]
    fn height_intervals_and_layers_gate_collisions() {
        let f = fp(0.0, 0.0, 0.5, 0.5, 0.3);
        let low = Body {
            footprint: f,
            y: [0.0, 0.8],
            layer: Layer::Solid,
        };
        let picture = Body {
            y: [1.2, 1.8],
            ..low
        };
        let rug = Body {
            y: [0.0, 0.01],
            layer: Layer::Cover,
            ..low
        };
        assert!(!low.collides(&picture, 0.0));
        assert!(!low.collides(&rug, 0.0));
        assert!(low.collides(&low, 0.0));
    }

    #[test]
    fn containment_and_room_bounds() {
        let table = fp(1.0, -2.0, 0.6, 0.4, 0.7);
        let cup = Footprint {
            centre: table.to_world(Vec2::new(0.5, 0.3)),
            half: Vec2::splat(0.05),
            yaw: 0.0,
        };
        assert!(table.contains(&cup));
        let off = Footprint {
            centre: table.to_world(Vec2::new(0.58, 0.3)),
            ..cup
        };
        assert!(!table.contains(&off));
        let layout = Layout::new(Vec3::new(4.0, 3.0, 8.0));
        let body = |x: f32, top: f32| Body {
            footprint: fp(x, 0.0, 0.3, 0.3, 0.0),
            y: [0.0, top],
            layer: Layer::Solid,
        };
        assert!(layout.in_room(&body(1.6, 2.0)));
        assert!(!layout.in_room(&body(1.8, 2.0)), "through the side wall");
        assert!(!layout.in_room(&body(0.0, 2.99)), "through the ceiling");
    }
}
