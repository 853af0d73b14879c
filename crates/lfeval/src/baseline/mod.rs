//! A classical estimator that needs no training, so every dataset has a yardstick and every
//! metric runs on real data: a photo-consistency cost volume over the disparity bins
//! ([`lfdata::cost`]), optionally averaged over a local window, turned into a discrete posterior by a
//! softmax of the negative cost with a temperature, and a winner-take-all point estimate.

use std::time::Instant;

use lfdata::bins::Bins;
use lfdata::cost::{box_filter, cost_volume};
use lfdata::lightfield::LightField;
use lfdata::posterior::{PosteriorForm, PosteriorMap};
use lfdata::prediction::{ScenePrediction, point_estimates};
use lfformat::pfm::FloatImage;
use lfformat::views::ViewSet;
use rayon::prelude::*;
use serde::Serialize;

/// Settings of the baseline.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BaselineConfig {
    /// Disparity hypotheses: the bin centres (default: the thesis' 108 over [-3.5, 3.5]).
    pub bins: Bins,
    /// Views entering the cost.
    pub views: ViewSet,
    /// Softmax temperature in cost units (colour variance, colours in [0, 1]).
    pub temperature: f64,
    /// Radius of the square cost aggregation window (0: per pixel).
    pub window: usize,
}

impl Default for BaselineConfig {
    fn default() -> Self {
        Self {
            bins: Bins::THESIS,
            views: ViewSet::Cross,
            temperature: DEFAULT_TEMPERATURE,
            window: DEFAULT_WINDOW,
        }
    }
}

/// Default softmax temperature, chosen on lfgen training scenes (see the README).
pub const DEFAULT_TEMPERATURE: f64 = 0.002;
/// Default aggregation radius (a 9×9 window), chosen with the temperature.
pub const DEFAULT_WINDOW: usize = 4;

/// Estimates the centre view's disparity posterior of `lf`. The runtime covers the
/// estimation, not the loading of the views.
pub fn estimate(lf: &LightField, cfg: &BaselineConfig) -> ScenePrediction {
    let start = Instant::now();
    let (w, h) = (lf.width, lf.height);
    let volume: Vec<Vec<f32>> = cost_volume(lf, &cfg.bins)
        .into_par_iter()
        .map(|slice| box_filter(&slice, w, h, cfg.window))
        .collect();
    let posterior = PosteriorMap {
        width: w,
        height: h,
        form: PosteriorForm::Discrete {
            bins: cfg.bins,
            probs: softmax(&volume, w * h, cfg.temperature),
        },
    };
    let disparity = point_estimates(&posterior);
    let variance = (0..w * h)
        .map(|i| posterior.pixel(i).variance() as f32)
        .collect();
    ScenePrediction {
        disparity,
        uncertainty: Some(FloatImage::new(w, h, variance)),
        posterior: Some(posterior),
        runtime_s: Some(start.elapsed().as_secs_f64()),
    }
}

/// Per pixel, `p_k ∝ exp(-(c_k - min c) / T)` over the slices of `volume`, laid out
/// pixel-major (`[pixel * K + k]`) as the posterior files are. Subtracting the minimum
/// keeps the exponentials in range for any temperature.
pub fn softmax(volume: &[Vec<f32>], pixels: usize, temperature: f64) -> Vec<f32> {
    let k = volume.len();
    let mut probs = vec![0.0f32; pixels * k];
    probs
        .par_chunks_mut(k.max(1))
        .enumerate()
        .for_each(|(i, out)| {
            let best = volume.iter().map(|s| s[i]).fold(f32::INFINITY, f32::min);
            let mut total = 0.0f64;
            for (o, slice) in out.iter_mut().zip(volume) {
                let p = (-(f64::from(slice[i]) - f64::from(best)) / temperature).exp();
                *o = p as f32;
                total += p;
            }
            for o in out.iter_mut() {
                *o = (f64::from(*o) / total) as f32;
            }
        });
    probs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn softmax_of_negative_cost_with_temperature() {
        // One pixel, costs 0, ln 2 · T, ln 4 · T → weights 1, ½, ¼ → 4/7, 2/7, 1/7.
        let t = 0.01;
        let volume = vec![
            vec![0.0f32],
            vec![(2.0f64.ln() * t) as f32],
            vec![(4.0f64.ln() * t) as f32],
        ];
        let p = softmax(&volume, 1, t);
        let expected = [4.0 / 7.0, 2.0 / 7.0, 1.0 / 7.0];
        for (a, b) in p.iter().zip(expected) {
            assert!((f64::from(*a) - b).abs() < 1e-6, "{p:?}");
        }
        // A large cost offset changes nothing (the minimum is subtracted).
        let shifted: Vec<Vec<f32>> = volume.iter().map(|s| vec![s[0] + 10.0]).collect();
        let q = softmax(&shifted, 1, t);
        for (a, b) in p.iter().zip(&q) {
            assert!((a - b).abs() < 1e-3);
        }
    }
}
