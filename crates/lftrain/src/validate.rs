//! Validation through lfeval's metrics: the same numbers `lfeval` reports for the written
//! predictions (front-mode MSE×100 and BadPix(0.07), KLD over all pixels).

use anyhow::Result;
use burn::prelude::*;
use lfdata::lightfield::LightField;
use lfdata::metrics::kld::KldSums;
use lfdata::metrics::mean;
use lfdata::scene_eval::{EvalConfig, PreparedTruth, evaluate};
use lfdata::truth::{Reference, SceneTruth};
use lfformat::dataset::SceneDir;
use rayon::prelude::*;
use serde::Serialize;

use crate::config::TrainConfig;
use crate::model::Network;
use crate::predict::predict_pass;

/// A validation scene, loaded once.
pub struct ValScene {
    /// Folder name.
    pub name: String,
    /// Star views.
    pub lf: LightField,
    /// Ground truth.
    pub truth: SceneTruth,
}

/// Loads the validation scenes (in parallel).
pub fn load_scenes(dirs: &[SceneDir]) -> Result<Vec<ValScene>> {
    dirs.par_iter()
        .map(|d| {
            Ok(ValScene {
                name: d.name.clone(),
                lf: LightField::load_star(&d.path)?,
                truth: SceneTruth::load(&d.path)?,
            })
        })
        .collect()
}

/// Dataset means of one validation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct ValScores {
    /// Mean over scenes of MSE×100 against the front-most mode.
    pub mse_x100: Option<f64>,
    /// Mean over scenes of BadPix(0.07) in %.
    pub badpix_007: Option<f64>,
    /// KLD over all evaluated pixels (nats).
    pub kld: Option<f64>,
}

/// The evaluation settings of validation: lfeval's defaults with the run's border.
pub fn eval_config(cfg: &TrainConfig) -> EvalConfig {
    EvalConfig {
        border: cfg.val_border,
        ..EvalConfig::default()
    }
}

/// Scores of `net` (validation mode, plain device) on `scenes`.
pub fn validate(
    cfg: &TrainConfig,
    net: &Network,
    scenes: &[ValScene],
    device: &Device,
) -> ValScores {
    let ecfg = eval_config(cfg);
    let mut kld = KldSums::default();
    let mut front = Vec::new();
    for s in scenes {
        // One pass: validation tracks the network; the views it holds are the star only, and
        // test-time denoising is `lftrain predict`'s, over every view.
        let pred = predict_pass(cfg, net, &s.lf, device);
        let scores = evaluate(&PreparedTruth::new(&s.truth, &ecfg), &pred, &ecfg);
        kld.merge(&scores.kld);
        front.push(scores.against(Reference::Front));
    }
    ValScores {
        mse_x100: mean(front.iter().map(|s| s.mse_x100)),
        badpix_007: mean(front.iter().map(|s| s.badpix_007)),
        kld: kld.scores().all,
    }
}
