//! The output of an evaluation: `metrics.json`, `report.md` / `report.html` with the tables,
//! and PNG plots (sparsification curves, per-scene BadPix maps, posteriors at pixels).

pub mod chart;
pub mod errormap;
pub mod json;
pub mod samples;
pub mod table;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use lfdata::prediction::Method;
use lfdata::scene_eval::{EvalConfig, SceneScores};
use lfformat::dataset::SceneDir;
use samples::PosteriorSample;

use crate::summary::MethodSummary;

/// Folder of the per-scene BadPix maps, one sub-folder per method.
pub const ERROR_MAP_DIR: &str = "error_maps";
/// Folder of the posterior plots.
pub const POSTERIOR_PLOT_DIR: &str = "posteriors";
/// The sparsification charts, by error measure.
pub const SPARSIFICATION_PLOTS: [&str; 2] =
    ["sparsification_badpix007.png", "sparsification_mse.png"];

/// One method's results.
pub struct MethodResult {
    /// The method.
    pub method: Method,
    /// Per scene, in the order of [`Evaluation::scenes`].
    pub scenes: Vec<SceneScores>,
    /// Over the dataset.
    pub summary: MethodSummary,
}

/// Everything an evaluation found.
pub struct Evaluation {
    /// The dataset folder given.
    pub dataset: PathBuf,
    /// The settings.
    pub config: EvalConfig,
    /// Scenes evaluated.
    pub scenes: Vec<SceneDir>,
    /// Scenes left out because they have no ground truth (e.g. HCI test scenes).
    pub skipped: Vec<String>,
    /// One entry per method, in command-line order.
    pub methods: Vec<MethodResult>,
    /// Posteriors at the plotted pixels.
    pub samples: Vec<PosteriorSample>,
}

/// Writes `metrics.json`, the tables and the dataset-level charts into `out` (the error
/// maps are written while scenes are evaluated, so predictions need not stay in memory).
pub fn write_all(eval: &Evaluation, out: &Path) -> Result<()> {
    json::write(eval, &out.join("metrics.json"))?;
    for (file, measure) in SPARSIFICATION_PLOTS.iter().zip(chart::Measure::ALL) {
        chart::sparsification(eval, measure, &out.join(file))?;
    }
    let dir = out.join(POSTERIOR_PLOT_DIR);
    if !eval.samples.is_empty() {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
    }
    for s in &eval.samples {
        chart::posterior(s, &eval.config.bins, &dir.join(posterior_plot_name(s)))?;
    }
    table::write_reports(eval, out)
}

/// File name of the posterior plot of `s`.
pub fn posterior_plot_name(s: &PosteriorSample) -> String {
    format!("{}_x{}_y{}.png", s.scene, s.x, s.y)
}

/// Writes `text` to `path` atomically, naming the file on failure.
pub fn write_text(path: &Path, text: &str) -> Result<()> {
    Ok(lfformat::files::write_atomic(path, text.as_bytes())?)
}
