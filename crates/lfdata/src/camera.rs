//! What a real camera does to views and a rendered light field lacks, once for the robustness
//! benchmark's corruptions (`lfeval`) and the trainer's augmentation (`lftrain`): the cos⁴
//! vignetting falloff and JPEG compression, and the benchmark's 8-bit sensor noise. Both act per view in image coordinates, the same
//! in every view, so they are the same pixels' error in each view — not a shifted copy of the
//! scene — and break the photo-consistency a depth estimator relies on.

use std::io::Cursor;

use anyhow::{Context, Result};
use image::RgbImage;
use image::codecs::jpeg::JpegEncoder;
use lfformat::srgb::{from_linear, to_linear};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// A lens' vignetting: linear light divided by `(1 + t² ρ²)²`, the cos⁴ law, `ρ` the distance
/// from the optical centre over the image's half-diagonal and `t² = (1 − f)^-1/2 − 1` so that
/// the corners lose the share `f`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vignette {
    /// The optical centre, pixels, continuous (pixel `(x, y)` covers `[x, x + 1) × [y, y + 1)`).
    centre: (f32, f32),
    /// The squared half-diagonal of the whole image, pixels².
    half_diagonal2: f32,
    /// `t²` of the law.
    t2: f32,
}

impl Vignette {
    /// The vignetting of a `width × height` image that loses the share `lost` of its light at
    /// the corners, centred on it.
    pub fn centred(lost: f32, (width, height): (usize, usize)) -> Self {
        let (w, h) = (width as f32, height as f32);
        Self {
            centre: (0.5 * w, 0.5 * h),
            half_diagonal2: 0.25 * (w * w + h * h),
            t2: (1.0 - lost).powf(-0.5) - 1.0,
        }
    }

    /// The same lens seen from a crop whose pixel `(i, j)` is the image's pixel
    /// `corner + step · (i, j)` (as [`crate::lightfield::LightField::crop`] takes it).
    pub fn in_crop(self, (x0, y0): (isize, isize), step: usize) -> Self {
        let k = step.max(1) as f32;
        let to_crop = |c: f32, origin: isize| (c - origin as f32 - 0.5) / k + 0.5;
        Self {
            centre: (to_crop(self.centre.0, x0), to_crop(self.centre.1, y0)),
            half_diagonal2: self.half_diagonal2 / (k * k),
            t2: self.t2,
        }
    }

    /// The same lens after `quarter_turns` turns of a `side × side` image by
    /// [`crate::lightfield::rotate_plane`] (source pixel `(x, y)` lands at `(y, side − 1 − x)`).
    pub fn rotated(self, side: usize, quarter_turns: usize) -> Self {
        let mut centre = self.centre;
        for _ in 0..quarter_turns % 4 {
            centre = (centre.1, side as f32 - centre.0);
        }
        Self { centre, ..self }
    }

    /// The divisor of linear light at the centre of pixel `(x, y)`.
    pub fn falloff(&self, x: usize, y: usize) -> f32 {
        let (dx, dy) = (
            x as f32 + 0.5 - self.centre.0,
            y as f32 + 0.5 - self.centre.1,
        );
        let s = 1.0 + self.t2 * (dx * dx + dy * dy) / self.half_diagonal2;
        s * s
    }

    /// The sRGB value `v` (in `[0, 1]`) after a [`falloff`](Self::falloff), which acts on
    /// linear light.
    pub fn darken(v: f32, falloff: f32) -> f32 {
        from_linear(to_linear(v) / falloff)
    }
}

/// Sensor noise as the robustness benchmark adds it: every 8-bit value of `img` plus Gaussian
/// noise of standard deviation `sigma` levels from `rng` (one draw per value, in memory order),
/// rounded and clipped.
pub fn add_noise(img: &mut RgbImage, sigma: f64, rng: &mut impl Rng) {
    for v in img.iter_mut() {
        let z: f64 = StandardNormal.sample(rng);
        let x = f32::from(*v) / 255.0 + (sigma * z) as f32 / 255.0;
        *v = (x * 255.0).round().clamp(0.0, 255.0) as u8;
    }
}

/// `img` through a JPEG encoder at `quality` (1–100) and back.
pub fn jpeg_round_trip(img: &RgbImage, quality: u8) -> Result<RgbImage> {
    let mut bytes = Cursor::new(Vec::new());
    JpegEncoder::new_with_quality(&mut bytes, quality)
        .encode_image(img)
        .context("cannot encode JPEG")?;
    let decoded = image::load_from_memory_with_format(bytes.get_ref(), image::ImageFormat::Jpeg)
        .context("cannot decode JPEG")?;
    Ok(decoded.to_rgb8())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lightfield::rotate_plane;

    /// The centre keeps its light and the corners lose the share.
    #[test]
    fn the_corners_lose_the_share() {
        let v = Vignette::centred(0.5, (400, 300));
        assert!((v.falloff(200, 150) - 1.0).abs() < 1e-4);
        for (x, y) in [(0, 0), (399, 0), (0, 299), (399, 299)] {
            assert!((1.0 / v.falloff(x, y) - 0.5).abs() < 0.01, "{x} {y}");
        }
    }

    /// A crop (every other pixel, from a corner) and its rotations see the falloff the whole
    /// image has at the pixels they took.
    #[test]
    fn a_crop_and_its_turns_see_the_image_s_falloff() {
        let (w, h) = (37, 29);
        let whole = Vignette::centred(0.6, (w, h));
        let image: Vec<f32> = (0..w * h).map(|i| whole.falloff(i % w, i / w)).collect();
        let (corner, step, side) = ((3isize, 2isize), 2usize, 12usize);
        let crop = crate::lightfield::crop_plane(&image, w, h, 1, corner, (side, side), step);
        let mut turned = crop.clone();
        for turns in 0..4 {
            let lens = whole.in_crop(corner, step).rotated(side, turns);
            for (i, want) in turned.iter().enumerate() {
                let got = lens.falloff(i % side, i / side);
                assert!((got - want).abs() < 1e-4, "turns {turns}, pixel {i}");
            }
            turned = rotate_plane(&turned, side, side, 1);
        }
    }

    /// JPEG at quality 30 loses more of a textured image than at 75, and both stay close.
    #[test]
    fn jpeg_loses_more_at_lower_quality() {
        let clean = RgbImage::from_fn(64, 64, |x, y| {
            image::Rgb([
                ((x * 37 + y * 11) % 256) as u8,
                (x * 4) as u8,
                (y * 4) as u8,
            ])
        });
        let error = |q| {
            let img = jpeg_round_trip(&clean, q).unwrap();
            let sq: f64 = (img.iter().zip(clean.iter()))
                .map(|(&a, &b)| (a as f64 - b as f64).powi(2))
                .sum();
            (sq / img.len() as f64).sqrt()
        };
        let (e75, e30) = (error(75), error(30));
        assert!(0.5 < e75 && e75 < e30 && e30 < 60.0, "{e75} {e30}");
    }
}
