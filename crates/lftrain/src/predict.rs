//! Inference on whole scenes, turned into lfeval's prediction formats: BASE a disparity map,
//! UPR a Laplace posterior, ESE a mixture of the M shifted passes, DPP a discrete posterior,
//! EPI-Shift a disparity map with `1 − max_s C^s` as its uncertainty.

use std::time::Instant;

use burn::prelude::*;
use lfdata::lightfield::{LightField, rotate_plane};
use lfdata::posterior::{PixelPosterior, PosteriorForm, PosteriorMap};
use lfdata::prediction::ScenePrediction;
use lfdata::stacks::{Direction, Region};
use lfdata::{Bins, laplace};
use lfformat::pfm::FloatImage;
use lfformat::views::ViewSet;

use crate::config::{EsePoint, ModelKind, NetInput, TrainConfig};
use crate::epishift::EpiShiftNet;
use crate::input::StackInput;
use crate::model::{Network, StackNet, decode};
use crate::shift_predict::estimate;
use crate::tensors::{tensor4, values};

/// Raw network outputs `[C][H·W]` (channel planes) for `lf` EPI-shifted by `shift`, averaged
/// over `lf` turned by `0 .. rotations` quarter turns (each output turned back; see
/// [`TrainConfig::test_rotations`]).
///
/// `net` must be in validation mode on a device without autodiff (batch norm then uses its
/// running statistics).
pub fn run_net(
    net: &impl StackNet,
    model: ModelKind,
    input: &StackInput,
    lf: &LightField,
    shift: f32,
    rotations: usize,
    device: &Device,
) -> Vec<Vec<f32>> {
    let once = |lf: &LightField| run_once(net, model, input, lf, shift, device);
    let mut sum = once(lf);
    for turns in 1..rotations {
        let turned = lf.rotate(turns);
        let planes = once(&turned);
        for (total, plane) in sum.iter_mut().zip(planes) {
            let back = turn_plane(plane, turned.width, turned.height, 4 - turns);
            total.iter_mut().zip(back).for_each(|(t, v)| *t += v);
        }
    }
    let scale = 1.0 / rotations as f32;
    sum.iter_mut().flatten().for_each(|v| *v *= scale);
    sum
}

/// The model's output planes for `lf` as it is.
fn run_once(
    net: &impl StackNet,
    model: ModelKind,
    input: &StackInput,
    lf: &LightField,
    shift: f32,
    device: &Device,
) -> Vec<Vec<f32>> {
    let region = Region::whole(lf);
    let shape = [1, input.channels(lf.nx), lf.height, lf.width];
    let planes = |dir| input.planes(lf, dir, region, shift);
    let stacks = Direction::ALL.map(|dir| tensor4(planes(dir), shape, device));
    let out = values(decode(net.forward(stacks), model, input));
    out.chunks_exact(lf.width * lf.height)
        .map(<[f32]>::to_vec)
        .collect()
}

/// A `w × h` plane turned by `turns` quarter turns (as [`LightField::rotate`] turns views).
fn turn_plane(plane: Vec<f32>, w: usize, h: usize, turns: usize) -> Vec<f32> {
    (0..turns % 4)
        .fold((plane, w, h), |(p, w, h), _| {
            (rotate_plane(&p, w, h, 1), h, w)
        })
        .0
}

/// The prediction of `net` (trained as `cfg.model`) for `lf`, with its runtime; with
/// [`TrainConfig::test_denoise`] on, predicted again on the star's views of `lf` denoised
/// through the first prediction (the denoising reads every loaded view: load them all).
pub fn predict(
    cfg: &TrainConfig,
    net: &Network,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    let first = predict_pass(cfg, net, lf, device);
    if cfg.test_denoise == 0.0 {
        return first;
    }
    let start = Instant::now();
    let denoised =
        lfdata::denoise::denoise(lf, &first.disparity.data, cfg.test_denoise, ViewSet::Star);
    let spent = start.elapsed().as_secs_f64() + first.runtime_s.unwrap_or(0.0);
    let mut second = predict_pass(cfg, net, &denoised, device);
    second.runtime_s = second.runtime_s.map(|s| s + spent);
    second
}

