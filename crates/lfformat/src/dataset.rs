//! Finding the scene folders of a dataset.
//!
//! Three layouts are accepted, so that both lfgen datasets and the HCI benchmark work as
//! they are: a scene folder itself, a folder of scene folders (`DATASET/val`, HCI's
//! `training/`), or a folder of split folders (`DATASET` with `train/` and `val/`). A scene
//! folder is one holding `parameters.cfg`.

use std::path::{Path, PathBuf};

use crate::manifest::{Manifest, verify_scene_entry};
use crate::{Error, Result};

/// The file that marks a scene folder.
pub const PARAMETERS_FILE: &str = "parameters.cfg";

/// One scene of a dataset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneDir {
    /// The folder name; predictions are looked up by it.
    pub name: String,
    /// The split folder it was found in, if any.
    pub split: Option<String>,
    /// The scene folder.
    pub path: PathBuf,
}

/// The scenes under `root`, sorted by split then name; `splits`, when not empty, keeps only
/// those split folders (an error if one does not exist).
pub fn discover(root: &Path, splits: &[String]) -> Result<Vec<SceneDir>> {
    if !root.is_dir() {
        return Err(Error::format(root, "dataset folder does not exist"));
    }
    let scenes = if is_scene(root) {
        reject_splits(root, splits)?;
        vec![scene_at(root, None)]
    } else {
        let direct = scene_children(root, None)?;
        if direct.is_empty() {
            from_splits(root, splits)?
        } else {
            reject_splits(root, splits)?;
            direct
        }
    };
    if scenes.is_empty() {
        return Err(Error::format(
            root,
            format!("no scene folders (folders with {PARAMETERS_FILE}) found"),
        ));
    }
    check_unique(root, &scenes)?;
    verify_against_manifest(root, splits, &scenes)?;
    Ok(scenes)
}

/// Where the scenes belong to an lfgen dataset (a `manifest.json` at `root` or up to two
/// folders above it), every scene must be listed in it and its files must match their
/// checksums: a damaged file, or a stray scene folder the manifest does not describe, is an
/// error naming it instead of a silently wrong score.
fn verify_against_manifest(root: &Path, splits: &[String], scenes: &[SceneDir]) -> Result<()> {
    let root = root.canonicalize().unwrap_or_else(|_| root.to_path_buf());
    // Any entry of that name counts, so that one which is no regular file (a FIFO, a link to
    // /dev/zero) is refused naming it by the reader instead of passing for "no manifest" and
    // skipping every checksum.
    let Some(dataset) = root
        .ancestors()
        .take(3)
        .find(|d| d.join("manifest.json").symlink_metadata().is_ok())
    else {
        return Ok(());
    };
    let manifest_path = dataset.join("manifest.json");
    let manifest = Manifest::read(&manifest_path)?;
    let mut found = Vec::with_capacity(scenes.len());
    for scene in scenes {
        let path = scene
            .path
            .canonicalize()
            .unwrap_or_else(|_| scene.path.clone());
        let rel = relative(&path, dataset);
        let entry = manifest
            .scenes
            .iter()
            .find(|e| e.dir == rel)
            .ok_or_else(|| {
                Error::format(
                    &scene.path,
                    format!(
                        "not listed in {} (a stray or unfinished scene): remove it, or \
                         complete the dataset with lfgen --resume",
                        manifest_path.display()
                    ),
                )
            })?;
        verify_scene_entry(dataset, entry)?;
        found.push(rel);
    }
    refuse_missing(
        dataset,
        &relative(&root, dataset),
        splits,
        &manifest,
        &found,
    )
}

/// `path` relative to `dataset`, `/`-separated (the form of the manifest's `dir`).
fn relative(path: &Path, dataset: &Path) -> String {
    let rel = path.strip_prefix(dataset).unwrap_or(path);
    let parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    parts.join("/")
}

