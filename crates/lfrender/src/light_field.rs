//! The renderer's front door: a whole light field — every view of a camera grid, and the ground
//! truth of the views that carry it — from one scene and one set of settings.
//!
//! It owns the pass policy, so that a caller (the CLI, a benchmark, a library user) only says
//! what it wants: shared shading's cache is filled first from every view, the exposure is fixed
//! from the centre view, and then every view is rendered, the centre first, and handed to the
//! caller one at a time so that it can write it and let it go.

use super::RenderScene;
use super::cache::{CacheParams, RadianceCache};
use super::framing::auto_exposure;
use super::integrator::{PathSettings, Shading};
use super::slices::SliceAssignment;
use super::view::{Adaptive, HciLayer, RenderSettings, ViewOutput, gt_own_spp};
use crate::camera::LightFieldCamera;
use crate::scene::SceneDesc;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicU64;

/// Fill samples a shared-shading cache cell gathers per colour sample of a pixel, at least.
pub const FILL_PER_SPP: u32 = 1;

/// Fill samples a shared-shading cache cell gathers at least: where the views' fill takes
/// fewer per pixel footprint, cells grow until they hold this many (see
/// [`LightFieldSettings::cache_params`]).
pub const CELL_FILL: f64 = 256.0;

/// Which views get multimodal ground truth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GtViews {
    Center,
    All,
}

/// How the light leaving a surface is estimated across the views of a light field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ShadingMode {
    /// The view-independent (diffuse) light is estimated once from the samples of every view
    /// and shared by all of them; the glossy lobe and delta surfaces stay per view.
    Shared,
    /// Every view is path-traced on its own: the unbiased reference.
    Independent,
}

/// Everything a light-field render needs besides the scene.
#[derive(Clone, Debug)]
pub struct LightFieldSettings {
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
    /// Shade every hit of GT rays (true slice colours).
    pub shade_all_hits: bool,
    pub slice_assignment: SliceAssignment,
    /// Choose the exposure from the centre view (else keep the scene's).
    pub auto_exposure: bool,
    pub shading: ShadingMode,
    /// Fill samples per pixel of every view, at least (see [`Self::fill_spp`]).
    pub cache_spp: u32,
    /// The configured cache; its cell is the smallest allowed (see [`Self::cache_params`]).
    pub cache: CacheParams,
    /// Filter library textures over a sample's footprint (see [`PathSettings::footprint`]).
    pub texture_filter: bool,
}

/// One rendered view, as [`RenderScene::render_light_field`] hands it over.
pub struct RenderedView {
    pub view: u32,
    /// Colour, and the ground truth where this view carries it.
    pub output: ViewOutput,
    /// The view's HCI layer at [`LightFieldSettings::gt_highres`] pixels per pixel, where the
    /// view carries ground truth and high-resolution GT is asked for.
    pub highres: Option<HciLayer>,
    /// The scene's exposure (radiance × exposure = display units), fixed by the centre view.
    pub exposure: f32,
}

impl LightFieldSettings {
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

    /// The cache of a scene with `views` views: `cache.cell_px`, widened until a cell
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

