//! Generator configuration: `generator.toml`, presets and `--set` overrides.
//!
//! Defaults live in exactly one place, the `Default` impls below; `generator.toml` documents them
//! and a test keeps the two identical. Overrides are applied to the TOML tree *before*
//! deserialising, so a `--set` key goes through the same validation as a key in the file, and
//! unknown keys are rejected by name instead of being silently ignored.

use crate::camera::LightFieldCamera;
use crate::output::images::ToneCurve;
pub use crate::procgen::settings::RoomSettings as SceneConfig;
pub use crate::render::integrator::GlassLight;
pub use crate::render::light_field::{GtViews, ShadingMode};
pub use crate::render::sensor::SensorSettings as SensorConfig;
pub use crate::render::slices::SliceAssignment;
pub use crate::scene::SliceSpacing;
pub use crate::scene::gltf::GltfSettings as GltfConfig;
use crate::scene::gltf::ImportSettings;
use crate::scene::memory::{self, Budget};
use crate::scene::{MAX_GRID, MAX_SLICES};
use crate::scene::{SceneStart, SliceRange};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The whole configuration of one dataset.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    pub dataset: DatasetConfig,
    pub camera: CameraConfig,
    pub render: RenderConfig,
    pub scene: SceneConfig,
    pub gltf: GltfConfig,
    /// The camera's imaging model (noise, vignetting, exposure and white balance), off by
    /// default.
    pub sensor: SensorConfig,
}

/// What is generated and where it goes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DatasetConfig {
    /// Number of scenes when `--scenes` is not given.
    pub scenes: u64,
    /// Master seed; every random choice derives from (seed, scene index, view, pixel).
    pub seed: u64,
    /// Scene `i` goes to `val` when `i % val_every == val_every - 1`, else to `train`
    /// (110 scenes give the thesis' 100/10 split); a dataset of fewer than `val_every` scenes
    /// puts its last one in `val` (none with a single scene). 0 puts every scene in `train`.
    pub val_every: u64,
    /// Default output folder.
    pub out: String,
    /// `date` written into parameters.cfg; empty means the day the run starts (set it to make
    /// datasets byte-identical across days).
    pub date: String,
}

impl Default for DatasetConfig {
    fn default() -> Self {
        Self {
            scenes: 110,
            seed: 0,
            val_every: 11,
            out: "datasets/lfgen".into(),
            date: String::new(),
        }
    }
}

impl DatasetConfig {
    /// The date written into every scene: `dataset.date`, or today (UTC) when it is empty.
    pub fn render_date(&self) -> String {
        match self.date.is_empty() {
            true => today(),
            false => self.date.clone(),
        }
    }
}

/// Today's date (UTC) as `YYYY-MM-DD`.
pub fn today() -> String {
    humantime::format_rfc3339(std::time::SystemTime::now()).to_string()[..10].to_string()
}

/// How baseline and focus distance are chosen.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BaselineMode {
    /// Solved per scene so the visible depth range maps onto `disparity_range`.
    Auto,
    /// `baseline_mm` and `focus_distance_m` as given.
    Fixed,
}

/// The light-field camera grid (HCI conventions, docs/reference/format.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CameraConfig {
    /// Image size in pixels, `[width, height]`.
    pub resolution: [u32; 2],
    /// Number of cameras, `[num_cams_x, num_cams_y]`; both odd.
    pub grid: [u32; 2],
    pub focal_length_mm: f64,
    /// The larger sensor side, as in HCI.
    pub sensor_size_mm: f64,
    pub baseline: BaselineMode,
    /// Used when `baseline = "fixed"`.
    pub baseline_mm: f64,
    /// Used when `baseline = "fixed"`.
    pub focus_distance_m: f64,
    /// Target disparity range `[d_min, d_max]` in pixels for `baseline = "auto"`.
    pub disparity_range: [f64; 2],
}

impl Default for CameraConfig {
    fn default() -> Self {
        Self {
            resolution: [512, 512],
            grid: [9, 9],
            focal_length_mm: 100.0,
            sensor_size_mm: 35.0,
            baseline: BaselineMode::Auto,
            baseline_mm: 50.0,
            focus_distance_m: 3.0,
            disparity_range: [-3.5, 3.5],
        }
    }
}

