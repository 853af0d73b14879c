//! Every metric of one method on one scene, from data already in memory.
//!
//! The ground truth is prepared once per scene ([`PreparedTruth`]) and shared by all
//! methods; [`evaluate`] then only reads the prediction.

use serde::Serialize;

use crate::bins::Bins;
use crate::metrics::Frame;
use crate::metrics::hci::{self, HciScores};
use crate::metrics::kld::{self, KldSums};
use crate::metrics::region::{RegionScores, RegionTruth};
use crate::metrics::sparsification::Sparsification;
use crate::prediction::ScenePrediction;
use crate::truth::{self, EtaKind, Reference, SceneTruth};

/// BadPix threshold of the table and the sparsification curves (the thesis' BadPix007).
pub const MAIN_BADPIX: f64 = 0.07;

/// The evaluation settings; the defaults are the thesis' and HCI's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalConfig {
    /// KLD bins (thesis: 108 over [-3.5, 3.5]).
    pub bins: Bins,
    /// Added to every KLD bin before renormalising (thesis code: 1e-5).
    pub epsilon: f64,
    /// Pixels left out at each image side (HCI: 15).
    pub border: usize,
    /// Which `η` is a mode's probability.
    pub eta: EtaKind,
    /// Unimodal ground truth of the summary table, sparsification and error maps.
    pub reference: Reference,
    /// Samples of the sparsification curves.
    pub sparsification_steps: usize,
    /// Side of the scored centre crop as a fraction of the image side (1: the whole frame).
    pub crop: f64,
}

impl Default for EvalConfig {
    fn default() -> Self {
        Self {
            bins: Bins::THESIS,
            epsilon: kld::EPSILON,
            border: 15,
            eta: EtaKind::Over,
            reference: Reference::Front,
            sparsification_steps: 100,
            crop: 1.0,
        }
    }
}

/// Where a method's uncertainty for sparsification came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum UncertaintySource {
    /// `uncertainty/<scene>.pfm`.
    Map,
    /// The variance of `posteriors/<scene>.npz`.
    PosteriorVariance,
}

/// Sparsification of the two error measures of the thesis.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SparsificationPair {
    /// Error = 100 if `|d - gt| > 0.07`, else 0 (so the mean is BadPix in %).
    pub badpix_007: Sparsification,
    /// Error = `100 (d - gt)²` (so the mean is MSE×100).
    pub mse_x100: Sparsification,
}

/// Every metric of one method on one scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneScores {
    /// HCI scores against each reference, in [`Reference::ALL`] order.
    pub unimodal: Vec<(Reference, HciScores)>,
    /// Per-pixel KLD sums.
    pub kld: KldSums,
    /// Present when the method gives an uncertainty.
    pub sparsification: Option<SparsificationPair>,
    /// Seconds, when the method reports it.
    pub runtime_s: Option<f64>,
    /// Percentage of frame pixels whose disparity is NaN or ±∞.
    pub invalid_percent: Option<f64>,
    /// Source of the uncertainty ranking.
    pub uncertainty: Option<UncertaintySource>,
    /// `discrete`, `laplace`, `mixture` or `point` (only a disparity map).
    pub distribution: &'static str,
    /// The HCI region metrics against `gt_disp_lowres.pfm`, where the scene has masks.
    pub regions: Option<RegionScores>,
}

impl SceneScores {
    /// The HCI scores against `reference`.
    pub fn against(&self, reference: Reference) -> HciScores {
        self.unimodal
            .iter()
            .find(|(r, _)| *r == reference)
            .map(|(_, s)| *s)
            .unwrap_or_default()
    }
}

/// A scene's ground truth with the per-pixel quantities every method is compared with.
pub struct PreparedTruth<'a> {
    /// The ground truth.
    pub truth: &'a SceneTruth,
    /// The evaluated pixels.
    pub frame: Frame,
    /// Unimodal ground truth per reference, in [`Reference::ALL`] order.
    pub references: Vec<(Reference, Vec<f32>)>,
    /// The scene's evaluation masks, when it has them.
    pub regions: Option<RegionTruth>,
}

impl<'a> PreparedTruth<'a> {
    /// Prepares `truth` for `cfg`.
    pub fn new(truth: &'a SceneTruth, cfg: &EvalConfig) -> Self {
        let references = Reference::ALL
            .iter()
            .map(|&r| (r, truth.reference_map(r, cfg.eta)))
            .collect();
        Self {
            truth,
            frame: Frame::new(truth.width(), truth.height(), cfg.border).cropped(cfg.crop),
            references,
            regions: None,
        }
    }

    /// With the scene's evaluation masks, so [`evaluate`] scores the HCI region metrics.
    pub fn with_regions(self, regions: Option<RegionTruth>) -> Self {
        Self { regions, ..self }
    }

    /// The unimodal ground truth by `reference`.
    pub fn reference(&self, reference: Reference) -> &[f32] {
        &self
            .references
            .iter()
            .find(|(r, _)| *r == reference)
            .expect("every reference is prepared")
            .1
    }
}

