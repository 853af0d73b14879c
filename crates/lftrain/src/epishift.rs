//! The EPI-Shift network of thesis §4.2.3: a siamese feature extractor for the horizontal and
//! vertical stacks (weights shared through a quarter turn, as EPINET's streams), applied to
//! the shifts `s − 1`, `s`, `s + 1`; their features and the centre view reduced to the U-Net's
//! width; the U-Net; a 3×3 convolution to the classification `C^s` and the regression `R^s`.

use burn::nn::conv::Conv2d;
use burn::prelude::*;

use crate::config::EpiShiftConfig;
use crate::model::{turn_back, turn_to_reference};
use crate::unet::{Block3, UNet, blocks3, chain3, conv3x3};

/// A training batch on the device: `B` crops with `S` shifts each. The stacks hold the `S + 2`
/// shifts `s_0 − 1, …, s_{S−1} + 1` of every crop, crop after crop.
pub struct ShiftInput {
    /// `[B·(S+2), n·3, H, W]` horizontal stacks (centre row, left → right).
    pub horizontal: Tensor<4>,
    /// `[B·(S+2), n·3, H, W]` vertical stacks (centre column, bottom → top).
    pub vertical: Tensor<4>,
    /// `[B, 3, H, W]` the centre view.
    pub centre: Tensor<4>,
}

/// The network.
#[derive(Module, Debug)]
pub struct EpiShiftNet {
    /// Shared by the horizontal and the (turned) vertical stack.
    features: Vec<Block3>,
    /// The 387 → 64 reduction (for the defaults).
    reduce: Conv2d,
    unet: UNet,
    /// To `C^s` and `R^s`, without ReLU: offsets can be negative.
    out: Conv2d,
}

impl EpiShiftNet {
    /// A freshly initialised network for stacks of `stack_channels` (views × 3) channels.
    pub fn new(cfg: &EpiShiftConfig, stack_channels: usize, device: &Device) -> Self {
        let f = if cfg.feature_blocks == 0 {
            stack_channels
        } else {
            cfg.feature_width
        };
        Self {
            features: blocks3(stack_channels, f, cfg.feature_blocks, device),
            reduce: conv3x3(6 * f + 3, cfg.unet_width, 1, device),
            unet: UNet::new(cfg.unet_width, cfg.unet_depth, device),
            out: conv3x3(cfg.unet_width, 2, 1, device),
        }
    }

    /// The network with every batch norm frozen (§4.2.5: "fixed the learned BN parameters").
    pub fn freeze_batch_norm(self) -> Self {
        Self {
            features: self
                .features
                .into_iter()
                .map(Block3::freeze_batch_norm)
                .collect(),
            unet: self.unet.freeze_batch_norm(),
            ..self
        }
    }

    /// Features of stacks `[N, n·3, H, W]`; a vertical stack is turned onto a horizontal one
    /// for the shared weights and its features turned back.
    pub fn features(&self, stacks: Tensor<4>, vertical: bool) -> Tensor<4> {
        if vertical {
            turn_back(chain3(&self.features, turn_to_reference(stacks)))
        } else {
            chain3(&self.features, stacks)
        }
    }

    /// `[B, 2, H, W]` (`C^s`, `R^s`) from the features of the shifts `s − 1, s, s + 1` of both
    /// stacks and the centre view (`6 F + 3` channels).
    pub fn head(
        &self,
        horizontal: [Tensor<4>; 3],
        vertical: [Tensor<4>; 3],
        centre: Tensor<4>,
    ) -> Tensor<4> {
        let mut parts: Vec<Tensor<4>> = horizontal.into_iter().chain(vertical).collect();
        parts.push(centre);
        self.head_of(Tensor::cat(parts, 1))
    }

    fn head_of(&self, x: Tensor<4>) -> Tensor<4> {
        self.out.forward(self.unet.forward(self.reduce.forward(x)))
    }

    /// `(C, R)`, each `[B, S, H, W]`: the classification and regression of every crop at
    /// every one of its `S` shifts (the U-Net runs once on all `B·S`).
    pub fn forward(&self, input: ShiftInput) -> (Tensor<4>, Tensor<4>) {
        let [b, _, h, w] = input.centre.dims();
        let s = input.horizontal.dims()[0] / b - 2;
        let fh = self.features(input.horizontal, false);
        let f = fh.dims()[1];
        let fh: Tensor<5> = fh.reshape([b, s + 2, f, h, w]);
        let fv: Tensor<5> = self
            .features(input.vertical, true)
            .reshape([b, s + 2, f, h, w]);
        let three = |t: &Tensor<5>, j: usize| t.clone().narrow(1, j, 3).reshape([b, 3 * f, h, w]);
        // Shift-major: rows j·B .. (j+1)·B are shift j.
        let inputs = (0..s)
            .map(|j| Tensor::cat(vec![three(&fh, j), three(&fv, j), input.centre.clone()], 1))
            .collect();
        let out: Tensor<5> = self
            .head_of(Tensor::cat(inputs, 0))
            .reshape([s, b, 2, h, w]);
        let out = out.swap_dims(0, 1);
        let plane = |c: usize| out.clone().narrow(2, c, 1).reshape([b, s, h, w]);
        (plane(0), plane(1))
    }
}
