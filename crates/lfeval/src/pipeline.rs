//! The dataset-level commands: loops over scenes with file I/O, progress bars and rayon.
//!
//! Evaluation runs scenes in parallel (each is cheap and independent); the baseline runs
//! scenes one after another because each cost volume is already computed in parallel and
//! holds `width × height × bins` floats.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use indicatif::{ParallelProgressIterator, ProgressBar, ProgressIterator, ProgressStyle};
use lfdata::bins::Bins;
use lfdata::lightfield::LightField;
use lfdata::prediction::{Method, RUNTIME_DIR, write_prediction};
use lfdata::progress::progress;
use lfdata::regions::load_region_truth;
use lfdata::scene_eval::{EvalConfig, MAIN_BADPIX, PreparedTruth, SceneScores, evaluate};
use lfdata::truth::{EtaKind, HCI_GT_FILE, Reference, SceneTruth};
use lfformat::dataset::SceneDir;
use lfformat::views::{ViewSet, centre_view};
use rayon::prelude::*;
use serde::Serialize;

use crate::baseline::{self, BaselineConfig};
use crate::report::errormap::{self, badpix_map, luminance};
use crate::report::samples::{PixelRequest, PosteriorSample, auto_pixels};
use crate::report::{ERROR_MAP_DIR, Evaluation, MethodResult};
use crate::slfc::{self, SlfcConfig};
use crate::summary::MethodSummary;

/// Options of [`evaluate_dataset`] beyond the metric settings.
#[derive(Clone, Debug, Default)]
pub struct EvalOptions {
    /// The metric settings.
    pub config: EvalConfig,
    /// Report folder (error maps are written there during the run).
    pub out: PathBuf,
    /// Pixels to plot posteriors at.
    pub pixels: Vec<PixelRequest>,
    /// Number of scenes (from the first) that get automatically chosen posterior plots.
    pub auto_plot_scenes: usize,
    /// Whether to write per-scene BadPix maps.
    pub error_maps: bool,
    /// No progress bar.
    pub quiet: bool,
}

/// What one scene contributes: every method's scores and the posterior samples.
struct SceneOutcome {
    scores: Vec<SceneScores>,
    samples: Vec<PosteriorSample>,
}

/// Evaluates every method on every scene that has ground truth; scenes without
/// `gt_disp_lowres.pfm` (HCI test scenes) are skipped and listed.
pub fn evaluate_dataset(
    dataset: &Path,
    scenes: Vec<SceneDir>,
    methods: Vec<Method>,
    opts: &EvalOptions,
) -> Result<Evaluation> {
    check_method_names(&methods)?;
    for p in &opts.pixels {
        if !scenes.iter().any(|s| s.name == p.scene) {
            bail!(
                "--pixel {}:{},{}: no scene called {:?}",
                p.scene,
                p.x,
                p.y,
                p.scene
            );
        }
    }
    // Present in any form counts as ground truth: a FIFO or a broken link there is an error
    // when the scene is read, not a test scene to leave out.
    let (with_gt, without): (Vec<SceneDir>, Vec<SceneDir>) = scenes
        .into_iter()
        .partition(|s| s.path.join(HCI_GT_FILE).symlink_metadata().is_ok());
    if with_gt.is_empty() {
        bail!(
            "{}: no scene has {HCI_GT_FILE}, nothing to evaluate",
            dataset.display()
        );
    }
    if let Some(first) = without.first() {
        lfformat::note!(
            "warning: {} scene(s) without {HCI_GT_FILE} left out of the scores ({}{}); they are \
             listed as skipped_scenes in metrics.json",
            without.len(),
            first.name,
            if without.len() > 1 { ", …" } else { "" }
        );
    }
    let bar = progress(with_gt.len(), "evaluating", opts.quiet);
    let outcomes: Vec<SceneOutcome> = with_gt
        .par_iter()
        .enumerate()
        .progress_with(bar)
        .map(|(index, scene)| evaluate_scene(scene, index, &methods, opts))
        .collect::<Result<_>>()?;
    let mut samples = Vec::new();
    let mut per_method: Vec<Vec<SceneScores>> = vec![Vec::new(); methods.len()];
    for outcome in outcomes {
        samples.extend(outcome.samples);
        for (m, s) in per_method.iter_mut().zip(outcome.scores) {
            m.push(s);
        }
    }
    let steps = opts.config.sparsification_steps;
    let methods = methods
        .into_iter()
        .zip(per_method)
        .map(|(method, scenes)| MethodResult {
            summary: MethodSummary::from_scenes(&scenes, steps),
            method,
            scenes,
        })
        .collect();
    Ok(Evaluation {
        dataset: dataset.to_path_buf(),
        config: opts.config.clone(),
        scenes: with_gt,
        skipped: without.into_iter().map(|s| s.name).collect(),
        methods,
        samples,
    })
}