/// Every metric of `pred` against `gt` (sizes already checked by the reader).
pub fn evaluate(gt: &PreparedTruth, pred: &ScenePrediction, cfg: &EvalConfig) -> SceneScores {
    let disparity = &pred.disparity.data;
    let unimodal = gt
        .references
        .iter()
        .map(|(r, map)| (*r, HciScores::compute(disparity, map, &gt.frame)))
        .collect();
    let uncertainty = uncertainty(pred);
    let sparsification = uncertainty.as_ref().map(|(_, u)| {
        sparsify(
            disparity,
            gt.reference(cfg.reference),
            u,
            &gt.frame,
            cfg.sparsification_steps,
        )
    });
    SceneScores {
        unimodal,
        kld: kld_sums(gt, pred, cfg),
        sparsification,
        runtime_s: pred.runtime_s,
        invalid_percent: hci::invalid_percent(disparity, &gt.frame),
        uncertainty: uncertainty.map(|(source, _)| source),
        distribution: pred.posterior.as_ref().map_or("point", |p| p.form_name()),
        regions: gt
            .regions
            .as_ref()
            .map(|r| RegionScores::compute(disparity, gt.reference(Reference::Hci), &gt.frame, r)),
    }
}

/// The predicted distribution of pixel `i` over `bins` into `out`: the posterior's bin
/// masses, or all mass in the bin of the point estimate.
pub fn predicted_masses(pred: &ScenePrediction, i: usize, bins: &Bins, out: &mut [f64]) {
    match &pred.posterior {
        Some(p) => p.pixel(i).bin_masses(bins, out),
        None => kld::point_masses(pred.disparity.data[i].into(), bins, out),
    }
}

/// KLD over frame pixels that have a true distribution (`Σ η > 0`).
fn kld_sums(gt: &PreparedTruth, pred: &ScenePrediction, cfg: &EvalConfig) -> KldSums {
    let k = cfg.bins.count;
    let (mut p, mut q) = (vec![0.0; k], vec![0.0; k]);
    let mut sums = KldSums::default();
    let width = gt.frame.width;
    for i in gt.frame.indices() {
        let modes = gt.truth.modes.pixel(i % width, i / width);
        if truth::histogram(modes, cfg.eta, &cfg.bins, &mut p) <= 0.0 {
            continue;
        }
        predicted_masses(pred, i, &cfg.bins, &mut q);
        let value = kld::pixel_kld(&mut p, &mut q, cfg.epsilon);
        sums.add(value, truth::is_multimodal(modes, cfg.eta));
    }
    sums
}

/// The per-pixel uncertainty and its source: the uncertainty map if given, else the
/// posterior variance, else none.
fn uncertainty(pred: &ScenePrediction) -> Option<(UncertaintySource, Vec<f64>)> {
    if let Some(map) = &pred.uncertainty {
        let values = map.data.iter().map(|&u| f64::from(u)).collect();
        return Some((UncertaintySource::Map, values));
    }
    let p = pred.posterior.as_ref()?;
    let values = (0..p.width * p.height)
        .map(|i| p.pixel(i).variance())
        .collect();
    Some((UncertaintySource::PosteriorVariance, values))
}

