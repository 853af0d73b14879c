//! Photometric augmentations of the thesis (§5.3.1): a rotation of the colours in RGB space and
//! random brightness and contrast; and, not in the thesis, the degradations of a real camera
//! ([`Degrade`]: blur, vignetting, sensor noise and JPEG), so that a net trained on clean
//! rendered views keeps working on noisy captured ones. The geometric augmentations (EPI
//! shift, 90° rotation, down-scaling) live with the geometry in [`lfdata::stacks`] and
//! [`lfdata::lightfield`].

use image::RgbImage;
use lfdata::camera::{Vignette, jpeg_round_trip};
use rand::{Rng, RngExt};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg32;

use crate::config::{AugmentConfig, ColourAugment};

/// One draw of the photometric augmentation, applied identically to every view of a sample
/// (the views of one light field must stay photo-consistent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photometric {
    /// Row-major 3×3 colour matrix.
    pub matrix: [[f32; 3]; 3],
    /// Brightness factor.
    pub gain: f32,
    /// Contrast factor about the sample's mean grey (after matrix and gain).
    pub stretch: f32,
    /// Contrast factor about mid-grey (the earlier augmentation).
    pub contrast: f32,
    /// Brightness offset (the earlier augmentation).
    pub brightness: f32,
}

impl Photometric {
    /// The identity (no augmentation).
    pub const IDENTITY: Photometric = Photometric {
        matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        gain: 1.0,
        stretch: 1.0,
        contrast: 1.0,
        brightness: 0.0,
    };

    /// A random draw under `cfg`.
    pub fn random(cfg: &AugmentConfig, rng: &mut impl Rng) -> Self {
        let matrix = match cfg.colour {
            ColourAugment::Redistribute => redistribution(rng),
            ColourAugment::Rotate => {
                grey_axis_rotation(rng.random_range(0.0..std::f32::consts::TAU))
            }
            ColourAugment::Off => Self::IDENTITY.matrix,
        };
        let (gain, stretch) = (
            within(rng, cfg.brightness_scale),
            within(rng, cfg.contrast_scale),
        );
        Self {
            matrix,
            gain,
            stretch,
            contrast: 1.0 + cfg.contrast * rng.random_range(-1.0f32..=1.0),
            brightness: cfg.brightness * rng.random_range(-1.0f32..=1.0),
        }
    }

    /// The mean grey the contrast stretches about: the mean of `centre` (RGB interleaved, the
    /// sample's centre view) after the matrix and the gain. The same value for every view.
    pub fn pivot(&self, centre: &[f32]) -> f32 {
        let n = (centre.len() / 3).max(1) as f32;
        let mut mean = [0.0f32; 3];
        for px in centre.chunks_exact(3) {
            (0..3).for_each(|c| mean[c] += px[c] / n);
        }
        let mixed: f32 = self
            .matrix
            .iter()
            .map(|row| row[0] * mean[0] + row[1] * mean[1] + row[2] * mean[2])
            .sum();
        mixed / 3.0 * self.gain
    }

    /// Applies the draw to `views` stacked as planes `[k][R, G, B][pixels]`, stretching the
    /// contrast about `pivot` ([`Photometric::pivot`]).
    pub fn apply(&self, views: &mut [f32], plane: usize, pivot: f32) {
        for rgb in views.chunks_exact_mut(3 * plane) {
            let (r, rest) = rgb.split_at_mut(plane);
            let (g, b) = rest.split_at_mut(plane);
            for i in 0..plane {
                let c = [r[i], g[i], b[i]];
                let m = &self.matrix;
                let out = |row: usize| {
                    let v = (m[row][0] * c[0] + m[row][1] * c[1] + m[row][2] * c[2]) * self.gain;
                    let v = (v - pivot) * self.stretch + pivot;
                    (v - 0.5) * self.contrast + 0.5 + self.brightness
                };
                (r[i], g[i], b[i]) = (out(0), out(1), out(2));
            }
        }
    }
}

