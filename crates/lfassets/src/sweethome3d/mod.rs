//! `lfgen assets fetch sweethome3d`: Sweet Home 3D's furniture libraries as an asset catalogue.
//!
//! Debian ships the models in two packages of `main`: `sweethome3d-furniture` (five `.sh3f`
//! libraries: Blend Swap CC-0 and CC-BY, Kator Legaz, Reallusion, Scopia) and `sweethome3d`
//! (the default catalogue inside `sweethome3d.jar`). [`fetch`] downloads both with
//! `apt-get download` (no root packages are installed), unpacks them with `dpkg-deb -x`, and
//! [`convert`] turns every usable entry into a [`catalog::Asset`](lfformat::catalog::Asset):
//!
//! * the libraries' `PluginFurnitureCatalog.properties` / `DefaultFurnitureCatalog.properties`
//!   are parsed ([`parse_properties`]); entry `N` is the set of keys `field#N`;
//! * the model (`.obj`) and what it needs (its `.mtl` files and their textures; the whole model
//!   folder for `multiPartModel` entries) are unzipped to `<out>/<library>/…`, entry names
//!   sanitised;
//! * OBJ files that use material names none of their `.mtl` files define (Sweet Home 3D
//!   supplies those itself) get a `<stem>.lfgen.mtl` of their own next to them, from our
//!   [`builtin_material`] table, and an `mtllib` line for it;
//! * `<out>/catalog.json`, `<out>/ATTRIBUTION.md` and `<out>/lfgen_sh3d_builtin.mtl` (every
//!   built-in name met, for reference) are written, each atomically.
//!
//! What is left out, and why, is counted in the [`Summary`].

mod debian;
mod library;
mod licenses;
mod materials;
mod obj;
mod placement;
mod properties;

pub use library::safe_relative;
pub use licenses::{is_free_license, license_id};
pub use materials::{BuiltinMaterial, builtin_material};
pub use placement::placement;
pub use properties::{decode_properties, parse_properties};

use anyhow::{Context, Result, bail};
use debian::{cached_deb, deb_version, debian_sources, run_tool};
use indicatif::{ProgressBar, ProgressStyle};
use lfformat::catalog::{Asset, Catalog, SIZE_LIMITS, VERSION};
use library::{Library, parent_dir, read_entry};
use licenses::{copyright_line, license_summary, license_url, obj_header_license};
use materials::builtin_mtl;
use obj::plan_obj;
use placement::{excluded, hood_elevation, surfaces};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::fmt;
use std::fs;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The Debian packages downloaded, furniture libraries first.
pub const PACKAGES: [&str; 2] = ["sweethome3d-furniture", "sweethome3d"];
/// The reference table of every built-in material name met, written to the output folder.
pub const BUILTIN_MTL: &str = "lfgen_sh3d_builtin.mtl";
/// Suffix of the per-OBJ material file holding the built-in names that OBJ uses.
const BUILTIN_SUFFIX: &str = ".lfgen.mtl";

/// Downloads the two Debian packages into `<out>/.cache/` (reusing `.deb` files already
/// there), unpacks them and converts every library into `<out>/catalog.json`.
pub fn fetch(out: &Path, nonfree: bool) -> Result<Summary> {
    let cache = out.join(".cache");
    fs::create_dir_all(&cache).with_context(|| format!("cannot create {}", cache.display()))?;
    // apt-get runs in the cache folder, so the paths handed to the tools are absolute.
    let cache = std::path::absolute(&cache)?;
    let mut versions = HashMap::new();
    let mut debs = Vec::new();
    for package in PACKAGES {
        let deb = match cached_deb(&cache, package)? {
            Some(deb) => {
                lfformat::note!("{package}: reusing {}", deb.display());
                deb
            }
            None => {
                lfformat::note!("{package}: apt-get download …");
                run_tool("apt-get", &["download".as_ref(), package.as_ref()], &cache)?;
                cached_deb(&cache, package)?.with_context(|| {
                    format!("apt-get download {package} wrote no {package}_*.deb")
                })?
            }
        };
        versions.insert(package, deb_version(&deb));
        debs.push(deb);
    }
    let root = cache.join("root");
    if root.exists() {
        fs::remove_dir_all(&root).with_context(|| format!("cannot clear {}", root.display()))?;
    }
    fs::create_dir_all(&root)?;
    for deb in &debs {
        lfformat::note!("dpkg-deb -x {}", deb.display());
        run_tool(
            "dpkg-deb",
            &["-x".as_ref(), deb.as_os_str(), root.as_os_str()],
            &cache,
        )?;
    }
    let sources = debian_sources(&root, &versions)?;
    let opts = ConvertOptions {
        nonfree,
        progress: true,
    };
    let summary = convert(&sources, out, &opts)?;
    // The unpacked tree (~140 MB) is redone from the cached .deb files in seconds.
    fs::remove_dir_all(&root).with_context(|| format!("cannot remove {}", root.display()))?;
    Ok(summary)
}

