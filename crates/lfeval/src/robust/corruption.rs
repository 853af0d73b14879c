//! The corruptions of the robustness benchmark, applied to a view's 8-bit sRGB pixels: what a
//! real light field has and a clean rendered one lacks (sensor noise, low contrast, under-
//! exposure, vignetting, compression), each at fixed levels.

use anyhow::Result;
use image::RgbImage;
use lfdata::camera::{Vignette, add_noise, jpeg_round_trip};
use rand::Rng;
use serde::Serialize;

/// What a corruption does to a view.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "lowercase", tag = "kind", content = "level")]
pub enum Corruption {
    /// The views as they are.
    Clean,
    /// Gaussian noise of this σ in 8-bit levels, independent per view, pixel and channel,
    /// rounded and clipped to 0–255.
    Noise(f64),
    /// Contrast scaled by this factor about the scene's mean grey (the mean of its centre
    /// view, so every view keeps the same mapping and the light field stays consistent).
    Contrast(f64),
    /// Exposure changed by this many stops, in linear light (sRGB decoded, scaled, encoded).
    Exposure(f64),
    /// This share of light lost at the image corners, in linear light, by the cos⁴ law
    /// `(1 + t² ρ²)^-2`, `t² = (1 − f)^-1/2 − 1`, ρ the distance from the centre over the
    /// half-diagonal.
    Vignetting(f64),
    /// JPEG compression at this quality (1–100), decoded back to pixels.
    Jpeg(u8),
}

/// The benchmark's corruptions, in the order of its table.
pub const BENCHMARK: [Corruption; 12] = [
    Corruption::Clean,
    Corruption::Noise(1.0),
    Corruption::Noise(2.0),
    Corruption::Noise(5.0),
    Corruption::Noise(10.0),
    Corruption::Contrast(0.5),
    Corruption::Contrast(0.25),
    Corruption::Exposure(-1.0),
    Corruption::Exposure(-2.0),
    Corruption::Vignetting(0.5),
    Corruption::Jpeg(75),
    Corruption::Jpeg(30),
];

impl Corruption {
    /// The folder name of the corrupted copy (`noise_2`, `contrast_0.5`, `jpeg_30`, …).
    pub fn name(&self) -> String {
        match *self {
            Corruption::Clean => "clean".into(),
            Corruption::Noise(s) => format!("noise_{s}"),
            Corruption::Contrast(c) => format!("contrast_{c}"),
            Corruption::Exposure(ev) => format!("exposure_{ev}"),
            Corruption::Vignetting(f) => format!("vignetting_{f}"),
            Corruption::Jpeg(q) => format!("jpeg_{q}"),
        }
    }

    /// The family the plot draws it in, with the label of its strength axis.
    pub fn family(&self) -> (&'static str, &'static str) {
        match self {
            Corruption::Clean => ("clean", ""),
            Corruption::Noise(_) => ("noise", "σ (8-bit levels)"),
            Corruption::Contrast(_) => ("contrast", "contrast reduction (stops)"),
            Corruption::Exposure(_) => ("exposure", "stops under"),
            Corruption::Vignetting(_) => ("vignetting", "corner light lost"),
            Corruption::Jpeg(_) => ("jpeg", "100 − JPEG quality"),
        }
    }

    /// How strong it is on its family's axis; the clean views are 0 on every axis.
    pub fn strength(&self) -> f64 {
        match *self {
            Corruption::Clean => 0.0,
            Corruption::Noise(s) => s,
            Corruption::Contrast(c) => -c.log2(),
            Corruption::Exposure(ev) => -ev,
            Corruption::Vignetting(f) => f,
            Corruption::Jpeg(q) => 100.0 - q as f64,
        }
    }

    /// Corrupts `img` in place; `pivot` is the scene's mean grey in `[0, 1]` (contrast) and
    /// `rng` the view's noise stream.
    pub fn apply(&self, img: &mut RgbImage, pivot: f32, rng: &mut impl Rng) -> Result<()> {
        match *self {
            Corruption::Clean => {}
            Corruption::Noise(sigma) => add_noise(img, sigma, rng),
            Corruption::Contrast(c) => map_values(img, |v| (v - pivot) * c as f32 + pivot),
            Corruption::Exposure(ev) => {
                let gain = 2f32.powf(ev as f32);
                map_values(img, |v| linear_to_srgb(srgb_to_linear(v) * gain));
            }
            Corruption::Vignetting(f) => vignette(img, f as f32),
            Corruption::Jpeg(q) => *img = jpeg_round_trip(img, q)?,
        }
        Ok(())
    }
}

/// Replaces every 8-bit value `v` by `f(v / 255)`, rounded and clipped.
fn map_values(img: &mut RgbImage, mut f: impl FnMut(f32) -> f32) {
    for v in img.iter_mut() {
        *v = (f(*v as f32 / 255.0) * 255.0).round().clamp(0.0, 255.0) as u8;
    }
}

