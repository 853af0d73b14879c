//! The EPI-Shift losses of thesis §4.2.4 (eq. 4.5–4.10) on the network's `C^s`, `R^s`
//! (`[B, S, H, W]`), and the batch's targets on the device.
//!
//! `L_class = Σ (C^s − C_true^s)² W_disp` with `W_disp = (D − D_true)²`, `D` the final estimate
//! (the shift of the largest `C^s` plus its `R^s`, eq. 4.6): misclassifications that move the
//! result far are what the loss penalises. `L_reg = Σ |R^s − D_true + s| rect_ε'(D_true − s)`.
//! `L = α L_reg + L_class`. Both sums run over the shifts and the pixels of the loss region
//! where no view clipped; as lftrain's other losses they are divided by the number `N` of
//! loss-region pixels (the thesis' sums; only the step size differs).

use burn::prelude::*;
use burn::tensor::TensorData;

use crate::config::{ClassTarget, EpiShiftConfig};
use crate::shift_sample::ShiftBatch;
use crate::tensors::tensor4;

/// The targets of a [`ShiftBatch`] on the device.
pub struct ShiftTargets {
    /// `[B, 1, H, W]` `D_true` relative to each crop's base shift.
    pub disparity: Tensor<4>,
    /// `[B, S, H, W]` 1 where a pixel counts at a shift (loss region, a target, no clipping).
    pub mask: Tensor<4>,
    /// `[1, S, 1, 1]` the shifts `s` relative to the base shift (`−K ..= K`).
    pub shifts: Tensor<4>,
    /// `N`: loss-region pixels with a target.
    pub pixels: f32,
}

impl ShiftTargets {
    /// The targets of `batch`, whose crops have the relative shifts `offsets`.
    pub fn of(batch: &ShiftBatch, offsets: &[i32], device: &Device) -> Self {
        let (b, s, p) = (batch.size, batch.shifts, batch.patch);
        let weight = tensor4(batch.weight.clone(), [b, 1, p, p], device);
        let clip = tensor4(batch.clip.clone(), [b, s, p, p], device);
        let shifts: Vec<f32> = offsets.iter().map(|&o| o as f32).collect();
        Self {
            disparity: tensor4(batch.disparity.clone(), [b, 1, p, p], device),
            mask: clip * weight,
            shifts: Tensor::from_data(TensorData::new(shifts, [1, s, 1, 1]), device),
            pixels: batch.loss_pixels as f32,
        }
    }
}

/// `C_true^s` (eq. 4.7 rectangle, eq. 4.8 triangle) of `|D_true − s|`.
pub fn class_target(kind: ClassTarget, epsilon: f32, distance: Tensor<4>) -> Tensor<4> {
    match kind {
        ClassTarget::Rectangle => distance.lower_equal_elem(0.5 + epsilon).float(),
        ClassTarget::Triangle => (distance.neg() + (0.5 + epsilon)).clamp_min(0.0),
    }
}

/// The final estimate `D = s* + R^{s*}` with `s* = argmax_s C^s`, `[B, 1, H, W]` (no
/// gradient: it only weighs the classification loss).
pub fn final_estimate(class: Tensor<4>, reg: Tensor<4>, shifts: Tensor<4>) -> Tensor<4> {
    let best = class.detach().argmax(1);
    let s = shifts.expand(reg.shape()).gather(1, best.clone());
    (s + reg.detach().gather(1, best)).detach()
}

/// `L = α L_reg + L_class`, divided by `N` (scalar tensor).
pub fn epishift_loss(
    cfg: &EpiShiftConfig,
    class: Tensor<4>,
    reg: Tensor<4>,
    t: &ShiftTargets,
) -> Tensor<1> {
    let shape = class.shape();
    let d = t.disparity.clone().expand(shape.clone());
    let offset = d.clone() - t.shifts.clone().expand(shape);
    let distance = offset.clone().abs();
    let c_true = class_target(cfg.class_target, cfg.epsilon, distance.clone());
    let estimate = final_estimate(class.clone(), reg.clone(), t.shifts.clone());
    let w_disp = (estimate - t.disparity.clone()).square();
    let l_class = (class - c_true).square() * w_disp * t.mask.clone();
    let in_range = class_target(ClassTarget::Rectangle, cfg.reg_epsilon, distance);
    let l_reg = (reg - offset).abs() * in_range * t.mask.clone();
    let n = t.pixels.max(1.0);
    (l_reg.sum() * cfg.alpha + l_class.sum()) / n
}