/// One prediction of `net` for `lf`, without test-time denoising (see [`predict`]).
pub fn predict_pass(
    cfg: &TrainConfig,
    net: &Network,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    match net {
        Network::Epi(n) => predict_stacks(cfg, n, lf, device),
        Network::Cost(n) => predict_stacks(cfg, n, lf, device),
        Network::Shift(n) => predict_epishift(cfg, n, lf, device),
    }
}

/// EPI-Shift over the shifts covering `lf`'s range (`cfg.epishift.range` or the scene's
/// `parameters.cfg`): the disparity `D` (eq. 4.11 refined) and `1 − max_s C^s` as the
/// uncertainty lfeval's sparsification ranks by (the thesis gives no confidence; a pixel
/// whose best shift is barely classified is the least trustworthy).
pub fn predict_epishift(
    cfg: &TrainConfig,
    net: &EpiShiftNet,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    let start = Instant::now();
    let est = estimate(net, lf, &cfg.epishift, device);
    let (w, h) = (lf.width, lf.height);
    let uncertainty = est.confidence.iter().map(|c| 1.0 - c).collect();
    ScenePrediction {
        disparity: FloatImage::new(w, h, est.disparity),
        uncertainty: Some(FloatImage::new(w, h, uncertainty)),
        posterior: None,
        runtime_s: Some(start.elapsed().as_secs_f64()),
    }
}

fn predict_stacks(
    cfg: &TrainConfig,
    net: &impl StackNet,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    let start = Instant::now();
    let (w, h) = (lf.width, lf.height);
    let input = StackInput::of(cfg);
    let run = |shift| {
        run_net(
            net,
            cfg.model,
            &input,
            lf,
            shift,
            cfg.test_rotations,
            device,
        )
    };
    let posterior = match cfg.model {
        ModelKind::Base => None,
        ModelKind::Upr => {
            let mut out = run(0.0);
            let log_b = out.swap_remove(1);
            let mu = out.swap_remove(0);
            Some(PosteriorForm::Laplace { mu, log_b })
        }
        ModelKind::Ese => Some(ese_mixture(cfg, lf, run)),
        ModelKind::Dpp => Some(dpp_posterior(cfg, run(0.0))),
        ModelKind::EpiShift => unreachable!("EPI-Shift runs its own network"),
    };
    let (disparity, posterior) = match posterior {
        None => {
            let out = run(0.0);
            (FloatImage::new(w, h, out[0].clone()), None)
        }
        Some(form) => {
            let map = PosteriorMap {
                width: w,
                height: h,
                form,
            };
            let point = |i| match map.pixel(i) {
                PixelPosterior::Discrete { bins, probs } if cfg.dpp.mode_window > 0 => {
                    window_mode(probs, bins, cfg.dpp.mode_window)
                }
                PixelPosterior::Mixture { weights, mu, log_b }
                    if cfg.ese.point == EsePoint::Mode =>
                {
                    mixture_mode(weights, mu, log_b)
                }
                other => other.point_estimate() as f32,
            };
            let disparity = FloatImage::new(w, h, (0..w * h).map(point).collect());
            (disparity, Some(map))
        }
    };
    ScenePrediction {
        disparity,
        uncertainty: None,
        posterior,
        runtime_s: Some(start.elapsed().as_secs_f64()),
    }
}

/// The ESE mixture (thesis eq. 5.9): pass `k` on the light field shifted by `s_k` predicts
/// `d - s_k`, so its Laplacian is centred at `μ_k + s_k`; all passes weigh `1/M`.
fn ese_mixture(
    cfg: &TrainConfig,
    lf: &LightField,
    run: impl Fn(f32) -> Vec<Vec<f32>>,
) -> PosteriorForm {
    let shifts = cfg.ese.scene_shifts(lf.disparity_range);
    let m = shifts.len();
    let pixels = lf.width * lf.height;
    let (mut mu, mut log_b) = (vec![0.0; pixels * m], vec![0.0; pixels * m]);
    for (k, &s) in shifts.iter().enumerate() {
        let out = run(s);
        for i in 0..pixels {
            mu[i * m + k] = out[0][i] + s;
            log_b[i * m + k] = out[1][i];
        }
    }
    PosteriorForm::Mixture {
        components: m,
        weights: vec![1.0 / m as f32; pixels * m],
        mu,
        log_b,
    }
}

