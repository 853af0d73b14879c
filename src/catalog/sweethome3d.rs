//! `lfgen assets fetch sweethome3d`: Sweet Home 3D's furniture libraries as an asset catalogue.
//!
//! Debian ships the models in two packages of `main`: `sweethome3d-furniture` (five `.sh3f`
//! libraries: Blend Swap CC-0 and CC-BY, Kator Legaz, Reallusion, Scopia) and `sweethome3d`
//! (the default catalogue inside `sweethome3d.jar`). [`fetch`] downloads both with
//! `apt-get download` (no root packages are installed), unpacks them with `dpkg-deb -x`, and
//! [`convert`] turns every usable entry into a [`catalog::Asset`](super::Asset):
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

use super::{Asset, AssetPlacement, Catalog, SIZE_LIMITS, VERSION};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::ffi::OsStr;
use std::fmt;
use std::fs;
use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

/// The Debian packages downloaded, furniture libraries first.
pub const PACKAGES: [&str; 2] = ["sweethome3d-furniture", "sweethome3d"];
const FURNITURE_DIR: &str = "usr/share/sweethome3d/furniture";
const JAR: &str = "usr/share/sweethome3d/sweethome3d.jar";
const JAR_CATALOG: &str = "com/eteks/sweethome3d/io/DefaultFurnitureCatalog.properties";
const PLUGIN_CATALOG: &str = "PluginFurnitureCatalog.properties";
const DEBIAN_COPYRIGHT: &str = "usr/share/doc/sweethome3d/copyright";
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
                eprintln!("{package}: reusing {}", deb.display());
                deb
            }
            None => {
                eprintln!("{package}: apt-get download …");
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
        eprintln!("dpkg-deb -x {}", deb.display());
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

/// The newest `<package>_*.deb` in `dir`, if any.
fn cached_deb(dir: &Path, package: &str) -> Result<Option<PathBuf>> {
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
fn deb_version(deb: &Path) -> String {
    let name = deb.file_name().and_then(OsStr::to_str).unwrap_or("");
    let parts: Vec<&str> = name.trim_end_matches(".deb").split('_').collect();
    match parts.as_slice() {
        [_, version, ..] => version.replace("%3a", ":"),
        _ => "?".into(),
    }
}

/// Runs an external tool in `dir`; a missing tool or a failure names the command and shows
/// its stderr.
fn run_tool(tool: &str, args: &[&OsStr], dir: &Path) -> Result<()> {
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
fn debian_sources(root: &Path, versions: &HashMap<&str, String>) -> Result<Vec<Source>> {
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

/// The licence of the `Files: *` paragraph of a Debian machine-readable copyright file, as
/// an SPDX id (`GPL-2+` → `GPL-2.0-or-later`).
fn debian_files_license(copyright: &str) -> Option<String> {
    for paragraph in copyright.split("\n\n") {
        let mut lines = paragraph.lines();
        if lines.next().map(str::trim) != Some("Files: *") {
            continue;
        }
        let license = lines.find_map(|l| l.strip_prefix("License:"))?.trim();
        let spdx = match license {
            "GPL-2+" => "GPL-2.0-or-later",
            "GPL-2" => "GPL-2.0-only",
            "GPL-3+" => "GPL-3.0-or-later",
            other => other,
        };
        return Some(spdx.to_string());
    }
    None
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
            let formats: Vec<String> = self
                .skipped_formats
                .iter()
                .map(|(e, n)| format!("{e} ×{n}"))
                .collect();
            writeln!(f, "  model formats skipped: {}", formats.join(", "))?;
        }
        for (license, n) in &self.per_license {
            writeln!(f, "  licence {n:4}  {license}")?;
        }
        if self.nonfree.is_empty() {
            writeln!(f, "  no non-free licence found (--nonfree changes nothing)")?;
        } else {
            let list: Vec<String> = self
                .nonfree
                .iter()
                .map(|(l, n)| format!("{l} ×{n}"))
                .collect();
            let what = if self.nonfree_included {
                "included"
            } else {
                "skipped; --nonfree includes them"
            };
            writeln!(f, "  non-free licences ({what}): {}", list.join(", "))?;
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
// Java .properties

/// Decodes a `.properties` file the way Java 9+ resource bundles do: UTF-8 when the bytes are
/// valid UTF-8, else ISO-8859-1 (every byte one character).
pub fn decode_properties(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| char::from(b)).collect(),
    }
}

/// Parses Java `.properties` text (`java.util.Properties.load` rules): `#`/`!` comment lines,
/// `key=value`, `key:value` or `key value`, a backslash at the end of a line continues it on
/// the next (whose leading blanks are dropped), escapes `\t \n \r \f \uXXXX` and `\x` → `x`.
/// Pairs come in file order; later duplicates win when collected into a map.
///
/// Hand-written (about 80 lines, tested below) rather than the `java-properties` crate: that
/// crate decodes "ISO-8859-1" as windows-1252 through `encoding_rs` (bytes 0x80–0x9F differ),
/// does not do Java 9's UTF-8-first reading, and would add two dependencies to the build.
pub fn parse_properties(text: &str) -> Vec<(String, String)> {
    let text = text.replace("\r\n", "\n").replace('\r', "\n");
    let mut pairs = Vec::new();
    let mut logical = String::new();
    let mut continuing = false;
    for raw in text.split('\n') {
        let line = raw.trim_start_matches([' ', '\t', '\x0c']);
        if !continuing && (line.is_empty() || line.starts_with('#') || line.starts_with('!')) {
            continue;
        }
        let backslashes = line.bytes().rev().take_while(|&b| b == b'\\').count();
        if backslashes % 2 == 1 {
            logical.push_str(&line[..line.len() - 1]);
            continuing = true;
            continue;
        }
        logical.push_str(line);
        continuing = false;
        pairs.push(split_key_value(&logical));
        logical.clear();
    }
    if continuing {
        pairs.push(split_key_value(&logical));
    }
    pairs
}

/// Splits a logical line at the first unescaped `=`, `:` or blank.
fn split_key_value(line: &str) -> (String, String) {
    let is_blank = |c: char| matches!(c, ' ' | '\t' | '\x0c');
    let mut key_end = line.len();
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        if escaped {
            escaped = false;
        } else if c == '\\' {
            escaped = true;
        } else if c == '=' || c == ':' || is_blank(c) {
            key_end = i;
            break;
        }
    }
    let mut rest = line[key_end..].trim_start_matches(is_blank);
    if let Some(r) = rest.strip_prefix(['=', ':']) {
        rest = r.trim_start_matches(is_blank);
    }
    (unescape(&line[..key_end]), unescape(rest))
}

/// Resolves the escapes of a key or value (`\uXXXX` surrogate pairs combined).
fn unescape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut chars = s.chars().peekable();
    let mut pending_high: Option<u32> = None;
    while let Some(c) = chars.next() {
        let decoded = if c != '\\' {
            Some(c)
        } else {
            match chars.next() {
                None => None,
                Some('t') => Some('\t'),
                Some('n') => Some('\n'),
                Some('r') => Some('\r'),
                Some('f') => Some('\x0c'),
                Some('u') => {
                    let hex: String = chars.clone().take(4).collect();
                    match u32::from_str_radix(&hex, 16) {
                        Ok(unit) if hex.len() == 4 => {
                            for _ in 0..4 {
                                chars.next();
                            }
                            if (0xD800..0xDC00).contains(&unit) {
                                if pending_high.replace(unit).is_some() {
                                    out.push(char::REPLACEMENT_CHARACTER);
                                }
                                continue;
                            }
                            if (0xDC00..0xE000).contains(&unit) {
                                let c = pending_high.take().and_then(|high| {
                                    char::from_u32(
                                        0x10000 + ((high - 0xD800) << 10) + (unit - 0xDC00),
                                    )
                                });
                                out.push(c.unwrap_or(char::REPLACEMENT_CHARACTER));
                                continue;
                            }
                            char::from_u32(unit)
                        }
                        _ => Some('u'),
                    }
                }
                Some(other) => Some(other),
            }
        };
        if pending_high.take().is_some() {
            out.push(char::REPLACEMENT_CHARACTER);
        }
        if let Some(c) = decoded {
            out.push(c);
        }
    }
    if pending_high.is_some() {
        out.push(char::REPLACEMENT_CHARACTER);
    }
    out
}

/// The furniture entries of a catalogue: entry `N` holds the fields of the keys `field#N`,
/// in increasing `N`.
fn catalogue_entries(pairs: &[(String, String)]) -> Vec<(usize, HashMap<String, String>)> {
    let mut entries: BTreeMap<usize, HashMap<String, String>> = BTreeMap::new();
    for (key, value) in pairs {
        let Some((field, index)) = key.rsplit_once('#') else {
            continue;
        };
        let Ok(index) = index.parse::<usize>() else {
            continue;
        };
        if field.is_empty() || !field.chars().all(|c| c.is_ascii_alphanumeric()) {
            continue;
        }
        entries
            .entry(index)
            .or_default()
            .insert(field.to_string(), value.clone());
    }
    entries
        .into_iter()
        .filter(|(_, e)| e.contains_key("model") || e.contains_key("name"))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Licences

/// An SPDX-style licence id for a licence text or name (a `LICENSE.TXT`, a catalogue's
/// `license` key, an OBJ header), or `None` when it names none we know.
pub fn license_id(text: &str) -> Option<String> {
    let t = text.to_lowercase();
    let version = ["4.0", "3.0", "2.5", "2.0", "1.0"]
        .into_iter()
        .find(|v| t.contains(v))
        .unwrap_or("3.0");
    let has = |phrases: &str| phrases.split('|').any(|p| t.contains(p));
    let id = if has("noncommercial|non-commercial|by-nc") {
        format!("CC-BY-NC-{version}")
    } else if has("noderivatives|no derivative|by-nd") {
        format!("CC-BY-ND-{version}")
    } else if has("creative commons zero|publicdomain/zero|choose/zero|cc0|cc-0") {
        "CC0-1.0".into()
    } else if has("sharealike|share alike|by-sa") {
        format!("CC-BY-SA-{version}")
    } else if has("attribution|cc-by|licenses/by/") {
        let us = has("united states|/by/3.0/us");
        format!("CC-BY-{version}{}", if us { "-US" } else { "" })
    } else if has("general public license|gnu gpl") {
        "GPL-2.0-or-later".into()
    } else if has("public domain") {
        "public-domain".into()
    } else {
        return None;
    };
    Some(id)
}

/// Whether a licence id is free for a dataset anyone may use: CC0, public domain, CC-BY and
/// CC-BY-SA, GPL (and expressions of them). Non-commercial (NC), no-derivatives (ND) and
/// unknown licences are not.
pub fn is_free_license(id: &str) -> bool {
    id.split(" OR ").any(|part| {
        let p = part.trim();
        let known = p == "CC0-1.0"
            || p == "public-domain"
            || p.starts_with("CC-BY-")
            || p.starts_with("GPL-");
        known && !p.contains("-NC") && !p.contains("-ND")
    })
}

/// The dual licence stated in the header comment of Sweet Home 3D's own OBJ files ("at your
/// choice, under the CC-BY … 3.0 … or under the terms of the GNU General Public License").
fn obj_header_license(obj: &[u8]) -> Option<String> {
    let head: String = obj
        .split(|&b| b == b'\n')
        .take(15)
        .filter(|l| l.first() == Some(&b'#'))
        .map(|l| String::from_utf8_lossy(l).to_lowercase())
        .collect::<Vec<_>>()
        .join(" ");
    let dual = head.contains("at your choice")
        && head.contains("creative commons attribution 3")
        && head.contains("general public license");
    dual.then(|| "CC-BY-3.0 OR GPL-2.0-or-later".to_string())
}

/// Where to read a licence's text.
fn license_url(id: &str) -> &'static str {
    match id {
        "CC0-1.0" => "https://creativecommons.org/publicdomain/zero/1.0/",
        "CC-BY-3.0" => "https://creativecommons.org/licenses/by/3.0/",
        "CC-BY-3.0-US" => "https://creativecommons.org/licenses/by/3.0/us/",
        "CC-BY-4.0" => "https://creativecommons.org/licenses/by/4.0/",
        "GPL-2.0-or-later" => "https://www.gnu.org/licenses/old-licenses/gpl-2.0.html",
        "CC-BY-3.0 OR GPL-2.0-or-later" => {
            "https://creativecommons.org/licenses/by/3.0/ or \
             https://www.gnu.org/licenses/old-licenses/gpl-2.0.html"
        }
        _ => "",
    }
}

/// One line on what a licence asks of users.
fn license_summary(id: &str) -> &'static str {
    if id == "CC0-1.0" || id == "public-domain" {
        "public-domain dedication: any use, no conditions (crediting the authors is still kind)"
    } else if id.contains(" OR ") {
        "at your choice CC-BY 3.0 (credit the author) or the GNU GPL (version 2 or later)"
    } else if id.starts_with("CC-BY-SA") {
        "any use, including commercial, crediting the author; adaptations under the same licence"
    } else if id.starts_with("CC-BY-") && is_free_license(id) {
        "any use, including commercial and adaptations, crediting the author and linking the \
         licence"
    } else if id.starts_with("GPL-") {
        "copyleft: redistributions and derived works under the GNU GPL"
    } else {
        "not a free licence: read the library's LICENSE.TXT before using these models"
    }
}

