//! The ground truth of one scene: the HCI single-valued disparity and the multimodal modes.
//!
//! Plain HCI benchmark scenes have no `modes.exr`; their single GT becomes one mode with
//! `η = 1`, so every metric runs on both kinds of scene with the same code.

use std::path::Path;

use anyhow::{Result, bail};
use clap::ValueEnum;
use lfformat::modes::read_modes_exr;
use lfformat::pfm::{FloatImage, read_pfm};
use lfformat::{Mode, ModeMap};
use serde::Serialize;

use crate::bins::Bins;
use crate::posterior::{PosteriorForm, PosteriorMap};
use crate::prediction::ScenePrediction;

/// File of the HCI single-valued centre-view disparity.
pub const HCI_GT_FILE: &str = "gt_disp_lowres.pfm";
/// File of the multimodal centre-view ground truth.
pub const MODES_FILE: &str = "modes.exr";
/// `η` above which a mode counts towards multimodality (thesis §5.3.2).
pub const MULTIMODAL_ETA: f32 = 0.3;

/// Which contribution of a mode is its probability.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum EtaKind {
    /// The over-operator contribution (thesis eq. 5.19), the thesis' definition.
    Over,
    /// The exact per-sample visible fraction.
    Exact,
}

/// Which single disparity a unimodal metric compares against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Reference {
    /// The front-most mode (the thesis' unimodal ground truth).
    Front,
    /// The mode with the largest `η` (front-most on ties).
    Dominant,
    /// `gt_disp_lowres.pfm`: the first surface with opacity ≥ 0.5 (HCI semantics).
    Hci,
}

impl Reference {
    /// All references, in report order.
    pub const ALL: [Reference; 3] = [Reference::Front, Reference::Dominant, Reference::Hci];

    /// Lower-case name, as in `metrics.json`.
    pub fn name(self) -> &'static str {
        match self {
            Reference::Front => "front",
            Reference::Dominant => "dominant",
            Reference::Hci => "hci",
        }
    }
}

/// Ground truth of a scene's centre view.
#[derive(Clone, Debug)]
pub struct SceneTruth {
    /// HCI single-valued disparity (NaN where it has none).
    pub hci: FloatImage,
    /// All modes per pixel, front to back.
    pub modes: ModeMap,
}

impl SceneTruth {
    /// Reads `gt_disp_lowres.pfm` and, when present, `modes.exr` from a scene folder.
    pub fn load(dir: &Path) -> Result<Self> {
        let hci = read_pfm(&dir.join(HCI_GT_FILE))?;
        let modes_path = dir.join(MODES_FILE);
        if !modes_path.exists() {
            return Ok(Self::from_single(hci));
        }
        let modes = read_modes_exr(&modes_path)?;
        if (modes.width, modes.height) != (hci.width, hci.height) {
            bail!(
                "{}: {}x{} modes, but {HCI_GT_FILE} is {}x{}",
                modes_path.display(),
                modes.width,
                modes.height,
                hci.width,
                hci.height
            );
        }
        Ok(Self { hci, modes })
    }

    /// Truth of a single-GT scene: every finite disparity is one mode with `η = 1`.
    pub fn from_single(hci: FloatImage) -> Self {
        let mut modes = ModeMap::new(hci.width, hci.height);
        for &d in &hci.data {
            let mode = Mode {
                disparity: d,
                depth: f32::NAN,
                eta: 1.0,
                eta_exact: 1.0,
            };
            let count = usize::from(d.is_finite());
            modes.push_pixel(&[mode][..count]);
        }
        Self { hci, modes }
    }

    /// Columns.
    pub fn width(&self) -> usize {
        self.hci.width
    }

    /// Rows.
    pub fn height(&self) -> usize {
        self.hci.height
    }

    /// The unimodal ground truth by `reference`, row-major; NaN where there is none.
    pub fn reference_map(&self, reference: Reference, eta: EtaKind) -> Vec<f32> {
        match reference {
            Reference::Hci => self.hci.data.clone(),
            Reference::Front => self.per_pixel(|m| front(m, eta)),
            Reference::Dominant => self.per_pixel(|m| dominant(m, eta)),
        }
    }

    /// The ground truth written as a method's prediction, to check a pipeline end to end
    /// (it must score 0 error and 0 KLD): the `reference` disparity as the point estimate
    /// and the `η` histogram over `bins` as a discrete posterior.
    pub fn as_prediction(
        &self,
        reference: Reference,
        eta: EtaKind,
        bins: &Bins,
    ) -> ScenePrediction {
        let (w, h) = (self.width(), self.height());
        let mut probs = vec![0.0f32; w * h * bins.count];
        let mut hist = vec![0.0; bins.count];
        for (modes, out) in self.modes.pixels().zip(probs.chunks_exact_mut(bins.count)) {
            histogram(modes, eta, bins, &mut hist);
            for (o, &p) in out.iter_mut().zip(&hist) {
                *o = p as f32;
            }
        }
        ScenePrediction {
            disparity: FloatImage::new(w, h, self.reference_map(reference, eta)),
            uncertainty: None,
            posterior: Some(PosteriorMap {
                width: w,
                height: h,
                form: PosteriorForm::Discrete { bins: *bins, probs },
            }),
            runtime_s: None,
        }
    }

    /// Applies `f` to each pixel's modes, NaN where it finds none.
    fn per_pixel(&self, f: impl Fn(&[Mode]) -> Option<f32>) -> Vec<f32> {
        self.modes
            .pixels()
            .map(|m| f(m).unwrap_or(f32::NAN))
            .collect()
    }
}