/// Sparsification over frame pixels where prediction and ground truth are finite.
fn sparsify(
    pred: &[f32],
    gt: &[f32],
    uncertainty: &[f64],
    frame: &Frame,
    steps: usize,
) -> SparsificationPair {
    let valid: Vec<usize> = frame
        .indices()
        .filter(|&i| pred[i].is_finite() && gt[i].is_finite())
        .collect();
    let diff = |i: usize| f64::from(pred[i]) - f64::from(gt[i]);
    let keys: Vec<f64> = valid.iter().map(|&i| uncertainty[i]).collect();
    let bad: Vec<f64> = valid
        .iter()
        .map(|&i| {
            if crate::metrics::hci::is_bad(pred[i], gt[i], MAIN_BADPIX) {
                100.0
            } else {
                0.0
            }
        })
        .collect();
    let squared: Vec<f64> = valid.iter().map(|&i| 100.0 * diff(i).powi(2)).collect();
    SparsificationPair {
        badpix_007: Sparsification::compute(&bad, &keys, steps),
        mse_x100: Sparsification::compute(&squared, &keys, steps),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::posterior::{PosteriorForm, PosteriorMap};
    use lfformat::pfm::FloatImage;
    use lfformat::{Mode, ModeMap};

    /// A 3×1 scene without border: a unimodal pixel at 1.0, a bimodal one (0.6 at 2.0,
    /// 0.4 at -1.0) and one without any mode.
    fn scene() -> SceneTruth {
        let mode = |d: f32, eta: f32| Mode {
            disparity: d,
            depth: 1.0,
            eta,
            eta_exact: eta,
        };
        let mut modes = ModeMap::new(3, 1);
        modes.push_pixel(&[mode(1.0, 1.0)]);
        modes.push_pixel(&[mode(2.0, 0.6), mode(-1.0, 0.4)]);
        modes.push_pixel(&[]);
        SceneTruth {
            hci: FloatImage::new(3, 1, vec![1.0, 2.0, f32::NAN]),
            modes,
        }
    }

    fn cfg() -> EvalConfig {
        EvalConfig {
            bins: Bins::new(-3.0, 3.0, 6).unwrap(),
            border: 0,
            sparsification_steps: 3,
            ..EvalConfig::default()
        }
    }

    fn point(data: Vec<f32>) -> ScenePrediction {
        ScenePrediction {
            disparity: FloatImage::new(3, 1, data),
            uncertainty: None,
            posterior: None,
            runtime_s: Some(1.5),
        }
    }

    #[test]
    fn the_truth_as_posterior_scores_zero_everywhere() {
        let truth = scene();
        let cfg = cfg();
        let gt = PreparedTruth::new(&truth, &cfg);
        // Discrete posterior equal to the η histogram on the same bins.
        let mut probs = vec![0.0f32; 18];
        probs[4] = 1.0; // pixel 0: 1.0 is in bin [1, 2)
        probs[6 + 5] = 0.6; // pixel 1: 2.0 in bin [2, 3)
        probs[6 + 2] = 0.4; // pixel 1: -1.0 in bin [-1, 0)
        let mut pred = point(vec![1.0, 2.0, f32::NAN]);
        pred.posterior = Some(PosteriorMap {
            width: 3,
            height: 1,
            form: PosteriorForm::Discrete {
                bins: cfg.bins,
                probs,
            },
        });
        let s = evaluate(&gt, &pred, &cfg);
        let front = s.against(Reference::Front);
        assert_eq!(front.mse_x100, Some(0.0));
        assert_eq!(front.badpix_007, Some(0.0));
        let k = s.kld.scores();
        assert_eq!(
            k.pixels_all, 2,
            "the pixel without modes has no true distribution"
        );
        assert_eq!((k.pixels_unimodal, k.pixels_multimodal), (1, 1));
        assert!(k.all.unwrap().abs() < 1e-12);
        let sp = s
            .sparsification
            .as_ref()
            .expect("posterior variance ranks pixels");
        assert_eq!(sp.badpix_007.curve, sp.badpix_007.oracle);
        assert_eq!(sp.mse_x100.ause(), Some(0.0));
        assert_eq!(s.uncertainty, Some(UncertaintySource::PosteriorVariance));
        assert_eq!(s.distribution, "discrete");
        assert_eq!(s.runtime_s, Some(1.5));
    }

    #[test]
    fn point_estimates_are_scored_against_each_reference() {
        let truth = scene();
        let cfg = cfg();
        let gt = PreparedTruth::new(&truth, &cfg);
        // Pixel 1 predicted at the background mode -1.0: wrong for front and dominant.
        let s = evaluate(&gt, &point(vec![1.0, -1.0, 0.0]), &cfg);
        // Front GT [1, 2, NaN]: MSE over 2 finite pixels = (0 + 9) / 2 → ×100 = 450.
        assert_eq!(s.against(Reference::Front).mse_x100, Some(450.0));
        // BadPix over the whole frame of 3 (NaN GT counts as good): 1/3.
        assert_eq!(s.against(Reference::Front).badpix_007, Some(100.0 / 3.0));
        assert_eq!(s.against(Reference::Dominant).mse_x100, Some(450.0));
        // KLD: pixel 0 right (≈0); pixel 1 puts all mass on the 0.4 mode, so with η read
        // as f32: p = (η₁+ε, η₂+ε, 4×ε)/(η₁+η₂+6ε), q = (ε, 1+ε, 4×ε)/(1+6ε).
        let eps = kld::EPSILON;
        let (e1, e2) = (f64::from(0.6f32), f64::from(0.4f32));
        let (np, nq) = (e1 + e2 + 6.0 * eps, 1.0 + 6.0 * eps);
        let (p1, p2, q1, q2) = ((e1 + eps) / np, (e2 + eps) / np, eps / nq, (1.0 + eps) / nq);
        let (po, qo) = (eps / np, eps / nq);
        let expected = p1 * (p1 / q1).ln() + p2 * (p2 / q2).ln() + 4.0 * po * (po / qo).ln();
        let k = s.kld.scores();
        assert!((k.multimodal.unwrap() - expected).abs() < 1e-9);
        assert!(k.unimodal.unwrap().abs() < 1e-12);
        assert_eq!(s.sparsification, None, "no uncertainty, no sparsification");
        assert_eq!(s.distribution, "point");
    }

    #[test]
    fn uncertainty_maps_take_precedence() {
        let truth = scene();
        let cfg = cfg();
        let gt = PreparedTruth::new(&truth, &cfg);
        let mut pred = point(vec![1.0, -1.0, 0.0]);
        // The wrong pixel is flagged as the most uncertain: the curve equals the Oracle.
        pred.uncertainty = Some(FloatImage::new(3, 1, vec![0.1, 5.0, 0.0]));
        let s = evaluate(&gt, &pred, &cfg);
        let sp = s.sparsification.unwrap();
        assert_eq!(sp.badpix_007.curve, vec![50.0, 50.0, 0.0]);
        assert_eq!(sp.badpix_007.curve, sp.badpix_007.oracle);
        assert_eq!(s.uncertainty, Some(UncertaintySource::Map));
    }
}
