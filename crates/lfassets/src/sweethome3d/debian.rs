//! Debian's Sweet Home 3D packages: downloading them with `apt-get download` (no root
//! needed), unpacking them with `dpkg-deb -x`, and where their libraries lie once unpacked.

use super::licenses::debian_files_license;
use super::{PACKAGES, Source};
use anyhow::{Context, Result, bail};
use std::collections::HashMap;
use std::ffi::OsStr;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

// Where the libraries and the copyright file lie in the unpacked packages, and where the
// catalogues lie in the archives.
const FURNITURE_DIR: &str = "usr/share/sweethome3d/furniture";
const JAR: &str = "usr/share/sweethome3d/sweethome3d.jar";
const JAR_CATALOG: &str = "com/eteks/sweethome3d/io/DefaultFurnitureCatalog.properties";
pub(super) const PLUGIN_CATALOG: &str = "PluginFurnitureCatalog.properties";
const DEBIAN_COPYRIGHT: &str = "usr/share/doc/sweethome3d/copyright";

/// The newest `<package>_*.deb` in `dir`, if any.
pub(super) fn cached_deb(dir: &Path, package: &str) -> Result<Option<PathBuf>> {
    let prefix = format!("{package}_");
    let mut found: Vec<PathBuf> = fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            let name = p.file_name().and_then(OsStr::to_str).unwrap_or("");
            name.starts_with(&prefix) && name.ends_with(".deb")
        })
        .collect();
    found.sort();
    Ok(found.pop())
}

/// The version in a Debian file name `package_version_arch.deb` (`%3a` is the epoch colon).
pub(super) fn deb_version(deb: &Path) -> String {
    let name = deb.file_name().and_then(OsStr::to_str).unwrap_or("");
    let parts: Vec<&str> = name.trim_end_matches(".deb").split('_').collect();
    match parts.as_slice() {
        [_, version, ..] => version.replace("%3a", ":"),
        _ => "?".into(),
    }
}

/// Runs an external tool in `dir`; a missing tool or a failure names the command and shows
/// its stderr.
pub(super) fn run_tool(tool: &str, args: &[&OsStr], dir: &Path) -> Result<()> {
    let shown = || {
        let args: Vec<String> = args.iter().map(|a| a.to_string_lossy().into()).collect();
        format!("{tool} {}", args.join(" "))
    };
    match Command::new(tool).args(args).current_dir(dir).output() {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "`{tool}` not found: `lfgen assets fetch sweethome3d` needs Debian's apt-get and \
             dpkg-deb (a Debian or Ubuntu machine)"
        ),
        Err(e) => Err(e).with_context(|| format!("cannot run `{}`", shown())),
        Ok(o) if !o.status.success() => bail!(
            "`{}` failed ({}):\n{}",
            shown(),
            o.status,
            String::from_utf8_lossy(&o.stderr).trim_end()
        ),
        Ok(_) => Ok(()),
    }
}

/// The libraries of the unpacked packages under `root`.
pub(super) fn debian_sources(root: &Path, versions: &HashMap<&str, String>) -> Result<Vec<Source>> {
    let furniture = root.join(FURNITURE_DIR);
    let mut libraries: Vec<PathBuf> = fs::read_dir(&furniture)
        .with_context(|| format!("cannot list {}", furniture.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension() == Some(OsStr::new("sh3f")))
        .collect();
    libraries.sort();
    if libraries.is_empty() {
        bail!("no .sh3f library in {}", furniture.display());
    }
    let version = |p: &str| versions.get(p).cloned().unwrap_or_else(|| "?".into());
    let mut sources: Vec<Source> = libraries
        .into_iter()
        .map(|archive| {
            let file = archive.file_name().unwrap_or_default().to_string_lossy();
            let name = archive.file_stem().unwrap_or_default().to_string_lossy();
            Source {
                name: name.into_owned(),
                origin: format!("{} {}: {file}", PACKAGES[0], version(PACKAGES[0])),
                properties: PLUGIN_CATALOG.into(),
                license: None,
                archive,
            }
        })
        .collect();
    let copyright = root.join(DEBIAN_COPYRIGHT);
    let text = fs::read_to_string(&copyright)
        .with_context(|| format!("cannot read {}", copyright.display()))?;
    sources.push(Source {
        name: "default".into(),
        archive: root.join(JAR),
        properties: JAR_CATALOG.into(),
        origin: format!("{} {}: sweethome3d.jar", PACKAGES[1], version(PACKAGES[1])),
        license: debian_files_license(&text),
    });
    Ok(sources)
}