impl CameraConfig {
    /// The configured rig (image, grid, lens, sensor, baseline, focus) at the origin looking
    /// down −Z: the scene builders place and aim it, and framing may replace baseline and
    /// focus (`camera.baseline = "auto"`).
    pub fn rig(&self) -> LightFieldCamera {
        LightFieldCamera {
            resolution: self.resolution,
            grid: self.grid,
            focal_length_mm: self.focal_length_mm,
            sensor_size_mm: self.sensor_size_mm,
            baseline_m: self.baseline_mm / 1000.0,
            focus_distance_m: self.focus_distance_m,
            position: glam::DVec3::ZERO,
            forward: glam::DVec3::NEG_Z,
            up: glam::DVec3::Y,
        }
    }
}

/// Path tracer and ground-truth settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderConfig {
    /// Samples per pixel (stratified over the pixel, box filter).
    pub spp: u32,
    /// Adaptive sampling: extra samples for a pixel still noisy after `spp` (0: off; see
    /// `render::view::Adaptive`).
    pub adaptive_spp: u32,
    /// Adaptive sampling: the noise above which a pixel gets `adaptive_spp` more samples —
    /// the standard error of its mean over the square root of its brightness, summed over
    /// RGB, in display units (Cycles' measure).
    pub adaptive_threshold: f64,
    /// Camera samples per pixel of the ground truth (modes, η, MPI colours); 0 (default): the
    /// colour's own samples, at no extra tracing. More samples make η at edges and behind
    /// semi-transparent surfaces finer than the colour's spp allows.
    pub gt_spp: u32,
    /// Maximum number of path vertices after the camera.
    pub max_depth: u32,
    /// Russian roulette starts after this many bounces.
    pub rr_depth: u32,
    pub gt_views: GtViews,
    /// High-resolution HCI ground truth (`gt_disp_highres.pfm`, `gt_depth_highres.pfm`,
    /// `objectids_highres.png`) on a grid this many times finer per side, from its
    /// pixel-centre rays (the HCI benchmark: 10); 0: none.
    pub gt_highres: u32,
    /// Number of depth slices S.
    pub slices: u32,
    pub slice_spacing: SliceSpacing,
    pub slice_assignment: SliceAssignment,
    /// A slice is a mode when its η (or η_exact) exceeds this.
    pub mode_epsilon: f64,
    /// Shade every hit of the GT rays, so the MPI layers (`gt_mpi_lowres.npz`) carry true
    /// slice colours; costs a shading per hit. (The renderer calls it `shade_all_hits`.)
    pub write_slices: bool,
    /// Also write linear `input_CamNNN.exr`.
    pub write_exr: bool,
    /// Choose the exposure per scene from the centre view (key 0.18 on the log-average).
    pub auto_exposure: bool,
    /// Multiplier applied on top of (auto) exposure.
    pub exposure: f64,
    /// How the PNGs encode radiance: `agx` (default; highlights roll off) or `clip`.
    pub tone_curve: ToneCurve,
    /// `shared` (default) or `independent` shading (see [`ShadingMode`]).
    pub shading: ShadingMode,
    /// Shared shading: fill samples per pixel of every view, at least; raised to
    /// ⌈spp / views⌉ so the cache's noise shrinks with spp (`LightFieldSettings::fill_spp`).
    pub cache_spp: u32,
    /// Shared shading: cache cell size in pixels of the centre view at the cell's depth, at
    /// least; widened until a cell gathers 256 fill samples (`LightFieldSettings::cache_params`).
    pub cache_cell: f64,
    /// Shared shading: glossy lobes at least this many times as wide as the camera grid's
    /// angle at a point are shared by all views (see `render::cache`).
    pub glossy_share: f64,
    /// Shared shading: glossy lobes narrower than this (`2α`, radians) stay per view whatever
    /// the grid spans (see `render::cache`).
    pub glossy_min_width: f64,
    /// Shared shading: vertices of each fill path whose coupled-irradiance estimates the cache
    /// keeps (1: the first alone; see `render::cache::CacheSums::add_later`). Only the path's
    /// own vertices, below `max_depth`, take part: larger values act as `max_depth`.
    pub fill_vertices: u32,
    /// Shared shading: light samples each fill path takes at its first vertex, averaged
    /// (see `render::cache::CacheGrid::fill_light_samples`).
    pub fill_light_samples: u32,
    /// Shared shading: shrink each cache cell's irradiance towards the next coarser level's
    /// as far as the cell's own noise explains their difference (see
    /// `render::cache::CellSums::shrunk`).
    pub cache_shrink: bool,
    /// Shared shading: a second fill pass whose paths read the first pass's cache at their
    /// second surface (a final gather), its estimates added to the cells' (see
    /// `render::integrator::Shading::Gather`): +0.1–0.9 dB for 1.15x the scene time at 512²;
    /// `--preset fast` (and `quick`) turn it off; `--preset clean` adds `cache_spp = 2` for
    /// 1.4x.
    pub final_gather: bool,
    /// Average library textures seen by camera rays over one sample's footprint.
    pub texture_filter: bool,
    /// Light through smooth glass: `caustics` (default, unbiased), `shadows` or `off` (see
    /// [`GlassLight`]).
    pub glass_light: GlassLight,
    /// Shared shading: smooth glass on a camera ray is traced both ways, reflection and
    /// refraction each with its Fresnel weight, instead of one chosen with that probability.
    pub split_glass: bool,
}