/// The cos⁴ falloff of [`Corruption::Vignetting`], in linear light, centred on the view.
fn vignette(img: &mut RgbImage, lost: f32) {
    let lens = Vignette::centred(lost, (img.width() as usize, img.height() as usize));
    for (x, y, px) in img.enumerate_pixels_mut() {
        let falloff = lens.falloff(x as usize, y as usize);
        for v in px.0.iter_mut() {
            let out = Vignette::darken(*v as f32 / 255.0, falloff);
            *v = (out * 255.0).round().clamp(0.0, 255.0) as u8;
        }
    }
}

use lfformat::srgb::to_linear as srgb_to_linear;

/// sRGB encoding of a linear value, clipped to `[0, 1]`.
fn linear_to_srgb(v: f32) -> f32 {
    lfformat::srgb::from_linear(v.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_pcg::Pcg64;

    fn rng(seed: u64) -> Pcg64 {
        Pcg64::new(seed as u128, 0x0a02_bdbf_7bb3_c0a7_ac28_fa16_a64a_bf96)
    }

    /// A flat mid-grey image: the added noise has the asked σ (within sampling bounds of
    /// 3 · 128² values) and zero mean, and another seed draws other noise.
    #[test]
    fn noise_has_its_sigma() {
        for sigma in [2.0, 10.0] {
            let mut img = RgbImage::from_pixel(128, 128, image::Rgb([128; 3]));
            Corruption::Noise(sigma)
                .apply(&mut img, 0.5, &mut rng(1))
                .unwrap();
            let d: Vec<f64> = img.iter().map(|&v| v as f64 - 128.0).collect();
            let n = d.len() as f64;
            let mean = d.iter().sum::<f64>() / n;
            let sd = (d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            // Rounding adds a variance of 1/12 level².
            let want = (sigma * sigma + 1.0 / 12.0).sqrt();
            assert!((sd / want - 1.0).abs() < 0.03, "σ {sigma}: {sd} vs {want}");
            assert!(mean.abs() < 5.0 * want / n.sqrt(), "{mean}");
        }
        let mut a = RgbImage::from_pixel(8, 8, image::Rgb([128; 3]));
        let mut b = a.clone();
        let mut c = a.clone();
        Corruption::Noise(5.0)
            .apply(&mut a, 0.5, &mut rng(1))
            .unwrap();
        Corruption::Noise(5.0)
            .apply(&mut b, 0.5, &mut rng(1))
            .unwrap();
        Corruption::Noise(5.0)
            .apply(&mut c, 0.5, &mut rng(2))
            .unwrap();
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    /// Contrast halves every distance to the pivot; exposure −1 EV halves linear light.
    #[test]
    fn contrast_and_exposure_scale_what_they_say() {
        let mut img = RgbImage::from_raw(2, 1, vec![0, 50, 100, 150, 200, 255]).unwrap();
        Corruption::Contrast(0.5)
            .apply(&mut img, 0.5, &mut rng(0))
            .unwrap();
        // (v − 127.5)·0.5 + 127.5, rounded.
        assert_eq!(img.into_raw(), vec![64, 89, 114, 139, 164, 191]);
        let mut img = RgbImage::from_pixel(1, 1, image::Rgb([255, 188, 0]));
        Corruption::Exposure(-1.0)
            .apply(&mut img, 0.5, &mut rng(0))
            .unwrap();
        let lin = img
            .get_pixel(0, 0)
            .0
            .map(|v| srgb_to_linear(v as f32 / 255.0));
        // White → linear 0.5 (sRGB 188); 188 (linear 0.503) → 0.251; black stays.
        assert!(
            (lin[0] - 0.5).abs() < 0.004 && (lin[1] - 0.2515).abs() < 0.003,
            "{lin:?}"
        );
        assert_eq!(img.get_pixel(0, 0).0[2], 0);
    }

    /// Vignetting keeps the centre and takes the asked share of linear light at the corners.
    #[test]
    fn vignetting_darkens_the_corners_by_the_share() {
        let mut img = RgbImage::from_pixel(401, 401, image::Rgb([255; 3]));
        Corruption::Vignetting(0.5)
            .apply(&mut img, 0.5, &mut rng(0))
            .unwrap();
        let lin = |x, y| srgb_to_linear(img.get_pixel(x, y).0[0] as f32 / 255.0);
        assert_eq!(img.get_pixel(200, 200).0, [255; 3]);
        assert!((lin(0, 0) - 0.5).abs() < 0.01, "{}", lin(0, 0));
        assert!((lin(400, 400) - 0.5).abs() < 0.01);
    }

    #[test]
    fn names_and_strengths() {
        let names: Vec<String> = BENCHMARK.iter().map(Corruption::name).collect();
        assert_eq!(names[..3], ["clean", "noise_1", "noise_2"]);
        assert_eq!(
            names[5..8],
            ["contrast_0.5", "contrast_0.25", "exposure_-1"]
        );
        assert_eq!(Corruption::Contrast(0.25).strength(), 2.0);
        assert_eq!(Corruption::Exposure(-2.0).strength(), 2.0);
    }
}
