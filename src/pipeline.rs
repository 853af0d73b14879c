//! One scene from description to published folder: build, frame, render every view, write —
//! for generated scenes, imported glTF scenes and saved `scene.json` files alike.

use crate::appearance::ImageStats;
use crate::camera::LightFieldCamera;
use crate::config::{BaselineMode, Config, GtViews, ShadingMode, SliceAssignment};
use crate::output::images::ToneCurve;
use crate::output::scene_dir::{GtImages, SceneWriter};
use crate::procgen::builtin;
use crate::procgen::library::AssetLibrary;
use crate::render::RenderScene;
use crate::render::cache::{CacheParams, RadianceCache};
use crate::render::framing::auto_exposure;
use crate::render::integrator::{PathSettings, Shading};
use crate::render::sensor::SensorSettings;
use crate::render::view::{Adaptive, RenderSettings, ViewOutput, gt_own_spp};
use crate::scene::SceneDesc;
use crate::scene::assets::Assets;
use crate::stats::SceneStats;
use anyhow::{Context, Result, bail};
use lfformat::manifest::FileEntry;
use std::path::Path;
use std::sync::atomic::AtomicU64;

/// Fill samples a shared-shading cache cell gathers per colour sample of a pixel, at least.
pub const FILL_PER_SPP: u32 = 1;

/// Fill samples a shared-shading cache cell gathers at least: where the views' fill takes
/// fewer per pixel footprint, cells grow until they hold this many (see
/// [`RenderJob::cache_params`]).
pub const CELL_FILL: f64 = 256.0;

/// Rendering choices that are not part of the scene itself.
#[derive(Clone, Debug)]
pub struct RenderJob {
    pub spp: u32,
    /// Extra samples of noisy pixels and the noise that calls for them ([`Adaptive`]).
    pub adaptive_spp: u32,
    pub adaptive_threshold: f32,
    /// Camera samples per pixel of the ground truth (`spp` unless configured).
    pub gt_spp: u32,
    pub path: PathSettings,
    pub gt_views: GtViews,
    /// High-resolution HCI ground truth at this many pixels per pixel (0: none).
    pub gt_highres: u32,
    pub mode_epsilon: f32,
    pub write_exr: bool,
    pub tone_curve: ToneCurve,
    /// Shade every hit of GT rays (true slice colours).
    pub shade_all_hits: bool,
    pub slice_assignment: SliceAssignment,
    /// Choose the exposure from the centre view (else keep the scene's).
    pub auto_exposure: bool,
    /// Date written into parameters.cfg.
    pub date: String,
    pub shading: ShadingMode,
    /// Fill samples per pixel of every view, at least (see [`RenderJob::fill_spp`]).
    pub cache_spp: u32,
    /// The configured cache; its cell is the smallest allowed (see [`RenderJob::cache_params`]).
    pub cache: CacheParams,
    /// Filter library textures over a sample's footprint (see [`PathSettings::footprint`]).
    pub texture_filter: bool,
    /// The camera model the written views go through (off: the clean render).
    pub sensor: SensorSettings,
}

impl RenderJob {
    pub fn from_config(cfg: &Config, date: &str) -> Self {
        let r = &cfg.render;
        Self {
            spp: r.spp,
            adaptive_spp: r.adaptive_spp,
            adaptive_threshold: r.adaptive_threshold as f32,
            gt_spp: if r.gt_spp == 0 { r.spp } else { r.gt_spp },
            path: PathSettings {
                max_depth: r.max_depth,
                rr_depth: r.rr_depth,
                footprint: 0.0, // per scene: see `settings`
                glass_light: r.glass_light,
                split_glass: r.split_glass,
            },
            gt_views: r.gt_views,
            gt_highres: r.gt_highres,
            mode_epsilon: r.mode_epsilon as f32,
            write_exr: r.write_exr,
            tone_curve: r.tone_curve,
            shade_all_hits: r.write_slices,
            slice_assignment: r.slice_assignment,
            auto_exposure: r.auto_exposure,
            date: date.to_string(),
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
            sensor: cfg.sensor.clone(),
        }
    }

    /// Camera samples per pixel position over the `views` views of a scene: every view's
    /// colour, the fill pass of shared shading, and the GT's own samples where it has them.
    pub fn samples_per_pixel(&self, views: u32) -> u64 {
        let fill = match self.shading {
            ShadingMode::Shared => self.fill_spp(views) * (1 + self.cache.final_gather as u32),
            ShadingMode::Independent => 0,
        };
        let gt_views = match self.gt_views {
            GtViews::All => views,
            GtViews::Center => 1,
        };
        let gt_own = gt_own_spp(self.spp, self.gt_spp);
        views as u64 * (self.spp + fill) as u64 + gt_views as u64 * gt_own as u64
    }