    /// Per-view render settings for scene `desc` (its seed, camera and exposure).
    pub fn view_settings(&self, desc: &SceneDesc) -> RenderSettings {
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

impl RenderScene {
    /// Fills the shared-shading cache of this scene seen by `cam` ([`LightFieldSettings::fill_spp`]
    /// samples per pixel of every view, cells as [`LightFieldSettings::cache_params`] says).
    pub fn fill_shared_cache(
        &self,
        cam: &LightFieldCamera,
        lf: &LightFieldSettings,
        settings: &RenderSettings,
        samples_done: &AtomicU64,
    ) -> RadianceCache {
        let views = cam.num_views();
        let (spp, params) = (lf.fill_spp(views), lf.cache_params(views));
        self.fill_cache(cam, settings, spp, params, samples_done)
    }

    /// Renders every view of `desc` as `lf` says, the centre view first, and hands each to
    /// `sink` as it is done; returns the exposure it fixed (the scene's own without
    /// [`LightFieldSettings::auto_exposure`]). `samples_done` counts camera samples for
    /// progress display ([`LightFieldSettings::samples_per_pixel`] per pixel in all). An error
    /// from `sink` stops the render and is returned.
    pub fn render_light_field(
        &self,
        desc: &SceneDesc,
        lf: &LightFieldSettings,
        samples_done: &AtomicU64,
        mut sink: impl FnMut(RenderedView) -> Result<()>,
    ) -> Result<f32> {
        let (cam, slices) = (&desc.camera, &desc.slices);
        let center = cam.center_view();
        let mut exposure = desc.exposure;
        let cache = (lf.shading == ShadingMode::Shared)
            .then(|| self.fill_shared_cache(cam, lf, &lf.view_settings(desc), samples_done));
        let shading = cache.as_ref().map_or(Shading::Independent, Shading::read);
        // Adaptive sampling judges noise in display units, so with it the exposure comes first,
        // from the centre view without the extra samples — the image a render without adaptive
        // sampling makes, GT pass included (its first hits come from the all-hits trace), so
        // the exposure is the same either way; about 1/60 of a 9×9 scene's time. Without it,
        // from the centre view itself.
        let adaptive = lf.adaptive_spp > 0;
        if lf.auto_exposure && adaptive {
            let plain = RenderSettings {
                adaptive: Adaptive::default(),
                ..lf.view_settings(desc)
            };
            let out =
                self.render_view_with(cam, slices, &plain, center, true, shading, samples_done);
            exposure *= auto_exposure(&out.image.pixels);
        }
        let mut settings = lf.view_settings(desc);
        settings.adaptive.display_scale = exposure;
        let order = std::iter::once(center).chain((0..cam.num_views()).filter(|&v| v != center));
        for view in order {
            let with_gt = view == center || lf.gt_views == GtViews::All;
            let output =
                self.render_view_with(cam, slices, &settings, view, with_gt, shading, samples_done);
            if view == center && lf.auto_exposure && !adaptive {
                exposure *= auto_exposure(&output.image.pixels);
            }
            let highres = (output.gt.is_some() && lf.gt_highres > 0)
                .then(|| self.render_hci_layer(cam, view, lf.gt_highres));
            sink(RenderedView {
                view,
                output,
                highres,
                exposure,
            })?;
        }
        Ok(exposure)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::GlassLight;

    fn settings(spp: u32, cache_spp: u32, gt_spp: u32) -> LightFieldSettings {
        LightFieldSettings {
            spp,
            adaptive_spp: 0,
            adaptive_threshold: 0.0,
            gt_spp: if gt_spp == 0 { spp } else { gt_spp },
            path: PathSettings {
                max_depth: 8,
                rr_depth: 3,
                footprint: 0.0,
                glass_light: GlassLight::Caustics,
                split_glass: false,
            },
            gt_views: GtViews::Center,
            gt_highres: 0,
            mode_epsilon: 0.0,
            shade_all_hits: false,
            slice_assignment: SliceAssignment::Surface,
            auto_exposure: true,
            shading: ShadingMode::Shared,
            cache_spp,
            cache: CacheParams {
                cell_px: 1.0,
                glossy_share: 0.0,
                glossy_min_width: 0.0,
                fill_vertices: 1,
                fill_light_samples: 1,
                shrink: false,
                final_gather: false,
            },
            texture_filter: false,
        }
    }

    #[test]
    fn cells_widen_until_they_hold_256_fill_samples() {
        let cell = |spp, cache_spp, views| settings(spp, cache_spp, 0).cache_params(views).cell_px;
        // Defaults: 1 fill sample per view × 81 views per pixel footprint → √(256 / 81) px.
        assert!((cell(20, 1, 81) - 16.0 / 9.0).abs() < 1e-6);
        // 4 per view → 324 ≥ 256: the configured 1 px; validate.sh's single view at 1024 too.
        assert_eq!(cell(16, 4, 81), 1.0);
        assert_eq!(cell(1024, 1, 1), 1.0);
        // A single view at 16 spp: 16 per footprint → 4 px.
        assert!((cell(16, 1, 1) - 4.0).abs() < 1e-6);
        // A configured cell wider than the rule wins.
        let mut wide = settings(20, 1, 0);
        wide.cache.cell_px = 3.0;
        assert_eq!(wide.cache_params(81).cell_px, 3.0);
    }

    #[test]
    fn the_fill_grows_with_spp_over_the_views() {
        // Defaults: 20 spp over 81 views needs 1 per view; so does the floor.
        assert_eq!(settings(20, 1, 0).fill_spp(81), 1);
        assert_eq!(settings(16, 4, 0).fill_spp(81), 4);
        // 1024 spp over 3×3 views → ⌈1024 / 9⌉ = 114 per view; validate.sh's single view
        // takes all 1024 itself.
        assert_eq!(settings(1024, 4, 0).fill_spp(9), 114);
        assert_eq!(settings(1024, 4, 0).fill_spp(1), 1024);
        // An explicit cache_spp above the rule wins.
        assert_eq!(settings(1024, 500, 0).fill_spp(9), 500);
    }

    #[test]
    fn samples_per_pixel_count_the_fills_and_the_gts_own_samples() {
        // 81 views × (16 + 4 fill); the centre GT adds 64 of its own.
        assert_eq!(settings(16, 4, 0).samples_per_pixel(81), 81 * 20);
        assert_eq!(settings(16, 4, 64).samples_per_pixel(81), 81 * 20 + 64);
        assert_eq!(settings(16, 4, 16).samples_per_pixel(81), 81 * 20);
        // A final gather fills the cache twice.
        let mut gather = settings(16, 4, 0);
        gather.cache.final_gather = true;
        assert_eq!(gather.samples_per_pixel(81), 81 * 24);
    }
}
