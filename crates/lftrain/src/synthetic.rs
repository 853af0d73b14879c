//! Analytically rendered two-layer light fields: a textured background plane and a
//! semi-transparent textured square in front of it. Tests and smoke runs use them where a
//! path-traced scene is not essential: they are exact (no sampling noise), cost microseconds,
//! and can be rendered with the scene content itself rotated, which is what the rotation
//! augmentation must reproduce.

use std::path::Path;

use anyhow::{Context, Result};
use lfdata::lightfield::LightField;
use lfformat::pfm::{FloatImage, write_pfm};
use lfformat::{HciParameters, Mode, ModeMap};

/// The scene description; coordinates are centre-relative pixels of the centre view
/// (x right, y down), disparities in pixels per view step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoPlanes {
    /// Views per grid side (odd).
    pub n: usize,
    /// Image side (square images).
    pub size: usize,
    /// Disparity of the background plane.
    pub back: f32,
    /// Disparity of the square.
    pub front: f32,
    /// Half side of the square.
    pub half: f32,
    /// Centre of the square.
    pub centre: (f32, f32),
    /// Opacity of the square (its `η`; the background gets `1 - alpha` behind it).
    pub alpha: f32,
    /// Texture phase, so that scenes differ.
    pub phase: f32,
    /// Quarter turns applied to the scene content (not to the cameras).
    pub turns: usize,
}

impl TwoPlanes {
    /// A small default scene.
    pub fn new(n: usize, size: usize) -> Self {
        Self {
            n,
            size,
            back: -1.0,
            front: 1.25,
            half: size as f32 * 0.23,
            centre: (0.6, -0.4),
            alpha: 0.7,
            phase: 0.0,
            turns: 0,
        }
    }

    /// The two tiny scenes the training tests learn from: `DIR/train/a`, `DIR/train/b` (5×5
    /// views of 24², disparities within ±1.25), with multimodal GT when `multimodal`.
    pub fn write_tiny_pair(dir: &Path, multimodal: bool) -> Result<()> {
        let base = TwoPlanes::new(5, 24);
        let b = TwoPlanes {
            phase: 1.7,
            centre: (-2.5, 1.5),
            front: 0.6,
            back: -0.4,
            ..base
        };
        base.write(&dir.join("train").join("a"), multimodal)?;
        b.write(&dir.join("train").join("b"), multimodal)
    }

    /// The scene point `p` expressed in the unrotated scene: `R^-turns p` with
    /// `R⁻¹(a, b) = (-b, a)` (the inverse of the quarter turn of [`lfdata::lightfield`]).
    fn unrotate(&self, (mut a, mut b): (f32, f32)) -> (f32, f32) {
        for _ in 0..self.turns % 4 {
            (a, b) = (-b, a);
        }
        (a, b)
    }

    fn in_square(&self, p: (f32, f32)) -> bool {
        let (a, b) = self.unrotate(p);
        (a - self.centre.0).abs() < self.half && (b - self.centre.1).abs() < self.half
    }

    fn texture(&self, p: (f32, f32), layer: f32) -> [f32; 3] {
        let (a, b) = self.unrotate(p);
        let s = |f: f32, g: f32, o: f32| 0.5 + 0.4 * (f * a + g * b + o + self.phase).sin();
        [
            s(0.37 + layer * 0.2, 0.21, 0.0),
            s(0.13, 0.41 - layer * 0.1, 1.0 + layer),
            s(0.29, -0.33, 2.0 * layer),
        ]
    }

    /// Centre-relative coordinates of pixel `(x, y)` (its centre).
    fn centred(&self, x: usize, y: usize) -> (f32, f32) {
        let c = self.size as f32 / 2.0;
        (x as f32 + 0.5 - c, y as f32 + 0.5 - c)
    }

    /// Colour of pixel `(x, y)` in view `(u, v)`: a point of disparity `d` at centre-view
    /// position `p` appears at `p - w d` in the view with offset `w`, so this pixel sees the
    /// layer point `p + w d`.
    pub fn colour(&self, u: usize, v: usize, x: usize, y: usize) -> [f32; 3] {
        let c = (self.n / 2) as f32;
        let (du, dv) = (u as f32 - c, v as f32 - c);
        let (px, py) = self.centred(x, y);
        let at = |d: f32| (px + du * d, py + dv * d);
        let back = self.texture(at(self.back), 0.0);
        let pf = at(self.front);
        if !self.in_square(pf) {
            return back;
        }
        let front = self.texture(pf, 1.0);
        std::array::from_fn(|i| self.alpha * front[i] + (1.0 - self.alpha) * back[i])
    }

