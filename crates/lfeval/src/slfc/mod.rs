//! Sparse Light Field Coding (SLFC; Johannsen, Sulc, Goldluecke, "What Sparse Light Field
//! Coding Reveals about Scene Structure", CVPR 2016), the multimodal baseline of the thesis'
//! §5.3.3: the EPI windows around a pixel in the horizontal and the vertical view stack are
//! coded by the Lasso (`α = 0.01`) against a dictionary whose atoms each carry one disparity
//! ([`dictionary`]). Large coefficients mean their disparity is seen at the pixel; several
//! disparities with large coefficients mean several layers (a semi-transparent surface over
//! another, a reflection).
//!
//! Per pixel, the absolute coefficients summed per disparity bin over both stacks, normalised,
//! are the discrete posterior (all zero, when the window has no texture above the Lasso's
//! threshold: then the posterior is uniform); its largest bin is the point estimate.
//!
//! Rows run in parallel; along a row each pixel's Lasso starts from its left neighbour's
//! solution, which already holds the right disparities almost everywhere.

pub mod dictionary;
pub mod lasso;
mod stack;

use std::time::Instant;

use anyhow::{Result, bail};
use indicatif::{ParallelProgressIterator, ProgressBar};
use lfdata::bins::Bins;
use lfdata::lightfield::LightField;
use lfdata::posterior::{PosteriorForm, PosteriorMap};
use lfdata::prediction::{ScenePrediction, point_estimates};
use lfdata::stacks::Region;
use lfformat::pfm::FloatImage;
use rayon::prelude::*;
use serde::Serialize;

use crate::report::errormap::luminance;
use dictionary::{Dictionary, Generators};
use lasso::LassoSettings;
use stack::EpiStack;

/// Settings of SLFC.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlfcConfig {
    /// Disparity hypotheses, one atom family per bin centre (the thesis: 108 steps).
    pub bins: Bins,
    /// EPI window radius in pixels (windows of `2r + 1` columns over all views of a stack).
    pub radius: usize,
    /// Share of the centre view's profile variance the generators hold
    /// ([`dictionary::Generators::of_view`]).
    pub energy: f64,
    /// The Lasso.
    pub lasso: LassoSettings,
    /// Side of the estimated centre crop, as a fraction of the image side (1: everything).
    pub crop: f64,
}

impl Default for SlfcConfig {
    fn default() -> Self {
        Self {
            bins: Bins::THESIS,
            radius: DEFAULT_RADIUS,
            energy: DEFAULT_ENERGY,
            lasso: LassoSettings {
                alpha: DEFAULT_ALPHA,
                tol: DEFAULT_TOL,
                max_sweeps: DEFAULT_MAX_SWEEPS,
            },
            crop: 1.0,
        }
    }
}

/// The authors' recommended Lasso weight (thesis §5.3.3).
pub const DEFAULT_ALPHA: f64 = 0.01;
/// Window radius: 9-pixel windows, as wide as the 9 views of a stack are tall.
pub const DEFAULT_RADIUS: usize = 4;
/// Generators hold 99 % of the centre view's profile variance: on the analytic planes every
/// pixel's strongest bin is then the plane's (±1), where 99.99 % lets one pixel in 64 stray.
pub const DEFAULT_ENERGY: f64 = 0.99;
/// scikit-learn's default duality-gap tolerance (relative to `‖y‖²`).
pub const DEFAULT_TOL: f64 = 1e-4;
/// scikit-learn's default iteration cap.
pub const DEFAULT_MAX_SWEEPS: usize = 1000;

/// SLFC's prediction for one scene and how many of its Lasso problems stopped at the sweep
/// cap before reaching the tolerance.
pub struct SlfcOutput {
    /// Disparity, posterior variance as uncertainty, posterior and runtime, all of the crop.
    pub prediction: ScenePrediction,
    /// Lasso problems that did not converge.
    pub unconverged: usize,
}

