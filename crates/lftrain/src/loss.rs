//! The training losses of thesis §5.2.1 on network outputs `[B, C, H, W]` and targets
//! `[B, L, H, W]` (disparity `d_j` and weight `η_j` per slot; the unimodal case is `L = 1` with
//! the front-most mode and `η = 1`, so one formula serves both). Every loss is the sum over
//! pixels and modes of `η_j ℓ(d_j)`, divided by the number of pixels `N` (eq. 5.4–5.16) inside
//! the loss region (η is 0 outside it, see [`crate::mask`]).

use burn::prelude::*;
use burn::tensor::activation::log_softmax;

use crate::config::{DppConfig, EseOutside, ModelKind, TrainConfig};

/// Targets on the device.
pub struct TargetTensors {
    /// `[B, L, H, W]` disparities.
    pub disparity: Tensor<4>,
    /// `[B, L, H, W]` weights (0 for unused slots).
    pub eta: Tensor<4>,
    /// `[B, L, H, W]` DPP bin of each disparity (DPP only).
    pub bins: Option<Tensor<4, Int>>,
    /// `N`: the pixels inside the loss region (η is 0 outside it).
    pub pixels: f32,
}

/// The DPP bin of disparity `d`: equal bins over `[min, max]`, the outer ones open-ended
/// (as lfeval's KLD bins), so a mode outside the range still pulls towards the nearest end.
pub fn dpp_bin(d: f32, cfg: &DppConfig) -> i64 {
    let h = (cfg.max - cfg.min) / cfg.bins as f32;
    (((d - cfg.min) / h).floor() as i64).clamp(0, cfg.bins as i64 - 1)
}

/// The loss of model `kind` (scalar tensor).
pub fn loss(cfg: &TrainConfig, out: Tensor<4>, t: &TargetTensors) -> Tensor<1> {
    match cfg.model {
        ModelKind::Base => l1(out, t),
        ModelKind::Upr => laplace_nll(out, t, t.eta.clone()),
        ModelKind::Ese => {
            let inside = t.disparity.clone().abs().lower_elem(cfg.ese.delta / 2.0);
            let w_in = t.eta.clone() * inside.float();
            match cfg.ese.outside {
                EseOutside::Ignore => laplace_nll(out, t, w_in),
                EseOutside::Upr => laplace_nll(out, t, t.eta.clone()),
                EseOutside::Uncertain => {
                    let w_out = t.eta.clone() - w_in.clone();
                    uncertain_outside(out, t, w_in, w_out, cfg.ese.max_log_b)
                }
            }
        }
        ModelKind::Dpp => cross_entropy(out, t),
        ModelKind::EpiShift => unreachable!("EPI-Shift's loss is crate::shift_loss"),
    }
}

/// `[B, L, H, W]` broadcast of output channel `c`.
fn channel(out: &Tensor<4>, c: usize, like: &Tensor<4>) -> Tensor<4> {
    out.clone().narrow(1, c, 1).expand(like.shape())
}

/// BASE: `Σ_j η_j |d_j − f|` (eq. 5.4, 5.8).
fn l1(out: Tensor<4>, t: &TargetTensors) -> Tensor<1> {
    let f = channel(&out, 0, &t.disparity);
    let n = t.pixels.max(1.0);
    (t.eta.clone() * (t.disparity.clone() - f).abs()).sum() / n
}

/// UPR / ESE: `Σ_j w_j (|d_j − μ| / b + log b)` with channels `μ`, `log b` (eq. 5.6, 5.7, 5.13).
fn laplace_nll(out: Tensor<4>, t: &TargetTensors, weights: Tensor<4>) -> Tensor<1> {
    let mu = channel(&out, 0, &t.disparity);
    let log_b = channel(&out, 1, &t.disparity);
    let n = t.pixels.max(1.0);
    let nll = (t.disparity.clone() - mu).abs() * log_b.clone().neg().exp() + log_b;
    (weights * nll).sum() / n
}

/// ESE with `outside = "uncertain"` (mmlf's `ImprovedUncertaintyL1Loss`): half the mean
/// Laplace NLL over the inside weights `w_in`, half the mean `−min(log b, cap)` over the outside
/// weights `w_out`, each mean over its own weight so a pass sees both however few pixels fall
/// inside its interval.
fn uncertain_outside(
    out: Tensor<4>,
    t: &TargetTensors,
    w_in: Tensor<4>,
    w_out: Tensor<4>,
    cap: f32,
) -> Tensor<1> {
    let mu = channel(&out, 0, &t.disparity);
    let log_b = channel(&out, 1, &t.disparity);
    let nll = (t.disparity.clone() - mu).abs() * log_b.clone().neg().exp() + log_b.clone();
    let mean = |w: Tensor<4>, v: Tensor<4>| (w.clone() * v).sum() / w.sum().clamp_min(1e-6);
    let inside = mean(w_in, nll);
    let outside = mean(w_out, log_b.clamp_max(cap).neg());
    (inside + outside) / 2.0
}

/// DPP: `−Σ_j η_j log softmax(z)_{bin(d_j)}` (eq. 5.15, 5.16).
fn cross_entropy(out: Tensor<4>, t: &TargetTensors) -> Tensor<1> {
    let bins = t.bins.clone().expect("DPP targets carry bin indices");
    let log_q = log_softmax(out, 1).gather(1, bins);
    let n = t.pixels.max(1.0);
    (t.eta.clone() * log_q).sum().neg() / n
}
