//! Per-scene figures (`stats.json`): how multimodal the ground truth is and what it spans.
//!
//! Nothing here depends on time or threads, so `stats.json` is as reproducible as the images;
//! render timings go to the dataset's `timings.jsonl` instead.

use crate::appearance::{ImageStats, quantiles};
use crate::scene::PlacementReport;
use lfformat::ModeMap;
use lfformat::views::CaptureDraw;
use serde::{Deserialize, Serialize};

/// η above which a mode counts towards "multimodal" (thesis §5.3.2).
pub const MULTIMODAL_ETA: f32 = 0.3;
/// Bins of the disparity histogram.
const HIST_BINS: usize = 64;

/// Figures of one scene's centre-view ground truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneStats {
    /// Fraction of pixels with at least two modes of η > 0.3.
    pub multimodal_fraction: f64,
    /// Fraction of pixels with at least two modes of any η.
    #[serde(default)]
    pub two_mode_fraction: f64,
    /// `mode_count_histogram[k]` = number of pixels with exactly k modes.
    pub mode_count_histogram: Vec<u64>,
    /// Min and max disparity over all modes.
    pub disparity_range: [f64; 2],
    /// Min and max of the HCI single-valued disparity map.
    pub hci_disparity_range: [f64; 2],
    /// η-weighted histogram of mode disparities over `disparity_range`, normalised to sum 1.
    pub disparity_histogram: Vec<f64>,
    /// Mean of Σ η over pixels (1 in a closed room).
    pub mean_eta_sum: f64,
    /// Fraction of pixels set in `valid_mask.png`.
    #[serde(default)]
    pub valid_fraction: f64,
    pub baseline_mm: f64,
    pub focus_distance_m: f64,
    pub depth_range_m: [f64; 2],
    pub exposure: f32,
    pub triangles: u64,
    /// Creation date (parameters.cfg `date`).
    pub date: String,
    /// Pieces placed and rejected by the built-in generator (absent for imported scenes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub placement: Option<PlacementReport>,
    /// Local contrast, flat share, mean luminance and noise of the written centre view
    /// ([`crate::appearance`]; absent in older datasets).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub appearance: Option<ImageStats>,
    /// The camera model's draw for this scene (absent when the model is off).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CaptureDraw>,
}

impl SceneStats {
    /// Computes the ground-truth figures; camera and scene fields are filled by the caller.
    pub fn from_gt(modes: &ModeMap, hci_disparity: &[f32], valid: &[bool]) -> Self {
        let pixels = (modes.width * modes.height).max(1) as f64;
        let mut counts = vec![0u64; modes.max_modes() + 1];
        let (mut multimodal, mut eta_sum) = (0u64, 0.0f64);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for px in modes.pixels() {
            counts[px.len()] += 1;
            multimodal += (px.iter().filter(|m| m.eta > MULTIMODAL_ETA).count() >= 2) as u64;
            eta_sum += px.iter().map(|m| m.eta as f64).sum::<f64>();
            for m in px {
                lo = lo.min(m.disparity as f64);
                hi = hi.max(m.disparity as f64);
            }
        }
        let mut hist = vec![0.0f64; HIST_BINS];
        let width = (hi - lo).max(1e-9);
        for m in modes.pixels().flatten() {
            let k = (((m.disparity as f64 - lo) / width * HIST_BINS as f64) as usize)
                .min(HIST_BINS - 1);
            hist[k] += m.eta as f64 / pixels;
        }
        let finite = hci_disparity
            .iter()
            .filter(|d| d.is_finite())
            .map(|&d| d as f64);
        let hci = finite.fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], d| {
            [a.min(d), b.max(d)]
        });
        Self {
            multimodal_fraction: multimodal as f64 / pixels,
            two_mode_fraction: counts.iter().skip(2).sum::<u64>() as f64 / pixels,
            mode_count_histogram: counts,
            disparity_range: [lo, hi],
            hci_disparity_range: hci,
            disparity_histogram: hist,
            mean_eta_sum: eta_sum / pixels,
            valid_fraction: valid.iter().filter(|&&v| v).count() as f64 / pixels,
            baseline_mm: 0.0,
            focus_distance_m: 0.0,
            depth_range_m: [0.0, 0.0],
            exposure: 1.0,
            triangles: 0,
            date: String::new(),
            placement: None,
            appearance: None,
            camera: None,
        }
    }
}

