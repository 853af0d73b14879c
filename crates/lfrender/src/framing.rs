//! Framing a scene: measure the depth range the camera grid sees, then fit baseline, focus and
//! the slice partition to it (docs/reference/format.md, Camera; Slices and modes).

use super::RenderScene;
use crate::camera::LightFieldCamera;
use crate::scene::{SliceRange, SliceSpacing};
use crate::util::colour::luminance;
use glam::Vec3;

/// Rays per image side of the depth probe (per corner and centre view).
const PROBE_RES: u32 = 96;

impl RenderScene {
    /// Nearest surface and farthest *visible* surface seen by the centre and corner views
    /// (any hit counts for the near end; the far end is the first fully opaque hit, since
    /// nothing behind it can contribute to a pixel). The two may coincide — a single
    /// fronto-parallel wall — since [`Self::frame`] widens the range anyway.
    pub fn probe_depth_range(&self, cam: &LightFieldCamera) -> Option<(f64, f64)> {
        let mut hits = Vec::new();
        let (mut near, mut far) = (f32::INFINITY, 0.0f32);
        let last = cam.num_views() - 1;
        for view in [
            cam.center_view(),
            0,
            cam.grid[0] - 1,
            last + 1 - cam.grid[0],
            last,
        ] {
            let rays = cam.view_rays(view);
            for j in 0..PROBE_RES {
                for i in 0..PROBE_RES {
                    let x = (i as f32 + 0.5) / PROBE_RES as f32 * cam.width() as f32;
                    let y = (j as f32 + 0.5) / PROBE_RES as f32 * cam.height() as f32;
                    let r = rays.ray(x, y);
                    self.geometry
                        .all_hits(r.origin, r.dir, f32::INFINITY, &mut hits);
                    let Some(first) = hits.first() else { continue };
                    near = near.min(first.t);
                    if let Some(h) = hits
                        .iter()
                        .find(|h| self.geometry.coverage(&self.materials, h, r.dir) >= 1.0)
                    {
                        far = far.max(h.t);
                    }
                }
            }
        }
        (near.is_finite() && far >= near).then_some((near as f64, far as f64))
    }

    /// The framed camera and the slice partition of its depth range.
    ///
    /// The probed range is widened by 2 % at each end so surfaces between probe rays still fall
    /// inside it. With `fit_disparity = Some(range)` (the automatic baseline) the camera's
    /// baseline and focus are chosen so that the widened range maps exactly onto `range`;
    /// with `None` the camera is kept as it is.
    pub fn frame(
        &self,
        cam: &LightFieldCamera,
        fit_disparity: Option<[f64; 2]>,
        slices: u32,
        spacing: SliceSpacing,
    ) -> anyhow::Result<(LightFieldCamera, SliceRange)> {
        let (near, far) = self.probe_depth_range(cam).ok_or_else(|| {
            anyhow::anyhow!("the camera sees no closed geometry: cannot fit a depth range")
        })?;
        let (z_near, z_far) = (near * 0.98, far * 1.02);
        let mut cam = cam.clone();
        if let Some(range) = fit_disparity {
            cam.fit_disparity_range(z_near, z_far, range);
        }
        let slices = SliceRange {
            z_near,
            z_far,
            count: slices,
            spacing,
        };
        Ok((cam, slices))
    }
}

/// Exposure mapping the log-average luminance of `pixels` to middle grey (0.18).
pub fn auto_exposure(pixels: &[Vec3]) -> f32 {
    let n = pixels.len().max(1) as f64;
    let log_sum: f64 = pixels
        .iter()
        .map(|&c| (luminance(c) as f64 + 1e-4).ln())
        .sum();
    (0.18 / (log_sum / n).exp()) as f32
}
