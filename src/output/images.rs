//! Colour images: linear radiance → 8-bit sRGB PNG, and optionally linear float EXR.

use anyhow::{Context, Result};
use glam::Vec3;
use std::path::Path;

/// The sRGB transfer function of a linear value in [0, 1].
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB of linear radiance times `exposure`, clamped.
pub fn to_srgb8(pixels: &[Vec3], exposure: f32) -> Vec<u8> {
    pixels
        .iter()
        .flat_map(|&c| (c * exposure).to_array())
        .map(|v| (linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8)
        .collect()
}

pub fn write_png(
    path: &Path,
    width: usize,
    height: usize,
    pixels: &[Vec3],
    exposure: f32,
) -> Result<()> {
    let buf = image::RgbImage::from_raw(width as u32, height as u32, to_srgb8(pixels, exposure))
        .context("image size mismatch")?;
    buf.save(path)
        .with_context(|| format!("cannot write {}", path.display()))
}

/// Linear radiance (before exposure) as a float RGB EXR.
pub fn write_linear_exr(path: &Path, width: usize, height: usize, pixels: &[Vec3]) -> Result<()> {
    exr::prelude::write_rgb_file(path, width, height, |x, y| {
        let c = pixels[y * width + x];
        (c.x, c.y, c.z)
    })
    .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_matches_reference_values() {
        assert_eq!(to_srgb8(&[Vec3::new(0.0, 1.0, 0.18)], 1.0), [0, 255, 118]);
        assert_eq!(to_srgb8(&[Vec3::splat(0.5)], 2.0), [255, 255, 255]);
        assert!((linear_to_srgb(0.002) - 0.02584).abs() < 1e-5);
    }
}