// ---------------------------------------------------------------------------------------------
// Placement

/// Lower-case words of a name and its tags.
fn words(name: &str, tags: &str) -> Vec<String> {
    format!("{name} {tags}")
        .to_lowercase()
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| !w.is_empty())
        .map(String::from)
        .collect()
}

/// Words (of a name or tag) of small pieces that still stand on the floor.
const FLOOR_STANDING: &str = "seat chair stool nightstand potty bin dustbin trash shoes slippers \
    sneakers bootie mocassin hood radiator";
/// Words of storage and fitted pieces that stand with their back against a wall.
const FITTED: &str = "cabinet wardrobe closet bookcase bookshelf shelves shelf cupboard dresser \
    chest sideboard vanity washbasin sink fridge refrigerator freezer dishwasher washer dryer \
    cooker oven stove fireplace radiator heater toilet toilets bidet urinal shower hood";

/// Where a Sweet Home 3D piece goes in a room, from its name, category, tags, size
/// `[width, height, depth]` and elevation (metres). Tuned on the 920 entries of Debian's
/// libraries; the first rule that applies wins:
///
/// 1. **ceiling**: names with ceiling / pendant / chandelier / smoke detector, and lights or
///    fans (category `Lights`, or lamp / light / fan / lantern in the name) whose top
///    (elevation + height) reaches 2.4 m — Sweet Home 3D's ceiling is 2.5 m — except hoods,
///    cabinets, heaters and showers, which reach it from a wall. A ceiling-named piece that
///    does not hang (top below 2.4 m, yet raised) falls through to wall_hung.
/// 2. **wall_hung**: any elevation ≥ 5 cm. In these catalogues every raised piece is
///    wall-mounted, low ones included (sockets at 22 cm, radiators at 10–20 cm, towels,
///    washbasins at 35–50 cm, curtains at 8 cm), so the threshold is not 0.3 m.
/// 3. **floor_cover**: rug, carpet, mat, doormat, bathmat, tatami no higher than 6 cm.
/// 4. **on_top**: small light things — height < 0.6 m and footprint < 0.5 m, flat ones
///    (height < 0.15 m, footprint < 0.8 m: hobs, trays, folded clothes), and appliances,
///    electronics and TVs below 0.55 m with a footprint < 0.9 m (coffee machines, fryers,
///    flat TVs) — except seats, tables, bins, shoes, potties, hoods and radiators, which stand
///    on the floor.
/// 5. **wall**: storage and fitted pieces by name or tag (cabinet, wardrobe, closet,
///    bookcase, shelves, cupboard, dresser, chest, vanity, sink, washbasin, fridge, freezer,
///    dishwasher, washer, dryer, cooker, oven, stove, fireplace, radiator, heater, toilet,
///    bidet, urinal, shower, hood, upright piano; not kitchen islands), and wide shallow tall
///    pieces (depth ≤ 0.45 m, width ≥ 2 × depth, height ≥ 1 m: screens, racks, brooms).
/// 6. **floor**: the rest (tables, seats, beds, sofas, plants, appliances …).
pub fn placement(
    name: &str,
    category: &str,
    tags: &str,
    size: [f32; 3],
    elevation: f32,
) -> AssetPlacement {
    let w = words(name, tags);
    let has = |list: &str| list.split_whitespace().any(|l| w.iter().any(|x| x == l));
    let [width, height, depth] = size;
    let top = elevation + height;
    let ceiling_named = has("ceiling pendant chandelier") || (has("smoke") && has("detector"));
    let light = category == "Lights" || has("lamp light fan lantern");
    let wall_fitted = has("hood cabinet heater shower");
    if (ceiling_named && (top >= 2.4 || elevation == 0.0)) || (light && top >= 2.4 && !wall_fitted)
    {
        return AssetPlacement::Ceiling;
    }
    if elevation >= 0.05 {
        return AssetPlacement::WallHung;
    }
    let cover = has("rug rugs carpet mat doormat bathmat tatami");
    if cover && height <= 0.06 {
        return AssetPlacement::FloorCover;
    }
    let footprint = width.max(depth);
    let appliance = has("appliance electronics television tv computer");
    let small = (height < 0.6 && footprint < 0.5)
        || (height < 0.15 && footprint < 0.8)
        || (appliance && height < 0.55 && footprint < 0.9);
    let floor_standing = has(FLOOR_STANDING) || name.to_lowercase().trim_end().ends_with("table");
    if small && !floor_standing {
        return AssetPlacement::OnTop;
    }
    let fitted = has(FITTED) || (has("piano") && !has("grand bench"));
    let panel = depth <= 0.45 && width >= 2.0 * depth && height >= 1.0;
    if (fitted && !has("island")) || panel {
        return AssetPlacement::Wall;
    }
    AssetPlacement::Floor
}