/// Method names key the report, so they must differ.
fn check_method_names(methods: &[Method]) -> Result<()> {
    for (i, a) in methods.iter().enumerate() {
        if let Some(b) = methods[i + 1..].iter().find(|b| b.name == a.name) {
            bail!(
                "{} and {} are both called {:?}; methods are named by their folder",
                a.dir.display(),
                b.dir.display(),
                a.name
            );
        }
    }
    Ok(())
}

/// Every method on one scene, writing its error maps.
fn evaluate_scene(
    scene: &SceneDir,
    index: usize,
    methods: &[Method],
    opts: &EvalOptions,
) -> Result<SceneOutcome> {
    let cfg = &opts.config;
    let truth = SceneTruth::load(&scene.path)?;
    let (w, h) = (truth.width(), truth.height());
    let regions = load_region_truth(&scene.path, w, h)?;
    let gt = PreparedTruth::new(&truth, cfg).with_regions(regions);
    let mut samples = plot_pixels(scene, index, &truth, &gt, opts)?;
    // The view only shades the error maps; a scene without views is still evaluated.
    let shade = centre_view(&scene.path)
        .ok()
        .filter(|(_, vw, vh)| (*vw, *vh) == (w, h))
        .map(|(rgb, _, _)| luminance(&rgb));
    let mut scores = Vec::with_capacity(methods.len());
    for method in methods {
        let pred = method.load_cropped(&scene.name, w, h, gt.frame.crop)?;
        scores.push(evaluate(&gt, &pred, cfg));
        for s in &mut samples {
            s.add(&method.name, &pred, &cfg.bins);
        }
        if opts.error_maps {
            let map = badpix_map(
                &pred.disparity.data,
                gt.reference(cfg.reference),
                &gt.frame,
                MAIN_BADPIX,
                shade.as_deref(),
            );
            let path = opts
                .out
                .join(ERROR_MAP_DIR)
                .join(&method.name)
                .join(format!("{}.png", scene.name));
            errormap::write(&path, &map)?;
        }
    }
    Ok(SceneOutcome { scores, samples })
}

/// The posterior samples of a scene: the requested pixels, plus automatic ones for the
/// first `auto_plot_scenes` scenes.
fn plot_pixels(
    scene: &SceneDir,
    index: usize,
    truth: &SceneTruth,
    gt: &PreparedTruth,
    opts: &EvalOptions,
) -> Result<Vec<PosteriorSample>> {
    let mut pixels = Vec::new();
    for p in opts.pixels.iter().filter(|p| p.scene == scene.name) {
        if p.x >= truth.width() || p.y >= truth.height() {
            bail!(
                "--pixel {}:{},{} lies outside the {}x{} image",
                p.scene,
                p.x,
                p.y,
                truth.width(),
                truth.height()
            );
        }
        pixels.push((p.x, p.y));
    }
    if index < opts.auto_plot_scenes {
        pixels.extend(auto_pixels(truth, &gt.frame, opts.config.eta));
    }
    Ok(pixels
        .into_iter()
        .map(|xy| PosteriorSample::new(&scene.name, truth, xy, opts.config.eta))
        .collect())
}

/// Settings echoed into `PRED/lfeval.json` so a prediction folder says what made it.
#[derive(Serialize)]
struct ProvenanceFile<'a, T: Serialize> {
    generator: String,
    command: &'a str,
    dataset: String,
    settings: &'a T,
}

