//! The thesis' discrete Kullback–Leibler divergence (eq. 5.21–5.23) between the true and
//! the predicted disparity distribution of a pixel.
//!
//! Both are histograms over the same bins. A bin with true mass but no predicted mass would
//! make the divergence infinite, so, as in the thesis' training code, `ε` (default 1e-5) is
//! added to every bin of both histograms, which are then renormalised to sum to 1. The
//! per-pixel value is `Σ_k p_k ln(p_k / q_k)` in nats; datasets report its mean over pixels
//! (the magnitudes of thesis Table 5.1; eq. 5.23's extra `1/K` would divide them by K).

use serde::Serialize;

use crate::bins::Bins;

/// The `ε` of the thesis' training code.
pub const EPSILON: f64 = 1e-5;

/// Adds `eps` to every entry and rescales to sum 1 (an all-zero histogram becomes uniform).
pub fn regularise(hist: &mut [f64], eps: f64) {
    let total: f64 = hist.iter().map(|h| h + eps).sum();
    for h in hist.iter_mut() {
        *h = (*h + eps) / total;
    }
}

/// `Σ_k p_k ln(p_k / q_k)` of two normalised histograms (terms with `p_k = 0` are 0).
pub fn divergence(p: &[f64], q: &[f64]) -> f64 {
    p.iter()
        .zip(q)
        .filter(|(pk, _)| **pk > 0.0)
        .map(|(pk, qk)| pk * (pk / qk).ln())
        .sum()
}

/// The KLD of one pixel: regularises the unnormalised histograms `truth` and `predicted`
/// in place with `eps` and compares them.
pub fn pixel_kld(truth: &mut [f64], predicted: &mut [f64], eps: f64) -> f64 {
    regularise(truth, eps);
    regularise(predicted, eps);
    divergence(truth, predicted)
}

/// The histogram of a point estimate: all mass in the bin of `d` (none for NaN).
pub fn point_masses(d: f64, bins: &Bins, out: &mut [f64]) {
    out.fill(0.0);
    if let Some(k) = bins.index(d) {
        out[k] = 1.0;
    }
}

/// A running sum of per-pixel values and their count.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Sum {
    /// Sum of the values.
    pub total: f64,
    /// Number of values.
    pub pixels: u64,
}

impl Sum {
    fn add(&mut self, value: f64) {
        self.total += value;
        self.pixels += 1;
    }

    fn merge(&mut self, other: Sum) {
        self.total += other.total;
        self.pixels += other.pixels;
    }

    /// The mean, `None` over no pixels.
    pub fn mean(&self) -> Option<f64> {
        (self.pixels > 0).then(|| self.total / self.pixels as f64)
    }
}

/// Per-pixel KLD sums over all, unimodal and multimodal pixels; pooled over scenes by
/// [`KldSums::merge`], because the thesis averages over all pixels of all scenes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct KldSums {
    /// Every evaluated pixel.
    pub all: Sum,
    /// Pixels with fewer than two modes of `η > 0.3`.
    pub unimodal: Sum,
    /// Pixels with at least two modes of `η > 0.3`.
    pub multimodal: Sum,
}

impl KldSums {
    /// Records one pixel's KLD.
    pub fn add(&mut self, value: f64, multimodal: bool) {
        self.all.add(value);
        if multimodal {
            self.multimodal.add(value);
        } else {
            self.unimodal.add(value);
        }
    }

    /// Adds another scene's sums.
    pub fn merge(&mut self, other: &KldSums) {
        self.all.merge(other.all);
        self.unimodal.merge(other.unimodal);
        self.multimodal.merge(other.multimodal);
    }

    /// The means and pixel counts, as reported.
    pub fn scores(&self) -> KldScores {
        KldScores {
            all: self.all.mean(),
            unimodal: self.unimodal.mean(),
            multimodal: self.multimodal.mean(),
            pixels_all: self.all.pixels,
            pixels_unimodal: self.unimodal.pixels,
            pixels_multimodal: self.multimodal.pixels,
        }
    }
}

