//! Colour images: linear radiance → 8-bit sRGB PNG, and optionally linear float EXR.

use anyhow::{Context, Result};
use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
use glam::Vec3;
use image::ImageEncoder;
use lfformat::files::write_file;
use std::io::Cursor;
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
    save_png(&buf, path)
}

/// Encodes `img` as PNG in memory and writes it with [`write_file`]: `image`'s own `save`
/// drops the error of its final flush, so a full disk would publish a truncated file.
pub fn save_png(img: &image::RgbImage, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
        .with_context(|| format!("cannot encode {}", path.display()))?;
    Ok(write_file(path, &bytes)?)
}

/// Linear radiance (before exposure) as a float RGB EXR, encoded in memory for the same
/// reason as [`save_png`].
pub fn write_linear_exr(path: &Path, width: usize, height: usize, pixels: &[Vec3]) -> Result<()> {
    let channels = SpecificChannels::rgb(|Vec2(x, y)| {
        let c: Vec3 = pixels[y * width + x];
        (c.x, c.y, c.z)
    });
    let mut bytes = Cursor::new(Vec::new());
    Image::from_channels((width, height), channels)
        .write()
        .to_buffered(&mut bytes)
        .with_context(|| format!("cannot encode {}", path.display()))?;
    Ok(write_file(path, bytes.get_ref())?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-symmetric image: red top-left corner, green bottom-right, blue elsewhere.
    fn corners(w: usize, h: usize) -> Vec<Vec3> {
        (0..w * h)
            .map(|i| match (i % w, i / w) {
                (0, 0) => Vec3::X,
                (x, y) if x == w - 1 && y == h - 1 => Vec3::Y,
                _ => Vec3::Z * 0.5,
            })
            .collect()
    }

    #[test]
    fn png_and_exr_round_trip_with_orientation() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h) = (5, 3);
        let pixels = corners(w, h);
        let png = dir.path().join("v.png");
        write_png(&png, w, h, &pixels, 1.0).unwrap();
        let back = image::open(&png).unwrap().to_rgb8();
        assert_eq!(back.dimensions(), (5, 3));
        assert_eq!(back.get_pixel(0, 0).0, [255, 0, 0]);
        assert_eq!(back.get_pixel(4, 2).0, [0, 255, 0]);
        assert_eq!(back.get_pixel(1, 0).0, [0, 0, 188]);
        let exr = dir.path().join("v.exr");
        write_linear_exr(&exr, w, h, &pixels).unwrap();
        let img = exr::prelude::read_first_rgba_layer_from_file(
            &exr,
            |res, _| vec![Vec3::ZERO; res.width() * res.height()],
            |buf: &mut Vec<Vec3>, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                buf[pos.y() * 5 + pos.x()] = Vec3::new(r, g, b)
            },
        )
        .unwrap();
        assert_eq!(img.layer_data.channel_data.pixels, pixels);
    }

    #[test]
    fn srgb_matches_reference_values() {
        assert_eq!(to_srgb8(&[Vec3::new(0.0, 1.0, 0.18)], 1.0), [0, 255, 118]);
        assert_eq!(to_srgb8(&[Vec3::splat(0.5)], 2.0), [255, 255, 255]);
        assert!((linear_to_srgb(0.002) - 0.02584).abs() < 1e-5);
    }
}
