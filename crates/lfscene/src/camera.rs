//! The HCI-compatible light-field camera: a grid of parallel, shifted-sensor pinhole cameras.
//!
//! World space is right-handed, metres, +Y up (glTF). Every view shares the centre camera's
//! orientation; view `(u, v)` sits `(u-uc)·b` along `right` and `(vc-v)·b` along `up` (row 0 is
//! the top row), and its sensor is shifted so the focus plane stays in register (docs/reference/format.md, Camera).
//! Ray directions have a forward component of exactly 1, so a hit's `t` *is* its planar depth.

use anyhow::{Result, ensure};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};

/// Camera grid and its per-scene baseline and focus.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightFieldCamera {
    pub resolution: [u32; 2],
    pub grid: [u32; 2],
    pub focal_length_mm: f64,
    pub sensor_size_mm: f64,
    pub baseline_m: f64,
    pub focus_distance_m: f64,
    /// Centre camera position (world).
    pub position: DVec3,
    /// Unit viewing direction of every camera.
    pub forward: DVec3,
    /// Unit up direction, orthogonal to `forward`.
    pub up: DVec3,
}

/// A camera ray: origin and a direction whose forward component is 1.
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub origin: Vec3,
    pub dir: Vec3,
}

impl LightFieldCamera {
    /// This rig (image, grid, sensor, baseline, focus) with its centre camera at `position`
    /// looking along `forward` (`up` is made orthogonal to it) and the vertical field of view
    /// `yfov` (radians) on the image: `f_px = H/2 / tan(yfov/2)`. The focal length is stored
    /// HCI-style on the sensor, `f_mm = f_px · sensor_size_mm / max(W, H)`.
    pub fn looking(&self, position: DVec3, forward: DVec3, up: DVec3, yfov: f64) -> Result<Self> {
        ensure!(
            yfov.is_finite() && yfov > 0.0 && yfov < std::f64::consts::PI,
            "vertical field of view {yfov} rad is not in (0, π)"
        );
        ensure!(
            position.is_finite(),
            "camera position {position} is not finite"
        );
        let frame = forward.try_normalize().and_then(|f| {
            let u = (up - f * up.dot(f)).try_normalize()?;
            Some((f, u))
        });
        let Some((forward, up)) = frame else {
            anyhow::bail!("camera forward {forward} and up {up} do not span a view");
        };
        let [w, h] = self.resolution;
        let f_px = h as f64 / 2.0 / (yfov / 2.0).tan();
        Ok(Self {
            focal_length_mm: f_px * self.sensor_size_mm / w.max(h) as f64,
            position,
            forward,
            up,
            ..*self
        })
    }

    pub fn width(&self) -> u32 {
        self.resolution[0]
    }

    pub fn height(&self) -> u32 {
        self.resolution[1]
    }

    pub fn num_views(&self) -> u32 {
        self.grid[0] * self.grid[1]
    }

    /// HCI file index of the centre view (`Cam040` for 9×9).
    pub fn center_view(&self) -> u32 {
        (self.grid[1] / 2) * self.grid[0] + self.grid[0] / 2
    }

    /// Column and row of a file index, each relative to the centre: `(u-uc, v-vc)`.
    pub fn view_offset(&self, view: u32) -> (i32, i32) {
        let u = (view % self.grid[0]) as i32 - (self.grid[0] / 2) as i32;
        let v = (view / self.grid[0]) as i32 - (self.grid[1] / 2) as i32;
        (u, v)
    }

    /// Focal length in pixels, on the larger image side (HCI).
    pub fn f_px(&self) -> f64 {
        let max_side = self.resolution[0].max(self.resolution[1]) as f64;
        self.focal_length_mm * max_side / self.sensor_size_mm
    }

    pub fn right(&self) -> DVec3 {
        self.forward.cross(self.up)
    }

    /// Disparity in pixels per view step of planar depth `z`.
    pub fn disparity(&self, z: f64) -> f64 {
        self.f_px() * self.baseline_m * (1.0 / z - 1.0 / self.focus_distance_m)
    }

