//! Appearance statistics of a view as written (8-bit): how much local contrast it has, how
//! much of it is flat, how bright and how noisy it is. Real and benchmark light fields are
//! largely dim, low-contrast areas; these figures in `stats.json` and the dataset README show
//! how far a dataset's views are from that.
//!
//! Every figure is on the 8-bit luminance `L = 0.2126 R + 0.7152 G + 0.0722 B` of the sRGB
//! codes (0–255):
//! - the residual of a 3×3 mean filter, `r = L − mean₃ₓ₃(L)`, on the pixels whose 3×3
//!   neighbourhood is inside the image;
//! - `local_contrast`: the median of `|r|`;
//! - `flat_share`: the share of the whole 16×16 blocks of that residual image whose residual
//!   has a standard deviation below [`FLAT_STD`] levels;
//! - `mean_luminance`: the mean of `L`;
//! - `noise`: Immerkær's estimate of the standard deviation of white noise (J. Immerkær,
//!   "Fast noise variance estimation", CVIU 64(2), 1996): `√(π/2) / (6 (W−2)(H−2)) · Σ |L ∗ N|`
//!   with the mask `N = [1 −2 1; −2 4 −2; 1 −2 1]`, which cancels smooth structure.

use serde::{Deserialize, Serialize};

/// Residual standard deviation (levels) below which a block counts as flat.
pub const FLAT_STD: f64 = 1.5;
/// Side of the blocks judged flat or not.
pub const BLOCK: usize = 16;

/// The appearance figures of one image.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageStats {
    /// Median |residual of a 3×3 mean filter| (8-bit levels).
    pub local_contrast: f64,
    /// Share of 16×16 blocks whose residual's standard deviation is below 1.5 levels.
    pub flat_share: f64,
    /// Mean 8-bit luminance.
    pub mean_luminance: f64,
    /// Estimated standard deviation of white noise (8-bit levels).
    pub noise: f64,
}

impl ImageStats {
    /// The figures of an 8-bit RGB image (`rgb`: three codes per pixel, row by row), or
    /// `None` for an image smaller than 3×3.
    pub fn of_rgb8(rgb: &[u8], width: usize, height: usize) -> Option<Self> {
        assert_eq!(rgb.len(), width * height * 3, "three codes per pixel");
        let lum: Vec<f64> = (rgb.chunks_exact(3))
            .map(|c| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64)
            .collect();
        Self::of_luminance(&lum, width, height)
    }

    /// The figures of a luminance image (8-bit levels, row by row).
    pub fn of_luminance(lum: &[f64], width: usize, height: usize) -> Option<Self> {
        if width < 3 || height < 3 {
            return None;
        }
        let at = |x: usize, y: usize| lum[y * width + x];
        let (w, h) = (width - 2, height - 2);
        let mut residual = Vec::with_capacity(w * h);
        let mut laplace = 0.0;
        for y in 1..height - 1 {
            for x in 1..width - 1 {
                let ring = [
                    (0, 0),
                    (1, 0),
                    (2, 0),
                    (0, 1),
                    (2, 1),
                    (0, 2),
                    (1, 2),
                    (2, 2),
                ];
                let sum: f64 = ring
                    .iter()
                    .map(|&(dx, dy)| at(x + dx - 1, y + dy - 1))
                    .sum();
                residual.push(at(x, y) - (sum + at(x, y)) / 9.0);
                let corners =
                    at(x - 1, y - 1) + at(x + 1, y - 1) + at(x - 1, y + 1) + at(x + 1, y + 1);
                let edges = at(x, y - 1) + at(x - 1, y) + at(x + 1, y) + at(x, y + 1);
                laplace += (corners - 2.0 * edges + 4.0 * at(x, y)).abs();
            }
        }
        let mut magnitudes: Vec<f64> = residual.iter().map(|r| r.abs()).collect();
        Some(Self {
            local_contrast: median(&mut magnitudes),
            flat_share: flat_share(&residual, w, h),
            mean_luminance: lum.iter().sum::<f64>() / lum.len() as f64,
            noise: (std::f64::consts::FRAC_PI_2).sqrt() * laplace / (6.0 * (w * h) as f64),
        })
    }
}