/// Writes `out/lfeval.json` describing how the predictions were made.
fn write_provenance<T: Serialize>(
    out: &Path,
    command: &str,
    dataset: &Path,
    settings: &T,
) -> Result<()> {
    let file = ProvenanceFile {
        generator: format!("lfeval {}", env!("CARGO_PKG_VERSION")),
        command,
        dataset: dataset.display().to_string(),
        settings,
    };
    let path = out.join("lfeval.json");
    let text = serde_json::to_string_pretty(&file)? + "\n";
    std::fs::write(&path, text).with_context(|| format!("{}: cannot write", path.display()))
}

/// Runs the baseline on every scene and writes its predictions under `out`.
pub fn baseline_dataset(
    dataset: &Path,
    scenes: &[SceneDir],
    out: &Path,
    cfg: &BaselineConfig,
    keep_posterior: bool,
    quiet: bool,
) -> Result<()> {
    create_dir(out)?;
    write_provenance(out, "baseline", dataset, cfg)?;
    for scene in scenes
        .iter()
        .progress_with(progress(scenes.len(), "baseline", quiet))
    {
        let lf = LightField::load(&scene.path, cfg.views)?;
        let mut pred = baseline::estimate(&lf, cfg);
        if !keep_posterior {
            pred.posterior = None;
        }
        write_prediction(out, &scene.name, &pred)?;
    }
    Ok(())
}

/// Runs SLFC on every scene and writes its predictions under `out`. A scene whose runtime
/// file exists (the last file [`write_prediction`] writes) is complete and skipped, so an
/// interrupted run resumes where it stopped. Scenes run one after another, rows in parallel.
pub fn slfc_dataset(
    dataset: &Path,
    scenes: &[SceneDir],
    out: &Path,
    cfg: &SlfcConfig,
    quiet: bool,
) -> Result<()> {
    create_dir(out)?;
    write_provenance(out, "slfc", dataset, cfg)?;
    for (i, scene) in scenes.iter().enumerate() {
        let done = out.join(RUNTIME_DIR).join(format!("{}.txt", scene.name));
        if done.is_file() {
            lfformat::note!("slfc: {} already predicted, skipped", scene.name);
            continue;
        }
        let lf = LightField::load(&scene.path, ViewSet::Cross)?;
        let message = format!("slfc {}/{} {}", i + 1, scenes.len(), scene.name);
        let bar = row_progress(&message, quiet);
        let result =
            slfc::estimate(&lf, cfg, &bar).with_context(|| format!("{}", scene.path.display()))?;
        bar.finish_and_clear();
        if result.unconverged > 0 {
            lfformat::note!(
                "slfc: {}: {} Lasso problems stopped at {} sweeps above the tolerance",
                scene.name,
                result.unconverged,
                cfg.lasso.max_sweeps
            );
        }
        write_prediction(out, &scene.name, &result.prediction)?;
    }
    Ok(())
}

/// A progress bar over one scene's rows (SLFC takes minutes per scene).
fn row_progress(message: &str, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let style = ProgressStyle::with_template(
        "{msg} [{bar:30}] {pos}/{len} rows, {elapsed_precise} (eta {eta})",
    )
    .expect("valid template")
    .progress_chars("=> ");
    ProgressBar::new(0)
        .with_style(style)
        .with_message(message.to_string())
}

/// Settings of [`truth_dataset`], for its provenance file.
#[derive(Serialize)]
struct TruthSettings {
    reference: Reference,
    eta: EtaKind,
    bins: Bins,
}

/// Writes every scene's ground truth as a method's prediction (a pipeline check: it must
/// score 0), skipping scenes without ground truth.
pub fn truth_dataset(
    dataset: &Path,
    scenes: &[SceneDir],
    out: &Path,
    (reference, eta, bins): (Reference, EtaKind, Bins),
    quiet: bool,
) -> Result<()> {
    create_dir(out)?;
    write_provenance(
        out,
        "truth",
        dataset,
        &TruthSettings {
            reference,
            eta,
            bins,
        },
    )?;
    let with_gt: Vec<&SceneDir> = scenes
        .iter()
        .filter(|s| s.path.join(HCI_GT_FILE).is_file())
        .collect();
    with_gt
        .par_iter()
        .progress_with(progress(with_gt.len(), "truth", quiet))
        .try_for_each(|scene| {
            let truth = SceneTruth::load(&scene.path)?;
            write_prediction(
                out,
                &scene.name,
                &truth.as_prediction(reference, eta, &bins),
            )
        })
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))
}
