//! Colour images: linear radiance → 8-bit sRGB PNG, and optionally linear float EXR.

use anyhow::{Context, Result};
use glam::{Mat3, Vec3};
use image::ImageEncoder;
use lfformat::files::write_file;
use lfformat::rgb_exr::write_rgb_exr;
use lfformat::srgb::from_linear as linear_to_srgb;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// 8-bit sRGB of linear radiance times `exposure`, clamped (reflectances, texture tiles).
pub fn to_srgb8(pixels: &[Vec3], exposure: f32) -> Vec<u8> {
    ToneCurve::Clip.encode(pixels, exposure)
}

/// How the views' scene-linear radiance becomes the 8-bit sRGB of their PNGs. The linear EXR
/// is never tone mapped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToneCurve {
    /// AgX, Blender's default view transform (base look): a log encoding of 16.5 stops
    /// around middle grey and a sigmoid, so highlights up to 16× diffuse white roll off and
    /// desaturate towards white instead of clipping, and shadows keep their texture.
    #[default]
    Agx,
    /// The sRGB of the value itself, clipped at display white (the curve before AgX).
    Clip,
}

impl ToneCurve {
    /// 8-bit codes of `pixels × exposure`, three per pixel.
    pub fn encode(self, pixels: &[Vec3], exposure: f32) -> Vec<u8> {
        let display = move |c: Vec3| match self {
            ToneCurve::Agx => agx(c),
            ToneCurve::Clip => c,
        };
        pixels
            .iter()
            .flat_map(|&c| display(c * exposure).to_array())
            .map(|v| (linear_to_srgb(v.clamp(0.0, 1.0)) * 255.0).round() as u8)
            .collect()
    }
}

/// AgX of a scene-linear Rec. 709 colour: display-linear Rec. 709 in [0, 1].
///
/// Hand-written because no maintained crate has it (`tonemap` 0.0.4 is from 2020 and has no
/// AgX); this is the widely used closed form of Blender's AgX (B. Wrensch, "Minimal AgX
/// implementation", 2023, after T. Sobotka's AgX): the inset matrix, log2 between −12.47 and
/// +4.03 EV around 0.18, a 6th-order fit of the default contrast sigmoid, the outset matrix,
/// then the display's 2.2 gamma undone (the caller encodes sRGB).
fn agx(c: Vec3) -> Vec3 {
    const MIN_EV: f32 = -12.473_93;
    const MAX_EV: f32 = 4.026_069;
    let inset = Mat3::from_cols(
        Vec3::new(0.842_479_06, 0.042_328_24, 0.042_375_654),
        Vec3::new(0.078_433_6, 0.878_468_6, 0.078_433_6),
        Vec3::new(0.079_223_745, 0.079_166_13, 0.879_143),
    );
    let outset = Mat3::from_cols(
        Vec3::new(1.196_879, -0.052_896_85, -0.052_971_635),
        Vec3::new(-0.098_020_88, 1.151_903_1, -0.098_043_45),
        Vec3::new(-0.099_029_74, -0.098_961_18, 1.151_073_7),
    );
    let log = (inset * c.max(Vec3::splat(1e-10)))
        .to_array()
        .map(|v| (v.log2().clamp(MIN_EV, MAX_EV) - MIN_EV) / (MAX_EV - MIN_EV));
    let sigmoid = |x: f32| {
        let (x2, x4) = (x * x, x * x * x * x);
        15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
            - 0.002_32
    };
    let display = outset * Vec3::from(log.map(sigmoid));
    display.max(Vec3::ZERO).powf(2.2)
}

pub fn write_png(
    path: &Path,
    width: usize,
    height: usize,
    pixels: &[Vec3],
    exposure: f32,
    tone: ToneCurve,
) -> Result<()> {
    let codes = tone.encode(pixels, exposure);
    let buf = image::RgbImage::from_raw(width as u32, height as u32, codes)
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
    Ok(write_rgb_exr(path, width, height, |i| {
        pixels[i].to_array()
    })?)
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
        write_png(&png, w, h, &pixels, 1.0, ToneCurve::Clip).unwrap();
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

    /// Against a float64 evaluation of the same closed form (numpy): middle grey lands in the
    /// middle of the code range, values that clip under `Clip` stay apart below white, white is
    /// reached at +4.03 EV (16.3), and a saturated highlight desaturates towards white.
    #[test]
    fn agx_rolls_highlights_off_instead_of_clipping() {
        let codes = |v: [f32; 3]| ToneCurve::Agx.encode(&[Vec3::from(v)], 1.0);
        let cases = [
            ([0.0; 3], [0; 3]),
            ([0.01; 3], [18; 3]),
            ([0.18; 3], [128; 3]),
            ([1.0; 3], [202; 3]),
            ([2.0; 3], [224; 3]),
            ([4.0; 3], [239; 3]),
            ([16.3; 3], [255; 3]),
            ([8.0, 0.0, 0.0], [255, 152, 152]),
        ];
        for (linear, want) in cases {
            let got = codes(linear);
            let near = got
                .iter()
                .zip(want)
                .all(|(&g, w)| (g as i32 - w).abs() <= 1);
            assert!(near, "{linear:?} → {got:?}, want {want:?}");
        }
        assert_eq!(ToneCurve::Clip.encode(&[Vec3::splat(2.0)], 1.0), [255; 3]);
    }

    #[test]
    fn srgb_matches_reference_values() {
        assert_eq!(to_srgb8(&[Vec3::new(0.0, 1.0, 0.18)], 1.0), [0, 255, 118]);
        assert_eq!(to_srgb8(&[Vec3::splat(0.5)], 2.0), [255, 255, 255]);
    }
}
