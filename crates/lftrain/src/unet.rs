//! The convolutional blocks and the U-Net of EPI-Shift (thesis §4.2.3): blocks of two 3×3
//! convolutions, each followed by ReLU and batch norm, and a U-Net whose down-sampling
//! convolutions halve the image and double the channels.

use burn::nn::conv::{Conv2d, Conv2dConfig, ConvTranspose2d, ConvTranspose2dConfig};
use burn::nn::{BatchNorm, BatchNormConfig, PaddingConfig2d};
use burn::prelude::*;
use burn::tensor::activation::relu;

/// A 3×3 convolution that keeps the size (zero padding 1), or halves it with `stride = 2`.
pub fn conv3x3(cin: usize, cout: usize, stride: usize, device: &Device) -> Conv2d {
    Conv2dConfig::new([cin, cout], [3, 3])
        .with_stride([stride, stride])
        .with_padding(PaddingConfig2d::Explicit(1, 1, 1, 1))
        .init(device)
}

/// `3×3 conv → ReLU → BN → 3×3 conv → ReLU → BN` (§4.2.3: "two 3×3 convolutions, each
/// followed by ReLU and batch norm"); the size is kept.
#[derive(Module, Debug)]
pub struct Block3 {
    first: Conv2d,
    first_norm: BatchNorm,
    second: Conv2d,
    second_norm: BatchNorm,
}

impl Block3 {
    /// A block from `cin` to `cout` channels.
    pub fn new(cin: usize, cout: usize, device: &Device) -> Self {
        Self {
            first: conv3x3(cin, cout, 1, device),
            first_norm: BatchNormConfig::new(cout).init(device),
            second: conv3x3(cout, cout, 1, device),
            second_norm: BatchNormConfig::new(cout).init(device),
        }
    }

    /// The block with both batch norms frozen (running statistics, no trained γ, β).
    pub fn freeze_batch_norm(self) -> Self {
        Self {
            first_norm: self.first_norm.freeze(),
            second_norm: self.second_norm.freeze(),
            ..self
        }
    }

    /// Same spatial size out as in.
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let x = self.first_norm.forward(relu(self.first.forward(x)));
        self.second_norm.forward(relu(self.second.forward(x)))
    }
}

/// `count` blocks, the first from `cin`, all to `width`.
pub fn blocks3(cin: usize, width: usize, count: usize, device: &Device) -> Vec<Block3> {
    (0..count)
        .map(|i| Block3::new(if i == 0 { cin } else { width }, width, device))
        .collect()
}

/// A chain of blocks.
pub fn chain3(blocks: &[Block3], x: Tensor<4>) -> Tensor<4> {
    blocks.iter().fold(x, |x, b| b.forward(x))
}

/// The U-Net (Ronneberger et al., as §4.2.3 describes it): level `i` has `width · 2^i`
/// channels at `1/2^i` of the size; each level of the encoder is a block followed by a 3×3
/// stride-2 convolution to the next level, the bottom is a block, and each level of the
/// decoder up-samples by a 3×3 transposed convolution, concatenates the encoder's output of
/// that level and applies a block. Input and output have `width` channels and the same size,
/// which must be a multiple of `2^depth`.
#[derive(Module, Debug)]
pub struct UNet {
    encoders: Vec<Block3>,
    downs: Vec<Conv2d>,
    bottom: Block3,
    ups: Vec<ConvTranspose2d>,
    decoders: Vec<Block3>,
}

impl UNet {
    /// A U-Net of `depth` down-sampling steps whose top level has `width` channels.
    pub fn new(width: usize, depth: usize, device: &Device) -> Self {
        let c = |i: usize| width << i;
        let up = |i: usize| {
            ConvTranspose2dConfig::new([c(i + 1), c(i)], [3, 3])
                .with_stride([2, 2])
                .with_padding([1, 1])
                .with_padding_out([1, 1])
                .init(device)
        };
        Self {
            encoders: (0..depth)
                .map(|i| Block3::new(c(i), c(i), device))
                .collect(),
            downs: (0..depth)
                .map(|i| conv3x3(c(i), c(i + 1), 2, device))
                .collect(),
            bottom: Block3::new(c(depth), c(depth), device),
            ups: (0..depth).map(up).collect(),
            decoders: (0..depth)
                .map(|i| Block3::new(2 * c(i), c(i), device))
                .collect(),
        }
    }

    /// The U-Net with every batch norm frozen.
    pub fn freeze_batch_norm(self) -> Self {
        let freeze = |v: Vec<Block3>| v.into_iter().map(Block3::freeze_batch_norm).collect();
        Self {
            encoders: freeze(self.encoders),
            bottom: self.bottom.freeze_batch_norm(),
            decoders: freeze(self.decoders),
            ..self
        }
    }

    /// `[B, width, H, W]` → `[B, width, H, W]`.
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let mut skips = Vec::with_capacity(self.encoders.len());
        let mut x = x;
        for (enc, down) in self.encoders.iter().zip(&self.downs) {
            let e = enc.forward(x);
            x = down.forward(e.clone());
            skips.push(e);
        }
        let mut x = self.bottom.forward(x);
        for ((up, dec), skip) in self.ups.iter().zip(&self.decoders).zip(skips).rev() {
            x = dec.forward(Tensor::cat(vec![up.forward(x), skip], 1));
        }
        x
    }
}