/// Softmax over the DPP's channel planes, stored per pixel.
fn dpp_posterior(cfg: &TrainConfig, planes: Vec<Vec<f32>>) -> PosteriorForm {
    let k = planes.len();
    let pixels = planes[0].len();
    let mut probs = vec![0.0; pixels * k];
    for i in 0..pixels {
        let max = planes
            .iter()
            .map(|p| p[i])
            .fold(f32::NEG_INFINITY, f32::max);
        let px = &mut probs[i * k..(i + 1) * k];
        for (q, p) in px.iter_mut().zip(&planes) {
            *q = (p[i] - max).exp();
        }
        let sum: f32 = px.iter().sum();
        px.iter_mut().for_each(|q| *q /= sum);
    }
    PosteriorForm::Discrete {
        bins: cfg.dpp.bins(),
        probs,
    }
}

/// The most likely mode of one pixel's discrete posterior `probs` over `bins` at a scale of
/// `2r + 1` bins ([`crate::config::DppConfig::mode_window`]): the bin whose window `k − r ..=
/// k + r` (clipped to the bins) holds the most probability (the first on ties), and the mean
/// of that window's centres weighted by their probability. `r = 0` is the most probable
/// bin's centre. NaN where the probabilities are not a usable distribution (a non-finite or
/// non-positive total), as lfeval's own point estimate, so its invalid-pixel count sees it.
pub fn window_mode(probs: &[f32], bins: &Bins, r: usize) -> f32 {
    let n = probs.len();
    let p = |j: usize| f64::from(probs[j]);
    let total: f64 = (0..n).map(p).sum();
    if !(total.is_finite() && total > 0.0) {
        return f32::NAN;
    }
    let mut sum: f64 = (0..n.min(r + 1)).map(p).sum();
    let (mut best, mut best_sum) = (0, sum);
    for k in 1..n {
        if k + r < n {
            sum += p(k + r);
        }
        if k > r {
            sum -= p(k - r - 1);
        }
        if sum > best_sum {
            (best, best_sum) = (k, sum);
        }
    }
    let window = best.saturating_sub(r)..(best + r + 1).min(n);
    let mass: f64 = window.clone().map(p).sum();
    let moment: f64 = window.map(|j| p(j) * bins.centre(j)).sum();
    (moment / mass) as f32
}

/// The most likely mode of a mixture of Laplacians `Σ w_k Laplace(μ_k, e^{log b_k})`
/// ([`EsePoint::Mode`]): the component centre `μ_j` where the mixture's density is highest
/// (the first on ties). NaN where the weights are not a usable distribution or no centre
/// has a finite density.
pub fn mixture_mode(weights: &[f32], mu: &[f32], log_b: &[f32]) -> f32 {
    let total: f64 = weights.iter().map(|&w| f64::from(w)).sum();
    if !(total.is_finite() && total > 0.0) {
        return f32::NAN;
    }
    let density = |x: f64| -> f64 {
        (weights.iter().zip(mu).zip(log_b))
            .map(|((&w, &m), &lb)| {
                f64::from(w) * laplace::density(m.into(), f64::from(lb).exp(), x)
            })
            .sum()
    };
    let mut best = (f64::NEG_INFINITY, f32::NAN);
    for &m in mu {
        let d = density(m.into());
        if d.is_finite() && d > best.0 {
            best = (d, m);
        }
    }
    best.1
}

/// `lftrain predict`: the run's checkpoint applied to every scene of `dataset`, written to
/// `out` in lfeval's layout (`disp_maps/`, `posteriors/`, `runtimes/`). Returns the scene count.
pub fn predict_dataset(
    run: &std::path::Path,
    dataset: &std::path::Path,
    out: &std::path::Path,
    quiet: bool,
) -> anyhow::Result<usize> {
    predict_dataset_over(run, dataset, out, quiet, &Overrides::default())
}

