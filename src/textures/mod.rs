//! The texture library: `lfgen textures --count N --out DIR` writes N distinct seamless PNG
//! textures from the procedural [`generators`] plus `catalog.json` (file, family, real tile size,
//! licence), for rooms and objects to draw from.

pub mod generators;
pub mod noise;

use crate::output::images::to_srgb8;
use anyhow::{Context, Result};
use generators::TextureSpec;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Pixels per texture side.
pub const TEXTURE_PX: u32 = 256;

/// One entry of `catalog.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CatalogEntry {
    pub file: String,
    #[serde(flatten)]
    pub spec: TextureSpec,
    pub licence: String,
    pub author: String,
}

/// `catalog.json` of a texture folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Catalog {
    pub generator: String,
    pub seed: u64,
    pub textures: Vec<CatalogEntry>,
}

/// Renders texture `spec` as linear RGB, `px × px`, sampled at pixel centres.
pub fn render(spec: &TextureSpec, px: u32) -> Vec<glam::Vec3> {
    let inv = 1.0 / px as f32;
    (0..px * px)
        .map(|i| spec.eval(((i % px) as f32 + 0.5) * inv, ((i / px) as f32 + 0.5) * inv))
        .collect()
}

/// Writes `count` textures and the catalogue into `out`.
pub fn write_library(out: &Path, count: u32, seed: u64) -> Result<Catalog> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let textures = (0..count)
        .into_par_iter()
        .map(|i| {
            let spec = TextureSpec::from_index(seed, i);
            let file = format!(
                "tex_{i:04}_{}.png",
                serde_json::to_value(spec.family)?.as_str().unwrap_or("x")
            );
            let rgb = to_srgb8(&render(&spec, TEXTURE_PX), 1.0);
            let img =
                image::RgbImage::from_raw(TEXTURE_PX, TEXTURE_PX, rgb).context("texture size")?;
            crate::output::images::save_png(&img, &out.join(&file))?;
            Ok(CatalogEntry {
                file,
                spec,
                licence: "CC0-1.0".into(),
                author: "lfgen procedural generator".into(),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let catalog = Catalog {
        generator: format!("lfgen {}", env!("CARGO_PKG_VERSION")),
        seed,
        textures,
    };
    crate::output::scene_dir::write_json(&out.join("catalog.json"), &catalog)?;
    Ok(catalog)
}

#[cfg(test)]
mod tests {
    use super::*;
    use generators::FAMILIES;

    fn luminance(c: glam::Vec3) -> f32 {
        c.dot(glam::Vec3::new(0.2126, 0.7152, 0.0722))
    }

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

    #[test]
    fn library_textures_are_distinct_and_catalogued() {
        let dir = tempfile::tempdir().unwrap();
        let cat = write_library(dir.path(), 60, 3).unwrap();
        assert_eq!(cat.textures.len(), 60);
        let mut hashes: Vec<String> = cat
            .textures
            .iter()
            .map(|t| crate::output::hex_sha256(&std::fs::read(dir.path().join(&t.file)).unwrap()))
            .collect();
        hashes.sort();
        hashes.dedup();
        assert_eq!(hashes.len(), 60, "textures must be distinct");
        let back: Catalog =
            serde_json::from_slice(&std::fs::read(dir.path().join("catalog.json")).unwrap())
                .unwrap();
        assert_eq!(back, cat);
    }
}