/// One draw of the camera degradations, the same for every view of a sample (one lens, one
/// sensor), with noise drawn independently per view, pixel and channel from `seed`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Degrade {
    /// Standard deviation of the noise at mid-grey, in units of the `[0, 1]` pixel range.
    pub noise: f32,
    /// Share of the noise variance at mid-grey that grows with the value (shot noise): the
    /// variance at value `v` is `noise² · (1 − shot + shot · v / 0.5)`.
    pub shot: f32,
    /// Gaussian blur σ, pixels (0: none).
    pub blur: f32,
    /// Share of light lost at the scene's corners (0: none).
    pub vignetting: f32,
    /// JPEG quality (0: not compressed).
    pub jpeg: u8,
    /// Seeds the noise streams (one per view).
    pub seed: u64,
}

impl Degrade {
    /// No degradation.
    pub const NONE: Degrade = Degrade {
        noise: 0.0,
        shot: 0.0,
        blur: 0.0,
        vignetting: 0.0,
        jpeg: 0,
        seed: 0,
    };

    /// A random draw under `cfg`; draws nothing from `rng` when every degradation is off, and
    /// draws the later ones only when they are on, so configurations without them train
    /// exactly as before they existed.
    pub fn random(cfg: &AugmentConfig, rng: &mut impl Rng) -> Self {
        let camera = cfg.vignetting[1] > 0.0 || cfg.jpeg_share > 0.0;
        if cfg.noise[1] <= 0.0 && cfg.blur[1] <= 0.0 && !camera {
            return Self::NONE;
        }
        let (noise, blur) = (within(rng, cfg.noise), within(rng, cfg.blur));
        let mut draw = Self {
            noise,
            shot: cfg.noise_shot,
            blur,
            seed: rng.random(),
            ..Self::NONE
        };
        if camera {
            draw.vignetting = within(rng, cfg.vignetting);
            let [lo, hi] = cfg.jpeg_quality;
            if rng.random_range(0.0f32..1.0) < cfg.jpeg_share {
                draw.jpeg = rng.random_range(lo..=hi);
            }
        }
        draw
    }

    /// [`Degrade::apply`] to every view present of a light field's `views` (RGB interleaved,
    /// `width` pixels a row), each with its index as its noise stream; `lens` places the
    /// vignetting's falloff on the crop.
    pub fn apply_all(&self, views: &mut [Option<Vec<f32>>], width: usize, lens: Vignette) {
        let lens = (self.vignetting > 0.0).then_some(lens);
        for (index, view) in views.iter_mut().enumerate() {
            if let Some(rgb) = view {
                self.apply(rgb, width, index, lens.as_ref());
            }
        }
    }

    /// Blurs, vignettes, adds noise to and compresses view number `index` of a sample: `rgb`
    /// interleaved sRGB values, `width` pixels a row; in a camera's order (lens, sensor,
    /// encoder).
    pub fn apply(&self, rgb: &mut [f32], width: usize, index: usize, lens: Option<&Vignette>) {
        if self.blur > 0.0 {
            gaussian_blur(rgb, width, self.blur);
        }
        if let Some(lens) = lens {
            vignette(rgb, width, lens);
        }
        if self.noise > 0.0 {
            let mut rng = Pcg32::new(self.seed, index as u64);
            let (constant, per_value) = (1.0 - self.shot, self.shot / 0.5);
            for v in rgb.iter_mut() {
                let variance = constant + per_value * v.max(0.0);
                let z: f32 = StandardNormal.sample(&mut rng);
                *v += self.noise * variance.sqrt() * z;
            }
        }
        if self.jpeg > 0 {
            jpeg(rgb, width, self.jpeg);
        }
    }
}