/// Estimates the posterior of `lf`'s centre view over the crop of `cfg`, advancing
/// `progress` by one per row. The runtime covers the estimation, not the loading.
pub fn estimate(lf: &LightField, cfg: &SlfcConfig, progress: &ProgressBar) -> Result<SlfcOutput> {
    let start = Instant::now();
    let stacks = stacks(lf, cfg)?;
    let region = Region::centre(lf.width, lf.height, cfg.crop);
    let k = cfg.bins.count;
    let mut probs = vec![0.0f32; region.width * region.height * k];
    progress.set_length(region.height as u64);
    let unconverged = probs
        .par_chunks_mut(region.width * k)
        .enumerate()
        .progress_with(progress.clone())
        .map(|(row, out)| code_row(&stacks, cfg, region, region.y0 + row, out))
        .sum();
    let posterior = PosteriorMap {
        width: region.width,
        height: region.height,
        form: PosteriorForm::Discrete {
            bins: cfg.bins,
            probs,
        },
    };
    let disparity = point_estimates(&posterior);
    let variance = (0..region.width * region.height)
        .map(|i| posterior.pixel(i).variance() as f32)
        .collect();
    let prediction = ScenePrediction {
        disparity,
        uncertainty: Some(FloatImage::new(region.width, region.height, variance)),
        posterior: Some(posterior),
        runtime_s: Some(start.elapsed().as_secs_f64()),
    };
    Ok(SlfcOutput {
        prediction,
        unconverged,
    })
}

/// Codes row `y` of `region`, writing each pixel's posterior (`bins` values) into `out`.
/// Returns the number of unconverged Lasso problems.
fn code_row(
    stacks: &[EpiStack],
    cfg: &SlfcConfig,
    region: Region,
    y: usize,
    out: &mut [f32],
) -> usize {
    let k = cfg.bins.count;
    let mut coefficients: Vec<Vec<f64>> =
        stacks.iter().map(|s| vec![0.0; s.dict.count()]).collect();
    let mut scratch: Vec<_> = stacks.iter().map(EpiStack::scratch).collect();
    let mut weights = vec![0.0f64; k];
    let mut unconverged = 0;
    for (dx, pixel) in out.chunks_exact_mut(k).enumerate() {
        weights.iter_mut().for_each(|w| *w = 0.0);
        for ((stack, w), s) in stacks.iter().zip(&mut coefficients).zip(&mut scratch) {
            if !stack.code((region.x0 + dx, y), &cfg.lasso, w, s) {
                unconverged += 1;
            }
            stack.accumulate(w, &mut weights);
        }
        let total: f64 = weights.iter().sum();
        for (p, &w) in pixel.iter_mut().zip(&weights) {
            *p = if total > 0.0 {
                (w / total) as f32
            } else {
                1.0 / k as f32
            };
        }
    }
    unconverged
}

/// The horizontal and vertical stacks of `lf` that have at least two views (one view shows
/// no parallax), as grey images, each with the dictionary of its centre view's generators.
fn stacks(lf: &LightField, cfg: &SlfcConfig) -> Result<Vec<EpiStack>> {
    let disparities = cfg.bins.centres();
    let mut out = Vec::new();
    for horizontal in [true, false] {
        let (cu, cv) = lf.centre();
        let mut views: Vec<(f32, Vec<f32>)> = lf
            .loaded()
            .filter(|&((u, v), _)| if horizontal { v == cv } else { u == cu })
            .map(|((u, v), rgb)| {
                let offset = if horizontal {
                    u as f32 - cu as f32
                } else {
                    v as f32 - cv as f32
                };
                (offset, luminance(rgb))
            })
            .collect();
        if views.len() < 2 {
            continue;
        }
        views.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (offsets, planes): (Vec<f32>, Vec<Vec<f32>>) = views.into_iter().unzip();
        let Some(centre) = offsets.iter().position(|&s| s == 0.0) else {
            bail!("SLFC learns its generators from the centre view, which is not loaded");
        };
        let support = dictionary::support(&offsets, cfg.radius, &disparities);
        let generators = Generators::of_view(
            &planes[centre],
            (lf.width, lf.height),
            horizontal,
            support,
            cfg.energy,
        );
        let dict = Dictionary::new(&offsets, cfg.radius, &disparities, &generators);
        out.push(EpiStack::new(
            horizontal,
            planes,
            (lf.width, lf.height),
            cfg.radius,
            dict,
        ));
    }
    if out.is_empty() {
        bail!("SLFC needs at least two views in the centre row or column of the light field");
    }
    Ok(out)
}