impl Default for RenderConfig {
    fn default() -> Self {
        Self {
            spp: 16,
            adaptive_spp: 48,
            adaptive_threshold: 0.15,
            gt_spp: 0,
            max_depth: 5,
            rr_depth: 3,
            gt_views: GtViews::Center,
            gt_highres: 0,
            slices: 128,
            slice_spacing: SliceSpacing::Depth,
            slice_assignment: SliceAssignment::Surface,
            mode_epsilon: 1e-4,
            write_slices: false,
            write_exr: false,
            auto_exposure: true,
            exposure: 1.0,
            tone_curve: ToneCurve::Agx,
            shading: ShadingMode::Shared,
            cache_spp: 1,
            cache_cell: 1.0,
            glossy_share: 4.0,
            glossy_min_width: 0.1,
            fill_vertices: 5,
            fill_light_samples: 4,
            cache_shrink: true,
            final_gather: true,
            texture_filter: true,
            glass_light: GlassLight::Caustics,
            split_glass: true,
        }
    }
}

impl Config {
    /// What a new scene description (generated or imported) starts with.
    pub fn scene_start(&self) -> SceneStart {
        SceneStart {
            rig: self.camera.rig(),
            seed: self.dataset.seed,
            slices: SliceRange::unframed(self.render.slices, self.render.slice_spacing),
            exposure: self.render.exposure as f32,
        }
    }

    /// What the glTF importer takes from this configuration.
    pub fn gltf_import(&self) -> ImportSettings<'_> {
        ImportSettings {
            gltf: &self.gltf,
            start: self.scene_start(),
        }
    }
}

/// A named bundle of overrides (`--preset NAME`), applied before the user's `--set`s.
#[derive(Clone, Copy, Debug)]
pub struct Preset {
    pub name: &'static str,
    /// One line for `--help` and the reference.
    pub about: &'static str,
    pub sets: &'static [&'static str],
}

/// The presets; without one, the defaults (generator.toml) make the full-size dataset.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "quick",
        about: "128² views at 10 + 30 spp, no final gather: a small dataset in minutes",
        sets: &[
            "camera.resolution=[128,128]",
            "render.spp=10",
            "render.adaptive_spp=30",
            "render.final_gather=false",
        ],
    },
    Preset {
        name: "fast",
        about: "the defaults without the final gather: 0.87× the time, views 0.1–0.9 dB noisier",
        sets: &["render.final_gather=false"],
    },
    Preset {
        name: "wide",
        about: "disparities of ±40 px instead of ±3.5 (wide baselines)",
        sets: &["camera.disparity_range=[-40.0,40.0]"],
    },
    Preset {
        name: "clean",
        about: "the least noisy views: 2 fill spp beside the final gather, 1.4× the time",
        sets: &["render.final_gather=true", "render.cache_spp=2"],
    },
    Preset {
        name: "classic",
        about: "the appearance of lfgen before its lighting moods and surface shares: evenly \
                lit rooms exposed to mid grey, every surface textured (reproduces older datasets)",
        sets: &[
            "scene.lighting.even=1.0",
            "scene.lighting.dim=0.0",
            "scene.lighting.spot=0.0",
            "scene.lighting.window=0.0",
            "scene.coloured_light=0.0",
            "scene.ev_offset=[0.0,0.0]",
            "scene.plain_share=0.0",
            "scene.subtle_share=0.0",
            "scene.glossy_share=0.0",
            "scene.metallic_share=0.0",
            "scene.catalog=\"\"",
        ],
    },
    Preset {
        name: "camera",
        about: "views as a camera records them: sensor noise, vignetting, exposure and white balance",
        sets: &["sensor.enabled=true"],
    },
];

