//! Predicted disparity posteriors in the three forms the thesis' models produce: discrete
//! bins (DPP), one Laplacian (UPR) and a mixture of Laplacians (ESE).
//!
//! Every form answers the same three questions per pixel, so the metrics never look at the
//! form: the probability of each evaluation bin (eq. 5.22), the variance (the uncertainty
//! that sparsification ranks by) and a point estimate (when no disparity map is given).

use crate::bins::Bins;
use crate::laplace;

/// A posterior for every pixel of a `width × height` image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct PosteriorMap {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// The per-pixel parameters.
    pub form: PosteriorForm,
}

/// Storage of a [`PosteriorMap`]; per-pixel blocks are contiguous.
#[derive(Clone, Debug, PartialEq)]
pub enum PosteriorForm {
    /// Probabilities of `bins.count` equal bins per pixel, index `pixel * count + k`.
    Discrete {
        /// The bins the probabilities refer to.
        bins: Bins,
        /// Non-negative, normalised per pixel on use.
        probs: Vec<f32>,
    },
    /// One Laplacian per pixel.
    Laplace {
        /// Location, pixels.
        mu: Vec<f32>,
        /// Natural log of the scale `b`.
        log_b: Vec<f32>,
    },
    /// `components` Laplacians per pixel, index `pixel * components + m`.
    Mixture {
        /// Components per pixel.
        components: usize,
        /// Non-negative, normalised per pixel on use.
        weights: Vec<f32>,
        /// Locations.
        mu: Vec<f32>,
        /// Natural logs of the scales.
        log_b: Vec<f32>,
    },
}

/// The posterior of one pixel, borrowed from a [`PosteriorMap`].
#[derive(Clone, Copy, Debug)]
pub enum PixelPosterior<'a> {
    /// See [`PosteriorForm::Discrete`].
    Discrete {
        /// The bins of `probs`.
        bins: &'a Bins,
        /// One value per bin.
        probs: &'a [f32],
    },
    /// See [`PosteriorForm::Laplace`].
    Laplace {
        /// Location.
        mu: f32,
        /// Log scale.
        log_b: f32,
    },
    /// See [`PosteriorForm::Mixture`].
    Mixture {
        /// Component weights.
        weights: &'a [f32],
        /// Component locations.
        mu: &'a [f32],
        /// Component log scales.
        log_b: &'a [f32],
    },
}

impl PosteriorMap {
    /// A short name of the form, for reports.
    pub fn form_name(&self) -> &'static str {
        match self.form {
            PosteriorForm::Discrete { .. } => "discrete",
            PosteriorForm::Laplace { .. } => "laplace",
            PosteriorForm::Mixture { .. } => "mixture",
        }
    }

    /// The posterior of pixel `i` (row-major index).
    pub fn pixel(&self, i: usize) -> PixelPosterior<'_> {
        match &self.form {
            PosteriorForm::Discrete { bins, probs } => PixelPosterior::Discrete {
                bins,
                probs: &probs[i * bins.count..(i + 1) * bins.count],
            },
            PosteriorForm::Laplace { mu, log_b } => PixelPosterior::Laplace {
                mu: mu[i],
                log_b: log_b[i],
            },
            PosteriorForm::Mixture {
                components,
                weights,
                mu,
                log_b,
            } => {
                let r = i * components..(i + 1) * components;
                PixelPosterior::Mixture {
                    weights: &weights[r.clone()],
                    mu: &mu[r.clone()],
                    log_b: &log_b[r],
                }
            }
        }
    }
}

