//! One furniture library opened: its zip archive, the names of its entries (and which of them
//! may be written out), its catalogue and its licence.

use super::Source;
use super::licenses::license_id;
use super::properties::{catalogue_entries, decode_properties, parse_properties};
use anyhow::{Context, Result};
use std::collections::{HashMap, HashSet};
use std::fs;
use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// A zip entry name as a relative path that stays inside the output folder (normal components
/// only: no root, no `..`, no `.`), or `None`.
pub fn safe_relative(name: &str) -> Option<PathBuf> {
    let ok = !name.contains(['\0', '\\'])
        && name
            .split('/')
            .all(|part| !part.is_empty() && part != "." && part != "..");
    let path = Path::new(name);
    (ok && path.components().all(|c| matches!(c, Component::Normal(_)))).then(|| path.to_path_buf())
}

/// `rel` resolved against the folder `dir` of a zip entry name (`..` allowed while it stays
/// inside the archive), with forward slashes.
pub(super) fn join_zip(dir: &str, rel: &str) -> Option<String> {
    let mut parts: Vec<&str> = dir.split('/').filter(|p| !p.is_empty()).collect();
    for part in rel.split(['/', '\\']) {
        match part {
            "" | "." => {}
            ".." => {
                parts.pop()?;
            }
            p => parts.push(p),
        }
    }
    Some(parts.join("/"))
}

/// The folder of a zip entry name (`""` at the archive's root).
pub(super) fn parent_dir(name: &str) -> &str {
    name.rsplit_once('/').map(|(d, _)| d).unwrap_or("")
}

/// An opened library archive.
pub(super) struct Library {
    pub(super) source: Source,
    pub(super) zip: zip::ZipArchive<fs::File>,
    /// Every entry name, to check the references of OBJ and MTL files against.
    pub(super) names: HashSet<String>,
    /// The catalogue's entries ([`catalogue_entries`]).
    pub(super) entries: Vec<(usize, HashMap<String, String>)>,
    /// Licence id of the models unless an entry or OBJ header says otherwise: from
    /// `LICENSE.TXT`, else the source's, else the catalogue's `license` key, else `"unknown"`.
    pub(super) license: String,
    /// `LICENSE.TXT` (or `LICENSE.txt`, `LICENSE`), copied next to the converted models.
    pub(super) license_text: Option<String>,
    /// The catalogue's keys without `#N` (`name`, `provider`, `license` …).
    pub(super) header: HashMap<String, String>,
}

impl Library {
    /// Opens the archive and reads its catalogue and licence.
    pub(super) fn open(source: &Source) -> Result<Self> {
        let file = fs::File::open(&source.archive)
            .with_context(|| format!("cannot open {}", source.archive.display()))?;
        let mut zip = zip::ZipArchive::new(file)
            .with_context(|| format!("{}: not a zip archive", source.archive.display()))?;
        let names: HashSet<String> = zip.file_names().map(String::from).collect();
        let props = read_entry(&mut zip, &source.properties)
            .with_context(|| format!("{}: no {}", source.archive.display(), source.properties))?;
        let pairs = parse_properties(&decode_properties(&props));
        let header: HashMap<String, String> = pairs
            .iter()
            .filter(|(k, _)| !k.contains('#'))
            .cloned()
            .collect();
        let entries = catalogue_entries(&pairs);
        let license_text = ["LICENSE.TXT", "LICENSE.txt", "LICENSE"]
            .iter()
            .find(|n| names.contains(**n))
            .and_then(|n| read_entry(&mut zip, n).ok())
            .map(|b| decode_properties(&b));
        let license = license_text
            .as_deref()
            .and_then(license_id)
            .or_else(|| source.license.clone())
            .or_else(|| header.get("license").and_then(|l| license_id(l)))
            .unwrap_or_else(|| "unknown".into());
        Ok(Self {
            source: source.clone(),
            zip,
            names,
            entries,
            license,
            license_text,
            header,
        })
    }

    /// Files of the folder `dir` and its sub-folders.
    pub(super) fn folder(&self, dir: &str) -> Vec<String> {
        let prefix = format!("{dir}/");
        let mut files: Vec<String> = self
            .names
            .iter()
            .filter(|n| n.starts_with(&prefix) && !n.ends_with('/'))
            .cloned()
            .collect();
        files.sort();
        files
    }
}

/// The bytes of the archive entry `name`.
pub(super) fn read_entry(zip: &mut zip::ZipArchive<fs::File>, name: &str) -> Result<Vec<u8>> {
    let mut file = zip.by_name(name)?;
    let mut bytes = Vec::with_capacity(file.size() as usize);
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zip_slip_names_are_refused() {
        for bad in [
            "../evil.obj",
            "/etc/passwd",
            "a/../../b",
            "a/./b",
            "",
            "a\\..\\b",
            "./a",
        ] {
            assert_eq!(safe_relative(bad), None, "{bad:?}");
        }
        assert_eq!(
            safe_relative("scopia/chair/chair.obj"),
            Some(PathBuf::from("scopia/chair/chair.obj"))
        );
        assert_eq!(join_zip("a/b", "../c.mtl").as_deref(), Some("a/c.mtl"));
        assert_eq!(join_zip("a", "../../c.mtl"), None);
    }
}
