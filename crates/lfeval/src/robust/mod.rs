//! The robustness benchmark (like ImageNet-C for light fields): `lfeval corrupt` writes seeded,
//! corrupted copies of a dataset's scenes ([`corrupt_dataset`], the corruptions in
//! [`corruption`]), and `lfeval robustness` scores every method's predictions on every copy
//! ([`benchmark`]). The ground truth is carried over untouched.

pub mod benchmark;
pub mod corruption;

use std::fs;
use std::path::Path;

use anyhow::{Context, Result, bail};
use lfformat::dataset::SceneDir;
use lfformat::views::centre_view;
use rand_pcg::Pcg64;
use rayon::prelude::*;
use serde::Serialize;

use corruption::{BENCHMARK, Corruption};

/// The list of corrupted copies `lfeval corrupt` writes beside them.
pub const INDEX_FILE: &str = "corruptions.json";

/// One entry of [`INDEX_FILE`].
#[derive(Serialize)]
struct IndexEntry {
    name: String,
    #[serde(flatten)]
    corruption: Corruption,
    family: &'static str,
    strength: f64,
}

/// Writes `out/<corruption>/[<split>/]<scene>/` for every corruption of [`BENCHMARK`] and scene
/// of `scenes`: its `input_CamNNN.png` corrupted with noise seeded by `seed`, the scene name
/// and the view; every other file but the linear EXR views and clean views (which would undo
/// the corruption) hard-linked, or copied where links are not possible.
pub fn corrupt_dataset(scenes: &[SceneDir], out: &Path, seed: u64) -> Result<()> {
    if out.exists() && fs::read_dir(out).map_or(true, |mut d| d.next().is_some()) {
        bail!(
            "{} exists and is not an empty folder: choose a new one",
            out.display()
        );
    }
    for (k, corruption) in BENCHMARK.iter().enumerate() {
        let root = out.join(corruption.name());
        for scene in scenes {
            let dir = match &scene.split {
                Some(split) => root.join(split).join(&scene.name),
                None => root.join(&scene.name),
            };
            let key = seed ^ ((k as u64) << 56) ^ fnv1a(&scene.name);
            corrupt_scene(&scene.path, &dir, corruption, key)?;
        }
    }
    let index: Vec<IndexEntry> = BENCHMARK
        .iter()
        .map(|c| IndexEntry {
            name: c.name(),
            corruption: *c,
            family: c.family().0,
            strength: c.strength(),
        })
        .collect();
    let text = serde_json::to_string_pretty(&index)? + "\n";
    Ok(lfformat::files::write_atomic(
        &out.join(INDEX_FILE),
        text.as_bytes(),
    )?)
}

/// One scene folder `src` corrupted into `dst`; `key` seeds its views' noise.
fn corrupt_scene(src: &Path, dst: &Path, corruption: &Corruption, key: u64) -> Result<()> {
    fs::create_dir_all(dst).with_context(|| format!("cannot create {}", dst.display()))?;
    let (centre, _, _) = centre_view(src)?;
    let pivot = centre.iter().sum::<f32>() / centre.len().max(1) as f32;
    let mut views = Vec::new();
    for entry in fs::read_dir(src).with_context(|| format!("cannot list {}", src.display()))? {
        let entry = entry.with_context(|| format!("cannot list {}", src.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_file = entry.file_type().is_ok_and(|t| t.is_file());
        let other_view = name.starts_with("input_Cam") || name.starts_with("clean_Cam");
        match view_index(&name) {
            Some(view) => views.push((name, view)),
            None if is_file && !other_view => carry(&entry.path(), &dst.join(&name))?,
            None => {}
        }
    }
    views.par_iter().try_for_each(|(name, view)| {
        let path = src.join(name);
        let mut img = image::open(&path)
            .with_context(|| format!("cannot read {}", path.display()))?
            .to_rgb8();
        let mut rng = Pcg64::new(key as u128, *view as u128);
        corruption.apply(&mut img, pivot, &mut rng)?;
        Ok(lfformat::png::write_png(&dst.join(name), &img)?)
    })
}

/// The view number of `input_CamNNN.png`.
fn view_index(name: &str) -> Option<u32> {
    let n = name.strip_prefix("input_Cam")?.strip_suffix(".png")?;
    (n.len() == 3).then(|| n.parse().ok()).flatten()
}

/// `src` at `dst`: a hard link, or a copy across file systems.
fn carry(src: &Path, dst: &Path) -> Result<()> {
    if fs::hard_link(src, dst).is_ok() {
        return Ok(());
    }
    fs::copy(src, dst)
        .map(drop)
        .with_context(|| format!("cannot copy {} to {}", src.display(), dst.display()))
}

/// FNV-1a of a scene name: a seed that does not depend on the order scenes are listed in.
fn fnv1a(s: &str) -> u64 {
    s.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_names() {
        assert_eq!(view_index("input_Cam040.png"), Some(40));
        assert_eq!(view_index("input_Cam040.exr"), None);
        assert_eq!(view_index("clean_Cam040.png"), None);
        assert_eq!(view_index("input_Cam40.png"), None);
    }
}
