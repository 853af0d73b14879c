//! The HCI 4D Light Field Benchmark's unimodal scores, with the toolkit's masks.
//!
//! The toolkit masks each score differently, and we follow it exactly so numbers compare
//! with published ones:
//! - MSE: the frame, minus pixels where the prediction or the ground truth is NaN or ±∞.
//! - BadPix: the whole frame. A NaN difference is not "> τ", so it counts as a good pixel;
//!   an infinite one counts as bad. ([`invalid_percent`] reports how many predictions are
//!   not finite, so such a prediction cannot hide.)
//! - Q25: the frame, minus pixels where `|pred - gt|` or the prediction is not finite; the
//!   score is the sorted error at index `⌊n · 25 / 100⌋`, times 100.

use serde::Serialize;

use super::Frame;

/// BadPix thresholds of the HCI benchmark, pixels.
pub const BADPIX_THRESHOLDS: [f64; 3] = [0.01, 0.03, 0.07];

/// The HCI scores of one prediction against one ground truth; `None` where the mask is
/// empty.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct HciScores {
    /// Mean squared error × 100.
    pub mse_x100: Option<f64>,
    /// Percentage of pixels with `|pred - gt| > 0.01`.
    pub badpix_001: Option<f64>,
    /// Percentage with `> 0.03`.
    pub badpix_003: Option<f64>,
    /// Percentage with `> 0.07`.
    pub badpix_007: Option<f64>,
    /// 25th percentile of `|pred - gt| × 100`.
    pub q25: Option<f64>,
}

impl HciScores {
    /// All scores of `pred` against `gt` (row-major, same size) inside `frame`.
    pub fn compute(pred: &[f32], gt: &[f32], frame: &Frame) -> Self {
        let [b1, b3, b7] = BADPIX_THRESHOLDS.map(|t| badpix(pred, gt, frame, t));
        Self {
            mse_x100: mse_x100(pred, gt, frame),
            badpix_001: b1,
            badpix_003: b3,
            badpix_007: b7,
            q25: q25(pred, gt, frame),
        }
    }

    /// The scores as `[mse_x100, badpix_001, badpix_003, badpix_007, q25]`, for code that
    /// treats them alike (averaging, tables).
    pub fn to_array(self) -> [Option<f64>; 5] {
        [
            self.mse_x100,
            self.badpix_001,
            self.badpix_003,
            self.badpix_007,
            self.q25,
        ]
    }

    /// Inverse of [`HciScores::to_array`].
    pub fn from_array(
        [mse_x100, badpix_001, badpix_003, badpix_007, q25]: [Option<f64>; 5],
    ) -> Self {
        Self {
            mse_x100,
            badpix_001,
            badpix_003,
            badpix_007,
            q25,
        }
    }
}

/// Column titles of [`HciScores::to_array`].
pub const SCORE_NAMES: [&str; 5] = [
    "MSE×100",
    "BadPix(0.01) %",
    "BadPix(0.03) %",
    "BadPix(0.07) %",
    "Q25",
];

/// `pred - gt` in f64 at pixel `i`.
fn diff(pred: &[f32], gt: &[f32], i: usize) -> f64 {
    f64::from(pred[i]) - f64::from(gt[i])
}

/// `100 · mean((gt - pred)²)` over frame pixels where both are finite.
pub fn mse_x100(pred: &[f32], gt: &[f32], frame: &Frame) -> Option<f64> {
    let (sum, n) = frame
        .indices()
        .filter(|&i| pred[i].is_finite() && gt[i].is_finite())
        .fold((0.0, 0usize), |(s, n), i| {
            (s + diff(pred, gt, i).powi(2), n + 1)
        });
    (n > 0).then(|| 100.0 * sum / n as f64)
}

/// Whether `|pred - gt| > t` as the HCI toolkit decides it: in float32, the difference and the
/// threshold both rounded to it (in f64, an error within ~4e-9 of `t` could flip).
pub fn is_bad(pred: f32, gt: f32, t: f64) -> bool {
    (pred - gt).abs() > t as f32
}

/// `100 · #(|pred - gt| > t) / #frame` (NaN differences are not bad, as in the toolkit).
pub fn badpix(pred: &[f32], gt: &[f32], frame: &Frame, t: f64) -> Option<f64> {
    let bad = frame
        .indices()
        .filter(|&i| is_bad(pred[i], gt[i], t))
        .count();
    (!frame.is_empty()).then(|| 100.0 * bad as f64 / frame.len() as f64)
}