/// One furniture library: a zip archive (`.sh3f` or `.jar`) with a catalogue inside.
#[derive(Clone, Debug)]
pub struct Source {
    /// Short name, also the library's sub-folder of the output, e.g. `"Scopia"`, `"default"`.
    pub name: String,
    pub archive: PathBuf,
    /// Name of the `.properties` entry inside the archive.
    pub properties: String,
    /// The catalogue's `origin` of its entries, e.g. `"sweethome3d-furniture 1.8-1: Scopia.sh3f"`.
    pub origin: String,
    /// Licence of the models when the archive has no `LICENSE.TXT` (the default catalogue:
    /// from Debian's copyright file).
    pub license: Option<String>,
}

/// Conversion settings.
#[derive(Clone, Debug, Default)]
pub struct ConvertOptions {
    /// Also convert models whose licence is not free (see [`is_free_license`]).
    pub nonfree: bool,
    /// Progress bar on stderr.
    pub progress: bool,
}

/// What a conversion wrote and what it left out.
#[derive(Clone, Debug, Default)]
pub struct Summary {
    pub out: PathBuf,
    /// Entries in all catalogues.
    pub entries: usize,
    /// Catalogue entries written.
    pub written: usize,
    /// Skipped entries per reason.
    pub skipped: BTreeMap<String, usize>,
    /// Entries skipped because their model is not `.obj`, per file extension.
    pub skipped_formats: BTreeMap<String, usize>,
    /// Entries written per licence.
    pub per_license: BTreeMap<String, usize>,
    /// Entries with a non-free licence, per licence, whether written or not.
    pub nonfree: BTreeMap<String, usize>,
    pub nonfree_included: bool,
    /// OBJ files given a material file for Sweet Home 3D's built-in material names.
    pub patched_objs: usize,
    /// Distinct built-in material names met.
    pub builtin_materials: usize,
    /// Material or texture files referenced but absent from the library.
    pub missing_files: usize,
    /// Zip entries refused because their names would leave the output folder.
    pub unsafe_names: usize,
}

impl Summary {
    fn skip(&mut self, reason: &str) {
        *self.skipped.entry(reason.to_string()).or_default() += 1;
    }
}

