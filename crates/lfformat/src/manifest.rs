//! The dataset-level `manifest.json`: what generated the dataset and, per scene, every file
//! with its checksum, so that resumed or sharded runs can tell finished scenes from broken ones.

use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::error::{Error, Result};

/// One file of a scene.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Relative to the dataset root, `/`-separated on every platform.
    pub path: String,
    /// Lowercase hex SHA-256 of the contents.
    pub sha256: String,
    /// Size in bytes (checked first: cheaper than hashing).
    pub bytes: u64,
}

/// One scene of the dataset.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SceneEntry {
    /// Scene index in the whole dataset (the split is a function of it).
    pub index: u64,
    /// Split name (`train`, `val`, …).
    pub split: String,
    /// Scene folder relative to the dataset root, `/`-separated.
    pub dir: String,
    /// Every file of the scene.
    pub files: Vec<FileEntry>,
}

/// Contents of `manifest.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Name of the generating program.
    pub generator: String,
    /// Its version.
    pub version: String,
    /// Hash of the configuration, to refuse resuming with a different one.
    pub config_hash: String,
    /// Dataset seed.
    pub seed: u64,
    /// The full configuration.
    pub config: serde_json::Value,
    /// Split name → number of scenes.
    pub splits: BTreeMap<String, u64>,
    /// The scenes written so far.
    pub scenes: Vec<SceneEntry>,
}

impl Manifest {
    /// Reads and parses `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::read::bytes(path)?;
        serde_json::from_slice(&text).map_err(|e| Error::format(path, e.to_string()))
    }

    /// Writes pretty JSON atomically ([`crate::files::write_atomic`]: a temporary name of this
    /// process, synced, then renamed over `path`), so an interrupted run never leaves a
    /// truncated manifest behind and two runs never write into one temporary file.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut text = serde_json::to_string_pretty(self).expect("a Manifest always serialises");
        text.push('\n');
        crate::files::write_atomic(path, text.as_bytes())
    }
}

/// Lowercase hex SHA-256 and size of the regular file at `path` ([`crate::read::open`]),
/// read in chunks so that large files are not held in memory.
pub fn sha256_file(path: &Path) -> Result<(String, u64)> {
    sha256_at_most(path, u64::MAX)
}

/// [`sha256_file`] reading at most `limit` bytes: a file that turns out longer reports
/// `limit` bytes, which the caller compares with the size it expected.
fn sha256_at_most(path: &Path, limit: u64) -> Result<(String, u64)> {
    let io = |e| Error::io(path, e);
    let mut file = crate::read::open(path)?.take(limit);
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 16];
    let mut bytes = 0u64;
    loop {
        let n = file.read(&mut buffer).map_err(io)?;
        if n == 0 {
            break;
        }
        hasher.update(&buffer[..n]);
        bytes += n as u64;
    }
    Ok((hex(&hasher.finalize()), bytes))
}

/// SHA-256 and size of the file a manifest entry describes, reading at most one byte more
/// than it records: a file grown without bound cannot keep the check reading.
fn sha256_of_entry(path: &Path, f: &FileEntry) -> Result<(String, u64)> {
    sha256_at_most(path, f.bytes.saturating_add(1))
}

/// Lowercase hex SHA-256 of `bytes` (content keys of assets, textures and configs).
pub fn hex_sha256(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks every file of `e` under `root`, naming the first that is missing, has another size
/// or another SHA-256 (flipped bytes in a ground-truth file would otherwise score silently).
pub fn verify_scene_entry(root: &Path, e: &SceneEntry) -> Result<()> {
    if e.files.is_empty() {
        return Err(Error::format(
            &root.join(&e.dir),
            "the manifest lists no files for this scene",
        ));
    }
    for f in &e.files {
        let path = root.join(&f.path);
        let (hex, bytes) = sha256_of_entry(&path, f)?;
        if bytes > f.bytes {
            return Err(Error::format(
                &path,
                format!(
                    "does not match manifest.json (more than the {} bytes it records): damaged \
                     or changed since it was generated",
                    f.bytes
                ),
            ));
        }
        if bytes != f.bytes || !hex.eq_ignore_ascii_case(&f.sha256) {
            return Err(Error::format(
                &path,
                format!(
                    "does not match manifest.json ({bytes} bytes, SHA-256 {hex}; the manifest \
                     says {} bytes, {}): damaged or changed since it was generated",
                    f.bytes, f.sha256
                ),
            ));
        }
    }
    Ok(())
}

/// Whether every file of `e` exists under `root` with the recorded size and hash. An entry
/// without files never verifies: a scene always has some, so an empty list is damage.
///
/// Any error (missing file, unreadable file) means "does not verify": the caller's remedy
/// is the same, re-generating the scene.
pub fn scene_entry_verifies(root: &Path, e: &SceneEntry) -> bool {
    !e.files.is_empty()
        && e.files.iter().all(|f| {
            let path = root.join(&f.path);
            let size_matches = std::fs::metadata(&path).is_ok_and(|m| m.len() == f.bytes);
            size_matches
                && sha256_of_entry(&path, f)
                    .is_ok_and(|(hex, _)| hex.eq_ignore_ascii_case(&f.sha256))
        })
}