    /// The star views.
    pub fn render(&self) -> LightField {
        LightField::from_fn(self.n, self.size, self.size, |u, v, x, y| {
            self.colour(u, v, x, y)
        })
    }

    /// The centre view's modes, front to back.
    pub fn modes(&self) -> ModeMap {
        let mut map = ModeMap::new(self.size, self.size);
        let mode = |d: f32, eta: f32| Mode {
            disparity: d,
            depth: 1.0,
            eta,
            eta_exact: eta,
        };
        for y in 0..self.size {
            for x in 0..self.size {
                if self.in_square(self.centred(x, y)) {
                    map.push_pixel(&[
                        mode(self.front, self.alpha),
                        mode(self.back, 1.0 - self.alpha),
                    ]);
                } else {
                    map.push_pixel(&[mode(self.back, 1.0)]);
                }
            }
        }
        map
    }

    /// HCI's single GT: the first surface with opacity ≥ 0.5.
    pub fn hci_disparity(&self) -> FloatImage {
        let data = (0..self.size * self.size)
            .map(|i| {
                let p = self.centred(i % self.size, i / self.size);
                if self.in_square(p) && self.alpha >= 0.5 {
                    self.front
                } else {
                    self.back
                }
            })
            .collect();
        FloatImage::new(self.size, self.size, data)
    }

    /// Writes an lfgen-style scene folder: `parameters.cfg`, every view as an 8-bit PNG (as
    /// lfgen and HCI write them; test-time denoising reads them all), `gt_disp_lowres.pfm`
    /// and, with `multimodal`, `modes.exr`.
    pub fn write(&self, dir: &Path, multimodal: bool) -> Result<()> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
        let (lo, hi) = (self.back.min(self.front), self.back.max(self.front));
        parameters(self.n, self.size, [lo, hi]).write(&dir.join("parameters.cfg"))?;
        for i in 0..self.n * self.n {
            let (u, v) = (i % self.n, i / self.n);
            let img = image::RgbImage::from_fn(self.size as u32, self.size as u32, |x, y| {
                let rgb = self.colour(u, v, x as usize, y as usize);
                image::Rgb(rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
            });
            let path = dir.join(format!("input_Cam{i:03}.png"));
            img.save(&path)
                .with_context(|| format!("{}: cannot write", path.display()))?;
        }
        write_pfm(&dir.join("gt_disp_lowres.pfm"), &self.hci_disparity())?;
        if multimodal {
            lfformat::modes::write_modes_exr(&dir.join("modes.exr"), &self.modes())?;
        }
        Ok(())
    }
}

/// HCI parameters of an `n × n` grid of `size²` images whose disparities span `range` (only
/// the grid, the size and the range matter here; the range is widened as HCI writes it).
fn parameters(n: usize, size: usize, [lo, hi]: [f32; 2]) -> HciParameters {
    HciParameters {
        focal_length_mm: 100.0,
        image_resolution_x_px: size as u32,
        image_resolution_y_px: size as u32,
        sensor_size_mm: 35.0,
        fstop: 100.0,
        num_cams_x: n as u32,
        num_cams_y: n as u32,
        baseline_mm: 10.0,
        focus_distance_m: 2.0,
        center_cam_x_m: 0.0,
        center_cam_y_m: 0.0,
        center_cam_z_m: 1.0,
        center_cam_rx_rad: std::f64::consts::FRAC_PI_2,
        center_cam_ry_rad: 0.0,
        center_cam_rz_rad: 0.0,
        scene: "synthetic".into(),
        category: "training".into(),
        date: "2026-01-01".into(),
        version: "synthetic".into(),
        cycles_seed: 0,
        disp_min: (lo as f64 * 10.0).floor() / 10.0 - 0.1,
        disp_max: (hi as f64 * 10.0).ceil() / 10.0 + 0.1,
        frustum_disp_min: -2.0,
        frustum_disp_max: 2.0,
        depth_map_scale: 1.0,
    }
}
