//! What the network reads per stack direction ([`crate::config::NetInput`]): the stack's
//! views, or its plane-sweep cost volume over the `[dpp]` bin centres.

use lfdata::cost::cost_stack;
use lfdata::lightfield::LightField;
use lfdata::stacks::{Direction, Region, extract};

use crate::config::{NetInput, TrainConfig};

/// The input of a run, resolved once from its configuration.
#[derive(Clone, Debug, PartialEq)]
pub enum StackInput {
    /// The stack's `n × 3` view planes.
    Views,
    /// One cost plane per hypothesis, at these disparities (pixels), with this variance
    /// floor ([`crate::config::NetConfig::cost_floor`]).
    Cost(Vec<f32>, f32),
}

impl StackInput {
    /// The input `cfg` asks for; the hypotheses are the centres of its `[dpp]` bins.
    pub fn of(cfg: &TrainConfig) -> Self {
        match cfg.net.input {
            NetInput::Views => StackInput::Views,
            NetInput::Cost => StackInput::Cost(hypotheses(cfg), cfg.net.cost_floor),
        }
    }

    /// Planes per stack for an `n × n` grid.
    pub fn channels(&self, n: usize) -> usize {
        match self {
            StackInput::Views => n * 3,
            StackInput::Cost(h, _) => h.len(),
        }
    }

    /// The largest hypothesis magnitude: how much further than the EPI shift the stack reads.
    pub fn reach(&self) -> f32 {
        match self {
            StackInput::Views => 0.0,
            StackInput::Cost(h, _) => h.iter().fold(0.0, |m, d| m.max(d.abs())),
        }
    }

    /// The input planes of stack `dir` over `region` of `lf` EPI-shifted by `shift`.
    pub fn planes(&self, lf: &LightField, dir: Direction, region: Region, shift: f32) -> Vec<f32> {
        match self {
            StackInput::Views => extract(lf, dir, region, shift),
            StackInput::Cost(h, floor) => cost_stack(lf, dir, region, shift, h, *floor),
        }
    }
}

/// The centres of `cfg`'s DPP bins: the cost volume's hypotheses, and the disparities whose
/// softmax-weighted mean is the output of BASE, UPR and ESE on a cost volume.
pub fn hypotheses(cfg: &TrainConfig) -> Vec<f32> {
    cfg.dpp
        .bins()
        .centres()
        .into_iter()
        .map(|c| c as f32)
        .collect()
}
