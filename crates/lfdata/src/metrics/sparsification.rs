//! Sparsification (thesis §5.3.2, after Ilg et al.): remove the fraction `x` of pixels with
//! the highest predicted uncertainty and measure the error of the rest. The Oracle removes
//! the truly worst pixels instead and is the lower bound; SE = curve − Oracle, and AuSE, the
//! area under SE over `x ∈ [0, 1)`, rates the uncertainty with one number (0 = perfect).
//!
//! Conventions: the curve is sampled at `x_s = s / steps`, `s = 0..steps`, removing
//! `⌊x_s · n⌋` pixels (at least one always remains); AuSE is the mean of SE over those
//! samples (the left Riemann sum of the area). Pixels with equal uncertainty are removed
//! in expectation, as if ties were broken at random, so a method that reports one constant
//! uncertainty gets a flat curve instead of one that depends on pixel order. A NaN
//! uncertainty ranks as the largest.

use serde::Serialize;

/// The fractions removed at each sample: `s / steps`.
pub fn fractions(steps: usize) -> Vec<f64> {
    (0..steps).map(|s| s as f64 / steps as f64).collect()
}

/// The mean of `errors` over the pixels kept after removing, at each fraction, those with
/// the largest `keys` (ties in expectation). Empty when there are no pixels.
pub fn curve(errors: &[f64], keys: &[f64], steps: usize) -> Vec<f64> {
    assert_eq!(errors.len(), keys.len(), "one key per error");
    let n = errors.len();
    if n == 0 {
        return Vec::new();
    }
    let rank = |k: f64| if k.is_nan() { f64::INFINITY } else { k };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by(|&a, &b| rank(keys[b]).total_cmp(&rank(keys[a])));
    let mut prefix = vec![0.0; n + 1];
    for (i, &p) in order.iter().enumerate() {
        prefix[i + 1] = prefix[i] + errors[p];
    }
    // Start of the tie group of each sorted position, and its end (exclusive).
    let mut group_start = vec![0; n];
    let mut group_end = vec![n; n];
    for i in 1..n {
        let tied = rank(keys[order[i]]) == rank(keys[order[i - 1]]);
        group_start[i] = if tied { group_start[i - 1] } else { i };
    }
    for i in (0..n - 1).rev() {
        group_end[i] = if group_start[i + 1] == group_start[i] {
            group_end[i + 1]
        } else {
            i + 1
        };
    }
    let removed_sum = |r: usize| {
        if r == 0 {
            return 0.0;
        }
        let (gs, ge) = (group_start[r - 1], group_end[r - 1]);
        let group_mean = (prefix[ge] - prefix[gs]) / (ge - gs) as f64;
        prefix[gs] + (r - gs) as f64 * group_mean
    };
    (0..steps)
        .map(|s| {
            let r = s * n / steps;
            (prefix[n] - removed_sum(r)) / (n - r) as f64
        })
        .collect()
}

/// A method's sparsification curve and its Oracle for one error measure.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Sparsification {
    /// Error of the kept pixels, removing by predicted uncertainty.
    pub curve: Vec<f64>,
    /// Error of the kept pixels, removing by true error.
    pub oracle: Vec<f64>,
}

impl Sparsification {
    /// Curve and Oracle of per-pixel `errors` ranked by `uncertainty`.
    pub fn compute(errors: &[f64], uncertainty: &[f64], steps: usize) -> Self {
        Self {
            curve: curve(errors, uncertainty, steps),
            oracle: curve(errors, errors, steps),
        }
    }

    /// SE = curve − Oracle at each sample.
    pub fn error(&self) -> Vec<f64> {
        self.curve
            .iter()
            .zip(&self.oracle)
            .map(|(c, o)| c - o)
            .collect()
    }

    /// Area under SE over `[0, 1)`; `None` without samples.
    pub fn ause(&self) -> Option<f64> {
        let se = self.error();
        (!se.is_empty()).then(|| se.iter().sum::<f64>() / se.len() as f64)
    }