    /// Planar depth of disparity `d` (inverse of [`Self::disparity`]).
    pub fn depth(&self, d: f64) -> f64 {
        1.0 / (d / (self.f_px() * self.baseline_m) + 1.0 / self.focus_distance_m)
    }

    /// Sets baseline and focus so `[z_near, z_far]` maps onto `[d_min, d_max]` (docs/reference/format.md, Camera).
    pub fn fit_disparity_range(&mut self, z_near: f64, z_far: f64, [d_min, d_max]: [f64; 2]) {
        let f = self.f_px();
        self.baseline_m = (d_max - d_min) / (f * (1.0 / z_near - 1.0 / z_far));
        self.focus_distance_m = 1.0 / (1.0 / z_near - d_max / (f * self.baseline_m));
    }

    /// Position of a view's camera.
    pub fn view_origin(&self, view: u32) -> DVec3 {
        let (du, dv) = self.view_offset(view);
        let b = self.baseline_m;
        self.position + self.right() * (du as f64 * b) - self.up * (dv as f64 * b)
    }

    /// Per-view constants for ray generation, computed once per view.
    pub fn view_rays(&self, view: u32) -> ViewRays {
        let (du, dv) = self.view_offset(view);
        let f = self.f_px();
        let shift_x = du as f64 * self.baseline_m / self.focus_distance_m;
        let shift_y = -dv as f64 * self.baseline_m / self.focus_distance_m;
        let o = self.view_origin(view);
        let half = [
            self.resolution[0] as f64 / 2.0,
            self.resolution[1] as f64 / 2.0,
        ];
        // dir(x, y) = forward + right·((x - cx)/f - sx) + up·(-(y - cy)/f - sy)
        let right = self.right();
        let base =
            self.forward - right * (half[0] / f + shift_x) + self.up * (half[1] / f - shift_y);
        ViewRays {
            origin: o.as_vec3(),
            base: base.as_vec3(),
            dx: (right / f).as_vec3(),
            dy: (-self.up / f).as_vec3(),
        }
    }

    /// Blender XYZ Euler angles of the centre camera in Blender's Z-up world (parameters.cfg).
    pub fn blender_rotation(&self) -> [f64; 3] {
        // Blender world = (x, -z, y) of ours; a Blender camera looks down its local -Z, up +Y.
        let to_blender = |v: DVec3| DVec3::new(v.x, -v.z, v.y);
        let cols = [
            to_blender(self.right()),
            to_blender(self.up),
            to_blender(-self.forward),
        ];
        let r = |row: usize, col: usize| cols[col][row];
        let x = r(2, 1).atan2(r(2, 2));
        let y = (-r(2, 0)).clamp(-1.0, 1.0).asin();
        let z = r(1, 0).atan2(r(0, 0));
        [x, y, z]
    }

    /// Centre camera position in Blender's Z-up world (parameters.cfg).
    pub fn blender_position(&self) -> [f64; 3] {
        let p = self.position;
        [p.x, -p.z, p.y]
    }
}

/// Affine pixel → ray-direction map of one view.
#[derive(Clone, Copy, Debug)]
pub struct ViewRays {
    origin: Vec3,
    base: Vec3,
    dx: Vec3,
    dy: Vec3,
}