/// A uniform draw from `[lo, hi]`; `lo` without drawing when the range is empty.
fn within(rng: &mut impl Rng, [lo, hi]: [f32; 2]) -> f32 {
    if lo < hi {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// Divides the linear light of `rgb` (sRGB values, `width` pixels a row) by `lens`' falloff.
fn vignette(rgb: &mut [f32], width: usize, lens: &Vignette) {
    for (i, px) in rgb.chunks_exact_mut(3).enumerate() {
        let falloff = lens.falloff(i % width, i / width);
        px.iter_mut()
            .for_each(|v| *v = Vignette::darken(*v, falloff));
    }
}

/// `rgb` (sRGB values in `[0, 1]`, `width` pixels a row) as 8-bit pixels through a JPEG
/// encoder at `quality` and back.
fn jpeg(rgb: &mut [f32], width: usize, quality: u8) {
    let height = rgb.len() / (3 * width);
    let bytes = rgb
        .iter()
        .map(|v| (v * 255.0).round().clamp(0.0, 255.0) as u8);
    let img = RgbImage::from_raw(width as u32, height as u32, bytes.collect())
        .expect("a view holds width × height RGB pixels");
    let out = jpeg_round_trip(&img, quality).expect("an in-memory RGB image encodes as JPEG");
    rgb.iter_mut()
        .zip(out.as_raw())
        .for_each(|(v, &b)| *v = b as f32 / 255.0);
}

/// Separable Gaussian blur of standard deviation `sigma` pixels over an RGB-interleaved image
/// `width` pixels wide, the kernel cut at 3σ and edge pixels repeated.
pub fn gaussian_blur(rgb: &mut [f32], width: usize, sigma: f32) {
    let height = rgb.len() / (3 * width.max(1));
    let radius = (3.0 * sigma).ceil() as isize;
    let weights: Vec<f32> = (-radius..=radius)
        .map(|d| (-0.5 * (d as f32 / sigma).powi(2)).exp())
        .collect();
    let total: f32 = weights.iter().sum();
    let kernel: Vec<f32> = weights.iter().map(|w| w / total).collect();
    let pass = |src: &[f32], step: (isize, isize)| -> Vec<f32> {
        let mut out = vec![0.0; src.len()];
        for y in 0..height as isize {
            for x in 0..width as isize {
                let i = 3 * (y as usize * width + x as usize);
                for (k, w) in kernel.iter().enumerate() {
                    let d = k as isize - radius;
                    let sx = (x + d * step.0).clamp(0, width as isize - 1) as usize;
                    let sy = (y + d * step.1).clamp(0, height as isize - 1) as usize;
                    let j = 3 * (sy * width + sx);
                    (0..3).for_each(|c| out[i + c] += w * src[j + c]);
                }
            }
        }
        out
    };
    let rows = pass(rgb, (1, 0));
    rgb.copy_from_slice(&pass(&rows, (0, 1)));
}

/// A random colour mix whose rows and columns each sum to 1 and whose entries are ≥ 0: a
/// random convex combination of the six 3×3 permutation matrices (every such matrix is one,
/// Birkhoff–von Neumann). Grey stays grey, and the mean colour of an image is preserved in
/// sum.
pub fn redistribution(rng: &mut impl Rng) -> [[f32; 3]; 3] {
    const PERMUTATIONS: [[usize; 3]; 6] = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let weights: [f32; 6] = std::array::from_fn(|_| rng.random_range(0.0f32..1.0));
    let total: f32 = weights.iter().sum::<f32>().max(f32::MIN_POSITIVE);
    let mut m = [[0.0f32; 3]; 3];
    for (p, w) in PERMUTATIONS.iter().zip(weights) {
        for (row, &col) in p.iter().enumerate() {
            m[row][col] += w / total;
        }
    }
    m
}

/// Rotation by `angle` about the unit grey axis (Rodrigues' formula).
pub fn grey_axis_rotation(angle: f32) -> [[f32; 3]; 3] {
    let k = 1.0 / 3f32.sqrt();
    let (s, c) = angle.sin_cos();
    let t = 1.0 - c;
    let diag = c + t * k * k;
    let (a, b) = (t * k * k - s * k, t * k * k + s * k);
    [[diag, a, b], [b, diag, a], [a, b, diag]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_axis_rotation_keeps_grey_and_norms() {
        let m = grey_axis_rotation(1.2);
        for row in m {
            assert!(
                (row.iter().sum::<f32>() - 1.0).abs() < 1e-6,
                "grey is fixed"
            );
            assert!((row.iter().map(|v| v * v).sum::<f32>() - 1.0).abs() < 1e-6);
        }
        let third = grey_axis_rotation(std::f32::consts::TAU / 3.0);
        // A third of a turn permutes the channels: R → G → B.
        assert!((third[1][0] - 1.0).abs() < 1e-5 && (third[0][2] - 1.0).abs() < 1e-5);
    }

    #[test]
    fn brightness_and_contrast() {
        let p = Photometric {
            contrast: 2.0,
            brightness: 0.1,
            ..Photometric::IDENTITY
        };
        let mut v = vec![0.25, 0.5, 0.75];
        p.apply(&mut v, 1, 0.5);
        let want = [0.1, 0.6, 1.1];
        assert!(v.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6));
    }

    #[test]
    fn gain_then_stretch_about_the_mean_grey() {
        // One pixel, R, G, B = 0.2, 0.4, 0.6; gain 1.5 gives 0.3, 0.6, 0.9.
        let p = Photometric {
            gain: 1.5,
            stretch: 0.5,
            ..Photometric::IDENTITY
        };
        let centre = [0.2, 0.4, 0.6, 0.4, 0.4, 0.4];
        // Mean grey of the centre view (0.4) times the gain: 0.6.
        let pivot = p.pivot(&centre);
        assert!((pivot - 0.6).abs() < 1e-6);
        let mut v = vec![0.2, 0.4, 0.6];
        p.apply(&mut v, 1, pivot);
        // (0.3 − 0.6)·0.5 + 0.6 = 0.45; (0.6 − 0.6)·0.5 + 0.6 = 0.6; (0.9 − 0.6)·0.5 + 0.6 = 0.75.
        let want = [0.45, 0.6, 0.75];
        assert!(
            v.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6),
            "{v:?}"
        );
    }

    /// A flat patch gets noise of the drawn σ at mid-grey, a variance growing with the value by
    /// the shot share, independent streams per view, and the same values for the same seed.
    #[test]
    fn noise_has_the_drawn_statistics() {
        let d = Degrade {
            noise: 0.02,
            shot: 0.5,
            ..Degrade::NONE
        };
        let stats = |value: f32, index: usize| {
            let mut v = vec![value; 3 * 128 * 128];
            d.apply(&mut v, 128, index, None);
            let n = v.len() as f64;
            let mean = v.iter().map(|&x| x as f64).sum::<f64>() / n;
            let var = v.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / n;
            (mean, var, v)
        };
        let n = (3 * 128 * 128) as f64;
        // At 0.1 the variance is σ² · (0.5 + 0.5 · 0.1 / 0.5) = 0.6 σ².
        for (value, want) in [(0.5, 0.02f64 * 0.02), (0.1, 0.02f64 * 0.02 * 0.6)] {
            let (mean, var, _) = stats(value, 0);
            assert!(
                (mean - value as f64).abs() < 5.0 * (want / n).sqrt(),
                "{mean}"
            );
            assert!(
                (var / want - 1.0).abs() < 5.0 * (2.0 / n).sqrt(),
                "{var} vs {want}"
            );
        }
        assert_eq!(stats(0.5, 3).2, stats(0.5, 3).2);
        assert_ne!(stats(0.5, 3).2, stats(0.5, 4).2);
    }

    /// Blurring keeps a flat image and the sum, and a single bright pixel spreads into the
    /// sampled Gaussian: its centre row holds the `exp(-d²/2σ²)` ratios.
    #[test]
    fn blur_spreads_a_point_as_a_gaussian() {
        let w = 21;
        let mut flat = vec![0.3f32; 3 * w * w];
        gaussian_blur(&mut flat, w, 1.5);
        assert!(flat.iter().all(|v| (v - 0.3).abs() < 1e-6));
        let mut point = vec![0.0f32; 3 * w * w];
        point[3 * (10 * w + 10)] = 1.0;
        gaussian_blur(&mut point, w, 1.5);
        let sum: f32 = point.iter().sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        let at = |x: usize| point[3 * (10 * w + x)];
        for d in 1..4 {
            let ratio = at(10 + d) / at(10);
            let want = (-((d * d) as f32) / (2.0 * 1.5 * 1.5)).exp();
            assert!((ratio - want).abs() < 1e-5, "{d}: {ratio} vs {want}");
            assert_eq!(at(10 + d), at(10 - d));
        }
        assert_eq!(point[3 * (10 * w + 10) + 1], 0.0, "channels stay apart");
    }

    /// Draws stay in their ranges; with both degradations off nothing is drawn from the stream.
    #[test]
    fn degrade_draws() {
        let cfg = AugmentConfig {
            noise: [0.0, 0.04],
            blur: [0.0, 1.0],
            ..AugmentConfig::default()
        };
        let mut rng = rand_pcg::Pcg32::new(1, 2);
        for _ in 0..100 {
            let d = Degrade::random(&cfg, &mut rng);
            assert!((0.0..=0.04).contains(&d.noise) && (0.0..=1.0).contains(&d.blur));
        }
        let (mut a, mut b) = (rand_pcg::Pcg32::new(1, 2), rand_pcg::Pcg32::new(1, 2));
        assert_eq!(
            Degrade::random(&AugmentConfig::default(), &mut a),
            Degrade::NONE
        );
        assert_eq!(a.random::<u64>(), b.random::<u64>());
        let camera = AugmentConfig {
            vignetting: [0.2, 0.6],
            jpeg_share: 0.5,
            jpeg_quality: [30, 60],
            ..AugmentConfig::default()
        };
        let draws: Vec<Degrade> = (0..400)
            .map(|_| Degrade::random(&camera, &mut rng))
            .collect();
        assert!(draws.iter().all(|d| (0.2..=0.6).contains(&d.vignetting)));
        assert!(
            draws
                .iter()
                .all(|d| d.jpeg == 0 || (30..=60).contains(&d.jpeg))
        );
        let compressed = draws.iter().filter(|d| d.jpeg > 0).count();
        assert!((160..240).contains(&compressed), "{compressed} of 400");
    }

    /// Vignetting takes the drawn share of linear light at the scene's corners and none at
    /// its centre, the same in every view; JPEG gives the benchmark's 8-bit round trip.
    #[test]
    fn vignetting_and_jpeg_are_the_benchmark_s() {
        let (w, h) = (40, 30);
        let d = Degrade {
            vignetting: 0.5,
            ..Degrade::NONE
        };
        let mut views = vec![Some(vec![1.0f32; 3 * w * h]); 3];
        d.apply_all(&mut views, w, Vignette::centred(0.5, (w, h)));
        let linear = |v: &[f32], x: usize, y: usize| lfformat::srgb::to_linear(v[3 * (y * w + x)]);
        for view in views.iter().flatten() {
            assert_eq!(view, views[0].as_ref().unwrap());
            assert!((linear(view, 0, 0) - 0.5).abs() < 0.02);
            assert!((linear(view, w - 1, h - 1) - 0.5).abs() < 0.02);
            assert!(linear(view, w / 2, h / 2) > 0.99);
        }
        let texture: Vec<u8> = (0..3 * w * h).map(|i| ((i * 37) % 251) as u8).collect();
        let mut rgb: Vec<f32> = texture.iter().map(|&b| b as f32 / 255.0).collect();
        let d = Degrade {
            jpeg: 30,
            ..Degrade::NONE
        };
        d.apply(&mut rgb, w, 0, None);
        let img = RgbImage::from_raw(w as u32, h as u32, texture).unwrap();
        let want = jpeg_round_trip(&img, 30).unwrap();
        let got: Vec<u8> = rgb.iter().map(|v| (v * 255.0).round() as u8).collect();
        assert_eq!(&got, want.as_raw());
        assert_ne!(&got, img.as_raw());
    }

    #[test]
    fn redistributions_have_rows_and_columns_summing_to_one() {
        let mut rng = rand_pcg::Pcg32::new(3, 4);
        let mut off_diagonal = 0.0f32;
        for _ in 0..100 {
            let m = redistribution(&mut rng);
            for i in 0..3 {
                let row: f32 = m[i].iter().sum();
                let col: f32 = (0..3).map(|r| m[r][i]).sum();
                assert!(
                    (row - 1.0).abs() < 1e-5 && (col - 1.0).abs() < 1e-5,
                    "{m:?}"
                );
                assert!(m[i].iter().all(|&v| v >= 0.0));
            }
            off_diagonal += m[0][1] + m[1][2] + m[2][0];
        }
        // Colours really move (a permutation-free draw would keep the identity).
        assert!(off_diagonal / 100.0 > 0.2, "{off_diagonal}");
    }
}