/// A scene the manifest lists under `root` (`root_rel` from the dataset; in the selected
/// `splits`) but whose folder or `parameters.cfg` is gone is an error naming it: scoring or
/// training on fewer scenes than the dataset holds must not pass for a full run.
fn refuse_missing(
    dataset: &Path,
    root_rel: &str,
    splits: &[String],
    manifest: &Manifest,
    found: &[String],
) -> Result<()> {
    let prefix = if root_rel.is_empty() {
        String::new()
    } else {
        format!("{root_rel}/")
    };
    for e in &manifest.scenes {
        let Some(below) = e.dir.strip_prefix(&prefix) else {
            continue;
        };
        let split = below.split('/').next().unwrap_or_default();
        let selected = splits.is_empty() || splits.iter().any(|s| s == split);
        if below.is_empty() || !selected || found.contains(&e.dir) {
            continue;
        }
        let folder = dataset.join(&e.dir);
        let (path, what) = if folder.is_dir() {
            (
                folder.join(PARAMETERS_FILE),
                "its parameters.cfg is missing",
            )
        } else {
            (folder, "its folder is missing")
        };
        return Err(Error::format(
            &path,
            format!(
                "scene {} is listed in {} but {what}: restore it, or re-generate it with \
                 lfgen --resume",
                e.dir,
                dataset.join("manifest.json").display()
            ),
        ));
    }
    Ok(())
}

/// Scenes of the split folders of `root`.
fn from_splits(root: &Path, splits: &[String]) -> Result<Vec<SceneDir>> {
    let mut scenes = Vec::new();
    for dir in sorted_subdirs(root)? {
        let split = file_name(&dir);
        if splits.is_empty() || splits.contains(&split) {
            scenes.extend(scene_children(&dir, Some(split))?);
        }
    }
    for s in splits {
        if !root.join(s).is_dir() {
            return Err(Error::format(root, format!("no split folder {s:?}")));
        }
    }
    Ok(scenes)
}

/// `--split` only makes sense for a folder of split folders.
fn reject_splits(root: &Path, splits: &[String]) -> Result<()> {
    if !splits.is_empty() {
        return Err(Error::format(
            root,
            "--split given, but this folder holds scenes, not split folders",
        ));
    }
    Ok(())
}

/// The scene folders directly inside `dir`.
fn scene_children(dir: &Path, split: Option<String>) -> Result<Vec<SceneDir>> {
    Ok(sorted_subdirs(dir)?
        .into_iter()
        .filter(|d| is_scene(d))
        .map(|d| scene_at(&d, split.clone()))
        .collect())
}

/// Visible sub-folders of `dir`, sorted (hidden ones are partial lfgen output).
fn sorted_subdirs(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut dirs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir() && !file_name(p).starts_with('.'))
        .collect();
    dirs.sort();
    Ok(dirs)
}

fn is_scene(dir: &Path) -> bool {
    dir.join(PARAMETERS_FILE).is_file()
}