impl ViewRays {
    /// Ray through image position `(x, y)` (pixel `(i, j)` covers `[i, i+1) × [j, j+1)`).
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> CameraRay {
        CameraRay {
            origin: self.origin,
            dir: self.base + self.dx * x + self.dy * y,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> LightFieldCamera {
        LightFieldCamera {
            resolution: [64, 48],
            grid: [9, 9],
            focal_length_mm: 100.0,
            sensor_size_mm: 35.0,
            baseline_m: 0.05,
            focus_distance_m: 3.0,
            position: DVec3::new(0.3, 1.2, 0.5),
            forward: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }

    /// Projects a world point into a view with an independent pinhole + sensor-shift model.
    fn project(c: &LightFieldCamera, view: u32, p: DVec3) -> (f64, f64) {
        let rel = p - c.view_origin(view);
        let z = rel.dot(c.forward);
        let (du, dv) = c.view_offset(view);
        let f = c.f_px();
        let sx = f * du as f64 * c.baseline_m / c.focus_distance_m;
        let sy = f * dv as f64 * c.baseline_m / c.focus_distance_m;
        let x = 32.0 + f * rel.dot(c.right()) / z + sx;
        let y = 24.0 - f * rel.dot(c.up) / z + sy;
        (x, y)
    }

    #[test]
    fn points_move_by_view_offset_times_disparity() {
        let c = camera();
        let p = DVec3::new(0.5, 1.0, -2.0);
        let d = c.disparity(2.5);
        let (xc, yc) = project(&c, c.center_view(), p);
        for view in [0, 8, 13, 72, 80] {
            let (du, dv) = c.view_offset(view);
            let (x, y) = project(&c, view, p);
            assert!((x - (xc - du as f64 * d)).abs() < 1e-9, "view {view}");
            assert!((y - (yc - dv as f64 * d)).abs() < 1e-9, "view {view}");
        }
    }

    #[test]
    fn rays_hit_the_point_they_project_from_at_planar_depth() {
        let c = camera();
        let p = DVec3::new(-0.4, 1.5, -4.0);
        for view in [0, 40, 80] {
            let (x, y) = project(&c, view, p);
            let ray = c.view_rays(view).ray(x as f32, y as f32);
            let z = (p - c.view_origin(view)).dot(c.forward);
            let hit = ray.origin.as_dvec3() + ray.dir.as_dvec3() * z;
            assert!((hit - p).length() < 1e-5, "view {view}: {hit} vs {p}");
        }
    }

    #[test]
    fn fitted_range_maps_onto_disparity_range() {
        let mut c = camera();
        c.fit_disparity_range(1.5, 9.0, [-3.5, 3.5]);
        assert!((c.disparity(1.5) - 3.5).abs() < 1e-9);
        assert!((c.disparity(9.0) + 3.5).abs() < 1e-9);
        assert!(
            (c.depth(1.25) - 1.0 / (1.25 / (c.f_px() * c.baseline_m) + 1.0 / c.focus_distance_m))
                .abs()
                < 1e-12
        );
        assert!((c.depth(c.disparity(4.2)) - 4.2).abs() < 1e-9);
    }

    #[test]
    fn looking_sets_the_vertical_field_of_view_and_an_orthonormal_frame() {
        let rig = LightFieldCamera {
            resolution: [64, 48],
            ..camera()
        };
        let yfov = 0.7f64;
        let c = rig
            .looking(
                DVec3::ZERO,
                DVec3::new(0.0, 0.0, -2.0),
                DVec3::new(0.0, 1.0, 0.5),
                yfov,
            )
            .unwrap();
        assert!((c.f_px() - 24.0 / (yfov / 2.0).tan()).abs() < 1e-9);
        // The top edge of the image is yfov/2 above the axis.
        let top = c.view_rays(c.center_view()).ray(32.0, 0.0).dir.as_dvec3();
        assert!((top.y.atan2(-top.z) - yfov / 2.0).abs() < 1e-6);
        assert!(c.up.dot(c.forward).abs() < 1e-12 && (c.up.length() - 1.0).abs() < 1e-12);
        let parallel = rig.looking(DVec3::ZERO, DVec3::Y, DVec3::Y, yfov);
        assert!(parallel.is_err());
        assert!(rig.looking(DVec3::ZERO, DVec3::Z, DVec3::Y, 3.2).is_err());
    }

    #[test]
    fn hci_indices_and_blender_pose() {
        let c = camera();
        assert_eq!(c.center_view(), 40);
        assert_eq!(c.view_offset(0), (-4, -4));
        assert_eq!(c.view_offset(80), (4, 4));
        // Looking horizontally along -Z (ours) is Blender's +Y: Euler (90°, 0, 0).
        let r = c.blender_rotation();
        assert!(
            (r[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-12
                && r[1].abs() < 1e-12
                && r[2].abs() < 1e-12
        );
        assert_eq!(c.blender_position(), [0.3, -0.5, 1.2]);
        // Row 0 is the top row: its cameras are above the centre.
        assert!(c.view_origin(0).y > c.position.y && c.view_origin(0).x < c.position.x);
    }
}