/// The contribution of `m` by `kind`.
pub fn eta_of(m: &Mode, kind: EtaKind) -> f32 {
    match kind {
        EtaKind::Over => m.eta,
        EtaKind::Exact => m.eta_exact,
    }
}

/// Disparity of the front-most mode that contributes (`η > 0`).
pub fn front(modes: &[Mode], eta: EtaKind) -> Option<f32> {
    modes
        .iter()
        .find(|m| eta_of(m, eta) > 0.0 && m.disparity.is_finite())
        .map(|m| m.disparity)
}

/// Disparity of the mode with the largest `η`, the front-most of equals.
pub fn dominant(modes: &[Mode], eta: EtaKind) -> Option<f32> {
    modes
        .iter()
        .filter(|m| eta_of(m, eta) > 0.0 && m.disparity.is_finite())
        .fold(None, |best: Option<&Mode>, m| match best {
            Some(b) if eta_of(b, eta) >= eta_of(m, eta) => best,
            _ => Some(m),
        })
        .map(|m| m.disparity)
}

/// Whether at least two modes have `η > 0.3` (thesis §5.3.2).
pub fn is_multimodal(modes: &[Mode], eta: EtaKind) -> bool {
    modes
        .iter()
        .filter(|m| eta_of(m, eta) > MULTIMODAL_ETA)
        .count()
        >= 2
}

/// The `η`-weighted histogram of the modes over `bins` into `out` (eq. 5.21), not
/// normalised: its total is the pixel's `Σ η`, which may be below 1 where the pixel is not
/// fully covered. Returns that total.
pub fn histogram(modes: &[Mode], eta: EtaKind, bins: &Bins, out: &mut [f64]) -> f64 {
    out.fill(0.0);
    let mut total = 0.0;
    for m in modes {
        let w = f64::from(eta_of(m, eta));
        if let (true, Some(k)) = (w > 0.0, bins.index(m.disparity.into())) {
            out[k] += w;
            total += w;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(disparity: f32, eta: f32, eta_exact: f32) -> Mode {
        Mode {
            disparity,
            depth: 1.0,
            eta,
            eta_exact,
        }
    }

    #[test]
    fn front_dominant_and_multimodality() {
        let m = [
            mode(2.0, 0.35, 0.5),
            mode(1.0, 0.5, 0.2),
            mode(-1.0, 0.15, 0.3),
        ];
        assert_eq!(front(&m, EtaKind::Over), Some(2.0));
        assert_eq!(dominant(&m, EtaKind::Over), Some(1.0));
        assert_eq!(dominant(&m, EtaKind::Exact), Some(2.0));
        assert!(is_multimodal(&m, EtaKind::Over), "0.35 and 0.5 exceed 0.3");
        assert!(!is_multimodal(&m, EtaKind::Exact), "only 0.5 exceeds 0.3");
        let hidden = [mode(3.0, 0.0, 0.1), mode(1.0, 1.0, 0.9)];
        assert_eq!(front(&hidden, EtaKind::Over), Some(1.0), "η = 0 is no mode");
        assert_eq!(front(&hidden, EtaKind::Exact), Some(3.0));
        assert_eq!(front(&[], EtaKind::Over), None);
    }

    #[test]
    fn dominant_ties_go_to_the_front() {
        let m = [mode(2.0, 0.5, 0.5), mode(1.0, 0.5, 0.5)];
        assert_eq!(dominant(&m, EtaKind::Over), Some(2.0));
        assert!(
            !is_multimodal(&[mode(0.0, 0.3, 0.3), mode(1.0, 0.7, 0.7)], EtaKind::Over),
            "η must exceed 0.3, not equal it"
        );
    }

    #[test]
    fn histogram_sums_eta_per_bin() {
        let bins = Bins::new(0.0, 4.0, 4).unwrap();
        let m = [
            mode(0.2, 0.25, 0.0),
            mode(0.7, 0.25, 0.0),
            mode(9.0, 0.4, 0.0),
        ];
        let mut out = vec![0.0; 4];
        let total = histogram(&m, EtaKind::Over, &bins, &mut out);
        assert_eq!(out, vec![0.5, 0.0, 0.0, f64::from(0.4f32)]);
        assert!((total - 0.9).abs() < 1e-7);
    }

    #[test]
    fn hci_scene_without_modes_file_loads_as_single_modes() {
        let dir = tempfile::tempdir().unwrap();
        let gt = FloatImage::new(2, 1, vec![0.5, -1.0]);
        lfformat::pfm::write_pfm(&dir.path().join(HCI_GT_FILE), &gt).unwrap();
        let t = SceneTruth::load(dir.path()).unwrap();
        assert_eq!(t.modes.pixel(1, 0)[0].disparity, -1.0);
        assert_eq!(
            t.reference_map(Reference::Dominant, EtaKind::Exact),
            vec![0.5, -1.0]
        );
        let missing = SceneTruth::load(&dir.path().join("nope")).unwrap_err();
        assert!(format!("{missing:#}").contains(HCI_GT_FILE), "{missing:#}");
    }

    #[test]
    fn single_gt_becomes_one_mode_with_eta_one() {
        let hci = FloatImage::new(2, 1, vec![1.5, f32::NAN]);
        let t = SceneTruth::from_single(hci);
        assert_eq!(t.modes.pixel(0, 0).len(), 1);
        assert_eq!(t.modes.pixel(0, 0)[0].eta, 1.0);
        assert!(t.modes.pixel(1, 0).is_empty());
        let front = t.reference_map(Reference::Front, EtaKind::Over);
        assert_eq!(front[0], 1.5);
        assert!(front[1].is_nan());
    }
}
