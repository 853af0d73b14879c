//! One scene from description to published folder: build, frame, render every view, write —
//! for generated scenes, imported glTF scenes and saved `scene.json` files alike.

use crate::appearance::ImageStats;
use crate::config::{BaselineMode, Config, GtViews};
use crate::output::images::ToneCurve;
use crate::output::scene_dir::{GtImages, SceneWriter};
use crate::procgen::builtin;
use crate::procgen::library::AssetLibrary;
use crate::render::RenderScene;
use crate::render::cache::CacheParams;
use crate::render::integrator::PathSettings;
use crate::render::light_field::LightFieldSettings;
use crate::render::sensor::SensorSettings;
use crate::render::view::ViewOutput;
use crate::scene::SceneDesc;
use crate::scene::assets::Assets;
use crate::stats::SceneStats;
use anyhow::{Context, Result, bail};
use lfformat::manifest::FileEntry;
use std::path::Path;
use std::sync::atomic::AtomicU64;

/// A render of one scene as the CLI runs it: the renderer's settings, and how the files are
/// written.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub render: LightFieldSettings,
    pub write_exr: bool,
    pub tone_curve: ToneCurve,
    /// Date written into parameters.cfg.
    pub date: String,
    /// The camera model the written views go through (off: the clean render).
    pub sensor: SensorSettings,
}

impl RenderJob {
    pub fn from_config(cfg: &Config, date: &str) -> Self {
        let r = &cfg.render;
        let render = LightFieldSettings {
            spp: r.spp,
            adaptive_spp: r.adaptive_spp,
            adaptive_threshold: r.adaptive_threshold as f32,
            gt_spp: if r.gt_spp == 0 { r.spp } else { r.gt_spp },
            path: PathSettings {
                max_depth: r.max_depth,
                rr_depth: r.rr_depth,
                footprint: 0.0, // per scene: see `LightFieldSettings::view_settings`
                glass_light: r.glass_light,
                split_glass: r.split_glass,
            },
            gt_views: r.gt_views,
            gt_highres: r.gt_highres,
            mode_epsilon: r.mode_epsilon as f32,
            shade_all_hits: r.write_slices,
            slice_assignment: r.slice_assignment,
            auto_exposure: r.auto_exposure,
            shading: r.shading,
            cache_spp: r.cache_spp,
            cache: CacheParams {
                cell_px: r.cache_cell as f32,
                glossy_share: r.glossy_share as f32,
                glossy_min_width: r.glossy_min_width as f32,
                fill_vertices: r.fill_vertices,
                fill_light_samples: r.fill_light_samples,
                shrink: r.cache_shrink,
                final_gather: r.final_gather,
            },
            texture_filter: r.texture_filter,
        };
        Self {
            render,
            write_exr: r.write_exr,
            tone_curve: r.tone_curve,
            date: date.to_string(),
            sensor: cfg.sensor.clone(),
        }
    }
}

/// Generates scene `index` of `cfg` (drawing catalogue pieces from `library`, if any) and
/// frames its camera: the re-renderable description.
pub fn generate_scene(
    cfg: &Config,
    index: u64,
    library: Option<&AssetLibrary>,
) -> Result<(SceneDesc, RenderScene)> {
    let mut desc = builtin::generate(&cfg.scene, &cfg.scene_start(), index, library);
    desc.validate()
        .context("the generator made an invalid scene")?;
    let assets = Assets::load(&desc)?;
    let scene = RenderScene::build_with(&desc, &assets)?;
    frame(&mut desc, &scene, cfg)?;
    Ok((desc, scene))
}

/// Fits the camera (automatic baseline and focus) and the slices of a new scene to the depth
/// range its camera grid sees, replacing the placeholders it was built with.
fn frame(desc: &mut SceneDesc, scene: &RenderScene, cfg: &Config) -> Result<()> {
    let fit = (cfg.camera.baseline == BaselineMode::Auto).then_some(cfg.camera.disparity_range);
    let r = &cfg.render;
    (desc.camera, desc.slices) = scene.frame(&desc.camera, fit, r.slices, r.slice_spacing)?;
    Ok(())
}

/// Renders every view of `desc` into `final_dir` (atomically) and returns the published files.
/// `samples_done` counts camera samples for progress display.
pub fn render_scene(
    desc: &mut SceneDesc,
    scene: &RenderScene,
    job: &RenderJob,
    final_dir: &Path,
    root: &Path,
    samples_done: &AtomicU64,
) -> Result<Vec<FileEntry>> {
    let mut writer = SceneWriter::create(final_dir, job.write_exr, job.tone_curve)?
        .with_clean_views(job.sensor.write_clean);
    let capture = job.sensor.capture(desc.seed, desc.index);
    let (center, per_view) = (
        desc.camera.center_view(),
        job.render.gt_views == GtViews::All,
    );
    let mut stats = None;
    let exposure = scene.render_light_field(desc, &job.render, samples_done, |v| {
        let (view, image, exposure) = (v.view, &v.output.image, v.exposure);
        let recorded = capture.map(|c| c.develop(&image.pixels, image.width, exposure, view));
        let size = (image.width, image.height);
        writer.write_view(view, size, &image.pixels, exposure, recorded.as_deref())?;
        if let Some(gt) = &v.output.gt {
            let images = GtImages {
                modes: &gt.modes,
                colors: &gt.colors,
                surfaces: &gt.surfaces,
                hci: &gt.hci,
                valid: &gt.valid,
            };
            writer.write_gt(view, view == center, per_view, &desc.camera, &images)?;
            if let Some(layer) = &v.highres {
                let (cam, scale) = (&desc.camera, job.render.gt_highres);
                writer.write_highres((view, view == center, per_view), cam, layer, scale)?;
            }
        }
        if view == center {
            let mut s = scene_stats(desc, scene, &v.output, job, exposure);
            let written = match &recorded {
                Some(recorded) => job.tone_curve.encode(recorded, 1.0),
                None => job.tone_curve.encode(&image.pixels, exposure),
            };
            s.appearance = ImageStats::of_rgb8(&written, image.width, image.height);
            s.camera = capture.map(|c| c.draw);
            stats = Some(s);
        }
        Ok(())
    })?;
    desc.exposure = exposure;
    writer.finish(desc, &stats.expect("centre view rendered"), root)
}

