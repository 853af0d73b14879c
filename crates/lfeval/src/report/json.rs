//! `metrics.json`: every number of the evaluation, for scripts.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Result;
use lfdata::metrics::hci::HciScores;
use lfdata::metrics::kld::KldScores;
use lfdata::metrics::region::RegionScores;
use lfdata::scene_eval::{EvalConfig, SceneScores, UncertaintySource};
use serde::Serialize;

use super::{Evaluation, MethodResult, write_text};
use crate::summary::MethodSummary;

#[derive(Serialize)]
struct MetricsFile<'a> {
    generator: String,
    dataset: String,
    config: &'a EvalConfig,
    scenes: Vec<SceneInfo<'a>>,
    skipped_scenes: &'a [String],
    methods: Vec<MethodJson<'a>>,
}

#[derive(Serialize)]
struct SceneInfo<'a> {
    name: &'a str,
    split: Option<&'a str>,
}

#[derive(Serialize)]
struct MethodJson<'a> {
    name: &'a str,
    dir: String,
    summary: &'a MethodSummary,
    scenes: BTreeMap<&'a str, SceneJson>,
}

#[derive(Serialize)]
struct SceneJson {
    unimodal: BTreeMap<&'static str, HciScores>,
    kld: KldScores,
    ause_badpix_007: Option<f64>,
    ause_mse_x100: Option<f64>,
    runtime_s: Option<f64>,
    invalid_percent: Option<f64>,
    uncertainty: Option<UncertaintySource>,
    distribution: &'static str,
    regions: Option<RegionScores>,
}

impl SceneJson {
    fn from(s: &SceneScores) -> Self {
        let sp = s.sparsification.as_ref();
        Self {
            unimodal: s.unimodal.iter().map(|(r, v)| (r.name(), *v)).collect(),
            kld: s.kld.scores(),
            ause_badpix_007: sp.and_then(|p| p.badpix_007.ause()),
            ause_mse_x100: sp.and_then(|p| p.mse_x100.ause()),
            runtime_s: s.runtime_s,
            invalid_percent: s.invalid_percent,
            uncertainty: s.uncertainty,
            distribution: s.distribution,
            regions: s.regions,
        }
    }
}

fn method_json<'a>(eval: &'a Evaluation, m: &'a MethodResult) -> MethodJson<'a> {
    MethodJson {
        name: &m.method.name,
        dir: m.method.dir.display().to_string(),
        summary: &m.summary,
        scenes: eval
            .scenes
            .iter()
            .zip(&m.scenes)
            .map(|(scene, s)| (scene.name.as_str(), SceneJson::from(s)))
            .collect(),
    }
}

/// Writes `metrics.json` (pretty, `null` for scores that do not exist).
pub fn write(eval: &Evaluation, path: &Path) -> Result<()> {
    let file = MetricsFile {
        generator: format!("lfeval {}", env!("CARGO_PKG_VERSION")),
        dataset: eval.dataset.display().to_string(),
        config: &eval.config,
        scenes: eval
            .scenes
            .iter()
            .map(|s| SceneInfo {
                name: &s.name,
                split: s.split.as_deref(),
            })
            .collect(),
        skipped_scenes: &eval.skipped,
        methods: eval.methods.iter().map(|m| method_json(eval, m)).collect(),
    };
    let text = serde_json::to_string_pretty(&file)? + "\n";
    write_text(path, &text)
}