/// Largest `render.gt_highres`: 16 makes a 512² scene's high-res layer 2 GiB.
const MAX_GT_HIGHRES: u32 = 16;

/// Memory of one high-resolution pixel: its layer (depth, normal, three ids) and PFM copies.
const HIGHRES_PIXEL_BYTES: u64 = 40;

/// Largest samples per pixel.
pub const MAX_SPP: u32 = 1 << 16;
/// Longest path.
pub const MAX_DEPTH: u32 = 1024;
/// The range of `render.exposure`: twenty stops either way, far inside f32.
const MIN_EXPOSURE: f64 = 1e-6;
const MAX_EXPOSURE: f64 = 1e6;

/// Where a config's values came from, for its errors: the file (or the defaults) and every
/// preset and `--set` applied over it, so a bad `--set` is not blamed on the defaults.
fn origin(path: Option<&Path>, presets: &[String], sets: &[String]) -> String {
    let mut origin = path.map_or("built-in defaults".into(), |p| p.display().to_string());
    for p in presets {
        origin += &format!(" + --preset {p}");
    }
    for s in sets {
        origin += &format!(" + --set {s}");
    }
    origin
}

/// Where `lfgen assets fetch sweethome3d` writes its catalogue (relative to the working
/// folder), which `scene.catalog = "auto"` draws from when it exists.
pub const SWEETHOME3D_CATALOG: &str = "assets/sweethome3d/catalog.json";

impl Config {
    /// Resolves `scene.catalog = "auto"` against `dir` (the working folder): the Sweet Home 3D
    /// catalogue of [`SWEETHOME3D_CATALOG`] if it exists, else procedural furniture only.
    /// Returns a line saying which, for the user (None: the catalogue was named explicitly).
    /// Resolved before the dataset is opened, so the manifest's config (and its hash, which
    /// `--resume` and shards compare) names the catalogue that was used.
    pub fn resolve_catalog(&mut self, dir: &Path) -> Option<String> {
        if self.scene.catalog != crate::procgen::settings::AUTO_CATALOG {
            return None;
        }
        let found = dir.join(SWEETHOME3D_CATALOG).is_file();
        self.scene.catalog = if found {
            SWEETHOME3D_CATALOG.into()
        } else {
            String::new()
        };
        Some(if found {
            format!(
                "drawing pieces from the Sweet Home 3D catalogue {SWEETHOME3D_CATALOG} \
                 (scene.catalog=\"\" for procedural furniture only)"
            )
        } else {
            format!(
                "procedural furniture only: no {SWEETHOME3D_CATALOG} (`lfgen assets fetch \
                 sweethome3d` installs real models there)"
            )
        })
    }

