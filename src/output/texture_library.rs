//! `lfgen textures --count N --out DIR`: N distinct seamless PNG textures from the procedural
//! generators plus `catalog.json` (file, family, real tile size, licence).

use super::images::{save_png, to_srgb8};
use super::scene_dir::write_json;
use crate::textures::generators::TextureSpec;
use crate::textures::{TEXTURE_PX, render};
use anyhow::{Context, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

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
            save_png(&img, &out.join(&file))?;
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
    write_json(&out.join("catalog.json"), &catalog)?;
    Ok(catalog)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_textures_are_distinct_and_catalogued() {
        let dir = tempfile::tempdir().unwrap();
        let cat = write_library(dir.path(), 60, 3).unwrap();
        assert_eq!(cat.textures.len(), 60);
        let mut hashes: Vec<String> = cat
            .textures
            .iter()
            .map(|t| {
                lfformat::manifest::hex_sha256(&std::fs::read(dir.path().join(&t.file)).unwrap())
            })
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