    /// Fill samples per pixel of each of `views` views: `cache_spp`, raised so that a cache
    /// cell (about one pixel footprint) gathers at least [`FILL_PER_SPP`] × `spp` samples over
    /// the views. The shared estimate is all a Lambert pixel's lighting, so a fixed fill
    /// would put a floor under its noise however high `spp` goes (validate.sh, the centre
    /// view alone at 1024 spp: 4.98 % mean block difference against Mitsuba with 4 fill
    /// samples, 0.84 / 0.51 % with 114 / 1024, the independent estimator 0.31 %). At the
    /// defaults (20 spp, 81 views) the floor of 1 per view already gives 4 × spp per pixel
    /// footprint, and [`Self::cache_params`] more per cell.
    pub fn fill_spp(&self, views: u32) -> u32 {
        let per_view = (FILL_PER_SPP * self.spp).div_ceil(views.max(1));
        self.cache_spp.max(per_view)
    }

    /// The cache of a scene with `views` views: `render.cache_cell`, widened until a cell
    /// gathers [`CELL_FILL`] fill samples (`fill_spp × views` per pixel footprint). A fill
    /// sample costs about five camera samples (a full path against one cache lookup), so at
    /// the defaults one per view and cells √(256 / 81) ≈ 1.8 pixel footprints wide are the
    /// cheaper way to a quiet cache: on `lfgen bench quality` (128²) they gave the views of
    /// 4 fill samples and 1-pixel cells within −0.5…+0.3 dB (8-bit), and a full-size scene in
    /// 0.69× the time, with 20 spp for 16 (results/measurements.jsonl). The
    /// wider cell blurs the lighting over more of a pixel footprint; where the fill is dense
    /// (validate.sh's single view at 1024 spp) the configured cell stays.
    pub fn cache_params(&self, views: u32) -> CacheParams {
        let per_footprint = self.fill_spp(views) as f64 * views.max(1) as f64;
        let cell = (CELL_FILL / per_footprint).sqrt() as f32;
        CacheParams {
            cell_px: self.cache.cell_px.max(cell),
            ..self.cache
        }
    }

    /// Fills the shared-shading cache of `scene` seen by `cam` ([`Self::fill_spp`] samples per
    /// pixel of every view, cells as [`Self::cache_params`] says).
    pub fn fill_cache(
        &self,
        scene: &RenderScene,
        cam: &LightFieldCamera,
        settings: &RenderSettings,
        samples_done: &AtomicU64,
    ) -> RadianceCache {
        let views = cam.num_views();
        let (spp, params) = (self.fill_spp(views), self.cache_params(views));
        scene.fill_cache(cam, settings, spp, params, samples_done)
    }