impl fmt::Display for Summary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: {} of {} entries written to catalog.json",
            self.out.display(),
            self.written,
            self.entries
        )?;
        for (reason, n) in &self.skipped {
            writeln!(f, "  skipped {n:4}  {reason}")?;
        }
        if !self.skipped_formats.is_empty() {
            let formats = counts(&self.skipped_formats);
            writeln!(f, "  model formats skipped: {formats}")?;
        }
        for (license, n) in &self.per_license {
            writeln!(f, "  licence {n:4}  {license}")?;
        }
        if self.nonfree.is_empty() {
            writeln!(f, "  no non-free licence found (--nonfree changes nothing)")?;
        } else {
            let list = counts(&self.nonfree);
            let what = if self.nonfree_included {
                "included"
            } else {
                "skipped; --nonfree includes them"
            };
            writeln!(f, "  non-free licences ({what}): {list}")?;
        }
        writeln!(
            f,
            "  {} OBJ files use {} of Sweet Home 3D's built-in material names: \
             given *{BUILTIN_SUFFIX} files",
            self.patched_objs, self.builtin_materials
        )?;
        if self.missing_files > 0 {
            writeln!(
                f,
                "  {} references to material/texture files missing from the library \
                 (authors' disk paths) commented out",
                self.missing_files
            )?;
        }
        if self.unsafe_names > 0 {
            writeln!(
                f,
                "  {} zip entry names refused (outside the output folder)",
                self.unsafe_names
            )?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------

/// `a ×2, b ×5`: counts by name, in the map's order.
fn counts(map: &BTreeMap<String, usize>) -> String {
    let list: Vec<String> = map.iter().map(|(k, n)| format!("{k} ×{n}")).collect();
    list.join(", ")
}

// ---------------------------------------------------------------------------------------------
// Conversion

/// One line of the attribution list.
struct Credit {
    library: String,
    name: String,
    author: String,
    license: String,
    origin: String,
    file: String,
}

/// The assets converted so far, with what `catalog.json`, `ATTRIBUTION.md` and the built-in
/// material table are written from.
#[derive(Default)]
struct Converted {
    assets: Vec<Asset>,
    ids: HashSet<String>,
    credits: Vec<Credit>,
    /// Built-in material names met in all OBJ files.
    builtin: BTreeSet<String>,
}

impl Converted {
    /// Adds an asset of the library `library`; an id met before gets a `~2`, `~3` … suffix
    /// (libraries reuse ids), so the catalogue's ids stay unique.
    fn add(
        &mut self,
        library: &str,
        mut asset: Asset,
        builtin: BTreeSet<String>,
        summary: &mut Summary,
    ) {
        let base = asset.id.clone();
        let mut n = 2;
        while !self.ids.insert(asset.id.clone()) {
            asset.id = format!("{base}~{n}");
            n += 1;
        }
        summary.patched_objs += !builtin.is_empty() as usize;
        self.builtin.extend(builtin);
        *summary
            .per_license
            .entry(asset.license.clone())
            .or_default() += 1;
        self.credits.push(Credit {
            library: library.to_string(),
            name: asset.name.clone(),
            author: asset.author.clone(),
            license: asset.license.clone(),
            origin: asset.origin.clone(),
            file: asset.file.clone(),
        });
        self.assets.push(asset);
    }
}

/// Converts the libraries into `<out>/catalog.json` (see the module documentation).
pub fn convert(sources: &[Source], out: &Path, opts: &ConvertOptions) -> Result<Summary> {
    fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut libraries = open_libraries(sources)?;
    let mut summary = Summary {
        out: out.to_path_buf(),
        nonfree_included: opts.nonfree,
        ..Summary::default()
    };
    summary.entries = libraries.iter().map(|l| l.entries.len()).sum();
    let bar = progress_bar(opts.progress, summary.entries);
    let mut converted = Converted::default();
    let mut written = HashSet::new();
    for lib in &mut libraries {
        bar.set_message(lib.source.name.clone());
        let entries = std::mem::take(&mut lib.entries);
        for (index, fields) in &entries {
            bar.inc(1);
            match convert_entry(lib, *index, fields, out, opts, &mut summary, &mut written)? {
                Ok((asset, builtin)) => {
                    converted.add(&lib.source.name, asset, builtin, &mut summary);
                }
                Err(reason) => summary.skip(&reason),
            }
        }
        lib.entries = entries;
        if let Some(text) = &lib.license_text {
            write_file(
                &out.join(&lib.source.name).join("LICENSE.TXT"),
                text.as_bytes(),
            )?;
        }
    }
    bar.finish_and_clear();
    summary.written = converted.assets.len();
    summary.builtin_materials = converted.builtin.len();
    write_catalog(out, &libraries, converted)?;
    Ok(summary)
}

/// Opens every library; each name becomes a folder of the output, so it must be a plain one.
fn open_libraries(sources: &[Source]) -> Result<Vec<Library>> {
    let mut libraries = Vec::new();
    for source in sources {
        if safe_relative(&source.name).is_none() || source.name.contains('/') {
            bail!("library name {:?} is not a plain folder name", source.name);
        }
        libraries.push(Library::open(source)?);
    }
    Ok(libraries)
}

/// A progress bar over the catalogue entries on stderr, or a hidden one.
fn progress_bar(show: bool, entries: usize) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(entries as u64);
    let style = "{elapsed_precise} [{bar:30}] {pos}/{len} catalogue entries — {msg}";
    bar.set_style(
        ProgressStyle::with_template(style)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// Writes the built-in material table, `ATTRIBUTION.md` and, last, `catalog.json`.
fn write_catalog(out: &Path, libraries: &[Library], converted: Converted) -> Result<()> {
    let builtin = builtin_mtl(&converted.builtin);
    write_atomic(&out.join(BUILTIN_MTL), builtin.as_bytes())?;
    write_atomic(
        &out.join("ATTRIBUTION.md"),
        attribution(libraries, &converted.credits).as_bytes(),
    )?;
    let catalog = Catalog {
        version: VERSION,
        assets: converted.assets,
    };
    let json = serde_json::to_string_pretty(&catalog).context("cannot encode catalog.json")?;
    write_atomic(&out.join("catalog.json"), json.as_bytes())
}

/// Converts one entry: `Ok(Err(reason))` when it is skipped, `Err` only for I/O failures.
#[allow(clippy::type_complexity)]
fn convert_entry(
    lib: &mut Library,
    index: usize,
    fields: &HashMap<String, String>,
    out: &Path,
    opts: &ConvertOptions,
    summary: &mut Summary,
    written: &mut HashSet<PathBuf>,
) -> Result<Result<(Asset, BTreeSet<String>), String>> {
    if let Some(reason) = excluded(fields) {
        return Ok(Err(reason.into()));
    }
    let model = field(fields, "model");
    let model = model.trim_start_matches('/');
    if let Err(reason) = check_model(lib, model, summary) {
        return Ok(Err(reason));
    }
    let dimensions = match dimensions(fields) {
        Ok(dimensions) => dimensions,
        Err(reason) => return Ok(Err(reason)),
    };
    let obj = read_entry(&mut lib.zip, model)
        .with_context(|| format!("{}: {model}", lib.source.archive.display()))?;
    let license = entry_license(lib, fields, &obj);
    if !is_free_license(&license) {
        *summary.nonfree.entry(license.clone()).or_default() += 1;
        if !opts.nonfree {
            return Ok(Err("non-free licence (use --nonfree)".into()));
        }
    }
    let multi_part = field(fields, "multiPartModel") == "true";
    let lib_dir = out.join(&lib.source.name);
    let builtin = write_model(lib, model, &obj, multi_part, &lib_dir, summary, written)?;
    let asset = entry_asset(lib, index, fields, model, dimensions, license);
    if let Some(problem) = asset.problem() {
        return Ok(Err(format!("refused by the catalogue check: {problem}")));
    }
    Ok(Ok((asset, builtin)))
}

/// A text field of an entry, trimmed; empty when absent.
fn field(fields: &HashMap<String, String>, key: &str) -> String {
    fields
        .get(key)
        .map(|v| v.trim().to_string())
        .unwrap_or_default()
}

/// Why an entry's model cannot be converted, if it cannot: not an OBJ (counted per format),
/// a name that would leave the output folder, or a file the archive lacks.
fn check_model(lib: &Library, model: &str, summary: &mut Summary) -> Result<(), String> {
    let ext = Path::new(model)
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_else(|| "(none)".into());
    if ext != "obj" {
        *summary.skipped_formats.entry(ext).or_default() += 1;
        return Err("model not .obj".into());
    }
    if safe_relative(model).is_none() {
        summary.unsafe_names += 1;
        return Err("unsafe model path".into());
    }
    if !lib.names.contains(model) {
        return Err("model file missing".into());
    }
    Ok(())
}

/// The size and position numbers of an entry.
struct Dimensions {
    /// `[width, height, depth]`, metres.
    size: [f32; 3],
    /// Metres above the floor, never negative.
    elevation: f32,
    /// Height as the catalogue gives it (cm), for [`surfaces`].
    height_cm: f32,
    /// `dropOnTopElevation` (cm), for [`surfaces`].
    drop_cm: Option<f32>,
    rotation: Option<[f32; 9]>,
}

/// An entry's [`Dimensions`], or why it is skipped: a number that cannot be read, or a size
/// outside [`SIZE_LIMITS`].
fn dimensions(fields: &HashMap<String, String>) -> Result<Dimensions, String> {
    let numbers = (|| -> Result<_, String> {
        let need = |k: &str| number(fields, k)?.ok_or_else(|| format!("no {k}"));
        let (w, d, h) = (need("width")?, need("depth")?, need("height")?);
        let elevation = number(fields, "elevation")?.unwrap_or(0.0);
        let drop = number(fields, "dropOnTopElevation")?;
        Ok((w, d, h, elevation, drop, rotation(fields)?))
    })();
    let Ok((w, d, h, elevation_cm, drop, rotation)) = numbers else {
        return Err("unreadable size or rotation".into());
    };
    let size = [w / 100.0, h / 100.0, d / 100.0];
    if size
        .iter()
        .any(|&v| !(SIZE_LIMITS[0]..=SIZE_LIMITS[1]).contains(&v))
    {
        return Err(format!(
            "size outside [{}, {}] m (paper-thin pieces: bills, rulers, hobs)",
            SIZE_LIMITS[0], SIZE_LIMITS[1]
        ));
    }
    Ok(Dimensions {
        size,
        elevation: elevation_cm.max(0.0) / 100.0,
        height_cm: h,
        drop_cm: drop,
        rotation,
    })
}

/// A number field of an entry in cm (or a plain number).
fn number(fields: &HashMap<String, String>, key: &str) -> Result<Option<f32>, String> {
    match fields.get(key).map(|v| v.trim()) {
        None | Some("") => Ok(None),
        Some(v) => match v.parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(format!("{key}={v:?}")),
        },
    }
}

/// The `modelRotation` field: a 3 × 3 matrix, row by row, or `None` when absent.
fn rotation(fields: &HashMap<String, String>) -> Result<Option<[f32; 9]>, String> {
    let Some(r) = fields.get("modelRotation") else {
        return Ok(None);
    };
    let v: Vec<f32> = r
        .split_whitespace()
        .filter_map(|x| x.parse().ok())
        .collect();
    let m: [f32; 9] = v.try_into().map_err(|_| format!("modelRotation={r:?}"))?;
    Ok(Some(m))
}

/// The licence of an entry: its own `license` field, else its OBJ's header comment, else its
/// library's.
fn entry_license(lib: &Library, fields: &HashMap<String, String>, obj: &[u8]) -> String {
    fields
        .get("license")
        .map(|l| license_id(l).unwrap_or_else(|| l.trim().to_string()))
        .or_else(|| obj_header_license(obj))
        .unwrap_or_else(|| lib.license.clone())
}

/// Writes an entry's files under `lib_dir`: its materials and textures (and for multi-part
/// models the rest of the model's folder), the OBJ (patched) and, when the OBJ uses built-in
/// material names, their `<stem>.lfgen.mtl`. Returns those names.
fn write_model(
    lib: &mut Library,
    model: &str,
    obj: &[u8],
    multi_part: bool,
    lib_dir: &Path,
    summary: &mut Summary,
    written: &mut HashSet<PathBuf>,
) -> Result<BTreeSet<String>> {
    let stem = Path::new(model)
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy();
    let builtin_file: String = format!("{stem}{BUILTIN_SUFFIX}")
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    let plan = plan_obj(lib, model, obj, &builtin_file);
    summary.missing_files += plan.missing;
    let mut files: BTreeSet<String> = plan.needs.clone();
    if multi_part {
        let dir = parent_dir(model);
        if !dir.is_empty() {
            files.extend(lib.folder(dir));
        }
    }
    files.remove(model);
    for name in files {
        copy_entry(lib, &name, lib_dir, &plan.patched, summary, written)?;
    }
    let target = lib_dir.join(model);
    write_file(&target, &plan.obj)?;
    written.insert(target.clone());
    if !plan.builtin.is_empty() {
        let mtl = target.with_file_name(&builtin_file);
        write_file(&mtl, builtin_mtl(&plan.builtin).as_bytes())?;
        written.insert(mtl);
    }
    Ok(plan.builtin)
}

/// Writes the archive file `name` under `lib_dir`: its rewritten text where `patched` has
/// one, else its bytes. Models share files, so rewritten files always replace raw copies and
/// raw copies never replace anything.
fn copy_entry(
    lib: &mut Library,
    name: &str,
    lib_dir: &Path,
    patched: &HashMap<String, Vec<u8>>,
    summary: &mut Summary,
    written: &mut HashSet<PathBuf>,
) -> Result<()> {
    let Some(rel) = safe_relative(name) else {
        summary.unsafe_names += 1;
        return Ok(());
    };
    let target = lib_dir.join(&rel);
    if let Some(bytes) = patched.get(name) {
        write_file(&target, bytes)?;
        written.insert(target);
        return Ok(());
    }
    if written.contains(&target) {
        return Ok(());
    }
    let mut entry = lib.zip.by_name(name)?;
    // The zip crate's own check as well as ours.
    if entry.enclosed_name().is_none() {
        summary.unsafe_names += 1;
        return Ok(());
    }
    let mut bytes = Vec::with_capacity(entry.size() as usize);
    entry.read_to_end(&mut bytes)?;
    write_file(&target, &bytes)?;
    written.insert(target);
    Ok(())
}

/// The catalogue entry of a converted model.
fn entry_asset(
    lib: &Library,
    index: usize,
    fields: &HashMap<String, String>,
    model: &str,
    dimensions: Dimensions,
    license: String,
) -> Asset {
    let name = field(fields, "name");
    let category = field(fields, "category");
    let elevation = hood_elevation(&name, dimensions.elevation);
    let tags = field(fields, "tags");
    let placement = placement(&name, &category, &tags, dimensions.size, elevation);
    let id = match field(fields, "id") {
        id if id.is_empty() => format!("{}#{index}", lib.source.name),
        id => id,
    };
    let author = match field(fields, "creator") {
        a if a.is_empty() => lib
            .header
            .get("provider")
            .cloned()
            .unwrap_or_else(|| "unknown".into()),
        a => a,
    };
    Asset {
        id,
        name,
        file: format!("{}/{model}", lib.source.name),
        category,
        size: dimensions.size,
        placement,
        elevation,
        surfaces: surfaces(dimensions.drop_cm, dimensions.height_cm, placement),
        rotation: dimensions.rotation,
        weight: 1.0,
        license,
        author,
        origin: lib.source.origin.clone(),
    }
}

/// `ATTRIBUTION.md`: per library its licence, then one line per converted model.
fn attribution(libraries: &[Library], credits: &[Credit]) -> String {
    let mut s = String::from(
        "# Attribution\n\nModels converted by `lfgen assets fetch sweethome3d` from Debian's \
         `sweethome3d-furniture` and `sweethome3d` packages (Sweet Home 3D's furniture \
         libraries). Materials in `*.lfgen.mtl` files are lfgen's own.\n\n## Libraries\n\n",
    );
    for lib in libraries {
        let n = credits
            .iter()
            .filter(|c| c.library == lib.source.name)
            .count();
        let url = license_url(&lib.license);
        s.push_str(&format!(
            "- **{}** ({}, {} models converted): {} — {}{}\n",
            lib.header
                .get("name")
                .map(String::as_str)
                .unwrap_or(&lib.source.name),
            lib.source.origin,
            n,
            lib.license,
            license_summary(&lib.license),
            if url.is_empty() {
                String::new()
            } else {
                format!(". <{url}>")
            }
        ));
        if let Some(line) = lib.license_text.as_deref().and_then(copyright_line) {
            s.push_str(&format!("  {line}\n"));
        }
        if lib.license_text.is_some() {
            s.push_str(&format!(
                "  Full text: `{}/LICENSE.TXT`.\n",
                lib.source.name
            ));
        }
        if lib.source.name == "default" {
            s.push_str(
                "  Sweet Home 3D's own OBJ files state \"at your choice\" CC-BY 3.0 or the GNU \
                 GPL; Debian's copyright file (`Files: *`) gives GPL-2+.\n",
            );
        }
    }
    s.push_str("\n## Models\n\nname — author — licence — origin — file\n\n");
    for c in credits {
        s.push_str(&format!(
            "- {} — {} — {} — {} — `{}`\n",
            c.name, c.author, c.license, c.origin, c.file
        ));
    }
    s
}

/// Writes `bytes` to `path` through a temporary file of this process and a rename.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    Ok(lfformat::files::write_atomic(path, bytes)?)
}

