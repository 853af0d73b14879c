//! The asset catalogue made ready for scene generation: every entry is checked once — its
//! fields, its model opened and validated, its textures decoded — and a broken or hostile
//! entry is skipped with one warning line (or refused, when strict). The entries that pass
//! become furniture [`Piece`]s whose parts refer to the model file ([`Shape::Mesh`]), scaled
//! to the catalogue's real size, so `scene.json` stays small and re-renderable.

use super::furniture::{Part, Piece, Placement, Surface};
use crate::catalog::{Asset, AssetPlacement, LoadedCatalog};
use crate::scene::obj::ObjFile;
use crate::scene::{Material, Opacity, Shape, SourceFile, Texture, Transform};
use anyhow::{Result, bail};
use glam::{Mat3, Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Free height above a piece's top surface (nothing of the piece is above it).
const OPEN_TOP: f32 = 3.0;

/// The usable entries of a catalogue.
pub struct AssetLibrary {
    assets: Vec<ReadyAsset>,
    /// One line per skipped entry: `id (file): problem`.
    pub skipped: Vec<String>,
}

/// A checked catalogue entry with what scenes need of its model.
struct ReadyAsset {
    asset: Asset,
    source: SourceFile,
    /// Per mesh of the file, its material (an index into `materials`, `None`: the default).
    meshes: Vec<Option<usize>>,
    /// Materials of the file; image maps name source 0 until a scene places the asset.
    materials: Vec<Material>,
    /// File coordinates → the catalogue's size, centred on the footprint, bottom at `y = 0`
    /// (column-major, as [`Shape::Mesh`] takes it).
    matrix: [f32; 16],
}

impl AssetLibrary {
    /// Reads the catalogue at `path` and checks every entry in parallel. Broken entries are
    /// skipped (see [`Self::skipped`]); with `strict` the first one is an error.
    pub fn open(path: &Path, strict: bool) -> Result<Self> {
        let loaded = LoadedCatalog::read(path)?;
        let checked: Vec<Result<ReadyAsset, String>> = (loaded.catalog.assets.par_iter())
            .map(|a| ready(&loaded, a).map_err(|e| format!("{} ({}): {e:#}", a.id, a.file)))
            .collect();
        let mut library = Self {
            assets: Vec::new(),
            skipped: Vec::new(),
        };
        let mut ids = std::collections::BTreeSet::new();
        for (entry, result) in loaded.catalog.assets.iter().zip(checked) {
            let result = match ids.insert(entry.id.as_str()) {
                true => result,
                false => Err(format!("{}: the id is used twice", entry.id)),
            };
            match result {
                Ok(ready) => library.assets.push(ready),
                Err(e) if strict => bail!("{}: {e}", path.display()),
                Err(e) => library.skipped.push(e),
            }
        }
        if library.assets.is_empty() {
            bail!("{}: no usable asset in the catalogue", path.display());
        }
        Ok(library)
    }

    pub fn len(&self) -> usize {
        self.assets.len()
    }

    pub fn is_empty(&self) -> bool {
        self.assets.is_empty()
    }

    /// Entry weights for drawing: the entry's own weight times its category's weight
    /// (categories not in `categories` weigh 1).
    pub fn weights(&self, categories: &BTreeMap<String, f64>) -> Vec<f32> {
        (self.assets.iter())
            .map(|r| {
                let c = categories.get(&r.asset.category).copied().unwrap_or(1.0);
                r.asset.weight * c as f32
            })
            .collect()
    }

    /// The catalogue entry `i`.
    pub fn asset(&self, i: usize) -> &Asset {
        &self.assets[i].asset
    }

    /// Where entry `i` is placed.
    pub fn piece_placement(&self, i: usize) -> Placement {
        placement(self.assets[i].asset.placement)
    }

    /// The source file entry `i`'s meshes refer to.
    pub fn source(&self, i: usize) -> &SourceFile {
        &self.assets[i].source
    }

    /// Entry `i` as a piece whose meshes refer to scene source `source`; `material` adds one
    /// of the model's materials to the scene (randomising it as the scene likes).
    pub fn piece(&self, i: usize, source: u32, material: &mut dyn FnMut(Material) -> u32) -> Piece {
        let r = &self.assets[i];
        let a = &r.asset;
        let elevation = match a.placement {
            AssetPlacement::WallHung => a.elevation,
            _ => 0.0,
        };
        let mut ids: BTreeMap<Option<usize>, u32> = BTreeMap::new();
        let mut parts = Vec::with_capacity(r.meshes.len());
        for (mesh, &m) in r.meshes.iter().enumerate() {
            let id = *ids.entry(m).or_insert_with(|| {
                let base = m.map_or_else(ObjFile::default_material, |m| r.materials[m].clone());
                material(with_source(base, source))
            });
            let shape = Shape::Mesh {
                source,
                mesh: mesh as u32,
                primitive: 0,
                uv_set: 0,
                matrix: r.matrix,
            };
            parts.push(Part {
                name: "mesh",
                shape,
                transform: Transform::at(Vec3::Y * elevation),
                material: id,
            });
        }
        let half = Vec2::new(a.size[0], a.size[2]) / 2.0;
        let surfaces = (a.surfaces.iter())
            .map(|&y| Surface {
                y: elevation + y,
                centre: Vec2::ZERO,
                half: half * 0.9,
                clearance: match y >= a.size[1] - 0.02 {
                    true => OPEN_TOP,
                    false => a.size[1] - y,
                },
            })
            .collect();
        Piece {
            placement: placement(a.placement),
            parts,
            half,
            height: elevation + a.size[1],
            surfaces,
            elevation,
            style: a.id.clone(),
        }
    }
}

fn placement(p: AssetPlacement) -> Placement {
    match p {
        AssetPlacement::Floor => Placement::Floor,
        AssetPlacement::Wall => Placement::Wall,
        AssetPlacement::WallHung => Placement::WallHung,
        AssetPlacement::OnTop => Placement::OnTop,
        AssetPlacement::Ceiling => Placement::Ceiling,
        AssetPlacement::FloorCover => Placement::FloorCover,
    }
}

/// Checks one entry: its fields, its model (glTF entries are not drawn from yet: OBJ only) and
/// every texture it uses.
fn ready(catalog: &LoadedCatalog, a: &Asset) -> Result<ReadyAsset> {
    if let Some(problem) = a.problem() {
        bail!("{problem}");
    }
    if !a.file.to_ascii_lowercase().ends_with(".obj") {
        bail!("only OBJ models are placed from a catalogue");
    }
    let file = ObjFile::open(&catalog.file(a), &catalog.dir)?;
    file.check_textures()?;
    let rot = a
        .rotation
        .map_or(Mat3::IDENTITY, |r| Mat3::from_cols_array(&r).transpose());
    let (lo, hi) = file.bounds(rot);
    let extent = hi - lo;
    if !(extent.is_finite() && extent.max_element() > 0.0) {
        bail!("the model has no extent");
    }
    // A flat model (a picture, a rug) keeps its zero thickness instead of dividing by it.
    let scale = Vec3::from(a.size) / extent.max(Vec3::splat(1e-6));
    let scale = Vec3::select(extent.cmpgt(Vec3::splat(1e-6)), scale, Vec3::ONE);
    let bottom_centre = Vec3::new((lo.x + hi.x) / 2.0, lo.y, (lo.z + hi.z) / 2.0);
    let matrix =
        Mat4::from_scale(scale) * Mat4::from_translation(-bottom_centre) * Mat4::from_mat3(rot);
    let meshes = (0..file.mesh_count() as u32)
        .map(|m| file.mesh_material(m))
        .collect();
    let materials = file.materials(0);
    let source = file.source_file()?;
    Ok(ReadyAsset {
        asset: a.clone(),
        source,
        meshes,
        materials,
        matrix: matrix.to_cols_array(),
    })
}

/// `m` with its image maps pointing at scene source `source`.
fn with_source(mut m: Material, source: u32) -> Material {
    if let Texture::Image { image, .. } = &mut m.base_color {
        image.source = source;
    }
    if let Opacity::Image { image, .. } = &mut m.opacity {
        image.source = source;
    }
    m
}
