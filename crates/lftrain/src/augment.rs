//! Photometric augmentations of the thesis (§5.3.1): a rotation of the colours in RGB space and
//! random brightness and contrast. The geometric ones (EPI shift, 90° rotation) live with the
//! geometry in [`lfdata::stacks`] and [`lfdata::lightfield`].

use rand::{Rng, RngExt};

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
        let mut within = |[lo, hi]: [f32; 2]| {
            if lo < hi {
                rng.random_range(lo..=hi)
            } else {
                lo
            }
        };
        let (gain, stretch) = (within(cfg.brightness_scale), within(cfg.contrast_scale));
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