/// What `lftrain predict`'s flags change in a run's config.
#[derive(Clone, Copy, Debug, Default)]
pub struct Overrides {
    /// `--range`: EPI-Shift's integer shifts, or ESE's passes at its step, cover this range
    /// instead of what the run's config (EPI-Shift: each scene's `parameters.cfg`) says.
    pub range: Option<[f32; 2]>,
    /// `--coarse-max`: [`crate::config::EpiShiftConfig::coarse_max`].
    pub coarse_max: Option<f32>,
    /// `--rotations`: [`TrainConfig::test_rotations`].
    pub rotations: Option<usize>,
    /// `--mode-window`: [`crate::config::DppConfig::mode_window`].
    pub mode_window: Option<usize>,
    /// `--denoise`: [`TrainConfig::test_denoise`].
    pub denoise: Option<f32>,
}

impl Overrides {
    /// `cfg` with these overrides, refused where a flag does not apply to its model or the
    /// result is invalid (the error names the flags).
    fn apply(&self, mut cfg: TrainConfig) -> anyhow::Result<TrainConfig> {
        use ModelKind::{Dpp, EpiShift, Ese};
        let model = cfg.model;
        let only = |flag: &str, models: &[ModelKind]| {
            let names: Vec<_> = models.iter().map(|m| m.name()).collect();
            anyhow::ensure!(
                models.contains(&model),
                "{flag} applies to {} runs, this is {}",
                names.join(" and "),
                model.name()
            );
            Ok(())
        };
        let mut given = Vec::new();
        if let Some(c) = self.coarse_max {
            only("--coarse-max", &[EpiShift])?;
            cfg.epishift.coarse_max = c;
            given.push(format!("--coarse-max {c}"));
        }
        if let Some(r) = self.range {
            only("--range", &[EpiShift, Ese])?;
            match model {
                EpiShift => cfg.epishift.range = Some(r),
                _ => cfg.ese.range = Some(r),
            }
            given.push(format!("--range {},{}", r[0], r[1]));
        }
        if let Some(k) = self.rotations {
            cfg.test_rotations = k;
            given.push(format!("--rotations {k}"));
        }
        if let Some(k) = self.denoise {
            cfg.test_denoise = k;
            given.push(format!("--denoise {k}"));
        }
        if let Some(r) = self.mode_window {
            only("--mode-window", &[Dpp])?;
            cfg.dpp.mode_window = r;
            given.push(format!("--mode-window {r}"));
        }
        cfg.validate().map_err(|e| e.context(given.join(" ")))?;
        Ok(cfg)
    }
}

/// The disparities a model can output without EPI shifts: a DPP's bins, and the hypotheses
/// of a cost-volume input (its soft argmin stays between them). `None` where nothing bounds
/// it: a regression on the views, and ESE and EPI-Shift, which shift to the scene's range.
pub fn output_range(cfg: &TrainConfig) -> Option<[f32; 2]> {
    match (cfg.model, cfg.net.input) {
        (ModelKind::Ese | ModelKind::EpiShift, _) => None,
        (ModelKind::Dpp, _) | (_, NetInput::Cost) => Some([cfg.dpp.min, cfg.dpp.max]),
        _ => None,
    }
}

/// The warning for the scenes (name, `parameters.cfg` range) whose range leaves `reach`, or
/// `None` when all fit: a researcher running a narrow model on wide scenes must not take the
/// clamped disparities for its answer.
fn reach_warning(
    model: ModelKind,
    reach: [f32; 2],
    scenes: &[(String, [f32; 2])],
) -> Option<String> {
    let beyond: Vec<&str> = scenes
        .iter()
        .filter(|(_, [lo, hi])| *lo < reach[0] || *hi > reach[1])
        .map(|(name, _)| name.as_str())
        .collect();
    (!beyond.is_empty()).then(|| {
        format!(
            "warning: {} of {} scenes ({}) have a parameters.cfg disparity range beyond \
             [{}, {}] px, all this {} model can output; their farther pixels are clamped \
             (EPI-Shift, or ESE over the scene's range, reaches them)",
            beyond.len(),
            scenes.len(),
            beyond.join(", "),
            reach[0],
            reach[1],
            model.name()
        )
    })
}

