//! Procedural seamless textures: the [`generators`] that rooms and objects draw from, evaluated
//! into tiles. (`lfgen textures` writes them as a PNG library: `output::texture_library`.)

pub mod generators;
pub mod noise;

use generators::TextureSpec;

/// Pixels per texture side.
pub const TEXTURE_PX: u32 = 256;

/// Renders texture `spec` as linear RGB, `px × px`, sampled at pixel centres.
pub fn render(spec: &TextureSpec, px: u32) -> Vec<glam::Vec3> {
    let inv = 1.0 / px as f32;
    (0..px * px)
        .map(|i| spec.eval(((i % px) as f32 + 0.5) * inv, ((i / px) as f32 + 0.5) * inv))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use generators::{FAMILIES, SUBTLE, SUBTLE_AMPLITUDE, SUBTLE_BASE};

    use crate::util::colour::luminance;

    /// Mean absolute luminance step across the wrap-around seam, and the largest mean step
    /// across any interior column or row boundary (grout lines and plank seams included): a
    /// seamless tile's wrap is just another interior boundary.
    fn seam_and_interior(img: &[glam::Vec3], px: usize) -> (f32, f32) {
        let l = |x: usize, y: usize| luminance(img[(y % px) * px + x % px]);
        let boundary = |j: usize| {
            let cols: f32 = (0..px).map(|k| (l(j + 1, k) - l(j, k)).abs()).sum();
            let rows: f32 = (0..px).map(|k| (l(k, j + 1) - l(k, j)).abs()).sum();
            (cols / px as f32).max(rows / px as f32)
        };
        let interior = (0..px - 1).map(boundary).fold(0.0, f32::max);
        (boundary(px - 1), interior)
    }

    #[test]
    fn every_family_is_seamless() {
        for i in 0..FAMILIES.len() as u32 * 3 {
            let spec = TextureSpec::from_index(0, i);
            let px = 128;
            let (seam, interior) = seam_and_interior(&render(&spec, px), px as usize);
            assert!(
                seam <= 1.1 * interior + 1e-4,
                "{:?} (#{i}): seam {seam} vs interior {interior}",
                spec.family
            );
        }
    }

    #[test]
    fn the_subtle_families_are_seamless_low_contrast_and_not_flat() {
        let px = 128;
        for k in 0..SUBTLE.len() as u32 * 3 {
            let spec = TextureSpec::from_index(0, SUBTLE_BASE + k);
            assert_eq!(spec.family, SUBTLE[k as usize % SUBTLE.len()]);
            let img = render(&spec, px);
            let (seam, interior) = seam_and_interior(&img, px as usize);
            assert!(
                seam <= 1.1 * interior + 1e-6,
                "{:?}: seam {seam}",
                spec.family
            );
            let base = luminance(glam::Vec3::from(spec.a));
            let rel: Vec<f32> = img.iter().map(|&c| luminance(c) / base - 1.0).collect();
            let max = rel.iter().fold(0.0f32, |m, r| m.max(r.abs()));
            let mean = rel.iter().sum::<f32>() / rel.len() as f32;
            let std =
                (rel.iter().map(|r| (r - mean).powi(2)).sum::<f32>() / rel.len() as f32).sqrt();
            assert!(
                max <= SUBTLE_AMPLITUDE * 1.0001,
                "{:?}: deviation {max}",
                spec.family
            );
            assert!(std > 0.002, "{:?}: flat (std {std})", spec.family);
        }
    }

    #[test]
    fn the_classic_library_keeps_its_families_below_the_subtle_indices() {
        for i in 0..FAMILIES.len() as u32 * 2 {
            assert_eq!(
                TextureSpec::from_index(3, i).family,
                FAMILIES[i as usize % 14]
            );
        }
    }

    #[test]
    fn a_clamped_edge_would_fail_the_seam_test() {
        // Guard: the test above can fail. 63 % of a smooth noise tile is not periodic.
        let spec = TextureSpec::from_index(0, 1);
        let px = 128;
        let half: Vec<glam::Vec3> = (0..px * px)
            .map(|i| {
                spec.eval(
                    ((i % px) as f32 + 0.5) / px as f32 * 0.63,
                    ((i / px) as f32 + 0.5) / px as f32 * 0.63,
                )
            })
            .collect();
        let (seam, interior) = seam_and_interior(&half, px);
        assert!(seam > 1.1 * interior, "seam {seam} interior {interior}");
    }
}