    /// Loads `path` (or the built-in defaults when `None`), then applies presets and overrides.
    pub fn load(path: Option<&Path>, presets: &[String], sets: &[String]) -> Result<Self> {
        let mut table = match path {
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .with_context(|| format!("cannot read config {}", p.display()))?;
                toml::from_str::<toml::Table>(&text)
                    .with_context(|| format!("{}: malformed TOML", p.display()))?
            }
            None => toml::Table::new(),
        };
        for name in presets {
            let preset = PRESETS.iter().find(|p| p.name == name).with_context(|| {
                let known: Vec<_> = PRESETS.iter().map(|p| p.name).collect();
                format!("unknown preset {name:?} (known: {})", known.join(", "))
            })?;
            for s in preset.sets {
                apply_set(&mut table, s)?;
            }
        }
        for s in sets {
            apply_set(&mut table, s)?;
        }
        let origin = origin(path, presets, sets);
        let cfg: Config = table
            .try_into()
            .with_context(|| format!("{origin}: invalid config"))?;
        cfg.validate()
            .with_context(|| format!("{origin}: invalid config"))?;
        Ok(cfg)
    }

    /// Semantic checks that serde cannot express. The upper bounds keep a typo (or a hostile
    /// `--set`) from allocating gigabytes: each is far beyond any useful setting.
    pub fn validate(&self) -> Result<()> {
        let c = &self.camera;
        if c.grid.iter().any(|&n| n == 0 || n % 2 == 0 || n > MAX_GRID) {
            bail!(
                "camera.grid must be odd counts (HCI) of at most {MAX_GRID}, got {:?}",
                c.grid
            );
        }
        if c.resolution.iter().any(|&n| n == 0 || n > 16384) {
            bail!("camera.resolution out of range: {:?}", c.resolution);
        }
        let views = format!("camera.resolution {:?} (grid {:?})", c.resolution, c.grid);
        Budget::of_this_process()?.charge(&views, memory::view_bytes(c.resolution, c.grid))?;
        if c.disparity_range[0] >= c.disparity_range[1]
            || c.disparity_range.iter().any(|d| !d.is_finite())
        {
            bail!(
                "camera.disparity_range must be increasing, got {:?}",
                c.disparity_range
            );
        }
        let positive = [
            c.focal_length_mm,
            c.sensor_size_mm,
            c.baseline_mm,
            c.focus_distance_m,
        ];
        if positive.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            bail!("camera focal length, sensor size, baseline and focus must be positive");
        }
        let fov = 2.0
            * (0.5 * c.sensor_size_mm / c.focal_length_mm)
                .atan()
                .to_degrees();
        if !(0.1..=170.0).contains(&fov) {
            bail!(
                "camera.focal_length_mm {} and sensor_size_mm {} give a {fov:.3}° field of view: \
                 it must be 0.1° to 170°",
                c.focal_length_mm,
                c.sensor_size_mm
            );
        }
        let r = &self.render;
        if r.spp == 0 || r.slices == 0 || r.max_depth == 0 {
            bail!("render.spp, render.slices and render.max_depth must be at least 1");
        }
        if r.gt_spp > MAX_SPP {
            bail!(
                "render.gt_spp must be 0 (spp) to {MAX_SPP}, got {}",
                r.gt_spp
            );
        }
        if r.gt_highres > MAX_GT_HIGHRES {
            bail!(
                "render.gt_highres must be 0 (off) to {MAX_GT_HIGHRES}, got {}",
                r.gt_highres
            );
        }
        let fine = c.resolution.map(|n| n as u64 * r.gt_highres as u64);
        let what = format!("render.gt_highres {} ({fine:?} pixels)", r.gt_highres);
        Budget::of_this_process()?.charge(&what, fine[0] * fine[1] * HIGHRES_PIXEL_BYTES)?;
        if r.cache_spp == 0 || r.cache_spp > MAX_SPP {
            bail!(
                "render.cache_spp must be 1 to {MAX_SPP}, got {}",
                r.cache_spp
            );
        }
        if !(r.cache_cell.is_finite() && (0.05..=64.0).contains(&r.cache_cell)) {
            bail!(
                "render.cache_cell must be 0.05 to 64 pixels, got {}",
                r.cache_cell
            );
        }
        let max_vertices = crate::render::cache::MAX_FILL_VERTICES;
        if !(1..=max_vertices).contains(&r.fill_vertices) {
            bail!(
                "render.fill_vertices must be 1 to {max_vertices}, got {}",
                r.fill_vertices
            );
        }
        if !(1..=64).contains(&r.fill_light_samples) {
            bail!(
                "render.fill_light_samples must be 1 to 64, got {}",
                r.fill_light_samples
            );
        }
        for (key, value) in [
            ("glossy_share", r.glossy_share),
            ("glossy_min_width", r.glossy_min_width),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                bail!("render.{key} must be a number ≥ 0, got {value}");
            }
        }
        if r.spp > MAX_SPP || r.slices > MAX_SLICES || r.max_depth > MAX_DEPTH {
            bail!(
                "render.spp (≤ {MAX_SPP}), render.slices (≤ {MAX_SLICES}) or render.max_depth \
                 (≤ {MAX_DEPTH}) is too large: {}, {}, {}",
                r.spp,
                r.slices,
                r.max_depth
            );
        }
        if !(0.0..1.0).contains(&r.mode_epsilon) {
            bail!(
                "render.mode_epsilon must be in [0, 1), got {}",
                r.mode_epsilon
            );
        }
        // The scene stores it as f32: 1e308 is finite here and infinite there.
        if !(MIN_EXPOSURE..=MAX_EXPOSURE).contains(&r.exposure) {
            bail!(
                "render.exposure must be {MIN_EXPOSURE:e} to {MAX_EXPOSURE:e}, got {}",
                r.exposure
            );
        }
        if r.adaptive_spp > MAX_SPP || r.adaptive_threshold.is_nan() || r.adaptive_threshold < 0.0 {
            bail!(
                "render.adaptive_spp must be ≤ {MAX_SPP} and render.adaptive_threshold a number ≥ 0: \
                 {}, {}",
                r.adaptive_spp,
                r.adaptive_threshold
            );
        }
        self.scene.validate()?;
        self.sensor.validate()?;
        self.gltf.validate()
    }

    /// SHA-256 of the canonical JSON form: identifies the config in the manifest.
    pub fn hash(&self) -> String {
        let json = serde_json::to_vec(self).expect("config serialises");
        lfformat::manifest::hex_sha256(&json)
    }
}

