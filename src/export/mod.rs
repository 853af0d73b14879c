//! `lfgen export`: a saved scene written for another renderer — POV-Ray 3.7, Mitsuba 3 or
//! Blender (Cycles) — with every light-field view as a true off-axis (shifted-sensor) camera,
//! so that independent renderers can check lfgen's images and ground truth (README,
//! "Validation").
//!
//! [`extract`] does everything the targets share (world triangles from the renderer's own
//! tessellation, the off-axis cameras); each target module only converts conventions.

pub mod blender;
pub mod extract;
pub mod mitsuba;
mod obj;
pub mod pov;

use crate::scene::assets::Assets;
use anyhow::{Context, Result};
use extract::{ExportScene, ViewSelection};
use std::path::Path;

/// The renderers lfgen exports to (`lfgen export --to`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// POV-Ray 3.7 scene files.
    #[value(alias = "povray")]
    Pov,
    /// Blender (Cycles): scene.py, which builds the scene and renders a view.
    #[value(alias = "cycles")]
    Blender,
    /// Mitsuba 3: scene.xml with one sensor per view.
    Mitsuba,
}

/// Path limits in lfgen's terms (`render.max_depth` vertices, Russian roulette from vertex
/// `render.rr_depth`), converted per renderer so that a comparison renders the same paths.
#[derive(Clone, Copy, Debug)]
pub struct PathLimits {
    pub max_depth: u32,
    pub rr_depth: u32,
}

/// Exports `SCENE_DIR/scene.json` for `target` into `out` (created) with the views `views`.
pub fn export_scene_dir(
    scene_dir: &Path,
    target: Target,
    out: &Path,
    views: &ViewSelection,
    limits: PathLimits,
) -> Result<()> {
    let json = scene_dir.join("scene.json");
    let desc = crate::scene::SceneDesc::read(&json)?;
    let assets = Assets::load(&desc).with_context(|| json.display().to_string())?;
    let views = views.resolve(&desc.camera)?;
    let scene =
        ExportScene::new(&desc, &assets, &views).with_context(|| json.display().to_string())?;
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    match target {
        Target::Pov => pov::write(&scene, out),
        Target::Mitsuba => mitsuba::write(&scene, out, limits),
        Target::Blender => blender::write(&scene, out, limits.max_depth),
    }
}

/// Writes a text file, naming it in the error.
fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes every object's mesh as `out/meshes/<id>.obj`.
fn write_meshes(scene: &ExportScene, out: &Path) -> Result<()> {
    let dir = out.join("meshes");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for m in &scene.meshes {
        write_file(&out.join(obj::path(m)), &obj::text(m))?;
    }
    Ok(())
}
