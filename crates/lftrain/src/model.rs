//! The EPINET-style network of thesis appendix B.1: two weight-shared input streams for the
//! four stacks, concatenated features, an output stream and a final block to the head's
//! channels. Every width and depth comes from [`NetConfig`].

use burn::nn::conv::{Conv2d, Conv2dConfig};
use burn::nn::{BatchNorm, BatchNormConfig, PaddingConfig2d};
use burn::prelude::*;
use burn::tensor::TensorData;
use burn::tensor::activation::{relu, softmax};

use crate::config::{ModelKind, NetConfig};
use crate::costnet::CostNet;
use crate::epishift::EpiShiftNet;
use crate::input::StackInput;

/// A 2×2 convolution; `grow` pads by one on every side (size + 1), otherwise none (size − 1):
/// the thesis alternates the two so that every block keeps the image size.
pub(crate) fn conv2x2(cin: usize, cout: usize, grow: bool, device: &Device) -> Conv2d {
    let padding = if grow {
        PaddingConfig2d::Explicit(1, 1, 1, 1)
    } else {
        PaddingConfig2d::Valid
    };
    Conv2dConfig::new([cin, cout], [2, 2])
        .with_padding(padding)
        .init(device)
}

/// `2×2 conv → ReLU → 2×2 conv → BN → ReLU` (Tables B.2, B.3).
#[derive(Module, Debug)]
pub struct Block {
    first: Conv2d,
    second: Conv2d,
    norm: BatchNorm,
}

impl Block {
    /// A block from `cin` to `cout` channels.
    pub fn new(cin: usize, cout: usize, device: &Device) -> Self {
        Self {
            first: conv2x2(cin, cout, true, device),
            second: conv2x2(cout, cout, false, device),
            norm: BatchNormConfig::new(cout).init(device),
        }
    }

    /// The block with its batch norm frozen (running statistics, no trained γ, β).
    pub fn freeze_batch_norm(self) -> Self {
        Self {
            norm: self.norm.freeze(),
            ..self
        }
    }

    /// Same spatial size out as in.
    pub fn forward(&self, x: Tensor<4>) -> Tensor<4> {
        let x = relu(self.first.forward(x));
        relu(self.norm.forward(self.second.forward(x)))
    }
}

/// A chain of blocks.
pub(crate) fn chain(blocks: &[Block], x: Tensor<4>) -> Tensor<4> {
    blocks.iter().fold(x, |x, b| b.forward(x))
}

/// `count` blocks, the first from `cin`, all to `width`.
pub(crate) fn blocks(cin: usize, width: usize, count: usize, device: &Device) -> Vec<Block> {
    (0..count)
        .map(|i| Block::new(if i == 0 { cin } else { width }, width, device))
        .collect()
}

/// Quarter turn of `[B, C, H, W]` images that maps the 90° stack's EPIs onto the 0° stack's
/// (and the 45° stack onto the −45° one): `new[i][j] = old[H-1-j][i]`, i.e. the centred map
/// `(x, y) → (-y, x)` (clockwise as displayed). See [`lfdata::stacks`] for the stack order.
pub fn turn_to_reference(x: Tensor<4>) -> Tensor<4> {
    x.swap_dims(2, 3).flip([3])
}

/// Inverse of [`turn_to_reference`]: `new[i][j] = old[j][W-1-i]`.
pub fn turn_back(x: Tensor<4>) -> Tensor<4> {
    x.swap_dims(2, 3).flip([2])
}

/// The network.
#[derive(Module, Debug)]
pub struct EpiNet {
    /// Shared by the 0° and (turned) 90° stacks.
    straight: Vec<Block>,
    /// Shared by the −45° and (turned) 45° stacks.
    diagonal: Vec<Block>,
    /// Output stream at the head width.
    head: Vec<Block>,
    /// Final block: conv to the output channels, ReLU, conv (Table B.3).
    last_first: Conv2d,
    last_second: Conv2d,
}