    /// The sample-wise mean of several scenes' curves (all with the same sample count);
    /// scenes without samples are left out.
    pub fn mean<'a>(items: impl IntoIterator<Item = &'a Sparsification>) -> Option<Self> {
        let items: Vec<_> = items.into_iter().filter(|s| !s.curve.is_empty()).collect();
        let first = items.first()?;
        let avg = |pick: fn(&Sparsification) -> &Vec<f64>| -> Vec<f64> {
            (0..pick(first).len())
                .map(|i| items.iter().map(|s| pick(s)[i]).sum::<f64>() / items.len() as f64)
                .collect()
        };
        Some(Self {
            curve: avg(|s| &s.curve),
            oracle: avg(|s| &s.oracle),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_curve_oracle_and_ause() {
        // BadPix-like errors; uncertainty ranks pixel 0, 2, 3, 1.
        let errors = [1.0, 0.0, 0.0, 1.0];
        let keys = [0.9, 0.1, 0.5, 0.2];
        let s = Sparsification::compute(&errors, &keys, 4);
        // Remove 0: {1,0,0,1} → ½; 1: {0,0,1} → ⅓; 2: {1,0} → ½; 3: {0} → 0.
        assert_eq!(s.curve, vec![0.5, 1.0 / 3.0, 0.5, 0.0]);
        // Oracle removes the ones first: ½, ⅓, 0, 0.
        assert_eq!(s.oracle, vec![0.5, 1.0 / 3.0, 0.0, 0.0]);
        assert_eq!(s.error(), vec![0.0, 0.0, 0.5, 0.0]);
        assert_eq!(s.ause(), Some(0.125));
        assert_eq!(fractions(4), vec![0.0, 0.25, 0.5, 0.75]);
    }

    #[test]
    fn perfect_prediction_and_perfect_uncertainty_lie_on_the_oracle() {
        let zeros = [0.0; 10];
        let keys: Vec<f64> = (0..10).map(f64::from).collect();
        let s = Sparsification::compute(&zeros, &keys, 5);
        assert_eq!(s.curve, vec![0.0; 5]);
        assert_eq!(s.curve, s.oracle);
        assert_eq!(s.ause(), Some(0.0));
        let errors = [0.3, 2.0, 0.1, 5.0, 0.0, 1.0];
        let s = Sparsification::compute(&errors, &errors, 6);
        assert_eq!(s.curve, s.oracle);
        assert_eq!(s.ause(), Some(0.0));
    }

    #[test]
    fn ties_are_removed_in_expectation() {
        // One constant uncertainty: every removal keeps the mean, ½.
        let errors = [1.0, 0.0, 0.0, 1.0];
        assert_eq!(curve(&errors, &[7.0; 4], 4), vec![0.5; 4]);
        // Pixel 3 most uncertain, then a tie of pixels 0 and 1 (errors 1, 0), then pixel 2.
        let c = curve(&errors, &[0.5, 0.5, 0.1, 0.9], 4);
        // Remove 2 = pixel 3 and half of the tie (expected error ½): (1 - ½) / 2 = ¼.
        assert_eq!(c, vec![0.5, 1.0 / 3.0, 0.25, 0.0]);
    }

    #[test]
    fn nan_uncertainty_is_removed_first_and_empty_input_has_no_curve() {
        let c = curve(&[5.0, 1.0], &[f64::NAN, 100.0], 2);
        assert_eq!(c, vec![3.0, 1.0]);
        assert!(curve(&[], &[], 3).is_empty());
        assert_eq!(Sparsification::compute(&[], &[], 3).ause(), None);
    }

    #[test]
    fn mean_averages_sample_wise() {
        let a = Sparsification {
            curve: vec![1.0, 3.0],
            oracle: vec![0.0, 1.0],
        };
        let b = Sparsification {
            curve: vec![3.0, 1.0],
            oracle: vec![2.0, 1.0],
        };
        let m = Sparsification::mean([&a, &b, &Sparsification::default()]).unwrap();
        assert_eq!(m.curve, vec![2.0, 2.0]);
        assert_eq!(m.oracle, vec![1.0, 1.0]);
        assert_eq!(Sparsification::mean([]), None);
    }
}
