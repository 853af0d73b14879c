//! The network for cost-volume input with `[net] cost_network = "per_hypothesis"`: one small
//! convolutional net, shared by every hypothesis, aggregates the four directions' costs of
//! that hypothesis over the neighbourhood into its logit. It is the classical baseline's
//! "average the cost over a window, take the minimum" with the window and the weighing of the
//! directions learned (edge-aware aggregation, a direction occluded at this pixel discounted),
//! as a 3D cost-aggregation net with a kernel depth of one hypothesis. Sharing the weights over
//! the hypotheses keeps the net tiny and makes every hypothesis equally well trained whatever
//! the training set's disparity histogram; the hypotheses meet only in the softmax (and in
//! the `log b` head of UPR and ESE, which reads the logits).

use burn::nn::conv::Conv2d;
use burn::prelude::*;
use burn::tensor::activation::relu;

use crate::config::NetConfig;
use crate::model::{Block, StackNet, blocks, chain, conv2x2};

/// Channels of the hidden layer of the `log b` head.
const SPREAD_WIDTH: usize = 8;

/// Shared per-hypothesis aggregation of four cost volumes.
#[derive(Module, Debug)]
pub struct CostNet {
    /// Blocks from the four directions' costs to `cost_width` channels.
    aggregate: Vec<Block>,
    /// Final block to one logit per hypothesis.
    last_first: Conv2d,
    last_second: Conv2d,
    /// UPR's and ESE's `log b` from the logits (absent for BASE and DPP).
    spread: Option<(Conv2d, Conv2d)>,
}

impl CostNet {
    /// A freshly initialised net for `hypotheses` logits, with a `log b` head if `spread`.
    pub fn new(cfg: &NetConfig, hypotheses: usize, spread: bool, device: &Device) -> Self {
        let w = cfg.cost_width;
        Self {
            aggregate: blocks(4, w, cfg.cost_blocks, device),
            last_first: conv2x2(w, w, true, device),
            last_second: conv2x2(w, 1, false, device),
            spread: spread.then(|| {
                (
                    conv2x2(hypotheses, SPREAD_WIDTH, true, device),
                    conv2x2(SPREAD_WIDTH, 1, false, device),
                )
            }),
        }
    }
}

impl StackNet for CostNet {
    /// `[B, K (+1), H, W]` from four `[B, K, H, W]` cost volumes: the `K` logits, then
    /// `log b` when the net has its head.
    fn forward(&self, stacks: [Tensor<4>; 4]) -> Tensor<4> {
        let [b, k, h, w] = stacks[0].dims();
        let per_hypothesis = stacks.map(|s| s.reshape([b * k, 1, h, w]));
        let x = chain(&self.aggregate, Tensor::cat(per_hypothesis.to_vec(), 1));
        let logits = self
            .last_second
            .forward(relu(self.last_first.forward(x)))
            .reshape([b, k, h, w]);
        match &self.spread {
            None => logits,
            Some((first, second)) => {
                let log_b = second.forward(relu(first.forward(logits.clone())));
                Tensor::cat(vec![logits, log_b], 1)
            }
        }
    }
}

impl CostNet {
    /// The net with every batch norm frozen (see [`crate::model::EpiNet::freeze_batch_norm`]).
    pub fn freeze_batch_norm(self) -> Self {
        Self {
            aggregate: self
                .aggregate
                .into_iter()
                .map(Block::freeze_batch_norm)
                .collect(),
            ..self
        }
    }
}