/// Share of the whole [`BLOCK`]² blocks of `residual` (`w × h`) with a standard deviation
/// below [`FLAT_STD`]; 0 when not one block fits.
fn flat_share(residual: &[f64], w: usize, h: usize) -> f64 {
    let (bx, by) = (w / BLOCK, h / BLOCK);
    if bx * by == 0 {
        return 0.0;
    }
    let n = (BLOCK * BLOCK) as f64;
    let mut flat = 0;
    for j in 0..by {
        for i in 0..bx {
            let rows = (0..BLOCK).map(|y| (j * BLOCK + y) * w + i * BLOCK);
            let values: Vec<f64> = rows
                .flat_map(|r| residual[r..r + BLOCK].iter().copied())
                .collect();
            let mean = values.iter().sum::<f64>() / n;
            let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
            flat += (var.sqrt() < FLAT_STD) as usize;
        }
    }
    flat as f64 / (bx * by) as f64
}

/// The median of `v` (mean of the two middle values for an even count), reordering `v`.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    (v[(n - 1) / 2] + v[n / 2]) / 2.0
}

/// `[min, q25, median, q75, max]` of `values` (linear interpolation between order
/// statistics); zeros when there are none.
pub fn quantiles(values: &[f64]) -> [f64; 5] {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return [0.0; 5];
    }
    [0.0, 0.25, 0.5, 0.75, 1.0].map(|q| {
        let t = q * (v.len() - 1) as f64;
        let (i, f) = (t.floor() as usize, t.fract());
        v[i] + (v[(i + 1).min(v.len() - 1)] - v[i]) * f
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_image_has_no_contrast_no_noise_and_only_flat_blocks() {
        let s = ImageStats::of_luminance(&vec![100.0; 34 * 34], 34, 34).unwrap();
        assert_eq!((s.local_contrast, s.noise), (0.0, 0.0));
        assert_eq!((s.flat_share, s.mean_luminance), (1.0, 100.0));
    }

    /// A checkerboard of ±a around m: every interior pixel's 3×3 mean is m ± a/9 (five of
    /// one sign, four of the other), so |r| = 8a/9 everywhere; no block is flat when
    /// 8a/9 ≥ 1.5.
    #[test]
    fn a_checkerboard_has_the_analytic_residual() {
        let (w, a) = (34, 9.0);
        let lum: Vec<f64> = (0..w * w)
            .map(|i| {
                if (i % w + i / w) % 2 == 0 {
                    100.0 + a
                } else {
                    100.0 - a
                }
            })
            .collect();
        let s = ImageStats::of_luminance(&lum, w, w).unwrap();
        assert!((s.local_contrast - 8.0 * a / 9.0).abs() < 1e-9, "{s:?}");
        assert_eq!(s.flat_share, 0.0);
        // The mask's response to a checkerboard is 16a at every pixel.
        let expected = std::f64::consts::FRAC_PI_2.sqrt() * 16.0 * a / 6.0;
        assert!((s.noise - expected).abs() < 1e-9, "{s:?}");
    }

    /// Left half a checkerboard, right half flat: half the blocks are flat (those on the
    /// right; the seam's small residual keeps its block's deviation far below 1.5).
    #[test]
    fn half_textured_half_flat_gives_half_the_blocks_flat() {
        let (w, h) = (66, 34);
        let lum: Vec<f64> = (0..w * h)
            .map(|i| match (i % w, i / w) {
                (x, _) if x >= 33 => 50.0,
                (x, y) if (x + y) % 2 == 0 => 60.0,
                _ => 40.0,
            })
            .collect();
        let s = ImageStats::of_luminance(&lum, w, h).unwrap();
        // 64 × 32 residual pixels: 4 × 2 blocks, the right two columns of blocks flat.
        assert_eq!(s.flat_share, 0.5);
        assert!(s.mean_luminance > 49.0 && s.mean_luminance < 51.0);
    }

    #[test]
    fn rgb_codes_are_weighted_to_luminance_and_tiny_images_are_refused() {
        let rgb: Vec<u8> = [10u8, 200, 30].repeat(9);
        let s = ImageStats::of_rgb8(&rgb, 3, 3).unwrap();
        let l = 0.2126 * 10.0 + 0.7152 * 200.0 + 0.0722 * 30.0;
        assert!((s.mean_luminance - l).abs() < 1e-9);
        assert_eq!(ImageStats::of_rgb8(&[0; 6], 2, 1), None);
    }

    #[test]
    fn quantiles_interpolate_between_order_statistics() {
        assert_eq!(
            quantiles(&[4.0, 0.0, 2.0, 1.0, 3.0]),
            [0.0, 1.0, 2.0, 3.0, 4.0]
        );
        assert_eq!(quantiles(&[1.0, 3.0]), [1.0, 1.5, 2.0, 2.5, 3.0]);
        assert_eq!(quantiles(&[]), [0.0; 5]);
    }
}