impl PixelPosterior<'_> {
    /// Probability of each bin of `eval` into `out` (eq. 5.22), summing to 1, or all zeros
    /// when the pixel holds no usable distribution (NaN, all-zero weights).
    ///
    /// Discrete posteriors are treated as piecewise-uniform densities and re-binned by
    /// overlap, which is the identity when both grids agree. Continuous ones are integrated
    /// in closed form. Mass outside `eval`'s range lands in its open-ended outer bins.
    pub fn bin_masses(&self, eval: &Bins, out: &mut [f64]) {
        out.fill(0.0);
        match *self {
            PixelPosterior::Discrete { bins, probs } => {
                if let Some(norm) = normaliser(probs) {
                    rebin(bins, probs, norm, eval, out);
                }
            }
            PixelPosterior::Laplace { mu, log_b } => {
                add_laplace(1.0, mu.into(), f64::from(log_b).exp(), eval, out);
            }
            PixelPosterior::Mixture { weights, mu, log_b } => {
                if let Some(norm) = normaliser(weights) {
                    for ((&w, &m), &lb) in weights.iter().zip(mu).zip(log_b) {
                        add_laplace(
                            f64::from(w) / norm,
                            m.into(),
                            f64::from(lb).exp(),
                            eval,
                            out,
                        );
                    }
                }
            }
        }
        let total: f64 = out.iter().sum();
        if !(total.is_finite() && total > 0.0) {
            out.fill(0.0);
        }
    }

    /// Variance of the distribution; NaN when it has none (invalid parameters).
    ///
    /// Discrete bins count as uniform over their width (`+ w²/12`), so a posterior confined
    /// to one bin still reports the bin's own spread rather than 0.
    pub fn variance(&self) -> f64 {
        let variance = match *self {
            PixelPosterior::Discrete { bins, probs } => normaliser(probs).map(|norm| {
                let spread = bins.width().powi(2) / 12.0;
                mixture_variance(probs, norm, |k| (bins.centre(k), spread))
            }),
            PixelPosterior::Laplace { mu, log_b } => {
                let b = f64::from(log_b).exp();
                Some(mixture_variance(&[1.0], 1.0, |_| {
                    (mu.into(), laplace::variance(b))
                }))
            }
            PixelPosterior::Mixture { weights, mu, log_b } => normaliser(weights).map(|norm| {
                mixture_variance(weights, norm, |m| {
                    (mu[m].into(), laplace::variance(f64::from(log_b[m]).exp()))
                })
            }),
        };
        variance.unwrap_or(f64::NAN)
    }

    /// The point estimate when a method gives no disparity map: the most probable bin's
    /// centre (discrete), `μ` (Laplace), or the `μ` of the component with the highest peak
    /// density `w / 2b` (mixture). NaN when the pixel holds no usable distribution.
    pub fn point_estimate(&self) -> f64 {
        match *self {
            PixelPosterior::Discrete { bins, probs } => {
                let best = normaliser(probs).and(argmax(probs.iter().map(|&p| f64::from(p))));
                best.map_or(f64::NAN, |k| bins.centre(k))
            }
            PixelPosterior::Laplace { mu, .. } => mu.into(),
            PixelPosterior::Mixture { weights, mu, log_b } => {
                let peaks = weights
                    .iter()
                    .zip(log_b)
                    .map(|(&w, &lb)| f64::from(w) / f64::from(lb).exp());
                let best = normaliser(weights).and(argmax(peaks));
                best.map_or(f64::NAN, |m| mu[m].into())
            }
        }
    }
}

/// The sum of `values` when it is a usable normaliser (finite, positive), else `None`.
fn normaliser(values: &[f32]) -> Option<f64> {
    let sum: f64 = values.iter().map(|&v| f64::from(v)).sum();
    (sum.is_finite() && sum > 0.0).then_some(sum)
}

/// Variance of a mixture whose component `i` has weight `w[i] / norm` and mean and
/// variance `component(i)`: `Σ p_i (var_i + (mean_i - mean)²)`. Summing squared deviations
/// (rather than `E[d²] - mean²`) is exact for equal components, so equal posteriors get
/// equal variances and tie in the sparsification ranking instead of being ordered by
/// rounding noise.
fn mixture_variance(w: &[f32], norm: f64, component: impl Fn(usize) -> (f64, f64)) -> f64 {
    let p = |i: usize| f64::from(w[i]) / norm;
    let mean: f64 = (0..w.len()).map(|i| p(i) * component(i).0).sum();
    (0..w.len())
        .map(|i| {
            let (m, var) = component(i);
            p(i) * (var + (m - mean).powi(2))
        })
        .sum()
}

/// Index of the largest finite value (first on ties); `None` if there is none.
fn argmax(values: impl Iterator<Item = f64>) -> Option<usize> {
    values
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .fold(None, |best: Option<(usize, f64)>, (i, v)| match best {
            Some((_, bv)) if bv >= v => best,
            _ => Some((i, v)),
        })
        .map(|(i, _)| i)
}

/// Adds `weight ×` the bin masses of `Laplace(mu, b)` to `out`.
fn add_laplace(weight: f64, mu: f64, b: f64, eval: &Bins, out: &mut [f64]) {
    if weight == 0.0 {
        return;
    }
    for (k, o) in out.iter_mut().enumerate() {
        let (lo, hi) = eval.open_interval(k);
        *o += weight * laplace::mass(mu, b, lo, hi);
    }
}

