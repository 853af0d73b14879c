//! One method's scores over a whole dataset.
//!
//! Aggregation follows each reference: HCI scores are averaged over scenes (as the HCI
//! benchmark ranks methods), the KLD is averaged over all pixels of all scenes (thesis
//! §5.3.2), sparsification curves are averaged sample-wise over scenes and AuSE is the area
//! under the averaged SE (equal to the mean of the scenes' AuSE).

use std::collections::BTreeMap;

use lfdata::metrics::hci::HciScores;
use lfdata::metrics::kld::{KldScores, KldSums};
use lfdata::metrics::mean;
use lfdata::metrics::region::RegionScores;
use lfdata::metrics::sparsification::{Sparsification, fractions};
use lfdata::scene_eval::SceneScores;
use lfdata::truth::Reference;
use serde::Serialize;

/// A sparsification curve over the dataset, with its Oracle, SE and AuSE.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurveSummary {
    /// Error of the kept pixels by predicted uncertainty.
    pub curve: Vec<f64>,
    /// Error of the kept pixels by true error.
    pub oracle: Vec<f64>,
    /// `curve - oracle`.
    pub error: Vec<f64>,
    /// Area under `error` over `[0, 1)`.
    pub ause: Option<f64>,
}

impl CurveSummary {
    fn from(s: Sparsification) -> Self {
        Self {
            error: s.error(),
            ause: s.ause(),
            curve: s.curve,
            oracle: s.oracle,
        }
    }
}

/// Sparsification of both error measures over the dataset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SparsificationSummary {
    /// Fraction of pixels removed at each sample.
    pub fractions: Vec<f64>,
    /// BadPix(0.07) in %.
    pub badpix_007: CurveSummary,
    /// MSE×100.
    pub mse_x100: CurveSummary,
}

/// A method's dataset-level scores.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MethodSummary {
    /// Scenes evaluated.
    pub scenes: usize,
    /// Mean HCI scores over scenes, per reference name.
    pub unimodal: BTreeMap<&'static str, HciScores>,
    /// KLD pooled over pixels.
    pub kld: KldScores,
    /// Present when every scene had an uncertainty.
    pub sparsification: Option<SparsificationSummary>,
    /// Mean runtime over the scenes that report one.
    pub runtime_mean_s: Option<f64>,
    /// Mean percentage of non-finite predictions.
    pub invalid_percent: Option<f64>,
    /// Mean HCI region scores over the scenes with evaluation masks.
    pub regions: Option<RegionScores>,
}

impl MethodSummary {
    /// Aggregates `scenes` (one method) with curves of `steps` samples.
    pub fn from_scenes(scenes: &[SceneScores], steps: usize) -> Self {
        let unimodal = Reference::ALL
            .iter()
            .map(|&r| (r.name(), mean_scores(scenes.iter().map(|s| s.against(r)))))
            .collect();
        let mut kld = KldSums::default();
        for s in scenes {
            kld.merge(&s.kld);
        }
        Self {
            scenes: scenes.len(),
            unimodal,
            kld: kld.scores(),
            sparsification: sparsification(scenes, steps),
            runtime_mean_s: mean(scenes.iter().map(|s| s.runtime_s)),
            invalid_percent: mean(scenes.iter().map(|s| s.invalid_percent)),
            regions: regions(scenes),
        }
    }
}

/// Region scores averaged over the scenes that have them, `None` when no scene has masks.
fn regions(scenes: &[SceneScores]) -> Option<RegionScores> {
    let with: Vec<RegionScores> = scenes.iter().filter_map(|s| s.regions).collect();
    (!with.is_empty()).then(|| RegionScores::mean(&with))
}

/// Dataset sparsification, only when every scene has one: a partial average would compare
/// a method on other scenes than its competitors.
fn sparsification(scenes: &[SceneScores], steps: usize) -> Option<SparsificationSummary> {
    let pairs: Option<Vec<_>> = scenes.iter().map(|s| s.sparsification.as_ref()).collect();
    let pairs = pairs.filter(|p| !p.is_empty())?;
    Some(SparsificationSummary {
        fractions: fractions(steps),
        badpix_007: CurveSummary::from(Sparsification::mean(pairs.iter().map(|p| &p.badpix_007))?),
        mse_x100: CurveSummary::from(Sparsification::mean(pairs.iter().map(|p| &p.mse_x100))?),
    })
}

/// Score-wise mean over scenes, each score over the scenes that have it.
fn mean_scores(scores: impl Iterator<Item = HciScores> + Clone) -> HciScores {
    HciScores::from_array(std::array::from_fn(|k| {
        mean(scores.clone().map(|s| s.to_array()[k]))
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lfdata::scene_eval::SparsificationPair;

    fn scene(mse: f64, kld: f64, runtime: Option<f64>, curve: Option<Vec<f64>>) -> SceneScores {
        let scores = HciScores {
            mse_x100: Some(mse),
            ..HciScores::default()
        };
        let mut sums = KldSums::default();
        sums.add(kld, false);
        let sp = curve.map(|c| SparsificationPair {
            badpix_007: Sparsification {
                oracle: vec![0.0; c.len()],
                curve: c.clone(),
            },
            mse_x100: Sparsification {
                oracle: c.clone(),
                curve: c,
            },
        });
        SceneScores {
            unimodal: Reference::ALL.iter().map(|&r| (r, scores)).collect(),
            kld: sums,
            sparsification: sp,
            runtime_s: runtime,
            invalid_percent: Some(0.0),
            regions: None,
            uncertainty: None,
            distribution: "point",
        }
    }

    #[test]
    fn scenes_are_averaged_and_pixels_pooled() {
        let s = MethodSummary::from_scenes(
            &[
                scene(1.0, 2.0, Some(3.0), Some(vec![4.0, 2.0])),
                scene(3.0, 4.0, None, Some(vec![2.0, 0.0])),
            ],
            2,
        );
        assert_eq!(s.scenes, 2);
        assert_eq!(s.unimodal["front"].mse_x100, Some(2.0));
        assert_eq!(s.unimodal["hci"].badpix_007, None);
        assert_eq!(s.kld.all, Some(3.0));
        assert_eq!(
            s.runtime_mean_s,
            Some(3.0),
            "mean over the scenes that report it"
        );
        let sp = s.sparsification.unwrap();
        assert_eq!(sp.fractions, vec![0.0, 0.5]);
        assert_eq!(sp.badpix_007.curve, vec![3.0, 1.0]);
        assert_eq!(sp.badpix_007.ause, Some(2.0));
        assert_eq!(sp.mse_x100.ause, Some(0.0));
    }

    #[test]
    fn sparsification_needs_every_scene() {
        let s = MethodSummary::from_scenes(
            &[
                scene(1.0, 2.0, None, Some(vec![1.0])),
                scene(1.0, 2.0, None, None),
            ],
            1,
        );
        assert_eq!(s.sparsification, None);
        assert_eq!(MethodSummary::from_scenes(&[], 1).sparsification, None);
    }
}
