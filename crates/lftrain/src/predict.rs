//! Inference on whole scenes, turned into lfeval's prediction formats: BASE a disparity map,
//! UPR a Laplace posterior, ESE a mixture of the M shifted passes, DPP a discrete posterior,
//! EPI-Shift a disparity map with `1 − max_s C^s` as its uncertainty.

use std::time::Instant;

use burn::prelude::*;
use lfeval::Bins;
use lfeval::posterior::{PosteriorForm, PosteriorMap};
use lfeval::prediction::{ScenePrediction, point_estimates};
use lfformat::pfm::FloatImage;

use crate::config::{ModelKind, TrainConfig};
use crate::epishift::EpiShiftNet;
use crate::lightfield::{LightField, rotate_plane};
use crate::model::{EpiNet, Network};
use crate::shift_predict::estimate;
use crate::stacks::{Direction, Region, extract};
use crate::tensors::{tensor4, values};

/// Raw network outputs `[C][H·W]` (channel planes) for `lf` EPI-shifted by `shift`, averaged
/// over `lf` turned by `0 .. rotations` quarter turns (each output turned back; see
/// [`TrainConfig::test_rotations`]).
///
/// `net` must be in validation mode on a device without autodiff (batch norm then uses its
/// running statistics).
pub fn run_net(
    net: &EpiNet,
    lf: &LightField,
    shift: f32,
    rotations: usize,
    device: &Device,
) -> Vec<Vec<f32>> {
    let mut sum = run_once(net, lf, shift, device);
    for turns in 1..rotations {
        let turned = lf.rotate(turns);
        let planes = run_once(net, &turned, shift, device);
        for (total, plane) in sum.iter_mut().zip(planes) {
            let back = turn_plane(plane, turned.width, turned.height, 4 - turns);
            total.iter_mut().zip(back).for_each(|(t, v)| *t += v);
        }
    }
    let scale = 1.0 / rotations as f32;
    sum.iter_mut().flatten().for_each(|v| *v *= scale);
    sum
}

/// The network's output planes for `lf` as it is.
fn run_once(net: &EpiNet, lf: &LightField, shift: f32, device: &Device) -> Vec<Vec<f32>> {
    let region = Region::whole(lf);
    let shape = [1, lf.n * 3, lf.height, lf.width];
    let stacks = Direction::ALL.map(|dir| tensor4(extract(lf, dir, region, shift), shape, device));
    let out = values(net.forward(stacks));
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

/// The prediction of `net` (trained as `cfg.model`) for `lf`, with its runtime.
pub fn predict(
    cfg: &TrainConfig,
    net: &Network,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    match net {
        Network::Epi(n) => predict_epinet(cfg, n, lf, device),
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

fn predict_epinet(
    cfg: &TrainConfig,
    net: &EpiNet,
    lf: &LightField,
    device: &Device,
) -> ScenePrediction {
    let start = Instant::now();
    let (w, h) = (lf.width, lf.height);
    let posterior = match cfg.model {
        ModelKind::Base => None,
        ModelKind::Upr => {
            let mut out = run_net(net, lf, 0.0, cfg.test_rotations, device);
            let log_b = out.swap_remove(1);
            let mu = out.swap_remove(0);
            Some(PosteriorForm::Laplace { mu, log_b })
        }
        ModelKind::Ese => Some(ese_mixture(cfg, net, lf, device)),
        ModelKind::Dpp => Some(dpp_posterior(
            cfg,
            run_net(net, lf, 0.0, cfg.test_rotations, device),
        )),
        ModelKind::EpiShift => unreachable!("EPI-Shift runs its own network"),
    };
    let (disparity, posterior) = match posterior {
        None => {
            let out = run_net(net, lf, 0.0, cfg.test_rotations, device);
            (FloatImage::new(w, h, out[0].clone()), None)
        }
        Some(form) => {
            let map = PosteriorMap {
                width: w,
                height: h,
                form,
            };
            (point_estimates(&map), Some(map))
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
fn ese_mixture(cfg: &TrainConfig, net: &EpiNet, lf: &LightField, device: &Device) -> PosteriorForm {
    let shifts = cfg.ese.scene_shifts(lf.disparity_range);
    let m = shifts.len();
    let pixels = lf.width * lf.height;
    let (mut mu, mut log_b) = (vec![0.0; pixels * m], vec![0.0; pixels * m]);
    for (k, &s) in shifts.iter().enumerate() {
        let out = run_net(net, lf, s, cfg.test_rotations, device);
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
    let bins = Bins::new(cfg.dpp.min as f64, cfg.dpp.max as f64, cfg.dpp.bins)
        .expect("validated DPP bins");
    PosteriorForm::Discrete { bins, probs }
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
}

impl Overrides {
    /// `cfg` with these overrides, refused where they do not apply to its model or are out
    /// of range (the error names the flag).
    fn apply(&self, mut cfg: TrainConfig) -> anyhow::Result<TrainConfig> {
        let name = cfg.model.name();
        if let Some(c) = self.coarse_max {
            if cfg.model != ModelKind::EpiShift {
                anyhow::bail!("--coarse-max applies to epishift runs, this is {name}");
            }
            cfg.epishift.coarse_max = c;
            cfg.validate()
                .map_err(|e| e.context(format!("--coarse-max {c}")))?;
        }
        if let Some(r) = self.range {
            match cfg.model {
                ModelKind::EpiShift => cfg.epishift.range = Some(r),
                ModelKind::Ese => cfg.ese.range = Some(r),
                _ => anyhow::bail!("--range applies to epishift and ese runs, this is {name}"),
            }
            cfg.validate()
                .map_err(|e| e.context(format!("--range {},{}", r[0], r[1])))?;
        }
        if let Some(k) = self.rotations {
            cfg.test_rotations = k;
            cfg.validate()
                .map_err(|e| e.context(format!("--rotations {k}")))?;
        }
        Ok(cfg)
    }
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
    let bar = lfeval::pipeline::progress(scenes.len(), "predicting", quiet);
    for s in &scenes {
        let lf = LightField::load(&s.path)?;
        if lf.n != state.grid {
            anyhow::bail!(
                "{}: {}x{} views, the network was trained on {}x{}",
                s.path.display(),
                lf.n,
                lf.n,
                state.grid,
                state.grid
            );
        }
        let pred = predict(&cfg, &net, &lf, &device);
        lfeval::prediction::write_prediction(out, &s.name, &pred)?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(scenes.len())
}