fn scene_stats(
    desc: &SceneDesc,
    scene: &RenderScene,
    out: &ViewOutput,
    job: &RenderJob,
    exposure: f32,
) -> SceneStats {
    let gt = out.gt.as_ref().expect("centre view has GT");
    let hci_disp: Vec<f32> = gt
        .hci
        .depth
        .iter()
        .map(|&z| desc.camera.disparity(z as f64) as f32)
        .collect();
    let mut s = SceneStats::from_gt(&gt.modes, &hci_disp, &gt.valid);
    s.baseline_mm = desc.camera.baseline_m * 1000.0;
    s.focus_distance_m = desc.camera.focus_distance_m;
    s.depth_range_m = [desc.slices.z_near, desc.slices.z_far];
    s.exposure = exposure;
    s.triangles = scene.geometry.triangle_count() as u64;
    s.date = job.date.clone();
    s.placement = desc.placement.clone();
    s
}

/// `lfgen render FILE --out DIR`: a glTF 2.0 scene (`.gltf`, `.glb`) is imported and
/// rendered; anything else is read as a saved `scene.json` and rendered again. `camera` (a
/// glTF camera name) overrides `gltf.camera`.
pub fn render_file(
    cfg: &Config,
    input: &Path,
    camera: Option<&str>,
    out: &Path,
    quiet: bool,
) -> Result<()> {
    let ext = input.extension().map(|e| e.to_ascii_lowercase());
    match ext.as_ref().and_then(|e| e.to_str()) {
        Some("gltf" | "glb") => {
            let mut cfg = cfg.clone();
            if let Some(name) = camera {
                cfg.gltf.camera = name.to_string();
            }
            render_gltf(&cfg, input, out, quiet)
        }
        _ if camera.is_some() => bail!(
            "--camera applies to glTF scenes (.gltf, .glb); {} keeps its saved camera",
            input.display()
        ),
        _ => rerender(cfg, input, out, quiet),
    }
}

/// Imports a glTF scene, frames its camera grid (baseline and focus per `cfg.camera`) and
/// writes it as a scene folder, like a generated scene.
pub fn render_gltf(cfg: &Config, gltf: &Path, out: &Path, quiet: bool) -> Result<()> {
    let imported = crate::scene::gltf::import(gltf, &cfg.gltf_import())?;
    for w in &imported.warnings {
        lfformat::note!("warning: {}: {w}", gltf.display());
    }
    let mut desc = imported.desc;
    let scene = RenderScene::build_with(&desc, &imported.assets)
        .with_context(|| gltf.display().to_string())?;
    frame(&mut desc, &scene, cfg).with_context(|| gltf.display().to_string())?;
    let (near, far) = (desc.slices.z_near, desc.slices.z_far);
    if cfg.camera.baseline == BaselineMode::Auto && far < 1.1 * near {
        lfformat::note!(
            "warning: {}: the camera sees depths {near:.3}–{far:.3} m only, so the automatic \
             baseline is {:.3} m; set camera.baseline=fixed for a physical one",
            gltf.display(),
            desc.camera.baseline_m
        );
    }
    let job = RenderJob::from_config(cfg, &cfg.dataset.render_date());
    publish(&mut desc, &scene, &job, out, quiet)
}

/// `lfgen render SCENE.json --out DIR`: renders a saved scene again, with its saved camera,
/// slices and exposure, and the render settings of `cfg`.
pub fn rerender(cfg: &Config, scene_json: &Path, out: &Path, quiet: bool) -> Result<()> {
    let mut desc = SceneDesc::read(scene_json)?;
    let assets = Assets::load(&desc).with_context(|| scene_json.display().to_string())?;
    let scene = RenderScene::build_with(&desc, &assets)
        .with_context(|| scene_json.display().to_string())?;
    let mut job = RenderJob::from_config(cfg, &cfg.dataset.render_date());
    job.render.auto_exposure = false;
    publish(&mut desc, &scene, &job, out, quiet)
}

/// Renders one scene into the folder `out` (its parent is created) and reports it.
fn publish(
    desc: &mut SceneDesc,
    scene: &RenderScene,
    job: &RenderJob,
    out: &Path,
    quiet: bool,
) -> Result<()> {
    let root = out
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(root).with_context(|| format!("cannot create {}", root.display()))?;
    let samples = AtomicU64::new(0);
    render_scene(desc, scene, job, out, root, &samples)?;
    if !quiet {
        lfformat::note!(
            "{}: {} camera rays, written to {}",
            desc.name,
            samples.into_inner(),
            out.display()
        );
    }
    Ok(())
}