fn scene_at(dir: &Path, split: Option<String>) -> SceneDir {
    let canonical = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    SceneDir {
        name: file_name(&canonical),
        split,
        path: dir.to_path_buf(),
    }
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Predictions are keyed by scene name, so two scenes may not share one.
fn check_unique(root: &Path, scenes: &[SceneDir]) -> Result<()> {
    let mut names: Vec<&str> = scenes.iter().map(|s| s.name.as_str()).collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(Error::format(
            root,
            format!(
                "two scenes are called {:?}; pick one split with --split",
                w[0]
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn make_scene(dir: &Path) {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join(PARAMETERS_FILE), "").unwrap();
    }

    fn names(s: &[SceneDir]) -> Vec<&str> {
        s.iter().map(|s| s.name.as_str()).collect()
    }

    #[test]
    fn all_three_layouts_are_found() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        make_scene(&r.join("train/scene_0001"));
        make_scene(&r.join("train/scene_0000"));
        make_scene(&r.join("val/scene_0002"));
        std::fs::create_dir_all(r.join("train/.scene_0003.partial")).unwrap();
        let all = discover(r, &[]).unwrap();
        assert_eq!(names(&all), ["scene_0000", "scene_0001", "scene_0002"]);
        assert_eq!(all[2].split.as_deref(), Some("val"));
        let val = discover(r, &["val".into()]).unwrap();
        assert_eq!(names(&val), ["scene_0002"]);
        assert_eq!(
            names(&discover(&r.join("train"), &[]).unwrap()),
            ["scene_0000", "scene_0001"]
        );
        assert_eq!(
            names(&discover(&r.join("val/scene_0002"), &[]).unwrap()),
            ["scene_0002"]
        );
    }

    #[test]
    fn problems_are_reported() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        assert!(
            discover(r, &[])
                .unwrap_err()
                .to_string()
                .contains("no scene folders")
        );
        make_scene(&r.join("a/x"));
        make_scene(&r.join("b/x"));
        assert!(
            discover(r, &[])
                .unwrap_err()
                .to_string()
                .contains("two scenes")
        );
        assert!(
            discover(r, &["c".into()])
                .unwrap_err()
                .to_string()
                .contains("\"c\"")
        );
        assert!(discover(&r.join("a"), &["a".into()]).is_err());
        assert!(discover(&r.join("missing"), &[]).is_err());
    }

    #[test]
    fn a_manifest_is_verified_and_unlisted_scenes_are_refused() {
        use crate::manifest::{FileEntry, SceneEntry, sha256_file};
        let d = tempfile::tempdir().unwrap();
        let r = d.path();
        let scene = r.join("val/scene_0000");
        make_scene(&scene);
        std::fs::write(scene.join("gt_disp_lowres.pfm"), b"PFMDATA").unwrap();
        let entry = |name: &str| {
            let (sha256, bytes) = sha256_file(&scene.join(name)).unwrap();
            FileEntry {
                path: format!("val/scene_0000/{name}"),
                sha256,
                bytes,
            }
        };
        let manifest = Manifest {
            generator: "test".into(),
            version: "0".into(),
            config_hash: String::new(),
            seed: 0,
            config: serde_json::Value::Null,
            splits: Default::default(),
            scenes: vec![SceneEntry {
                index: 0,
                split: "val".into(),
                dir: "val/scene_0000".into(),
                files: vec![entry(PARAMETERS_FILE), entry("gt_disp_lowres.pfm")],
            }],
        };
        manifest.write(&r.join("manifest.json")).unwrap();
        assert_eq!(discover(r, &[]).unwrap().len(), 1);
        assert_eq!(discover(&r.join("val"), &[]).unwrap().len(), 1);
        // One flipped byte in the ground truth.
        std::fs::write(scene.join("gt_disp_lowres.pfm"), b"PFMDATB").unwrap();
        let e = format!("{:#}", discover(r, &[]).unwrap_err());
        assert!(
            e.contains("gt_disp_lowres.pfm") && e.contains("manifest"),
            "{e}"
        );
        std::fs::write(scene.join("gt_disp_lowres.pfm"), b"PFMDATA").unwrap();
        // A scene folder the manifest does not describe.
        make_scene(&r.join("val/scene_0001"));
        let e = format!("{:#}", discover(r, &[]).unwrap_err());
        assert!(e.contains("scene_0001") && e.contains("not listed"), "{e}");
    }

    /// A manifest.json that is a link to /dev/zero is refused naming it, not taken for an
    /// absent manifest (which would skip every checksum).
    #[cfg(unix)]
    #[test]
    fn a_manifest_that_is_no_regular_file_is_refused() {
        let d = tempfile::tempdir().unwrap();
        make_scene(&d.path().join("val/scene_0000"));
        std::os::unix::fs::symlink("/dev/zero", d.path().join("manifest.json")).unwrap();
        let e = format!("{:#}", discover(d.path(), &[]).unwrap_err());
        assert!(
            e.contains("manifest.json") && e.contains("not a regular file"),
            "{e}"
        );
    }
}
