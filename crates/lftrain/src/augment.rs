//! Photometric augmentations of the thesis (§5.3.1): a rotation of the colours in RGB space and
//! random brightness and contrast. The geometric ones (EPI shift, 90° rotation) live with the
//! geometry in [`crate::stacks`] and [`crate::lightfield`].

use rand::{Rng, RngExt};

use crate::config::AugmentConfig;

/// One draw of the photometric augmentation, applied identically to every view of a sample
/// (the views of one light field must stay photo-consistent).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photometric {
    /// Row-major 3×3 colour matrix.
    pub matrix: [[f32; 3]; 3],
    /// Contrast factor about mid-grey.
    pub contrast: f32,
    /// Brightness offset.
    pub brightness: f32,
}

impl Photometric {
    /// The identity (no augmentation).
    pub const IDENTITY: Photometric = Photometric {
        matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        contrast: 1.0,
        brightness: 0.0,
    };

    /// A random draw under `cfg`.
    ///
    /// The colour rotation turns RGB about the grey axis `(1, 1, 1)/√3` by a uniform angle: it
    /// changes hues but keeps grey levels (and thus the luminance structure that carries the
    /// disparity cues) and never leaves the colour cube by much.
    pub fn random(cfg: &AugmentConfig, rng: &mut impl Rng) -> Self {
        let matrix = if cfg.colour_rotation {
            grey_axis_rotation(rng.random_range(0.0..std::f32::consts::TAU))
        } else {
            Self::IDENTITY.matrix
        };
        Self {
            matrix,
            contrast: 1.0 + cfg.contrast * rng.random_range(-1.0f32..=1.0),
            brightness: cfg.brightness * rng.random_range(-1.0f32..=1.0),
        }
    }

    /// Applies the draw to `views` stacked as planes `[k][R, G, B][pixels]`.
    pub fn apply(&self, views: &mut [f32], plane: usize) {
        for rgb in views.chunks_exact_mut(3 * plane) {
            let (r, rest) = rgb.split_at_mut(plane);
            let (g, b) = rest.split_at_mut(plane);
            for i in 0..plane {
                let c = [r[i], g[i], b[i]];
                let m = &self.matrix;
                let out = |row: usize| {
                    let v = m[row][0] * c[0] + m[row][1] * c[1] + m[row][2] * c[2];
                    (v - 0.5) * self.contrast + 0.5 + self.brightness
                };
                (r[i], g[i], b[i]) = (out(0), out(1), out(2));
            }
        }
    }
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
        p.apply(&mut v, 1);
        let want = [0.1, 0.6, 1.1];
        assert!(v.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-6));
    }
}
