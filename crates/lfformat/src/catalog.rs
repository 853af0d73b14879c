//! The external asset catalogue (`catalog.json`): which model files exist, what they are, how
//! large they are in reality and where they may stand. The built-in generator draws pieces from
//! it (besides its procedural furniture) when `scene.catalog` names one.
//!
//! A catalogue is data written by people or by `lfgen assets fetch`; reading it checks every
//! entry and reports what is wrong with it by id, so a bad entry can be skipped with one warning
//! instead of failing a whole dataset. The schema lives here, with the other file formats: the
//! converter that writes catalogues (`lfassets`) and the generator that reads them (`lfprocgen`)
//! both depend on it, and neither on the other.

use crate::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Current schema version of `catalog.json`.
pub const VERSION: u32 = 1;

/// A list of model files with their real sizes and placement rules.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Catalog {
    pub version: u32,
    pub assets: Vec<Asset>,
}

/// One model of the catalogue. The model's own frame: +Y up, front towards +Z (the side that
/// faces the room; the back goes against a wall), after `rotation`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Asset {
    /// Unique id, e.g. `"Scopia#bathroom3"`.
    pub id: String,
    /// Human-readable name.
    pub name: String,
    /// Model file (`.obj` with its `.mtl`, `.gltf` or `.glb`), relative to the catalogue's
    /// folder. It may not leave that folder.
    pub file: String,
    /// Free-form category, e.g. `"Living room"`; weights are per category.
    pub category: String,
    /// Real size in metres: width (x), height (y), depth (z). The model is scaled to it.
    pub size: [f32; 3],
    pub placement: AssetPlacement,
    /// Height of the model's bottom above the floor (wall-hung and ceiling pieces), metres.
    #[serde(default)]
    pub elevation: f32,
    /// Heights above the model's bottom (metres) of the surfaces others can stand on; each
    /// spans the model's footprint.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub surfaces: Vec<f32>,
    /// Rotation applied to the file's coordinates before scaling: a row-major 3×3 matrix
    /// (Sweet Home 3D's `modelRotation`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f32; 9]>,
    /// Relative frequency within its category (default 1).
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub weight: f32,
    /// Licence of the model, e.g. `"CC-BY-3.0"`.
    pub license: String,
    /// Author (creator) of the model.
    pub author: String,
    /// Where it came from, e.g. `"sweethome3d-furniture 1.8-1: Scopia.sh3f"`.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub origin: String,
}

/// Where a catalogue model is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AssetPlacement {
    /// On the floor, free-standing or with its back against a wall.
    Floor,
    /// On the floor, back against a wall (cabinets, wardrobes, shelves).
    Wall,
    /// Hanging on a wall at `elevation` (pictures, wall shelves, wall lamps).
    WallHung,
    /// On a surface of another piece (vases, lamps, books).
    OnTop,
    /// Hanging from the ceiling (pendant lamps): its top touches the ceiling.
    Ceiling,
    /// Flat on the floor; others may stand on it (rugs).
    FloorCover,
}

fn one() -> f32 {
    1.0
}

fn is_one(w: &f32) -> bool {
    *w == 1.0
}

/// Sizes outside this range (metres) are refused as absurd.
pub const SIZE_LIMITS: [f32; 2] = [0.005, 20.0];

impl Asset {
    /// What is wrong with this entry, if anything (sizes, weight, file path).
    pub fn problem(&self) -> Option<String> {
        let bad_size = |v: f32| !(SIZE_LIMITS[0]..=SIZE_LIMITS[1]).contains(&v);
        if self.size.iter().any(|&v| bad_size(v)) {
            return Some(format!(
                "size {:?} m is outside [{}, {}] m",
                self.size, SIZE_LIMITS[0], SIZE_LIMITS[1]
            ));
        }
        if !(self.elevation.is_finite() && (0.0..=SIZE_LIMITS[1]).contains(&self.elevation)) {
            return Some(format!("elevation {} m is not sensible", self.elevation));
        }
        if self
            .surfaces
            .iter()
            .any(|&s| !(0.0..=self.size[1]).contains(&s))
        {
            return Some(format!(
                "surface heights {:?} are not within the height {} m",
                self.surfaces, self.size[1]
            ));
        }
        if !(self.weight.is_finite() && self.weight >= 0.0) {
            return Some(format!(
                "weight {} is not a non-negative number",
                self.weight
            ));
        }
        if let Some(r) = self.rotation
            && r.iter().any(|v| !v.is_finite())
        {
            return Some("rotation has a non-finite entry".into());
        }
        match relative_inside(&self.file) {
            true => None,
            false => Some(format!(
                "file {:?} is not a relative path inside the catalogue folder",
                self.file
            )),
        }
    }
}

/// Whether `file` is a relative path that stays inside its base folder (no `..`, no root).
fn relative_inside(file: &str) -> bool {
    let p = Path::new(file);
    !file.is_empty()
        && p.components()
            .all(|c| matches!(c, std::path::Component::Normal(_)))
}

/// A catalogue read from disk: its entries and the folder their files are relative to.
#[derive(Clone, Debug)]
pub struct LoadedCatalog {
    pub path: PathBuf,
    pub dir: PathBuf,
    pub catalog: Catalog,
}

impl LoadedCatalog {
    /// Reads and parses `path`; the entries are not checked (see [`Asset::problem`]).
    pub fn read(path: &Path) -> Result<Self> {
        let text = crate::read::text(path)?;
        let catalog: Catalog = serde_json::from_str(&text)
            .map_err(|e| Error::format(path, format!("not a valid asset catalogue: {e}")))?;
        if catalog.version != VERSION {
            return Err(Error::format(
                path,
                format!(
                    "catalogue version {} (this lfgen reads version {VERSION})",
                    catalog.version
                ),
            ));
        }
        // A bare file name's parent is "", which names no folder: it is the working folder.
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        }
        .to_path_buf();
        Ok(Self {
            path: path.to_path_buf(),
            dir,
            catalog,
        })
    }

    /// Absolute-or-relative path of an entry's model file.
    pub fn file(&self, asset: &Asset) -> PathBuf {
        self.dir.join(&asset.file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn asset() -> Asset {
        Asset {
            id: "a".into(),
            name: "A".into(),
            file: "models/a.obj".into(),
            category: "Living room".into(),
            size: [0.5, 0.9, 0.5],
            placement: AssetPlacement::Floor,
            elevation: 0.0,
            surfaces: vec![0.45],
            rotation: None,
            weight: 1.0,
            license: "CC0-1.0".into(),
            author: "me".into(),
            origin: String::new(),
        }
    }

    #[test]
    fn entries_round_trip_and_bad_ones_say_why() {
        let c = Catalog {
            version: VERSION,
            assets: vec![asset()],
        };
        let json = serde_json::to_string_pretty(&c).unwrap();
        assert_eq!(serde_json::from_str::<Catalog>(&json).unwrap(), c);
        assert_eq!(asset().problem(), None);
        type Edit = fn(&mut Asset);
        let cases: [(Edit, &str); 5] = [
            (|a| a.size[0] = 0.0, "size"),
            (|a| a.size[1] = f32::NAN, "size"),
            (|a| a.file = "../x.obj".into(), "not a relative path"),
            (|a| a.file = "/etc/passwd".into(), "not a relative path"),
            (|a| a.surfaces = vec![2.0], "surface heights"),
        ];
        for (edit, says) in cases {
            let mut a = asset();
            edit(&mut a);
            let p = a.problem().expect("a problem");
            assert!(p.contains(says), "{p}");
        }
    }
}