/// Re-bins the piecewise-uniform density `probs / norm` over `src` onto `eval` by overlap.
fn rebin(src: &Bins, probs: &[f32], norm: f64, eval: &Bins, out: &mut [f64]) {
    for (j, &p) in probs.iter().enumerate() {
        if p <= 0.0 {
            continue;
        }
        let (lo, hi) = (src.edge(j), src.edge(j + 1));
        let (first, last) = (eval.index(lo), eval.index(hi));
        let (Some(first), Some(last)) = (first, last) else {
            continue;
        };
        for (k, o) in out.iter_mut().enumerate().take(last + 1).skip(first) {
            let (elo, ehi) = eval.open_interval(k);
            let overlap = hi.min(ehi) - lo.max(elo);
            if overlap > 0.0 {
                *o += f64::from(p) / norm * overlap / (hi - lo);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bins4() -> Bins {
        Bins::new(0.0, 4.0, 4).unwrap()
    }

    fn masses(p: PixelPosterior, eval: &Bins) -> Vec<f64> {
        let mut out = vec![0.0; eval.count];
        p.bin_masses(eval, &mut out);
        out
    }

    fn assert_close(a: &[f64], b: &[f64]) {
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-12, "{a:?} != {b:?}");
        }
    }

    #[test]
    fn discrete_on_the_same_grid_is_normalised_unchanged() {
        let b = bins4();
        let probs = [1.0, 3.0, 0.0, 4.0];
        let p = PixelPosterior::Discrete {
            bins: &b,
            probs: &probs,
        };
        assert_close(&masses(p, &b), &[0.125, 0.375, 0.0, 0.5]);
    }

    #[test]
    fn discrete_rebins_by_overlap_and_clamps_outside_mass() {
        // Source bins of width 2 over [-2, 6]: [-2,0) [0,2) [2,4) [4,6), masses ¼ each.
        let src = Bins::new(-2.0, 6.0, 4).unwrap();
        let probs = [0.25, 0.25, 0.25, 0.25];
        let p = PixelPosterior::Discrete {
            bins: &src,
            probs: &probs,
        };
        // [-2,0) falls below [0,4] → first bin; [0,2) splits ⅛/⅛; [2,4) splits ⅛/⅛;
        // [4,6) lies above → last bin.
        assert_close(&masses(p, &bins4()), &[0.375, 0.125, 0.125, 0.375]);
    }

    #[test]
    fn discrete_variance_and_point() {
        let b = bins4();
        let probs = [0.5, 0.0, 0.0, 0.5];
        let p = PixelPosterior::Discrete {
            bins: &b,
            probs: &probs,
        };
        // Centres 0.5 and 3.5: variance 1.5² + 1/12.
        assert!((p.variance() - (2.25 + 1.0 / 12.0)).abs() < 1e-12);
        assert_eq!(p.point_estimate(), 0.5, "first of the tied maxima");
    }

    #[test]
    fn laplace_bins_integrate_the_cdf_with_open_ends() {
        let b = bins4();
        let p = PixelPosterior::Laplace {
            mu: 2.0,
            log_b: 0.0,
        };
        let e1 = (-1.0f64).exp();
        // (-∞,1]: ½e⁻¹; [1,2]: ½(1-e⁻¹); symmetric on the right.
        let expected = [0.5 * e1, 0.5 * (1.0 - e1), 0.5 * (1.0 - e1), 0.5 * e1];
        assert_close(&masses(p, &b), &expected);
        assert!((p.variance() - 2.0).abs() < 1e-12);
        assert_eq!(p.point_estimate(), 2.0);
    }

    #[test]
    fn mixture_is_the_weighted_sum_of_its_components() {
        let b = bins4();
        let (weights, mu, log_b) = ([1.0f32, 3.0], [0.5f32, 3.5], [-30.0f32, -30.0]);
        let p = PixelPosterior::Mixture {
            weights: &weights,
            mu: &mu,
            log_b: &log_b,
        };
        // Nearly point masses at 0.5 and 3.5 with weights ¼ and ¾.
        assert_close(&masses(p, &b), &[0.25, 0.0, 0.0, 0.75]);
        // Variance of {0.5: ¼, 3.5: ¾}: mean 2.75, E[d²] = 0.0625 + 9.1875 = 9.25 → 1.6875.
        assert!((p.variance() - 1.6875).abs() < 1e-9);
        assert_eq!(p.point_estimate(), 3.5);
    }

    #[test]
    fn equal_widths_give_bit_identical_variances() {
        // Sparsification ranks by variance: equal widths must tie exactly, wherever μ is.
        let v = |mu: f32| PixelPosterior::Laplace { mu, log_b: -1.3 }.variance();
        assert_eq!(v(0.1), v(3.3));
        assert_eq!(v(-2.7), v(0.1));
        assert_eq!(v(0.0), 2.0 * (-1.3f32 as f64).exp().powi(2));
    }

    #[test]
    fn unusable_pixels_have_no_mass_and_nan_statistics() {
        let b = bins4();
        let zeros = [0.0f32; 4];
        let p = PixelPosterior::Discrete {
            bins: &b,
            probs: &zeros,
        };
        assert_eq!(masses(p, &b), vec![0.0; 4]);
        assert!(p.variance().is_nan() && p.point_estimate().is_nan());
        let nan = PixelPosterior::Laplace {
            mu: f32::NAN,
            log_b: 0.0,
        };
        assert_eq!(masses(nan, &b), vec![0.0; 4]);
        assert!(nan.point_estimate().is_nan() && nan.variance().is_nan());
    }
}