/// [`predict_dataset`] with the run's config changed by `overrides`.
pub fn predict_dataset_over(
    run: &std::path::Path,
    dataset: &std::path::Path,
    out: &std::path::Path,
    quiet: bool,
    overrides: &Overrides,
) -> anyhow::Result<usize> {
    let run = crate::run::RunDir::new(run);
    let cfg = overrides.apply(run.config()?)?;
    let state = run.state()?;
    let device = crate::train::default_device();
    let net = run.load_net(&cfg, state.grid, &device)?.valid();
    let scenes = lfformat::dataset::discover(dataset, &[])?;
    let bar = lfdata::progress::progress(scenes.len(), "predicting", quiet);
    let mut ranges = Vec::new();
    for s in &scenes {
        let lf = if cfg.test_denoise > 0.0 {
            LightField::load(&s.path, ViewSet::Full)?
        } else {
            LightField::load_star(&s.path)?
        };
        ranges.extend(lf.disparity_range.map(|r| (s.name.clone(), r)));
        if (lf.nx, lf.ny) != (state.grid, state.grid) {
            anyhow::bail!(
                "{}: {}x{} views, the network was trained on {}x{}",
                s.path.display(),
                lf.nx,
                lf.ny,
                state.grid,
                state.grid
            );
        }
        let pred = predict(&cfg, &net, &lf, &device);
        lfdata::prediction::write_prediction(out, &s.name, &pred)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let warning = output_range(&cfg).and_then(|reach| reach_warning(cfg.model, reach, &ranges));
    if let Some(w) = warning {
        lfformat::note!("lftrain predict: {w}");
    }
    Ok(scenes.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// DPP and cost-volume models are bounded by the `[dpp]` range; views regressions, ESE
    /// and EPI-Shift are not. Only scenes reaching past it are named.
    #[test]
    fn narrow_models_warn_about_scenes_beyond_their_range() {
        let cfg = |model, input| {
            let mut c = TrainConfig {
                model,
                ..TrainConfig::default()
            };
            c.net.input = input;
            (c.dpp.min, c.dpp.max) = (-4.5, 4.5);
            output_range(&c)
        };
        assert_eq!(cfg(ModelKind::Dpp, NetInput::Views), Some([-4.5, 4.5]));
        assert_eq!(cfg(ModelKind::Base, NetInput::Cost), Some([-4.5, 4.5]));
        assert_eq!(cfg(ModelKind::Upr, NetInput::Cost), Some([-4.5, 4.5]));
        assert_eq!(cfg(ModelKind::Base, NetInput::Views), None);
        assert_eq!(cfg(ModelKind::Ese, NetInput::Cost), None);
        let scenes = [
            ("narrow".to_string(), [-3.5, 3.5]),
            ("wide".to_string(), [-40.0, 40.0]),
            ("far".to_string(), [-5.0, 1.0]),
        ];
        let w = reach_warning(ModelKind::Dpp, [-4.5, 4.5], &scenes).unwrap();
        assert!(w.contains("2 of 3 scenes (wide, far)"), "{w}");
        assert!(
            w.contains("[-4.5, 4.5] px") && w.contains("dpp model"),
            "{w}"
        );
        assert_eq!(
            reach_warning(ModelKind::Dpp, [-4.5, 4.5], &scenes[..1]),
            None
        );
    }

    /// Bins of width 1 over [0, n): bin `k`'s centre is `k + 0.5`.
    fn unit_bins(n: usize) -> Bins {
        Bins::new(0.0, n as f64, n).unwrap()
    }

    #[test]
    fn window_zero_is_the_most_probable_bin() {
        let probs = [0.1, 0.3, 0.2, 0.3, 0.1];
        assert_eq!(
            window_mode(&probs, &unit_bins(5), 0),
            1.5,
            "first of the tied maxima"
        );
    }

    #[test]
    fn a_window_prefers_the_broad_mode_to_a_lone_spike() {
        // A spike of 0.2 at bin 0; a mode of 3 × 0.16 at bins 5, 6, 7; 0.32 spread thinly.
        let mut probs = [0.02f32; 12];
        probs[0] = 0.2;
        probs[5..8].fill(0.16);
        assert_eq!(window_mode(&probs, &unit_bins(12), 0), 0.5);
        // Window 6 ± 1 holds 0.48: its weighted mean is centre 6.
        assert!((window_mode(&probs, &unit_bins(12), 1) - 6.5).abs() < 1e-6);
    }

    #[test]
    fn the_estimate_is_the_probability_weighted_mean_of_the_window() {
        // Windows of 3: bin 4's (0.1 + 0.3 + 0.2 = 0.6) beats bin 3's (0.4) and bin 5's (0.5);
        // (0.1·3.5 + 0.3·4.5 + 0.2·5.5) / 0.6 = 2.8 / 0.6.
        let probs = [0.0, 0.0, 0.0, 0.1, 0.3, 0.2, 0.0, 0.0];
        let d = window_mode(&probs, &unit_bins(8), 1);
        assert!((d - 2.8 / 0.6).abs() < 1e-6, "{d}");
    }

    #[test]
    fn the_mixture_mode_is_where_passes_agree_not_the_sharpest_pass() {
        // Two passes agree near 1.0 (b = 0.2); a lone sharper pass sits at 3.0 (b = 0.15).
        let (w, mu) = ([1.0 / 3.0; 3], [1.0f32, 1.05, 3.0]);
        let log_b = [0.2f32.ln(), 0.2f32.ln(), 0.15f32.ln()];
        // Peaks w / 2b: 0.83, 0.83, 1.11 — the highest peak is the lone pass.
        // Density at 1.0 and at 1.05: (1/3)/0.4 · (1 + e^{-0.25}) = 1.482, plus what the pass
        // at 3.0 adds (1.1 · e^{-2/0.15} = 1.8e-6 and 1.1 · e^{-1.95/0.15} = 2.5e-6, so 1.05
        // wins); at 3.0: 1.111 + 1e-4.
        assert_eq!(mixture_mode(&w, &mu, &log_b), 1.05);
        // Without the agreeing pass the sharp one wins.
        assert_eq!(mixture_mode(&w[..2], &mu[1..], &log_b[1..]), 3.0);
        assert!(mixture_mode(&[0.0, 0.0], &mu[..2], &log_b[..2]).is_nan());
        assert!(mixture_mode(&[0.5, f32::NAN], &mu[..2], &log_b[..2]).is_nan());
    }

    #[test]
    fn an_unusable_posterior_gives_nan() {
        let bins = unit_bins(3);
        assert!(window_mode(&[0.5, f32::NAN, 0.5], &bins, 1).is_nan());
        assert!(window_mode(&[0.0; 3], &bins, 1).is_nan());
    }

    #[test]
    fn windows_are_clipped_at_the_first_and_last_bins() {
        // All mass in bins 0 and 1: the window around bin 0 is 0..=2 clipped to 0..=2, mean 1.0.
        let probs = [0.5, 0.5, 0.0, 0.0, 0.0, 0.0];
        assert!((window_mode(&probs, &unit_bins(6), 2) - 1.0).abs() < 1e-6);
        // Mirrored at the last bins: (0.5·4.5 + 0.5·5.5) = 5.0.
        let probs = [0.0, 0.0, 0.0, 0.0, 0.5, 0.5];
        assert!((window_mode(&probs, &unit_bins(6), 2) - 5.0).abs() < 1e-6);
    }

    #[test]
    fn predict_flags_are_refused_where_they_do_not_apply() {
        let cfg = |model| TrainConfig {
            model,
            ..TrainConfig::default()
        };
        let err = |o: Overrides, model| o.apply(cfg(model)).unwrap_err().to_string();
        let window = Overrides {
            mode_window: Some(2),
            ..Default::default()
        };
        assert_eq!(
            window.apply(cfg(ModelKind::Dpp)).unwrap().dpp.mode_window,
            2
        );
        assert_eq!(
            err(window, ModelKind::Upr),
            "--mode-window applies to dpp runs, this is upr"
        );
        let range = Overrides {
            range: Some([-40.0, 40.0]),
            ..Default::default()
        };
        assert!(err(range, ModelKind::Base).contains("epishift and ese runs"));
        let turns = Overrides {
            rotations: Some(5),
            ..Default::default()
        };
        assert!(err(turns, ModelKind::Base).starts_with("--rotations 5"));
        let denoise = |k| Overrides {
            denoise: Some(k),
            ..Default::default()
        };
        let on = denoise(2.0).apply(cfg(ModelKind::EpiShift)).unwrap();
        assert_eq!(on.test_denoise, 2.0, "every model takes it");
        assert!(err(denoise(-1.0), ModelKind::Base).starts_with("--denoise -1"));
    }
}