/// Kitchen hoods hang above the cooker even where the catalogue leaves their elevation at 0
/// (Scopia's `kitchenHood`): 1.5 m then, a usual height above a 0.9 m worktop.
fn hood_elevation(name: &str, elevation: f32) -> f32 {
    let hood = words(name, "").iter().any(|w| w == "hood");
    if hood && elevation == 0.0 {
        1.5
    } else {
        elevation
    }
}

/// Heights (metres above the bottom) others can stand on. Sweet Home 3D's
/// `dropOnTopElevation` (cm) gives it: kept when it is at least 15 % of the height (lower
/// values are the insides of baskets, vases, boxes and bathtubs, where a dropped piece would be
/// hidden) and not above the top; a negative value means "nothing goes on it". Without the key
/// Sweet Home 3D drops on the top: kept as the height for floor and wall pieces up to 1.3 m
/// (tables, desks, chests, low cabinets), not for taller ones (wardrobes, fridges, curtains).
fn surfaces(drop_cm: Option<f32>, height_cm: f32, placement: AssetPlacement) -> Vec<f32> {
    match drop_cm {
        Some(d) if d > 0.0 && d >= 0.15 * height_cm && d <= height_cm => vec![d / 100.0],
        Some(_) => vec![],
        None => {
            let standing = matches!(placement, AssetPlacement::Floor | AssetPlacement::Wall);
            if standing && height_cm <= 130.0 {
                vec![height_cm / 100.0]
            } else {
                vec![]
            }
        }
    }
}