/// Mean KLD (nats per pixel) over the three pixel sets, with their sizes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct KldScores {
    /// Over every evaluated pixel.
    pub all: Option<f64>,
    /// Over unimodal pixels.
    pub unimodal: Option<f64>,
    /// Over multimodal pixels.
    pub multimodal: Option<f64>,
    /// Evaluated pixels.
    pub pixels_all: u64,
    /// Unimodal pixels.
    pub pixels_unimodal: u64,
    /// Multimodal pixels.
    pub pixels_multimodal: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regularise_adds_epsilon_then_renormalises() {
        let mut h = vec![0.9, 0.0, 0.0, 0.0];
        regularise(&mut h, 0.1);
        // (0.9 + 0.1) / 1.3 and 0.1 / 1.3.
        let expected = [1.0 / 1.3, 0.1 / 1.3, 0.1 / 1.3, 0.1 / 1.3];
        for (a, b) in h.iter().zip(expected) {
            assert!((a - b).abs() < 1e-15);
        }
        let mut empty = vec![0.0; 4];
        regularise(&mut empty, EPSILON);
        assert_eq!(empty, vec![0.25; 4], "no mass at all becomes uniform");
    }

    #[test]
    fn point_estimate_in_the_wrong_bin_costs_ln_of_one_over_epsilon() {
        // p = [(1+ε)/(1+2ε), ε/(1+2ε)], q mirrored: KLD = ln((1+ε)/ε) / (1+2ε).
        let bins = Bins::new(0.0, 2.0, 2).unwrap();
        let mut truth = vec![1.0, 0.0];
        let mut pred = vec![0.0; 2];
        point_masses(1.5, &bins, &mut pred);
        assert_eq!(pred, vec![0.0, 1.0]);
        let kld = pixel_kld(&mut truth, &mut pred, EPSILON);
        assert!((kld - 11.512_705_210_816_014).abs() < 1e-9, "{kld}");
    }

    #[test]
    fn uniform_posterior_against_one_mode() {
        // K = 108, truth one-hot: p_j = (1+ε)/(1+Kε), others ε/(1+Kε), q = 1/K:
        // KLD = p_j ln(K p_j) + (K-1) p_o ln(K p_o) = 4.66875625890222 (ln 108 = 4.682 as ε→0).
        let bins = Bins::THESIS;
        let mut truth = vec![0.0; 108];
        truth[bins.index(0.0).unwrap()] = 1.0;
        let mut uniform = vec![1.0 / 108.0; 108];
        let kld = pixel_kld(&mut truth, &mut uniform, EPSILON);
        assert!((kld - 4.668_756_258_902_22).abs() < 1e-9, "{kld}");
    }

    #[test]
    fn the_truth_itself_scores_zero_even_with_partial_coverage() {
        let mut truth = vec![0.45, 0.45, 0.0, 0.0];
        let mut pred = truth.clone();
        assert!(pixel_kld(&mut truth, &mut pred, EPSILON).abs() < 1e-15);
    }

    #[test]
    fn nan_point_estimate_has_no_mass() {
        let mut out = vec![1.0; 3];
        point_masses(f64::NAN, &Bins::new(0.0, 3.0, 3).unwrap(), &mut out);
        assert_eq!(out, vec![0.0; 3]);
    }

    #[test]
    fn sums_split_and_pool_pixels() {
        let mut a = KldSums::default();
        a.add(1.0, false);
        a.add(3.0, true);
        let mut b = KldSums::default();
        b.add(2.0, false);
        a.merge(&b);
        let s = a.scores();
        assert_eq!(s.all, Some(2.0));
        assert_eq!(s.unimodal, Some(1.5));
        assert_eq!(s.multimodal, Some(3.0));
        assert_eq!(
            (s.pixels_all, s.pixels_unimodal, s.pixels_multimodal),
            (3, 2, 1)
        );
        assert_eq!(KldSums::default().scores().all, None);
    }
}