/// Dataset-wide figures over every scene's `stats.json` (`summary.json` at the root).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DatasetSummary {
    pub scenes: usize,
    /// [min, median, max] over scenes.
    pub multimodal_fraction: [f64; 3],
    pub two_mode_fraction: [f64; 3],
    /// Fraction of pixels in `valid_mask.png`.
    #[serde(default)]
    pub valid_fraction: [f64; 3],
    pub exposure: [f64; 3],
    /// Pixels with exactly k modes, summed over scenes.
    pub mode_count_histogram: Vec<u64>,
    /// Smallest and largest mode disparity of any scene.
    pub disparity_range: [f64; 2],
    pub objects_placed: u64,
    pub objects_rejected: u64,
    /// `[min, q25, median, q75, max]` over the scenes that have them of each centre-view
    /// appearance figure ([`crate::appearance`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub appearance: Option<AppearanceSummary>,
}

/// Quantiles over scenes of the [`ImageStats`] figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AppearanceSummary {
    pub local_contrast: [f64; 5],
    pub flat_share: [f64; 5],
    pub mean_luminance: [f64; 5],
    pub noise: [f64; 5],
}

impl AppearanceSummary {
    /// The quantiles over `scenes`' figures, `None` when none has them.
    pub fn new(scenes: &[SceneStats]) -> Option<Self> {
        let figures: Vec<ImageStats> = scenes.iter().filter_map(|s| s.appearance).collect();
        let q = |f: fn(&ImageStats) -> f64| quantiles(&figures.iter().map(f).collect::<Vec<_>>());
        (!figures.is_empty()).then(|| Self {
            local_contrast: q(|s| s.local_contrast),
            flat_share: q(|s| s.flat_share),
            mean_luminance: q(|s| s.mean_luminance),
            noise: q(|s| s.noise),
        })
    }
}

impl DatasetSummary {
    pub fn new(scenes: &[SceneStats]) -> Self {
        let spread = |f: &dyn Fn(&SceneStats) -> f64| {
            let mut v: Vec<f64> = scenes.iter().map(f).collect();
            v.sort_by(f64::total_cmp);
            match v.len() {
                0 => [0.0; 3],
                n => [v[0], (v[(n - 1) / 2] + v[n / 2]) / 2.0, v[n - 1]],
            }
        };
        let mut hist = Vec::<u64>::new();
        for s in scenes {
            hist.resize(hist.len().max(s.mode_count_histogram.len()), 0);
            for (h, c) in hist.iter_mut().zip(&s.mode_count_histogram) {
                *h += c;
            }
        }
        let placement = scenes.iter().filter_map(|s| s.placement.as_ref());
        let (placed, rejected) = placement.fold((0, 0), |(p, r), x| {
            (p + x.placed as u64, r + x.rejected as u64)
        });
        Self {
            scenes: scenes.len(),
            multimodal_fraction: spread(&|s| s.multimodal_fraction),
            two_mode_fraction: spread(&|s| s.two_mode_fraction),
            valid_fraction: spread(&|s| s.valid_fraction),
            exposure: spread(&|s| s.exposure as f64),
            mode_count_histogram: hist,
            disparity_range: scenes
                .iter()
                .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], s| {
                    [a.min(s.disparity_range[0]), b.max(s.disparity_range[1])]
                }),
            objects_placed: placed,
            objects_rejected: rejected,
            appearance: AppearanceSummary::new(scenes),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lfformat::Mode;

    #[test]
    fn counts_multimodal_pixels_and_histogram_mass() {
        let mut map = ModeMap::new(2, 1);
        let m = |d: f32, eta: f32| Mode {
            disparity: d,
            depth: 1.0,
            eta,
            eta_exact: eta,
        };
        map.push_pixel(&[m(1.0, 0.4), m(-1.0, 0.6)]);
        map.push_pixel(&[m(0.0, 1.0)]);
        let s = SceneStats::from_gt(&map, &[0.5, f32::NAN], &[false, true]);
        assert_eq!(s.multimodal_fraction, 0.5);
        assert_eq!(s.two_mode_fraction, 0.5);
        assert_eq!(s.mode_count_histogram, vec![0, 1, 1]);
        assert_eq!(s.disparity_range, [-1.0, 1.0]);
        assert_eq!(s.hci_disparity_range, [0.5, 0.5]);
        assert!((s.disparity_histogram.iter().sum::<f64>() - 1.0).abs() < 1e-6);
        assert!((s.mean_eta_sum - 1.0).abs() < 1e-6);
        assert_eq!(s.valid_fraction, 0.5);
        let summary = DatasetSummary::new(&[s.clone(), s]);
        assert_eq!(summary.mode_count_histogram, vec![0, 2, 2]);
        assert_eq!(summary.multimodal_fraction, [0.5; 3]);
        assert_eq!(summary.valid_fraction, [0.5; 3]);
    }
}