/// Why an entry is skipped before looking at its files, if it is: doors and windows, people,
/// vehicles, exterior and garden pieces, architecture, and the default catalogue's light-source
/// markers (a sphere that stands for a light, not a visible object).
fn excluded(fields: &HashMap<String, String>) -> Option<&'static str> {
    let get = |k: &str| fields.get(k).map(String::as_str).unwrap_or("");
    if get("doorOrWindow").trim() == "true" {
        return Some("door or window");
    }
    let w = words(get("name"), get("tags"));
    let has = |list: &str| list.split_whitespace().any(|l| w.iter().any(|x| x == l));
    match get("category").trim() {
        "Characters" => return Some("people (category Characters)"),
        "Vehicles" => return Some("vehicles (category Vehicles)"),
        "Exterior" => return Some("exterior (category Exterior, or tagged Exterior/Garden/Road)"),
        "Doors and windows" | "Staircases" => {
            return Some("architecture (staircases, shutters, screen doors)");
        }
        _ => {}
    }
    if has("exterior garden road") {
        return Some("exterior (category Exterior, or tagged Exterior/Garden/Road)");
    }
    if get("model").ends_with("/lightSource.obj") || (has("light") && has("source")) {
        return Some("light-source marker (no visible object)");
    }
    None
}

// ---------------------------------------------------------------------------------------------
// Built-in materials

/// A material of our built-in table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuiltinMaterial {
    pub diffuse: [f32; 3],
    pub specular: f32,
    pub shininess: f32,
    /// Opacity (`d`); `Tr` = 1 − `d`.
    pub opacity: f32,
}

/// Words that make a material glass-like (transparent).
const GLASS_WORDS: &str =
    "glass glas verre vidrio vitre vetro cristal crystal transparent window windshield";

/// Colour words of material names and the colours we give them (our own values).
const COLOUR_WORDS: &[(&str, [f32; 3])] = &[
    ("black", [0.02, 0.02, 0.02]),
    ("ebony", [0.08, 0.06, 0.05]),
    ("white", [0.85, 0.85, 0.85]),
    ("ivory", [0.86, 0.83, 0.72]),
    ("bone", [0.84, 0.80, 0.70]),
    ("teeth", [0.90, 0.88, 0.80]),
    ("cream", [0.88, 0.84, 0.70]),
    ("grey", [0.50, 0.50, 0.50]),
    ("gray", [0.50, 0.50, 0.50]),
    ("silver", [0.75, 0.75, 0.77]),
    ("chrome", [0.80, 0.80, 0.82]),
    ("metal", [0.60, 0.60, 0.62]),
    ("steel", [0.62, 0.63, 0.65]),
    ("iron", [0.40, 0.40, 0.42]),
    ("alu", [0.78, 0.78, 0.80]),
    ("gold", [0.80, 0.62, 0.25]),
    ("brass", [0.76, 0.62, 0.30]),
    ("bronze", [0.62, 0.42, 0.22]),
    ("copper", [0.72, 0.42, 0.26]),
    ("brown", [0.40, 0.25, 0.12]),
    ("wood", [0.55, 0.38, 0.20]),
    ("oak", [0.62, 0.46, 0.28]),
    ("walnut", [0.38, 0.25, 0.15]),
    ("pine", [0.76, 0.60, 0.38]),
    ("redwood", [0.50, 0.22, 0.13]),
    ("mahogany", [0.42, 0.16, 0.10]),
    ("tan", [0.70, 0.55, 0.38]),
    ("blonde", [0.82, 0.70, 0.45]),
    ("sand", [0.76, 0.69, 0.54]),
    ("beige", [0.80, 0.74, 0.60]),
    ("stone", [0.58, 0.56, 0.52]),
    ("skin", [0.85, 0.64, 0.52]),
    ("flesh", [0.87, 0.66, 0.55]),
    ("lips", [0.62, 0.28, 0.28]),
    ("red", [0.70, 0.08, 0.06]),
    ("ruby", [0.60, 0.05, 0.12]),
    ("pink", [0.90, 0.55, 0.65]),
    ("orange", [0.90, 0.45, 0.08]),
    ("flame", [1.00, 0.55, 0.12]),
    ("amber", [0.85, 0.55, 0.10]),
    ("yellow", [0.90, 0.80, 0.12]),
    ("green", [0.15, 0.50, 0.15]),
    ("olive", [0.45, 0.45, 0.15]),
    ("teal", [0.10, 0.45, 0.45]),
    ("blue", [0.12, 0.22, 0.65]),
    ("blu", [0.12, 0.22, 0.65]),
    ("sky", [0.45, 0.65, 0.90]),
    ("iris", [0.35, 0.30, 0.70]),
    ("lavender", [0.70, 0.60, 0.85]),
    ("lavendar", [0.70, 0.60, 0.85]),
    ("purple", [0.45, 0.20, 0.55]),
    ("violet", [0.50, 0.25, 0.65]),
];

/// Words of shiny metals (stronger highlight).
const METAL_WORDS: &str = "silver chrome metal steel iron alu gold brass bronze copper";