impl EpiNet {
    /// A freshly initialised network for stacks of `stack_channels` (views × 3) channels.
    pub fn new(cfg: &NetConfig, stack_channels: usize, out: usize, device: &Device) -> Self {
        let sw = cfg.stream_width;
        let streams_out = if cfg.stream_blocks == 0 {
            stack_channels
        } else {
            sw
        };
        let head_out = if cfg.head_blocks == 0 {
            4 * streams_out
        } else {
            cfg.head_width
        };
        Self {
            straight: blocks(stack_channels, sw, cfg.stream_blocks, device),
            diagonal: blocks(stack_channels, sw, cfg.stream_blocks, device),
            head: blocks(4 * streams_out, cfg.head_width, cfg.head_blocks, device),
            last_first: conv2x2(head_out, out, true, device),
            last_second: conv2x2(out, out, false, device),
        }
    }

    /// The network with every batch norm frozen: from then on, training steps normalise with
    /// the running statistics (as inference does) and update neither them nor γ, β.
    pub fn freeze_batch_norm(self) -> Self {
        let freeze = |v: Vec<Block>| v.into_iter().map(Block::freeze_batch_norm).collect();
        Self {
            straight: freeze(self.straight),
            diagonal: freeze(self.diagonal),
            head: freeze(self.head),
            ..self
        }
    }

    /// Raw outputs `[B, out, H, W]` for the stacks `[0°, 90°, 45°, −45°]`, each `[B, C, H, W]`.
    pub fn forward(&self, stacks: [Tensor<4>; 4]) -> Tensor<4> {
        let [h, v, d45, dm45] = stacks;
        let features = vec![
            chain(&self.straight, h),
            turn_back(chain(&self.straight, turn_to_reference(v))),
            turn_back(chain(&self.diagonal, turn_to_reference(d45))),
            chain(&self.diagonal, dm45),
        ];
        let x = chain(&self.head, Tensor::cat(features, 1));
        self.last_second.forward(relu(self.last_first.forward(x)))
    }
}

/// A network on the four stacks (views or cost volumes), as prediction runs it.
pub trait StackNet {
    /// Raw outputs `[B, C, H, W]` for the stacks `[0°, 90°, 45°, −45°]`.
    fn forward(&self, stacks: [Tensor<4>; 4]) -> Tensor<4>;
}

impl StackNet for EpiNet {
    fn forward(&self, stacks: [Tensor<4>; 4]) -> Tensor<4> {
        EpiNet::forward(self, stacks)
    }
}

/// The model's outputs (what [`crate::loss`] and [`crate::predict`] read) from the network's
/// raw ones `[B, C, H, W]`: the same on views; on a cost volume, BASE's disparity and UPR's and
/// ESE's `μ` are the softmax-weighted mean of the hypotheses over the first `K` channels (a
/// soft argmin: differentiable, and finer than the hypotheses' spacing), UPR's and ESE's
/// `log b` is channel `K`, and DPP's logits are the `K` channels themselves.
pub fn decode(raw: Tensor<4>, model: ModelKind, input: &StackInput) -> Tensor<4> {
    let StackInput::Cost(hypotheses, _) = input else {
        return raw;
    };
    if model == ModelKind::Dpp {
        return raw;
    }
    let k = hypotheses.len();
    let centres = Tensor::<4>::from_data(
        TensorData::new(hypotheses.clone(), [1, k, 1, 1]),
        &raw.device(),
    );
    let mu = (softmax(raw.clone().narrow(1, 0, k), 1) * centres).sum_dim(1);
    match model {
        ModelKind::Base => mu,
        _ => Tensor::cat(vec![mu, raw.narrow(1, k, 1)], 1),
    }
}

/// The network of a run: EPINET's for BASE, UPR, ESE and DPP (on views, or on cost volumes
/// with `cost_network = "streams"`), the per-hypothesis [`CostNet`] on cost volumes, EPI-Shift's
/// for EPI-Shift.
// One network per run, moved rarely: the size difference does not matter, and burn's Module
// derive does not see through a Box.
#[allow(clippy::large_enum_variant)]
#[derive(Module, Debug)]
pub enum Network {
    /// Appendix B.1.
    Epi(EpiNet),
    /// Shared per-hypothesis cost aggregation.
    Cost(CostNet),
    /// Thesis §4.2.3.
    Shift(EpiShiftNet),
}

impl Network {
    /// The network with every batch norm frozen.
    pub fn freeze_batch_norm(self) -> Self {
        match self {
            Network::Epi(n) => Network::Epi(n.freeze_batch_norm()),
            Network::Cost(n) => Network::Cost(n.freeze_batch_norm()),
            Network::Shift(n) => Network::Shift(n.freeze_batch_norm()),
        }
    }
}