/// Writes `bytes` to `path` (checked and synced), creating its folders on the way.
fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent() {
        fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    Ok(lfformat::files::write_file(path, bytes)?)
}

#[cfg(test)]
mod tests {
    use super::debian::PLUGIN_CATALOG;
    use super::*;
    use lfformat::catalog::AssetPlacement;
    use std::io::Write;

    /// A `.sh3f` written in the test, converted field by field.
    #[test]
    fn synthetic_library_converts() {
        let dir = tempfile::tempdir().unwrap();
        let archive = dir.path().join("Test.sh3f");
        let props = "id=SweetHome3D#Test\nname=Test catalog\n\
            license=Creative Commons Attribution 3.0\n\
            id#1=Test#chair\nname#1=Chair\ncategory#1=Living room\ntags#1=Seat\n\
            model#1=/test/chair/chair.obj\nwidth#1=45\ndepth#1=50\nheight#1=90\n\
            dropOnTopElevation#1=45\nmodelRotation#1=1 0 0 0 0 1 0 -1 0\ncreator#1=Alice\n\
            multiPartModel#1=true\n\
            id#2=Test#door\nname#2=Door\ncategory#2=Doors and windows\ndoorOrWindow#2=true\n\
            model#2=/test/door/door.obj\nwidth#2=90\ndepth#2=10\nheight#2=210\n\
            id#3=Test#man\nname#3=Man\ncategory#3=Characters\nmodel#3=/test/man/man.obj\n\
            width#3=50\ndepth#3=30\nheight#3=180\n\
            id#4=Test#vase\nname#4=Vase\ncategory#4=Miscellaneous\nmodel#4=/test/vase/vase.3ds\n\
            width#4=20\ndepth#4=20\nheight#4=30\n\
            id#5=Test#cabinet\nname#5=Glass cabinet\ncategory#5=Kitchen\n\
            model#5=/test/cab/cab.obj\nwidth#5=60\ndepth#5=40\nheight#5=80\nelevation#5=145\n\
            creator#5=Bob\n\
            id#6=Test#evil\nname#6=Evil\ncategory#6=Kitchen\nmodel#6=/../evil.obj\n\
            width#6=60\ndepth#6=40\nheight#6=80\n";
        let chair_obj = "mtllib chair.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n";
        let chair_mtl = "newmtl wood\nKd 0.5 0.3 0.1\nmap_Kd wood.png\n\
                         map_Ks C:/Users/me/spec.jpg\nmap_Bump -bm 0.03 wood.png\n\
                         map_Ka /Users/me/My wood.png\n";
        let cab_obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl glass\nf 1 2 3\nusemtl white\nf 1 3 2\n";
        {
            let mut zip = zip::ZipWriter::new(fs::File::create(&archive).unwrap());
            let opts = zip::write::FileOptions::default();
            let files: [(&str, &[u8]); 9] = [
                ("PluginFurnitureCatalog.properties", props.as_bytes()),
                (
                    "LICENSE.TXT",
                    b"(C) Copyright Alice\nCreative Commons Attribution 3.0 license\n",
                ),
                ("test/chair/chair.obj", chair_obj.as_bytes()),
                ("test/chair/chair.mtl", chair_mtl.as_bytes()),
                ("test/chair/wood.png", b"png"),
                ("test/chair/LICENSE.txt", b"by Alice"),
                ("test/vase/vase.3ds", b"3ds"),
                ("test/cab/cab.obj", cab_obj.as_bytes()),
                ("../evil.obj", b"evil"),
            ];
            for (name, bytes) in files {
                zip.start_file(name, opts).unwrap();
                zip.write_all(bytes).unwrap();
            }
            zip.finish().unwrap();
        }
        let out = dir.path().join("out");
        let sources = [Source {
            name: "Test".into(),
            archive,
            properties: PLUGIN_CATALOG.into(),
            origin: "test 1.0: Test.sh3f".into(),
            license: None,
        }];
        let summary = convert(&sources, &out, &ConvertOptions::default()).unwrap();
        assert_eq!(summary.entries, 6);
        assert_eq!(summary.written, 2);
        assert_eq!(summary.skipped["door or window"], 1);
        assert_eq!(summary.skipped["people (category Characters)"], 1);
        assert_eq!(summary.skipped["model not .obj"], 1);
        assert_eq!(summary.skipped["unsafe model path"], 1);
        assert_eq!(summary.skipped_formats["3ds"], 1);
        assert_eq!(summary.per_license["CC-BY-3.0"], 2);
        assert!(summary.nonfree.is_empty());
        assert!(!dir.path().join("evil.obj").exists());

        let catalog = lfformat::catalog::LoadedCatalog::read(&out.join("catalog.json")).unwrap();
        let assets = &catalog.catalog.assets;
        assert_eq!(assets.len(), 2);
        let chair = &assets[0];
        assert_eq!(chair.id, "Test#chair");
        assert_eq!(chair.name, "Chair");
        assert_eq!(chair.category, "Living room");
        assert_eq!(chair.file, "Test/test/chair/chair.obj");
        assert_eq!(chair.size, [0.45, 0.9, 0.5]);
        assert_eq!(chair.placement, AssetPlacement::Floor);
        assert_eq!(chair.elevation, 0.0);
        assert_eq!(chair.surfaces, vec![0.45]);
        assert_eq!(
            chair.rotation,
            Some([1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0])
        );
        assert_eq!(chair.weight, 1.0);
        assert_eq!(chair.license, "CC-BY-3.0");
        assert_eq!(chair.author, "Alice");
        assert_eq!(chair.origin, "test 1.0: Test.sh3f");
        // Multi-part folder: material, texture and the model's licence file come along; the
        // OBJ, whose material is defined, is unchanged.
        let chair_dir = out.join("Test/test/chair");
        assert_eq!(
            fs::read_to_string(chair_dir.join("chair.obj")).unwrap(),
            chair_obj
        );
        for f in ["chair.mtl", "wood.png", "LICENSE.txt"] {
            assert!(chair_dir.join(f).exists(), "{f}");
        }
        assert!(!chair_dir.join("chair.lfgen.mtl").exists());
        // A texture from the author's disk is commented out, so every reference stays inside.
        let mtl = fs::read_to_string(chair_dir.join("chair.mtl")).unwrap();
        assert!(
            mtl.contains("\n# lfgen: file missing from the library: map_Ks C:/Users/me/spec.jpg\n")
        );
        assert!(mtl.contains("\nmap_Kd wood.png\n"));
        // Options and disk paths in front of a file of the folder are dropped (tobj reads the
        // whole rest of the line as the path).
        assert!(
            mtl.contains("\nmap_Bump wood.png\nmap_Ka wood.png\n"),
            "{mtl}"
        );
        assert_eq!(summary.missing_files, 1);

        let cab = &assets[1];
        assert_eq!(cab.id, "Test#cabinet");
        assert_eq!(cab.placement, AssetPlacement::WallHung);
        assert!((cab.elevation - 1.45).abs() < 1e-6);
        assert_eq!(cab.surfaces, Vec::<f32>::new());
        assert_eq!(cab.rotation, None);
        assert_eq!(cab.author, "Bob");
        for a in assets {
            assert_eq!(a.problem(), None);
            assert!(catalog.file(a).exists());
        }
        // The OBJ without mtllib now names its own material file, where glass is transparent.
        let obj = fs::read_to_string(out.join("Test/test/cab/cab.obj")).unwrap();
        assert!(obj.contains("mtllib cab.lfgen.mtl\n"), "{obj}");
        assert!(obj.ends_with(cab_obj));
        let mtl = fs::read_to_string(out.join("Test/test/cab/cab.lfgen.mtl")).unwrap();
        let glass = mtl
            .split("newmtl ")
            .find(|m| m.starts_with("glass\n"))
            .unwrap();
        let value = |m: &str, key: &str| -> f32 {
            m.lines()
                .find_map(|l| l.strip_prefix(key))
                .unwrap()
                .trim()
                .parse()
                .unwrap()
        };
        let (d, tr) = (value(glass, "d "), value(glass, "Tr "));
        assert!(
            (0.15..=0.3).contains(&d) && (d + tr - 1.0).abs() < 1e-6,
            "{glass}"
        );
        let white = mtl
            .split("newmtl ")
            .find(|m| m.starts_with("white\n"))
            .unwrap();
        assert_eq!(value(white, "d "), 1.0);
        assert_eq!(summary.patched_objs, 1);
        let reference = fs::read_to_string(out.join(BUILTIN_MTL)).unwrap();
        assert!(reference.contains("newmtl glass\n") && reference.contains("newmtl white\n"));
        let attribution = fs::read_to_string(out.join("ATTRIBUTION.md")).unwrap();
        assert!(attribution.contains("(C) Copyright Alice"));
        assert!(attribution.contains("- Chair — Alice — CC-BY-3.0 — test 1.0: Test.sh3f"));
        assert!(out.join("Test/LICENSE.TXT").exists());
    }
}