/// A plausible material for one of Sweet Home 3D's built-in material names (used in OBJ files
/// without a definition): the mean of the colour words found in the name (longest first, so
/// `redwood` is not `red`), darkened by `dk`/`dark` (twice for `dkdk`), lightened by
/// `lt`/`light`/`brt`; neutral grey when no colour word is found. Every glass-like name
/// ([`GLASS_WORDS`]) is transparent: opacity 0.2.
pub fn builtin_material(name: &str) -> BuiltinMaterial {
    let lower = name.to_lowercase();
    let glass = GLASS_WORDS.split(' ').any(|w| lower.contains(w));
    let mut rest = lower.clone();
    let mut words: Vec<&(&str, [f32; 3])> = COLOUR_WORDS.iter().collect();
    words.sort_by_key(|(w, _)| std::cmp::Reverse(w.len()));
    let mut sum = [0.0f32; 3];
    let mut found = 0;
    for (word, colour) in words {
        while let Some(i) = rest.find(word) {
            rest.replace_range(i..i + word.len(), &" ".repeat(word.len()));
            for k in 0..3 {
                sum[k] += colour[k];
            }
            found += 1;
        }
    }
    let mut diffuse = match found {
        0 if glass => [0.80, 0.88, 0.90],
        0 => [0.60, 0.60, 0.60],
        n => sum.map(|s| s / n as f32),
    };
    if rest.contains("dkdk") {
        diffuse = diffuse.map(|c| c * 0.35);
    } else if rest.contains("dk") || rest.contains("dark") {
        diffuse = diffuse.map(|c| c * 0.55);
    } else if rest.contains("lt") || rest.contains("light") || rest.contains("brt") {
        diffuse = diffuse.map(|c| c + (1.0 - c) * 0.4);
    }
    let metal = METAL_WORDS.split(' ').any(|w| lower.contains(w));
    let (specular, shininess) = match (glass, metal) {
        (true, _) => (0.9, 300.0),
        (false, true) => (0.6, 120.0),
        _ => (0.1, 20.0),
    };
    BuiltinMaterial {
        diffuse,
        specular,
        shininess,
        opacity: if glass { 0.2 } else { 1.0 },
    }
}

/// MTL text defining `names` with [`builtin_material`].
fn builtin_mtl<'a>(names: impl IntoIterator<Item = &'a String>) -> String {
    let mut s = String::from(
        "# Written by lfgen assets fetch sweethome3d: lfgen's own colours for material names\n\
         # that Sweet Home 3D supplies itself (never defined in the library's .mtl files).\n",
    );
    for name in names {
        let m = builtin_material(name);
        let [r, g, b] = m.diffuse;
        let (k, d) = (m.specular, m.opacity);
        let illum = if d < 1.0 { 4 } else { 2 };
        s.push_str(&format!("\nnewmtl {name}\n"));
        s.push_str(&format!(
            "Ka {:.3} {:.3} {:.3}\n",
            r * 0.2,
            g * 0.2,
            b * 0.2
        ));
        s.push_str(&format!(
            "Kd {r:.3} {g:.3} {b:.3}\nKs {k:.2} {k:.2} {k:.2}\n"
        ));
        s.push_str(&format!(
            "Ns {:.0}\nd {d:.2}\nTr {:.2}\nillum {illum}\n",
            m.shininess,
            1.0 - d
        ));
    }
    s
}

