//! Moving batches onto the device.

use burn::prelude::*;
use burn::tensor::TensorData;

use crate::config::{ModelKind, TrainConfig};
use crate::epishift::ShiftInput;
use crate::loss::{TargetTensors, dpp_bin};
use crate::sample::Batch;
use crate::shift_sample::ShiftBatch;

/// A `[b, c, h, w]` float tensor from row-major values.
pub fn tensor4(values: Vec<f32>, shape: [usize; 4], device: &Device) -> Tensor<4> {
    Tensor::from_data(TensorData::new(values, shape), device)
}

/// The four stacks of `batch`.
pub fn stack_tensors(batch: &Batch, device: &Device) -> [Tensor<4>; 4] {
    let shape = [batch.size, batch.stack_channels, batch.patch, batch.patch];
    batch
        .stacks
        .clone()
        .map(|values| tensor4(values, shape, device))
}

/// The network input of an EPI-Shift batch.
pub fn shift_input(batch: &ShiftBatch, device: &Device) -> ShiftInput {
    let (b, p) = (batch.size, batch.patch);
    let stacks = [b * (batch.shifts + 2), batch.stack_channels, p, p];
    ShiftInput {
        horizontal: tensor4(batch.horizontal.clone(), stacks, device),
        vertical: tensor4(batch.vertical.clone(), stacks, device),
        centre: tensor4(batch.centre.clone(), [b, 3, p, p], device),
    }
}

/// The targets of `batch`, with DPP bin indices when `cfg.model` is DPP.
pub fn target_tensors(batch: &Batch, cfg: &TrainConfig, device: &Device) -> TargetTensors {
    let shape = [batch.size, batch.modes, batch.patch, batch.patch];
    let bins = (cfg.model == ModelKind::Dpp).then(|| {
        let idx: Vec<i64> = batch
            .disparity
            .iter()
            .map(|&d| dpp_bin(d, &cfg.dpp))
            .collect();
        Tensor::from_data(TensorData::new(idx, shape), device)
    });
    TargetTensors {
        disparity: tensor4(batch.disparity.clone(), shape, device),
        eta: tensor4(batch.eta.clone(), shape, device),
        bins,
        pixels: batch.loss_pixels as f32,
    }
}

/// The values of a tensor, row-major.
pub fn values(t: Tensor<4>) -> Vec<f32> {
    t.into_data()
        .convert::<f32>()
        .try_into_vec::<f32>()
        .expect("float tensor data")
}
