//! Window and door openings in the back wall of a built-in room: where they go, and what is
//! behind them. A window shows a bright daylight backdrop (an emissive plane a little outside,
//! which lights the room and gives rays through the window a finite depth), usually behind a
//! glass pane; a door leads into a short, unlit corridor.

use super::placement::{Body, Footprint, Layer};
use glam::Vec2;

/// Depth of the wall around an opening (its reveal).
pub const REVEAL: f32 = 0.15;
/// Clear space kept in front of a door.
const DOOR_CLEARANCE: f32 = 0.9;
/// Gap between openings, and between an opening and a side wall.
const GAP: f32 = 0.3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpeningKind {
    Window,
    Door,
}

/// A rectangular opening in the back wall: `x0..x1` across the room, `y0..y1` above the floor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening {
    pub kind: OpeningKind,
    pub x0: f32,
    pub x1: f32,
    pub y0: f32,
    pub y1: f32,
}

impl Opening {
    pub fn width(&self) -> f32 {
        self.x1 - self.x0
    }

    pub fn centre_x(&self) -> f32 {
        (self.x0 + self.x1) / 2.0
    }

    /// Whether it keeps [`GAP`] from `other` and from the side walls of a room `width` wide.
    pub fn fits(&self, width: f32, others: &[Opening]) -> bool {
        let inside = self.x0 >= -width / 2.0 + GAP && self.x1 <= width / 2.0 - GAP;
        inside
            && others
                .iter()
                .all(|o| self.x1 + GAP <= o.x0 || o.x1 + GAP <= self.x0)
    }

    /// The hole in the back wall's own frame (origin at its centre, the wall `height` high).
    pub fn hole(&self, height: f32) -> [f32; 4] {
        let h = height / 2.0;
        [self.x0, self.y0 - h, self.x1, self.y1 - h]
    }

    /// The space furniture must leave free, against the back wall at `z_wall`: the opening
    /// itself (so nothing hangs across a window) and, for a door, the floor in front of it.
    pub fn keep_clear(&self, z_wall: f32) -> Body {
        let depth = match self.kind {
            OpeningKind::Window => 0.06,
            OpeningKind::Door => DOOR_CLEARANCE / 2.0,
        };
        Body {
            footprint: Footprint {
                centre: Vec2::new(self.centre_x(), z_wall + depth),
                half: Vec2::new(self.width() / 2.0, depth),
                yaw: 0.0,
            },
            y: [self.y0, self.y1],
            layer: Layer::Solid,
        }
    }
}

/// The intervals of `[-width/2, width/2]` not covered by doors (where skirting runs).
pub fn skirting_runs(width: f32, openings: &[Opening]) -> Vec<[f32; 2]> {
    let mut doors: Vec<&Opening> = openings
        .iter()
        .filter(|o| o.kind == OpeningKind::Door)
        .collect();
    doors.sort_by(|a, b| a.x0.total_cmp(&b.x0));
    let mut runs = Vec::new();
    let mut x = -width / 2.0;
    for d in doors {
        runs.push([x, d.x0]);
        x = d.x1;
    }
    runs.push([x, width / 2.0]);
    runs.retain(|[a, b]| b > a);
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(x0: f32, x1: f32) -> Opening {
        Opening {
            kind: OpeningKind::Window,
            x0,
            x1,
            y0: 0.9,
            y1: 2.0,
        }
    }

    #[test]
    fn openings_keep_apart_and_inside_the_wall() {
        let a = window(-1.0, 0.0);
        assert!(a.fits(4.0, &[]));
        assert!(
            !window(-1.9, -1.0).fits(4.0, &[]),
            "too close to the side wall"
        );
        assert!(!window(0.1, 1.0).fits(4.0, &[a]), "closer than the gap");
        assert!(window(0.3, 1.0).fits(4.0, &[a]));
        assert_eq!(a.hole(3.0), [-1.0, -0.6, 0.0, 0.5]);
    }

    #[test]
    fn skirting_stops_at_doors_only() {
        let door = Opening {
            kind: OpeningKind::Door,
            x0: 0.5,
            x1: 1.4,
            y0: 0.0,
            y1: 2.1,
        };
        assert_eq!(
            skirting_runs(4.0, &[window(-1.0, 0.0), door]),
            vec![[-2.0, 0.5], [1.4, 2.0]]
        );
        assert_eq!(skirting_runs(4.0, &[]), vec![[-2.0, 2.0]]);
    }
}