// ---------------------------------------------------------------------------------------------
// Zip archives

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
fn join_zip(dir: &str, rel: &str) -> Option<String> {
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

fn parent_dir(name: &str) -> &str {
    name.rsplit_once('/').map(|(d, _)| d).unwrap_or("")
}

/// An opened library archive.
struct Library {
    source: Source,
    zip: zip::ZipArchive<fs::File>,
    names: HashSet<String>,
    entries: Vec<(usize, HashMap<String, String>)>,
    license: String,
    license_text: Option<String>,
    header: HashMap<String, String>,
}

impl Library {
    fn open(source: &Source) -> Result<Self> {
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
    fn folder(&self, dir: &str) -> Vec<String> {
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

fn read_entry(zip: &mut zip::ZipArchive<fs::File>, name: &str) -> Result<Vec<u8>> {
    let mut file = zip.by_name(name)?;
    let mut bytes = Vec::with_capacity(file.size() as usize);
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

// ---------------------------------------------------------------------------------------------
// OBJ and MTL

/// Lines of a text file as bytes, without the line end.
fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    bytes
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
}

/// The argument of a `keyword arg…` line, if the line is one.
fn statement(line: &[u8], keyword: &str) -> Option<String> {
    let text = String::from_utf8_lossy(line);
    let text = text.trim_start();
    let rest = text.strip_prefix(keyword)?;
    if !rest.starts_with([' ', '\t']) {
        return None;
    }
    let arg = rest.trim();
    (!arg.is_empty()).then(|| arg.to_string())
}

/// The archive file a reference (`mtllib`, `map_Kd` …) names, if it is a clean relative path
/// ([`safe_relative`]) to a file of the archive: the whole argument, else its last word (map
/// options such as `-s 1 1 1` come first, and disk paths with blanks such as
/// `/Users/x/Living room rug.jpg` end with the file's name). Other absolute paths from the
/// authors' disks (`C:/Documents and Settings/…`) and missing files give `None`.
fn resolve(lib: &Library, dir: &str, arg: &str) -> Option<Reference> {
    let last = arg.split_whitespace().last().unwrap_or("");
    [arg, last].into_iter().find_map(|a| {
        safe_relative(a)?;
        let name = join_zip(dir, a).filter(|n| lib.names.contains(n))?;
        Some(Reference {
            name,
            path: a.to_string(),
            whole: a == arg,
        })
    })
}

/// A file a reference names.
struct Reference {
    /// Its archive name.
    name: String,
    /// The path as written, relative to the referring file.
    path: String,
    /// Whether that is the whole argument (else its last word, after options or a disk path).
    whole: bool,
}

/// `text` with the lines that are keys of `new` replaced by their values, or `None` when
/// there are none.
fn rewrite(text: &[u8], new: &HashMap<Vec<u8>, String>) -> Option<Vec<u8>> {
    if new.is_empty() {
        return None;
    }
    let mut out = Vec::with_capacity(text.len() + 64 * new.len());
    for (i, line) in text.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        match new.get(line.strip_suffix(b"\r").unwrap_or(line)) {
            Some(replacement) => out.extend_from_slice(replacement.as_bytes()),
            None => out.extend_from_slice(line),
        }
    }
    Some(out)
}

/// A line commented out because the file it names is not in the library.
fn missing_line(line: &[u8]) -> String {
    format!(
        "# lfgen: file missing from the library: {}",
        String::from_utf8_lossy(line)
    )
}

/// What the converter learnt of one OBJ and its materials.
struct ObjPlan {
    /// The OBJ with an `mtllib` for its built-in names and missing `mtllib`s commented out.
    obj: Vec<u8>,
    /// Built-in material names the OBJ uses (not defined by its `.mtl` files).
    builtin: BTreeSet<String>,
    /// `.mtl` files and textures it needs (archive names).
    needs: BTreeSet<String>,
    /// `.mtl` files rewritten: references to missing textures commented out, the others
    /// reduced to the plain relative path (`map_Kd rug.jpg`, no options or disk path before it).
    patched: HashMap<String, Vec<u8>>,
    /// References to files absent from the library (or outside it).
    missing: usize,
}

fn plan_obj(lib: &mut Library, obj_name: &str, obj: &[u8], builtin_file: &str) -> ObjPlan {
    let dir = parent_dir(obj_name).to_string();
    let mut plan = ObjPlan {
        obj: Vec::new(),
        builtin: BTreeSet::new(),
        needs: BTreeSet::new(),
        patched: HashMap::new(),
        missing: 0,
    };
    let mut missing_libs = HashMap::new();
    let mut defined = HashSet::new();
    let mut used = BTreeSet::new();
    for line in lines(obj) {
        if let Some(name) = statement(line, "usemtl") {
            used.insert(name);
            continue;
        }
        let Some(arg) = statement(line, "mtllib") else {
            continue;
        };
        let Some(Reference { name: mtl, .. }) = resolve(lib, &dir, &arg) else {
            missing_libs.insert(line.to_vec(), missing_line(line));
            plan.missing += 1;
            continue;
        };
        let Ok(text) = read_entry(&mut lib.zip, &mtl) else {
            continue;
        };
        let mtl_dir = parent_dir(&mtl).to_string();
        let mut new_lines = HashMap::new();
        for l in lines(&text) {
            if let Some(name) = statement(l, "newmtl") {
                defined.insert(name);
            }
            let s = String::from_utf8_lossy(l);
            let mut it = s.trim_start().splitn(2, [' ', '\t']);
            let key = it.next().unwrap_or("");
            let lower = key.to_ascii_lowercase();
            let map = lower.starts_with("map_")
                || matches!(lower.as_str(), "bump" | "disp" | "decal" | "refl");
            if let (true, Some(arg)) = (map, it.next()) {
                match resolve(lib, &mtl_dir, arg.trim()) {
                    Some(file) => {
                        if !file.whole {
                            new_lines.insert(l.to_vec(), format!("{key} {}", file.path));
                        }
                        plan.needs.insert(file.name);
                    }
                    None => {
                        new_lines.insert(l.to_vec(), missing_line(l));
                        plan.missing += 1;
                    }
                }
            }
        }
        if let Some(patched) = rewrite(&text, &new_lines) {
            plan.patched.insert(mtl.clone(), patched);
        }
        plan.needs.insert(mtl);
    }
    plan.builtin = used.into_iter().filter(|n| !defined.contains(n)).collect();
    if !plan.builtin.is_empty() {
        plan.obj.extend_from_slice(
            format!("# lfgen: materials Sweet Home 3D supplies itself\nmtllib {builtin_file}\n")
                .as_bytes(),
        );
    }
    match rewrite(obj, &missing_libs) {
        Some(patched) => plan.obj.extend_from_slice(&patched),
        None => plan.obj.extend_from_slice(obj),
    }
    plan
}

// ---------------------------------------------------------------------------------------------
// Conversion

/// Writes `bytes` to `path` through a temporary file and a rename.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let written = fs::File::create(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()
    });
    written.with_context(|| format!("cannot write {}", tmp.display()))?;
    fs::rename(&tmp, path).with_context(|| format!("cannot rename to {}", path.display()))
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Some(dir) = path.parent() {
        fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
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

/// One line of the attribution list.
struct Credit {
    library: String,
    name: String,
    author: String,
    license: String,
    origin: String,
    file: String,
}

/// Converts the libraries into `<out>/catalog.json` (see the module documentation).
pub fn convert(sources: &[Source], out: &Path, opts: &ConvertOptions) -> Result<Summary> {
    fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut libraries = Vec::new();
    for source in sources {
        if safe_relative(&source.name).is_none() || source.name.contains('/') {
            bail!("library name {:?} is not a plain folder name", source.name);
        }
        libraries.push(Library::open(source)?);
    }
    let mut summary = Summary {
        out: out.to_path_buf(),
        nonfree_included: opts.nonfree,
        ..Summary::default()
    };
    summary.entries = libraries.iter().map(|l| l.entries.len()).sum();
    let bar = if opts.progress {
        let bar = ProgressBar::new(summary.entries as u64);
        let style = "{elapsed_precise} [{bar:30}] {pos}/{len} catalogue entries — {msg}";
        bar.set_style(
            ProgressStyle::with_template(style)
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut assets: Vec<Asset> = Vec::new();
    let mut ids = HashSet::new();
    let mut credits = Vec::new();
    let mut all_builtin = BTreeSet::new();
    let mut written = HashSet::new();
    for lib in &mut libraries {
        bar.set_message(lib.source.name.clone());
        let entries = std::mem::take(&mut lib.entries);
        for (index, fields) in &entries {
            bar.inc(1);
            let outcome =
                convert_entry(lib, *index, fields, out, opts, &mut summary, &mut written)?;
            let (mut asset, builtin) = match outcome {
                Ok(done) => done,
                Err(reason) => {
                    summary.skip(&reason);
                    continue;
                }
            };
            let base = asset.id.clone();
            let mut n = 2;
            while !ids.insert(asset.id.clone()) {
                asset.id = format!("{base}~{n}");
                n += 1;
            }
            summary.patched_objs += !builtin.is_empty() as usize;
            all_builtin.extend(builtin);
            *summary
                .per_license
                .entry(asset.license.clone())
                .or_default() += 1;
            credits.push(Credit {
                library: lib.source.name.clone(),
                name: asset.name.clone(),
                author: asset.author.clone(),
                license: asset.license.clone(),
                origin: asset.origin.clone(),
                file: asset.file.clone(),
            });
            assets.push(asset);
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
    summary.written = assets.len();
    summary.builtin_materials = all_builtin.len();
    write_atomic(&out.join(BUILTIN_MTL), builtin_mtl(&all_builtin).as_bytes())?;
    write_atomic(
        &out.join("ATTRIBUTION.md"),
        attribution(&libraries, &credits).as_bytes(),
    )?;
    let catalog = Catalog {
        version: VERSION,
        assets,
    };
    let json = serde_json::to_string_pretty(&catalog).context("cannot encode catalog.json")?;
    write_atomic(&out.join("catalog.json"), json.as_bytes())?;
    Ok(summary)
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
    let get = |k: &str| {
        fields
            .get(k)
            .map(|v| v.trim().to_string())
            .unwrap_or_default()
    };
    let model = get("model");
    let model = model.trim_start_matches('/');
    let ext = Path::new(model)
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_else(|| "(none)".into());
    if ext != "obj" {
        *summary.skipped_formats.entry(ext).or_default() += 1;
        return Ok(Err("model not .obj".into()));
    }
    if safe_relative(model).is_none() {
        summary.unsafe_names += 1;
        return Ok(Err("unsafe model path".into()));
    }
    if !lib.names.contains(model) {
        return Ok(Err("model file missing".into()));
    }
    let numbers = (|| -> Result<_, String> {
        let need = |k: &str| number(fields, k)?.ok_or_else(|| format!("no {k}"));
        let (w, d, h) = (need("width")?, need("depth")?, need("height")?);
        let elevation = number(fields, "elevation")?.unwrap_or(0.0);
        let drop = number(fields, "dropOnTopElevation")?;
        let rotation = match fields.get("modelRotation") {
            None => None,
            Some(r) => {
                let v: Vec<f32> = r
                    .split_whitespace()
                    .filter_map(|x| x.parse().ok())
                    .collect();
                let m: [f32; 9] = v.try_into().map_err(|_| format!("modelRotation={r:?}"))?;
                Some(m)
            }
        };
        Ok((w, d, h, elevation, drop, rotation))
    })();
    let Ok((w, d, h, elevation_cm, drop, rotation)) = numbers else {
        return Ok(Err("unreadable size or rotation".into()));
    };
    let size = [w / 100.0, h / 100.0, d / 100.0];
    let elevation = elevation_cm.max(0.0) / 100.0;
    if size
        .iter()
        .any(|&v| !(SIZE_LIMITS[0]..=SIZE_LIMITS[1]).contains(&v))
    {
        return Ok(Err(format!(
            "size outside [{}, {}] m (paper-thin pieces: bills, rulers, hobs)",
            SIZE_LIMITS[0], SIZE_LIMITS[1]
        )));
    }
    let obj = read_entry(&mut lib.zip, model)
        .with_context(|| format!("{}: {model}", lib.source.archive.display()))?;
    let license = fields
        .get("license")
        .map(|l| license_id(l).unwrap_or_else(|| l.trim().to_string()))
        .or_else(|| obj_header_license(&obj))
        .unwrap_or_else(|| lib.license.clone());
    if !is_free_license(&license) {
        *summary.nonfree.entry(license.clone()).or_default() += 1;
        if !opts.nonfree {
            return Ok(Err("non-free licence (use --nonfree)".into()));
        }
    }
    // Files: the OBJ (patched), its materials and textures, and for multi-part models the rest
    // of the model's folder.
    let stem = Path::new(model)
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy();
    let builtin_file: String = format!("{stem}{BUILTIN_SUFFIX}")
        .chars()
        .map(|c| if c.is_whitespace() { '_' } else { c })
        .collect();
    let plan = plan_obj(lib, model, &obj, &builtin_file);
    summary.missing_files += plan.missing;
    let lib_dir = out.join(&lib.source.name);
    let mut files: BTreeSet<String> = plan.needs.clone();
    if get("multiPartModel") == "true" {
        let dir = parent_dir(model);
        if !dir.is_empty() {
            files.extend(lib.folder(dir));
        }
    }
    files.remove(model);
    for name in files {
        let Some(rel) = safe_relative(&name) else {
            summary.unsafe_names += 1;
            continue;
        };
        let target = lib_dir.join(&rel);
        // Rewritten files always replace raw copies; raw copies never replace anything.
        if let Some(bytes) = plan.patched.get(&name) {
            write_file(&target, bytes)?;
            written.insert(target);
            continue;
        }
        if written.contains(&target) {
            continue;
        }
        let mut entry = lib.zip.by_name(&name)?;
        // The zip crate's own check as well as ours.
        if entry.enclosed_name().is_none() {
            summary.unsafe_names += 1;
            continue;
        }
        let mut bytes = Vec::with_capacity(entry.size() as usize);
        entry.read_to_end(&mut bytes)?;
        write_file(&target, &bytes)?;
        written.insert(target);
    }
    let target = lib_dir.join(model);
    write_file(&target, &plan.obj)?;
    written.insert(target.clone());
    if !plan.builtin.is_empty() {
        let mtl = target.with_file_name(&builtin_file);
        write_file(&mtl, builtin_mtl(&plan.builtin).as_bytes())?;
        written.insert(mtl);
    }
    let name = get("name");
    let category = get("category");
    let elevation = hood_elevation(&name, elevation);
    let placement = placement(&name, &category, &get("tags"), size, elevation);
    let id = match get("id") {
        id if id.is_empty() => format!("{}#{index}", lib.source.name),
        id => id,
    };
    let author = match get("creator") {
        a if a.is_empty() => lib
            .header
            .get("provider")
            .cloned()
            .unwrap_or_else(|| "unknown".into()),
        a => a,
    };
    let asset = Asset {
        id,
        name,
        file: format!("{}/{model}", lib.source.name),
        category,
        size,
        placement,
        elevation,
        surfaces: surfaces(drop, h, placement),
        rotation,
        weight: 1.0,
        license,
        author,
        origin: lib.source.origin.clone(),
    };
    if let Some(problem) = asset.problem() {
        return Ok(Err(format!("refused by the catalogue check: {problem}")));
    }
    Ok(Ok((asset, plan.builtin)))
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

/// The `(C) …` / `Copyright …` line of a licence text, if any.
fn copyright_line(text: &str) -> Option<String> {
    text.lines()
        .map(str::trim)
        .find(|l| l.starts_with("(C)") || l.to_lowercase().starts_with("copyright"))
        .map(String::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn properties_comments_separators_and_escapes() {
        let text = "# comment\n! other comment\n   \nid=SweetHome3D#Lib\n\
                    name#1 = Chair \\u00e9t\\u00E9\n\
                    width#1:45\nkey\\ with\\=stuff value\\tx\nempty#1=\nsurrogate=\\uD83C\\uDF10\n";
        let pairs = parse_properties(text);
        let map: HashMap<_, _> = pairs.iter().cloned().collect();
        assert_eq!(map["id"], "SweetHome3D#Lib");
        assert_eq!(map["name#1"], "Chair été");
        assert_eq!(map["width#1"], "45");
        assert_eq!(map["key with=stuff"], "value\tx");
        assert_eq!(map["empty#1"], "");
        assert_eq!(map["surrogate"], "🌐");
        assert_eq!(pairs.len(), 6);
    }

    #[test]
    fn properties_continuations_and_latin1() {
        let text =
            "tags#2=a, \\\n    b, \\\r\n  c\nback=ends with \\\\\nnext=1\n#not=a key\nlast=x\\";
        let map: HashMap<_, _> = parse_properties(text).into_iter().collect();
        assert_eq!(map["tags#2"], "a, b, c");
        assert_eq!(map["back"], "ends with \\");
        assert_eq!(map["next"], "1");
        assert_eq!(map["last"], "x");
        assert!(!map.contains_key("#not"));
        // ISO-8859-1 bytes (invalid UTF-8) and UTF-8 both decode.
        assert_eq!(decode_properties(b"name=H\xf4i An"), "name=Hôi An");
        assert_eq!(decode_properties("name=Hôi An".as_bytes()), "name=Hôi An");
    }

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

    #[test]
    fn licences_and_materials() {
        assert_eq!(
            license_id("Creative Commons Zero (Public Domain)").as_deref(),
            Some("CC0-1.0")
        );
        assert_eq!(
            license_id(
                "Attribution 3.0 United States http://creativecommons.org/licenses/by/3.0/us/"
            )
            .as_deref(),
            Some("CC-BY-3.0-US")
        );
        assert_eq!(
            license_id("Creative Commons Attribution 3.0 Unported").as_deref(),
            Some("CC-BY-3.0")
        );
        assert_eq!(license_id("CC BY-NC 4.0").as_deref(), Some("CC-BY-NC-4.0"));
        assert!(is_free_license("CC-BY-3.0 OR GPL-2.0-or-later"));
        assert!(!is_free_license("CC-BY-NC-4.0"));
        assert!(!is_free_license("unknown"));
        for glass in [
            "glass",
            "glasstransparent",
            "cristal_blanco",
            "Verre",
            "vidrio",
            "Fenster_Glas",
            "window",
        ] {
            let m = builtin_material(glass);
            assert!((0.15..=0.3).contains(&m.opacity), "{glass}: {m:?}");
        }
        let luminance = |n: &str| builtin_material(n).diffuse.iter().sum::<f32>() / 3.0;
        assert!(luminance("black") < 0.05 && luminance("white") > 0.8);
        assert!(
            luminance("dkgrey") < luminance("grey") && luminance("grey") < luminance("flltgrey")
        );
        let red = builtin_material("red").diffuse;
        assert!(red[0] > 0.5 && red[1] < 0.2);
        let redwood = builtin_material("redwood").diffuse;
        assert!(
            redwood[1] > 0.15,
            "redwood is a wood, not pure red: {redwood:?}"
        );
        assert_eq!(builtin_material("white").opacity, 1.0);
    }

    #[test]
    fn placement_rules() {
        use AssetPlacement::*;
        let p = |name, cat, tags, s: [f32; 3], e| placement(name, cat, tags, s, e);
        assert_eq!(
            p("Pendant lamp", "Lights", "", [0.6, 0.8, 0.6], 1.7),
            Ceiling
        );
        assert_eq!(
            p("Wall spotlight", "Lights", "", [0.06, 0.1, 0.23], 1.9),
            WallHung
        );
        assert_eq!(p("Hood", "Kitchen", "", [0.6, 0.94, 0.52], 1.56), WallHung);
        assert_eq!(hood_elevation("Range hood", 0.0), 1.5);
        assert_eq!(hood_elevation("Hood", 1.56), 1.56);
        assert_eq!(
            p(
                "Wall switch",
                "Miscellaneous",
                "",
                [0.085, 0.085, 0.011],
                1.15
            ),
            WallHung
        );
        assert_eq!(
            p(
                "Oriental rug",
                "Living room",
                "Carpet",
                [1.86, 0.025, 2.58],
                0.0
            ),
            FloorCover
        );
        assert_eq!(p("Teapot", "Kitchen", "", [0.22, 0.21, 0.15], 0.0), OnTop);
        assert_eq!(
            p("Stool", "Living room", "Chair, Seat", [0.4, 0.46, 0.4], 0.0),
            Floor
        );
        assert_eq!(
            p(
                "Bedside table",
                "Bedroom",
                "Nightstand",
                [0.38, 0.5, 0.38],
                0.0
            ),
            Floor
        );
        assert_eq!(
            p("Wardrobe", "Bedroom", "Closet", [1.0, 1.65, 0.54], 0.0),
            Wall
        );
        assert_eq!(p("Table", "Living room", "", [1.5, 0.74, 0.75], 0.0), Floor);
        let tv = "Blend Swap, Appliance, Television";
        assert_eq!(
            p("TV", "Living room", tv, [0.775, 0.508, 0.142], 0.0),
            OnTop
        );
        assert_eq!(
            p("Island", "Kitchen", "Cabinet", [0.94, 0.83, 0.7], 0.0),
            Floor
        );
    }

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

        let catalog = crate::catalog::LoadedCatalog::read(&out.join("catalog.json")).unwrap();
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