/// Applies one `section.key=value` override. The value is parsed as TOML (`[64,64]`, `4`,
/// `true`, `"x"`); a bare word that is not TOML is taken as a string (`render.gt_views=all`).
fn apply_set(table: &mut toml::Table, set: &str) -> Result<()> {
    let (key, raw) = set
        .split_once('=')
        .with_context(|| format!("--set {set:?}: expected section.key=value"))?;
    let path: Vec<&str> = key.trim().split('.').collect();
    check_known_key(&path).with_context(|| format!("--set {set:?}"))?;
    let raw = raw.trim();
    let value = toml::from_str::<toml::Table>(&format!("v = {raw}"))
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| toml::Value::String(raw.to_string()));
    let (last, parents) = path.split_last().expect("non-empty path");
    let mut node = table;
    for p in parents {
        node = node
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .with_context(|| format!("--set {set:?}: {p} is not a section"))?;
    }
    node.insert(last.to_string(), value);
    Ok(())
}

/// Rejects keys that the config does not have, listing the valid ones of that section.
fn check_known_key(path: &[&str]) -> Result<()> {
    let defaults = toml::Table::try_from(Config::default()).expect("defaults serialise");
    let mut node = &defaults;
    for (i, p) in path.iter().enumerate() {
        match node.get(*p) {
            Some(toml::Value::Table(t)) if i + 1 < path.len() => node = t,
            Some(v) if i + 1 == path.len() && !v.is_table() => return Ok(()),
            Some(_) if i + 1 == path.len() => bail!("{:?} is a section, not a key", path.join(".")),
            _ => {
                let known: Vec<&String> = node.keys().collect();
                bail!(
                    "unknown config key {:?} (known here: {known:?})",
                    path.join(".")
                );
            }
        }
    }
    unreachable!("the loop returns or fails on the last path element")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generator_toml_documents_exactly_the_defaults() {
        let text = include_str!("../generator.toml");
        let parsed: Config = toml::from_str(text).expect("generator.toml parses");
        assert_eq!(parsed, Config::default());
        // And every default key appears in the file (so the file documents all of them).
        let file: toml::Table = toml::from_str(text).unwrap();
        let defaults = toml::Table::try_from(Config::default()).unwrap();
        for (section, keys) in &defaults {
            for key in keys.as_table().unwrap().keys() {
                assert!(
                    file[section].as_table().unwrap().contains_key(key),
                    "{section}.{key} undocumented"
                );
            }
        }
    }

    #[test]
    fn sets_override_and_unknown_keys_are_named() {
        let sets = [
            "camera.resolution=[64,48]".to_string(),
            "render.gt_views=all".to_string(),
        ];
        let cfg = Config::load(None, &["quick".into()], &sets).unwrap();
        assert_eq!(cfg.camera.resolution, [64, 48]);
        assert_eq!(cfg.render.gt_views, GtViews::All);
        assert_eq!(cfg.render.spp, 10, "preset applied");
        let clean = Config::load(None, &["quick".into(), "clean".into()], &[]).unwrap();
        let r = &clean.render;
        assert_eq!((r.final_gather, r.cache_spp, r.spp), (true, 2, 10));
        assert_eq!(clean.camera.resolution, [128, 128], "presets compose");
        let gather = |presets: &[&str]| {
            let presets: Vec<String> = presets.iter().map(|p| p.to_string()).collect();
            Config::load(None, &presets, &[])
                .unwrap()
                .render
                .final_gather
        };
        assert_eq!(
            [gather(&[]), gather(&["fast"]), gather(&["quick"])],
            [true, false, false],
            "the final gather is the default, off in fast and quick"
        );
        let err = Config::load(None, &[], &["render.spp_=3".into()]).unwrap_err();
        assert!(format!("{err:#}").contains("render.spp_"), "{err:#}");
        for bad in [
            "render.adaptive_threshold=-1",
            "render.adaptive_threshold=nan",
        ] {
            let err = Config::load(None, &[], &[bad.into()]).unwrap_err();
            assert!(format!("{err:#}").contains("adaptive_threshold"), "{err:#}");
        }
        let err = Config::load(None, &[], &["render=3".into()]).unwrap_err();
        assert!(format!("{err:#}").contains("section"), "{err:#}");
    }
}
