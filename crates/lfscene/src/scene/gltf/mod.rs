//! Importing a glTF 2.0 scene (`.gltf` + files beside it, or `.glb`) as a re-renderable
//! [`SceneDesc`]: meshes become [`Shape::Mesh`] objects that refer back to the file, materials
//! and `KHR_lights_punctual` lights are converted, and a camera node becomes the centre view.
//!
//! World space is glTF's (metres, +Y up, right-handed; cameras look along their local −Z), so
//! nothing is converted. Reading is defensive throughout ([`source`], [`accessor`]): a
//! malformed or hostile file gives an error naming what is wrong, never a panic.
//!
//! [`Shape::Mesh`]: crate::scene::Shape::Mesh

mod accessor;
mod material;
mod mesh;
mod nodes;
mod settings;
mod source;

pub use settings::{GltfSettings, ImportSettings};
pub use source::GltfFile;

use super::assets::{Assets, Source};
use super::{Material, SceneDesc};
use anyhow::{Context, Result};
use std::path::Path;

/// An imported scene: its description, the data it refers to, and what was ignored or
/// approximated (to report once each).
pub struct Imported {
    pub desc: SceneDesc,
    pub assets: Assets,
    pub warnings: Vec<String>,
}

/// Reads `path` with `settings`. The camera's baseline and focus and the slice range are
/// provisional until the renderer frames the scene.
pub fn import(path: &Path, settings: &ImportSettings) -> Result<Imported> {
    import_file(path, settings).with_context(|| path.display().to_string())
}

fn import_file(path: &Path, s: &ImportSettings) -> Result<Imported> {
    let file = GltfFile::open(path)?;
    let mut notes = Notes::default();
    let ignored = file.unsupported_extensions();
    if !ignored.is_empty() {
        notes.add(format!("extensions ignored: {}", ignored.join(", ")));
    }
    let scene = nodes::pick_scene(&file, &s.gltf.scene)?;
    let placed = nodes::flatten(&file, &scene)?;
    let converted = material::materials(&file, 0, &mut notes)?;
    let mut materials = converted.list;
    let objects = nodes::objects(&placed, &converted.uv_sets, &mut materials, &mut notes);
    let lights = nodes::lights(&placed)?;
    let camera = nodes::camera(&placed, s.gltf, &s.start.rig, &mut notes)?;
    let lit = !lights.is_empty() || materials.iter().any(Material::is_emissive);
    let environment = match lit {
        true => s.gltf.environment,
        false => s.gltf.unlit_environment,
    };
    let name = path
        .file_stem()
        .map_or("gltf".into(), |s| s.to_string_lossy().into_owned());
    let mut desc = SceneDesc {
        generator: format!("lfgen {}", env!("CARGO_PKG_VERSION")),
        name,
        index: 0,
        seed: s.start.seed,
        camera,
        slices: s.start.slices,
        environment: environment.map(|v| v as f32),
        exposure: s.start.exposure,
        materials,
        objects,
        lights,
        placement: None,
        sources: Vec::new(),
    };
    let file = [Source::Gltf(Box::new(file))];
    let assets = Assets::from_files(&desc, &file)?;
    // After loading, so the checksums of every file read are recorded.
    desc.sources = vec![file[0].source_file()?];
    // What the renderer relies on, checked where the description is made (as SceneDesc::read
    // does for a saved one), so no caller can skip it.
    desc.validate().context("unsupported scene")?;
    Ok(Imported {
        desc,
        assets,
        warnings: notes.0,
    })
}

/// Things the import ignored or approximated, each kept once.
#[derive(Default)]
struct Notes(Vec<String>);

impl Notes {
    fn add(&mut self, note: impl Into<String>) {
        let note = note.into();
        if !self.0.contains(&note) {
            self.0.push(note);
        }
    }
}