    /// Per-view render settings for scene `desc`.
    pub fn settings(&self, desc: &SceneDesc) -> RenderSettings {
        let stratum = (1.0 / (self.spp as f64).sqrt()).max(0.125);
        let footprint = match self.texture_filter {
            true => (stratum / desc.camera.f_px()) as f32,
            false => 0.0,
        };
        RenderSettings {
            path: PathSettings {
                footprint,
                ..self.path
            },
            spp: self.spp,
            gt_spp: self.gt_spp,
            seed: desc.seed,
            scene_index: desc.index,
            mode_epsilon: self.mode_epsilon,
            shade_all_hits: self.shade_all_hits,
            slice_assignment: self.slice_assignment,
            adaptive: Adaptive {
                extra: self.adaptive_spp,
                threshold: self.adaptive_threshold,
                display_scale: desc.exposure,
            },
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
    let center = desc.camera.center_view();
    let per_view = job.gt_views == GtViews::All;
    // The centre view first: it fixes the exposure for all views and carries the GT.
    let mut order: Vec<u32> = vec![center];
    order.extend((0..desc.camera.num_views()).filter(|&v| v != center));
    let mut stats = None;
    let cache = (job.shading == ShadingMode::Shared)
        .then(|| job.fill_cache(scene, &desc.camera, &job.settings(desc), samples_done));
    let shading = cache.as_ref().map_or(Shading::Independent, Shading::read);
    // Adaptive sampling judges noise in display units, so with it the exposure comes first,
    // from the centre view without the extra samples — the image a render without adaptive
    // sampling makes, GT pass included (its first hits come from the all-hits trace), so the
    // exposure is the same either way; about 1/60 of a 9×9 scene's time. Without it, from the
    // centre view itself.
    let adaptive = job.adaptive_spp > 0;
    if job.auto_exposure && adaptive {
        let plain = RenderSettings {
            adaptive: Adaptive::default(),
            ..job.settings(desc)
        };
        let (cam, slices) = (&desc.camera, &desc.slices);
        let out = scene.render_view_with(cam, slices, &plain, center, true, shading, samples_done);
        desc.exposure *= auto_exposure(&out.image.pixels);
    }
    let settings = job.settings(desc);
    for view in order {
        let with_gt = view == center || per_view;
        let out = scene.render_view_with(
            &desc.camera,
            &desc.slices,
            &settings,
            view,
            with_gt,
            shading,
            samples_done,
        );
        if view == center && job.auto_exposure && !adaptive {
            desc.exposure *= auto_exposure(&out.image.pixels);
        }
        let image = &out.image;
        let recorded = capture.map(|c| c.develop(&image.pixels, image.width, desc.exposure, view));
        writer.write_view(
            view,
            (image.width, image.height),
            &image.pixels,
            desc.exposure,
            recorded.as_deref(),
        )?;
        if let Some(gt) = &out.gt {
            let images = GtImages {
                modes: &gt.modes,
                colors: &gt.colors,
                surfaces: &gt.surfaces,
                hci: &gt.hci,
                valid: &gt.valid,
            };
            writer.write_gt(view, view == center, per_view, &desc.camera, &images)?;
            if job.gt_highres > 0 {
                let (cam, scale) = (&desc.camera, job.gt_highres);
                let layer = scene.render_hci_layer(cam, view, scale);
                writer.write_highres((view, view == center, per_view), cam, &layer, scale)?;
            }
        }
        if view == center {
            let mut s = scene_stats(desc, scene, &out, job);
            let written = match &recorded {
                Some(recorded) => job.tone_curve.encode(recorded, 1.0),
                None => job.tone_curve.encode(&image.pixels, desc.exposure),
            };
            s.appearance = ImageStats::of_rgb8(&written, image.width, image.height);
            s.camera = capture.map(|c| c.draw);
            stats = Some(s);
        }
    }
    writer.finish(desc, &stats.expect("centre view rendered"), root)
}

fn scene_stats(
    desc: &SceneDesc,
    scene: &RenderScene,
    out: &ViewOutput,
    job: &RenderJob,
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
    s.exposure = desc.exposure;
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
    let job = RenderJob {
        auto_exposure: false,
        ..RenderJob::from_config(cfg, &cfg.dataset.render_date())
    };
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

#[cfg(test)]
mod tests {
    use super::*;

    fn job(spp: u32, cache_spp: u32, gt_spp: u32) -> RenderJob {
        let mut cfg = Config::default();
        (cfg.render.spp, cfg.render.cache_spp, cfg.render.gt_spp) = (spp, cache_spp, gt_spp);
        RenderJob::from_config(&cfg, "2026-01-01")
    }

    #[test]
    fn cells_widen_until_they_hold_256_fill_samples() {
        let cell = |spp, cache_spp, views| job(spp, cache_spp, 0).cache_params(views).cell_px;
        // Defaults: 1 fill sample per view × 81 views per pixel footprint → √(256 / 81) px.
        assert!((cell(20, 1, 81) - 16.0 / 9.0).abs() < 1e-6);
        // 4 per view → 324 ≥ 256: the configured 1 px; validate.sh's single view at 1024 too.
        assert_eq!(cell(16, 4, 81), 1.0);
        assert_eq!(cell(1024, 1, 1), 1.0);
        // A single view at 16 spp: 16 per footprint → 4 px.
        assert!((cell(16, 1, 1) - 4.0).abs() < 1e-6);
        // A configured cell wider than the rule wins.
        let mut wide = job(20, 1, 0);
        wide.cache.cell_px = 3.0;
        assert_eq!(wide.cache_params(81).cell_px, 3.0);
    }

    #[test]
    fn the_fill_grows_with_spp_over_the_views() {
        // Defaults: 20 spp over 81 views needs 1 per view; so does the floor.
        assert_eq!(job(20, 1, 0).fill_spp(81), 1);
        assert_eq!(job(16, 4, 0).fill_spp(81), 4);
        // 1024 spp over 3×3 views → ⌈1024 / 9⌉ = 114 per view; validate.sh's single view
        // takes all 1024 itself.
        assert_eq!(job(1024, 4, 0).fill_spp(9), 114);
        assert_eq!(job(1024, 4, 0).fill_spp(1), 1024);
        // An explicit cache_spp above the rule wins.
        assert_eq!(job(1024, 500, 0).fill_spp(9), 500);
    }

    #[test]
    fn samples_per_pixel_count_the_fills_and_the_gts_own_samples() {
        // 81 views × (16 + 4 fill); the centre GT adds 64 of its own.
        assert_eq!(job(16, 4, 0).samples_per_pixel(81), 81 * 20);
        assert_eq!(job(16, 4, 64).samples_per_pixel(81), 81 * 20 + 64);
        assert_eq!(job(16, 4, 16).samples_per_pixel(81), 81 * 20);
        // A final gather fills the cache twice.
        let mut gather = job(16, 4, 0);
        gather.cache.final_gather = true;
        assert_eq!(gather.samples_per_pixel(81), 81 * 24);
    }
}