/// The toolkit's Q25: `sorted(|pred - gt| · 100)[⌊n/4⌋]` over finite errors and predictions.
pub fn q25(pred: &[f32], gt: &[f32], frame: &Frame) -> Option<f64> {
    let mut errors: Vec<f64> = frame
        .indices()
        .filter(|&i| pred[i].is_finite())
        .map(|i| diff(pred, gt, i).abs() * 100.0)
        .filter(|e| e.is_finite())
        .collect();
    if errors.is_empty() {
        return None;
    }
    let k = errors.len() * 25 / 100;
    let (_, &mut value, _) = errors.select_nth_unstable_by(k, f64::total_cmp);
    Some(value)
}

/// Percentage of frame pixels whose prediction is NaN or ±∞.
pub fn invalid_percent(pred: &[f32], frame: &Frame) -> Option<f64> {
    let invalid = frame.indices().filter(|&i| !pred[i].is_finite()).count();
    (!frame.is_empty()).then(|| 100.0 * invalid as f64 / frame.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 5×5 image with a 1-pixel border: the 3×3 inside is evaluated. The outside holds
    /// huge errors that must not count.
    fn case() -> (Vec<f32>, Vec<f32>, Frame) {
        let inner_gt = [1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, f32::NAN];
        let inner_pred = [
            1.0,
            1.02,
            1.05,
            1.1,
            0.5,
            f32::NAN,
            f32::INFINITY,
            1.04,
            1.0,
        ];
        let mut gt = vec![0.0f32; 25];
        let mut pred = vec![100.0f32; 25];
        for (k, (&g, &p)) in inner_gt.iter().zip(&inner_pred).enumerate() {
            let i = (1 + k / 3) * 5 + 1 + k % 3;
            gt[i] = g;
            pred[i] = p;
        }
        let frame = Frame::new(5, 5, 1);
        (pred, gt, frame)
    }

    fn close(a: Option<f64>, b: f64) {
        let a = a.expect("score present");
        assert!((a - b).abs() < 1e-4, "{a} != {b}");
    }

    #[test]
    fn mse_masks_non_finite_prediction_and_truth() {
        let (pred, gt, frame) = case();
        // Finite pairs: errors 0, .02, .05, .1, .5, .04 → squares sum .2645 over 6 pixels.
        close(mse_x100(&pred, &gt, &frame), 100.0 * 0.2645 / 6.0);
    }

    #[test]
    fn badpix_counts_nan_as_good_and_inf_as_bad_over_the_whole_frame() {
        let (pred, gt, frame) = case();
        // Differences: 0, .02, .05, .1, .5, NaN, ∞, .04, NaN; denominator 9.
        close(badpix(&pred, &gt, &frame, 0.01), 100.0 * 6.0 / 9.0);
        close(badpix(&pred, &gt, &frame, 0.03), 100.0 * 5.0 / 9.0);
        close(badpix(&pred, &gt, &frame, 0.07), 100.0 * 3.0 / 9.0);
    }

    #[test]
    fn badpix_decides_at_the_threshold_in_float32_as_the_toolkit() {
        // |0.07f32 - 0| is 0.0700000003 in f64, just above 0.07, but equal to float32(0.07):
        // the toolkit's float32 comparison calls it good.
        let frame = Frame::new(1, 1, 0);
        close(badpix(&[0.07], &[0.0], &frame, 0.07), 0.0);
        close(badpix(&[1.070_001], &[1.0], &frame, 0.07), 100.0);
    }

    #[test]
    fn q25_is_the_toolkit_index_of_the_sorted_finite_errors() {
        let (pred, gt, frame) = case();
        // Finite errors ×100: 0, 2, 4, 5, 10, 50 → index ⌊6·25/100⌋ = 1 → 2.
        close(q25(&pred, &gt, &frame), 2.0);
    }

    #[test]
    fn compute_bundles_the_scores_and_invalid_share_is_reported() {
        let (pred, gt, frame) = case();
        let s = HciScores::compute(&pred, &gt, &frame);
        close(s.badpix_007, 100.0 / 3.0);
        close(s.q25, 2.0);
        assert_eq!(HciScores::from_array(s.to_array()), s);
        close(invalid_percent(&pred, &frame), 100.0 * 2.0 / 9.0);
    }

    #[test]
    fn perfect_prediction_scores_zero_and_empty_masks_give_none() {
        let (_, gt, frame) = case();
        let s = HciScores::compute(&gt, &gt, &frame);
        assert_eq!(s.to_array(), [Some(0.0); 5]);
        let empty = Frame { border: 3, ..frame };
        assert_eq!(HciScores::compute(&gt, &gt, &empty).to_array(), [None; 5]);
    }
}
