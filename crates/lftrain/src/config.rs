//! Training configuration: one TOML file (every field optional) plus a few command-line
//! overrides, stored in the run folder so that `--resume` and `predict` rebuild the same model.

use std::path::Path;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use lfdata::bins::Bins;
use serde::{Deserialize, Serialize};

/// The four posterior models of the thesis (§5.2.1) and EPI-Shift (chapter 4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// One disparity per pixel, L1 loss.
    Base,
    /// Unimodal posterior regression: a Laplacian (μ, log b).
    Upr,
    /// EPI-shift ensemble: the UPR network with a masked loss, M shifted passes at inference.
    Ese,
    /// Discrete posterior prediction: a softmax over disparity bins.
    Dpp,
    /// EPI-Shift (thesis §4.2): a classification and an offset per integer EPI shift, for
    /// disparity ranges far beyond the training data's.
    #[value(name = "epishift")]
    EpiShift,
}

impl ModelKind {
    /// Output channels of the model (what the losses and predictions read).
    pub fn out_channels(self, dpp_bins: usize) -> usize {
        match self {
            ModelKind::Base => 1,
            ModelKind::Upr | ModelKind::Ese | ModelKind::EpiShift => 2,
            ModelKind::Dpp => dpp_bins,
        }
    }

    /// Channels of the network's last layer for `input`: the output channels on views; on a
    /// cost volume one logit per bin, plus `log b` for UPR and ESE (see [`NetInput::Cost`]).
    pub fn net_channels(self, input: NetInput, dpp_bins: usize) -> usize {
        match input {
            NetInput::Views => self.out_channels(dpp_bins),
            NetInput::Cost => dpp_bins + usize::from(self.has_spread()),
        }
    }

    /// Whether the model predicts a Laplacian's `log b` beside its disparity (UPR, ESE).
    pub fn has_spread(self) -> bool {
        matches!(self, ModelKind::Upr | ModelKind::Ese)
    }

    /// Lower-case name (file and log names).
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Base => "base",
            ModelKind::Upr => "upr",
            ModelKind::Ese => "ese",
            ModelKind::Dpp => "dpp",
            ModelKind::EpiShift => "epishift",
        }
    }
}

/// Which mode a unimodal target takes where a pixel has several.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum UnimodalTarget {
    /// The front-most mode whose η reaches `target_min_eta` — the closest surface the pixel
    /// visibly shows; the dominant mode where none does. A 1e-4 sliver of a thin foreground
    /// edge does not make the target jump to it.
    Visible,
    /// The front-most mode with any η > 0 (the literal reading; lftrain's earlier target).
    Front,
    /// The mode with the largest η (mmlf's `--train_loss_strongest`).
    Dominant,
}

/// Widths and depths of the EPINET-style network; defaults are appendix B.1 (Tables B.2, B.3).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NetConfig {
    /// Channels of each input-stream block (70).
    pub stream_width: usize,
    /// Blocks per input stream (3).
    pub stream_blocks: usize,
    /// Channels of the output-stream blocks (280 = 4 × 70 in the thesis).
    pub head_width: usize,
    /// Output-stream blocks at `head_width`, before the final block to the output channels (7).
    pub head_blocks: usize,
    /// What each of the four input streams reads (the thesis: the stack's views).
    pub input: NetInput,
    /// The network on cost volumes: this EPINET on the hypotheses as channels, or the shared
    /// per-hypothesis aggregation of [`crate::costnet`] (whose sizes are the next two).
    pub cost_network: CostNetwork,
    /// Channels of the per-hypothesis net's blocks.
    pub cost_width: usize,
    /// Blocks of the per-hypothesis net (its receptive radius is `cost_blocks + 1`).
    pub cost_blocks: usize,
    /// The cost of a perfect match: the variance added before the cost's logarithm
    /// ([`lfdata::cost::cost_stack`]; RGB variances summed). The default, 8-bit quantisation,
    /// lets clean rendered views match far more exactly than a camera's noise allows, and a
    /// net trained on such dips loses them under noise; a floor near a camera's `3σ²` makes
    /// clean and noisy matches look alike.
    pub cost_floor: f32,
}

/// The network that reads cost volumes ([`NetInput::Cost`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CostNetwork {
    /// The EPINET streams and head, the hypotheses as channels.
    Streams,
    /// [`crate::costnet::CostNet`]: one small net shared by every hypothesis.
    PerHypothesis,
}

/// The network's input per stack direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NetInput {
    /// The stack's views, `n × 3` planes (thesis appendix B.1).
    Views,
    /// The stack's plane-sweep cost volume: for every `[dpp]` bin centre `h`, the colour
    /// variance of the stack's views EPI-shifted by `h` ([`lfdata::cost::cost_stack`]). The network then
    /// scores the hypotheses (one logit each, and UPR's and ESE's `log b`) and BASE, UPR and
    /// ESE take their disparity as the softmax-weighted mean of the bin centres (a soft
    /// argmin, as GC-Net's), DPP the logits as its posterior. Not in the thesis: a CPU-budget
    /// net on the views learns sub-pixel matching too slowly to beat the classical baseline's
    /// BadPix, while here the matching is given and the net learns to aggregate it.
    Cost,
}

impl NetConfig {
    /// Pixels on each side of an output pixel that reach it: every block's two 2×2
    /// convolutions widen the field by one pixel per side, over the stream blocks, the head
    /// blocks and the final block (the thesis net: 3 + 7 + 1 = 11, a 23 px field).
    pub fn receptive_radius(&self) -> usize {
        match (self.input, self.cost_network) {
            (NetInput::Cost, CostNetwork::PerHypothesis) => self.cost_blocks + 1,
            _ => self.stream_blocks + self.head_blocks + 1,
        }
    }
}

impl Default for NetConfig {
    fn default() -> Self {
        Self {
            stream_width: 70,
            stream_blocks: 3,
            head_width: 280,
            head_blocks: 7,
            input: NetInput::Views,
            cost_network: CostNetwork::Streams,
            cost_width: 8,
            cost_blocks: 5,
            cost_floor: lfdata::cost::VARIANCE_FLOOR,
        }
    }
}

/// Data augmentation of the thesis (§5.3.1); each can be switched off.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AugmentConfig {
    /// Random EPI shift drawn uniformly from `[-max_shift, max_shift]` pixels (thesis: 2).
    /// EPI-Shift rounds it to an integer base shift (its shifts must stay integer).
    pub max_shift: f32,
    /// Random integer down-scaling by 1 ..= this factor, taking every k-th pixel (mmlf's
    /// `RandomDownSampling(4)`); the disparities shrink by k. 1: off.
    pub max_downscale: usize,
    /// Random rotation by multiples of 90° (square view grids only).
    pub rotate: bool,
    /// How colours are mixed (one random 3×3 matrix per sample).
    pub colour: ColourAugment,
    /// Brightness factor drawn from this range (mmlf: ×U[0.1, 1.9]; [1, 1]: off).
    pub brightness_scale: [f32; 2],
    /// Contrast factor about the sample's mean grey, drawn from this range (mmlf: U[0.1, 1.9]).
    pub contrast_scale: [f32; 2],
    /// lftrain's earlier, milder augmentation: a brightness offset in `[-brightness,
    /// brightness]` (0: off) ...
    pub brightness: f32,
    /// ... and a contrast factor in `[1 - contrast, 1 + contrast]` about mid-grey (0: off).
    pub contrast: f32,
    /// Sensor noise (not in the thesis): a σ per sample drawn from this range, in units of
    /// the `[0, 1]` pixel range (0.02 ≈ 5/255), added independently per view, pixel and
    /// channel after the colour augmentation. `[0, 0]`: off.
    pub noise: [f32; 2],
    /// The share of that noise's variance at mid-grey that is shot noise, growing with the
    /// value (variance `σ² · (1 − s + s · v / 0.5)` at value `v`); 0: the same everywhere.
    pub noise_shot: f32,
    /// Optical blur (not in the thesis): a Gaussian σ in pixels per sample, drawn from this
    /// range, the same for every view, applied before the noise. `[0, 0]`: off.
    pub blur: [f32; 2],
    /// Vignetting (not in the thesis): the share of light a scene's corners lose, per sample
    /// from this range, by the cos⁴ law in linear light centred on the scene (each crop gets
    /// its part of the falloff), the same in every view, before the noise. `[0, 0]`: off.
    pub vignetting: [f32; 2],
    /// JPEG compression (not in the thesis): the share of samples whose views are each
    /// compressed, after the noise, ...
    pub jpeg_share: f32,
    /// ... at a quality (1–100) drawn per sample from this range.
    pub jpeg_quality: [u8; 2],
}

/// The random colour matrix of a sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ColourAugment {
    /// A random mix whose rows and columns sum to 1 (mmlf's `RedistColor`): a random convex
    /// combination of the six channel permutations.
    Redistribute,
    /// A rotation about the grey axis (keeps grey levels; lftrain's earlier augmentation).
    Rotate,
    /// None.
    Off,
}

impl Default for AugmentConfig {
    fn default() -> Self {
        Self {
            max_shift: 2.0,
            max_downscale: 4,
            rotate: true,
            colour: ColourAugment::Redistribute,
            brightness_scale: [0.1, 1.9],
            contrast_scale: [0.1, 1.9],
            brightness: 0.0,
            contrast: 0.0,
            noise: [0.0, 0.0],
            noise_shot: 0.5,
            blur: [0.0, 0.0],
            vignetting: [0.0, 0.0],
            jpeg_share: 0.0,
            jpeg_quality: [30, 90],
        }
    }
}

/// The ESE's shift spacing and ensemble size (thesis §5.2.1, eq. 5.12).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EseConfig {
    /// Δd: the loss applies where `|d| < Δd/2`, inference shifts are `k Δd`.
    pub delta: f32,
    /// M: inference passes at `s_k = k Δd`, `k = -(M-1)/2 ..= (M-1)/2`.
    pub members: usize,
    /// Instead of `members`: passes at `lo, lo + step, …` below `hi` across this disparity
    /// range (mmlf: `arange(-3.5, 3.5, 0.1)`, 70 passes; a wide-baseline scene's whole range).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f32; 2]>,
    /// The spacing of those passes (left out: Δd).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f32>,
    /// Without `range`: the passes span each scene's `parameters.cfg` range (`disp_min`,
    /// `disp_max`) at `step` — the thesis recommends ESE for wide baselines, whose range a
    /// fixed ±3 does not reach. Scenes without a range keep `members`.
    #[serde(default)]
    pub scene_range: bool,
    /// What the training loss does with pixels outside `|d| < Δd/2` (see [`EseOutside`]).
    #[serde(default)]
    pub outside: EseOutside,
    /// With `outside = "uncertain"`: `log b` above this earns nothing more (mmlf: no cap, so
    /// out-of-range `log b` grows without end). 5 is b ≈ 148 px, past any range.
    #[serde(default = "default_max_log_b")]
    pub max_log_b: f32,
    /// The point estimate (the disparity map lfeval scores MSE and BadPix on).
    #[serde(default)]
    pub point: EsePoint,
}

/// Which disparity of the ESE mixture is its point estimate.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EsePoint {
    /// The centre of the pass with the highest peak `w / 2b` (mmlf: the pass with the least
    /// `b`): one over-confident pass decides the pixel.
    #[default]
    Peak,
    /// The mixture's own most likely mode: the pass centre where the mixture's density is
    /// highest (not in the thesis). Passes that agree on a disparity add up there, so a
    /// lone over-confident pass no longer wins; O(M²) per pixel.
    Mode,
}

fn default_max_log_b() -> f32 {
    5.0
}

/// The ESE loss outside the interval each pass is trained for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EseOutside {
    /// No loss there (thesis eq. 5.13).
    #[default]
    Ignore,
    /// mmlf's padding variant (`ImprovedUncertaintyL1Loss`): `−log b` there, so passes learn
    /// to be uncertain out of range; the inside and outside means are weighted 50/50.
    Uncertain,
    /// Plain UPR on every pixel (what the thesis author's README trains ESE as).
    Upr,
}

/// Most ESE inference passes (each is one network evaluation of the scene).
pub const MAX_ESE_PASSES: usize = 10_000;

impl EseConfig {
    /// The inference shifts of a scene whose `parameters.cfg` range is `scene`: `range` if
    /// set, else with `scene_range` the scene's range, else [`EseConfig::shifts`].
    pub fn scene_shifts(&self, scene: Option<[f32; 2]>) -> Vec<f32> {
        match (self.range, scene) {
            (None, Some(r)) if self.scene_range => EseConfig {
                range: Some(r),
                ..self.clone()
            }
            .shifts(),
            _ => self.shifts(),
        }
    }

    /// The inference shifts, in order.
    pub fn shifts(&self) -> Vec<f32> {
        match self.range {
            Some([lo, hi]) => {
                let step = self.step.unwrap_or(self.delta);
                (0..)
                    .map(|k| lo + k as f32 * step)
                    .take_while(|s| *s < hi - 1e-6 * step)
                    .take(MAX_ESE_PASSES + 1)
                    .collect()
            }
            None => {
                let half = (self.members / 2) as i32;
                (-half..=half).map(|k| k as f32 * self.delta).collect()
            }
        }
    }
}

impl Default for EseConfig {
    fn default() -> Self {
        Self {
            delta: 1.0,
            members: 7,
            range: None,
            step: None,
            scene_range: false,
            outside: EseOutside::Ignore,
            max_log_b: default_max_log_b(),
            point: EsePoint::Peak,
        }
    }
}

/// The DPP's disparity bins (thesis: 108 over [-3.5, 3.5]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DppConfig {
    /// Number of bins.
    pub bins: usize,
    /// Lower edge of the first bin, pixels.
    pub min: f32,
    /// Upper edge of the last bin, pixels.
    pub max: f32,
    /// The point estimate (the disparity map lfeval scores MSE and BadPix on). 0: the most
    /// probable bin's centre (the thesis, mmlf). `r > 0`: the `2r + 1` neighbouring bins with
    /// the most probability together, and the mean of their centres weighted by it — the
    /// most likely mode at a scale of `2r + 1` bins instead of one (not in the thesis). An
    /// under-trained net's posterior has single-bin spikes far from its main mass, and the
    /// most probable bin lands on one of them at many pixels.
    pub mode_window: usize,
}

impl DppConfig {
    /// The bins (validated by [`TrainConfig::validate`]).
    pub fn bins(&self) -> Bins {
        Bins::new(self.min as f64, self.max as f64, self.bins).expect("validated DPP bins")
    }
}

impl Default for DppConfig {
    fn default() -> Self {
        Self {
            bins: 108,
            min: -3.5,
            max: 3.5,
            mode_window: 0,
        }
    }
}

/// The classification ground truth `C_true^s` of EPI-Shift (thesis eq. 4.7, 4.8).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClassTarget {
    /// 1 where `|d − s| ≤ 0.5 + ε`, else 0 (eq. 4.7; the thesis' choice, Table 4.1).
    Rectangle,
    /// `max(0.5 + ε − |d − s|, 0)` (eq. 4.8).
    Triangle,
}

/// EPI-Shift (thesis §4.2): network shape, losses and inference shifts. The defaults are the
/// thesis' settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EpiShiftConfig {
    /// Channels of the siamese feature extractor (64).
    pub feature_width: usize,
    /// Blocks of the feature extractor, each two 3×3 convolutions with ReLU and BN (4).
    pub feature_blocks: usize,
    /// Channels of the U-Net's top level, to which the concatenated features are reduced (64).
    pub unet_width: usize,
    /// Down-sampling steps of the U-Net (5); every level doubles the channels. Training
    /// crops must be a multiple of `2^unet_depth`.
    pub unet_depth: usize,
    /// Integer shifts per training crop, centred on the crop's (integer) base shift (7).
    pub train_shifts: usize,
    /// Classification ground truth (eq. 4.7 or 4.8).
    pub class_target: ClassTarget,
    /// ε of the classification ground truth (0.17).
    pub epsilon: f32,
    /// ε of the rectangle that masks the regression loss (eq. 4.9): "slightly higher" than
    /// `epsilon`; the thesis gives no value.
    pub reg_epsilon: f32,
    /// α of `L = α L_reg + L_class` (eq. 4.10; 2.5).
    pub alpha: f32,
    /// Refinement (eq. 4.11): where no `C^s` reaches this, the shift is chosen on
    /// median-filtered classification maps (0.01; 0: off).
    pub refine_threshold: f32,
    /// Side of that median filter (odd; the thesis gives no size).
    pub median_window: usize,
    /// Coarse-to-fine inference (not in the thesis; 0: off): a scene whose largest |disparity|
    /// exceeds this many pixels is first solved on its views box-averaged by the smallest
    /// power of two that brings it within, and at full size each pixel then chooses only among
    /// the shifts within `coarse_radius` of that estimate. Why: at ±40 px an outer view moves
    /// 160 px and occlusion bands are tens of pixels wide, far from anything a narrow training
    /// set shows; scaled down, the scene looks like the training data again.
    pub coarse_max: f32,
    /// Shifts (pixels) around the scaled-up coarse estimate that the full-size pass may choose.
    pub coarse_radius: f32,
    /// Disparity range the inference shifts cover; left out: each scene's
    /// `parameters.cfg` range (`disp_min`, `disp_max`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<[f32; 2]>,
}

impl Default for EpiShiftConfig {
    fn default() -> Self {
        Self {
            feature_width: 64,
            feature_blocks: 4,
            unet_width: 64,
            unet_depth: 5,
            train_shifts: 7,
            class_target: ClassTarget::Rectangle,
            epsilon: 0.17,
            reg_epsilon: 0.25,
            alpha: 2.5,
            refine_threshold: 0.01,
            median_window: 5,
            coarse_max: 0.0,
            coarse_radius: 2.0,
            range: None,
        }
    }
}

/// Most inference shifts of one EPI-Shift scene (each is one network evaluation).
pub const MAX_SHIFTS: usize = 10_000;
/// Widest EPI-Shift layer or feature (the thesis: 64 at the top, 2048 at depth 5).
pub const MAX_EPISHIFT_WIDTH: usize = 4096;

impl EpiShiftConfig {
    /// The integer shifts covering disparities `[lo, hi]`: shift `s` serves `|d − s| ≤ 0.5`,
    /// so `round(lo) ..= round(hi)`.
    pub fn shifts_for(lo: f32, hi: f32) -> Vec<i32> {
        (lo.round() as i32..=hi.round() as i32).collect()
    }

    /// The down-scaling of coarse-to-fine inference for a scene spanning `[lo, hi]`: the
    /// smallest power of two `k` (at most 64) with `max(|lo|, |hi|) / k ≤ coarse_max`; 1 when
    /// that is already met or coarse-to-fine is off.
    pub fn coarse_scale(&self, [lo, hi]: [f32; 2]) -> usize {
        let reach = lo.abs().max(hi.abs());
        let mut k = 1;
        while self.coarse_max > 0.0 && reach / k as f32 > self.coarse_max && k < 64 {
            k *= 2;
        }
        k
    }

    /// The shifts of a training crop relative to its base shift: `-K ..= K`.
    pub fn train_offsets(&self) -> Vec<i32> {
        let k = (self.train_shifts / 2) as i32;
        (-k..=k).collect()
    }

    /// Pixels on each side of an output pixel that reach it through the feature extractor and
    /// the reduction (two 3×3 convolutions per block, one more): the EPI features are free of
    /// zero padding this far inside a crop. The U-Net then sees far wider (thesis: 135 px).
    pub fn feature_radius(&self) -> usize {
        2 * self.feature_blocks + 1
    }

    fn validate(&self, patch: usize) -> Result<()> {
        let widths = [self.feature_width, self.unet_width];
        if widths.iter().any(|&w| w == 0 || w > MAX_EPISHIFT_WIDTH) {
            bail!("epishift.feature_width and unet_width must be 1 to {MAX_EPISHIFT_WIDTH}");
        }
        if self.feature_blocks > 64 || self.unet_depth > 8 {
            bail!("epishift.feature_blocks must be at most 64 and unet_depth at most 8");
        }
        if self.unet_width << self.unet_depth > MAX_EPISHIFT_WIDTH {
            bail!(
                "epishift: unet_width {} doubled {} times is over {MAX_EPISHIFT_WIDTH} channels",
                self.unet_width,
                self.unet_depth
            );
        }
        if !patch.is_multiple_of(1 << self.unet_depth) {
            bail!(
                "patch {patch} must be a multiple of 2^unet_depth = {} (the U-Net halves it \
                 unet_depth times)",
                1 << self.unet_depth
            );
        }
        if self.train_shifts.is_multiple_of(2) || self.train_shifts > 63 {
            bail!("epishift.train_shifts must be odd and at most 63");
        }
        let eps_ok = |e: f32| (0.0..=1.5).contains(&e);
        if !(eps_ok(self.epsilon) && eps_ok(self.reg_epsilon)) {
            bail!("epishift.epsilon and reg_epsilon must lie in [0, 1.5]");
        }
        if !(self.alpha.is_finite() && self.alpha >= 0.0) {
            bail!("epishift.alpha must be finite and ≥ 0");
        }
        if !(0.0..=1.0).contains(&self.refine_threshold)
            || self.median_window.is_multiple_of(2)
            || self.median_window > 63
        {
            bail!("epishift.refine_threshold must lie in [0, 1], median_window be odd and ≤ 63");
        }
        let coarse_ok = self.coarse_max.is_finite() && self.coarse_max >= 0.0;
        if !(coarse_ok && self.coarse_radius.is_finite() && self.coarse_radius >= 0.5) {
            bail!("epishift.coarse_max must be finite and ≥ 0, coarse_radius finite and ≥ 0.5");
        }
        if let Some([lo, hi]) = self.range {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                bail!("epishift.range must be an increasing [min, max]");
            }
            if Self::shifts_for(lo, hi).len() > MAX_SHIFTS {
                bail!("epishift.range asks for over {MAX_SHIFTS} shifts");
            }
        }
        Ok(())
    }
}

/// Everything a run needs besides the dataset paths.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrainConfig {
    /// Which model.
    pub model: ModelKind,
    /// Train against all modes weighted by η instead of the front-most one.
    pub multimodal: bool,
    /// Side of the square training crops (thesis: 96).
    pub patch: usize,
    /// Crops per step (thesis: 512 on GPUs).
    pub batch: usize,
    /// Optimiser steps in total.
    pub steps: usize,
    /// Adam learning rate (thesis: 1e-3).
    pub learning_rate: f64,
    /// Steps after which the learning rate is multiplied by `lr_decay` (each one once; empty:
    /// constant, the thesis' posterior models). E.g. `[3000]` with `lr_decay = 0.01`: 1e-3 for
    /// steps 1..=3000, 1e-5 after (the 1e-4 → 1e-5 drop of thesis §4.2.5).
    pub lr_decay_steps: Vec<usize>,
    /// Factor applied at each of `lr_decay_steps`.
    pub lr_decay: f64,
    /// From this step on, batch norm is frozen: running statistics instead of batch
    /// statistics, neither they nor γ, β are trained any more (thesis §4.2.5 "fixed the learned
    /// BN parameters" with the learning-rate drop). Left out: never.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub freeze_bn_after: Option<usize>,
    /// Linear learning-rate warm-up from 0 over this many steps (mmlf: 1 000; 0: none).
    pub warmup_steps: usize,
    /// Adam's ε (mmlf, PyTorch's default: 1e-8; burn's own default is 1e-5).
    pub adam_epsilon: f64,
    /// Crops are taken at least this many pixels inside the image (mmlf: 8), so no input
    /// pixel near the crop edge is a clamped copy of the image border.
    pub crop_margin: usize,
    /// No loss within this many pixels of the crop edge, where zero padding reaches into the
    /// receptive field (mmlf: its receptive radius, 11). Left out: the network's
    /// [`NetConfig::receptive_radius`]; 0: every pixel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loss_border: Option<usize>,
    /// No loss where the centre view is flat: the mean over a `texture_window²` window of
    /// |neighbour − centre| (RGB mean) below this (mmlf: 0.02; 0: off).
    pub texture_threshold: f32,
    /// Side of that window (mmlf: 23, its receptive field).
    pub texture_window: usize,
    /// The mode a unimodal target takes (`multimodal = false`).
    pub target: UnimodalTarget,
    /// The η a mode needs to count as visible for `target = "visible"`.
    pub target_min_eta: f32,
    /// Modes kept per pixel for multimodal targets (the thesis' loader: 12).
    pub max_modes: usize,
    /// Validate every this many steps (0: only at the end).
    pub val_every: usize,
    /// Write a checkpoint every this many steps (0: only at the end).
    pub checkpoint_every: usize,
    /// Pixels left out at each side when validating (HCI: 15).
    pub val_border: usize,
    /// Batches prepared ahead of the optimiser.
    pub prefetch: usize,
    /// Seed of the data sampling and the weight initialisation.
    pub seed: u64,
    /// Network shape.
    pub net: NetConfig,
    /// Augmentations.
    pub augment: AugmentConfig,
    /// ESE settings.
    pub ese: EseConfig,
    /// DPP settings.
    pub dpp: DppConfig,
    /// EPI-Shift settings.
    pub epishift: EpiShiftConfig,
    /// Test-time rotations of BASE, UPR, ESE and DPP (not in the thesis): `lftrain predict`
    /// averages the network's output planes over the light field turned by the first this
    /// many quarter turns (1: off; 4: all), each turned back. A net trained with
    /// `augment.rotate` has seen every turn, so each is an equally good estimate whose
    /// errors are partly independent. `lftrain predict --rotations` overrides it.
    pub test_rotations: usize,
    /// Test-time denoising (not in the thesis; `lfdata::denoise`): `lftrain predict` predicts
    /// once, averages each view with its 3 × 3 angular neighbours warped by that prediction
    /// (each weighted by its agreement, within this many times the noise the views show between
    /// them), and predicts again. Views without noise between them pass unchanged, so clean
    /// scenes cost only the second pass. 0: off. `lftrain predict --denoise` overrides it.
    pub test_denoise: f32,
}

impl Default for TrainConfig {
    fn default() -> Self {
        Self {
            model: ModelKind::Base,
            multimodal: false,
            patch: 96,
            batch: 16,
            steps: 10_000,
            learning_rate: 1e-3,
            lr_decay_steps: Vec::new(),
            lr_decay: 0.1,
            freeze_bn_after: None,
            warmup_steps: 1000,
            adam_epsilon: 1e-8,
            crop_margin: 8,
            loss_border: None,
            texture_threshold: 0.02,
            texture_window: 23,
            target: UnimodalTarget::Visible,
            target_min_eta: 0.1,
            max_modes: 12,
            val_every: 500,
            checkpoint_every: 500,
            val_border: 15,
            prefetch: 4,
            seed: 0,
            net: NetConfig::default(),
            augment: AugmentConfig::default(),
            ese: EseConfig::default(),
            dpp: DppConfig::default(),
            epishift: EpiShiftConfig::default(),
            test_rotations: 1,
            test_denoise: 0.0,
        }
    }
}

/// Largest training crop side (scenes themselves are at most 16384²).
pub const MAX_PATCH: usize = 4096;
/// Most modes a target keeps (lfgen writes at most a few dozen).
pub const MAX_MODES: usize = 1024;
/// Most pixels in one batch: 3.5× the thesis' 512 × 96², about 7 GB of inputs with 9 × 4 views
/// — a typo such as `batch = 1e9` is refused before it allocates.
pub const MAX_BATCH_PIXELS: usize = 1 << 24;

impl TrainConfig {
    /// Reads a TOML file; missing fields keep their defaults, unknown ones are errors.
    pub fn read(path: &Path) -> Result<Self> {
        let text = lfformat::read::text(path)?;
        let cfg: Self =
            toml::from_str(&text).with_context(|| format!("{}: invalid config", path.display()))?;
        cfg.validate()
            .with_context(|| format!("{}: invalid config", path.display()))?;
        Ok(cfg)
    }

    /// Writes the config as TOML.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = toml::to_string_pretty(self).context("cannot serialise config")?;
        std::fs::write(path, text).with_context(|| format!("{}: cannot write", path.display()))
    }

    /// Rejects settings that would fail later with an obscure tensor error.
    pub fn validate(&self) -> Result<()> {
        if self.patch < 2 || self.batch == 0 || self.max_modes == 0 {
            bail!("patch must be ≥ 2, batch and max_modes ≥ 1");
        }
        if self.patch > MAX_PATCH || self.max_modes > MAX_MODES {
            bail!(
                "patch must be at most {MAX_PATCH} and max_modes at most {MAX_MODES}, got {} and {}",
                self.patch,
                self.max_modes
            );
        }
        if self.batch.saturating_mul(self.patch * self.patch) > MAX_BATCH_PIXELS {
            bail!(
                "batch × patch² = {} × {}² is over {MAX_BATCH_PIXELS} pixels per batch \
                 (the thesis' 512 × 96² is 4.7 M): lower batch or patch",
                self.batch,
                self.patch
            );
        }
        if self.net.stream_width == 0 || self.net.head_width == 0 {
            bail!("network widths must be ≥ 1");
        }
        if self.dpp.bins < 2 || self.dpp.max <= self.dpp.min {
            bail!("dpp needs ≥ 2 bins over a non-empty range");
        }
        if self.net.cost_width == 0 || self.net.cost_blocks == 0 {
            bail!("net.cost_width and net.cost_blocks must be ≥ 1");
        }
        if !(self.net.cost_floor > 0.0 && self.net.cost_floor.is_finite()) {
            bail!("net.cost_floor must be a finite variance > 0");
        }
        if self.net.input == NetInput::Cost && self.model == ModelKind::EpiShift {
            bail!("net.input = \"cost\" is for BASE, UPR, ESE and DPP; EPI-Shift reads views");
        }
        if 2 * self.dpp.mode_window >= self.dpp.bins {
            bail!(
                "dpp.mode_window {} spans more than the {} bins",
                self.dpp.mode_window,
                self.dpp.bins
            );
        }
        if !(1..=4).contains(&self.test_rotations) {
            bail!(
                "test_rotations must be 1 to 4 quarter turns, got {}",
                self.test_rotations
            );
        }
        if self.model == ModelKind::EpiShift && self.test_rotations != 1 {
            bail!("test_rotations applies to base, upr, ese and dpp; epishift takes 1");
        }
        if !(self.test_denoise >= 0.0 && self.test_denoise.is_finite()) {
            bail!(
                "test_denoise must be 0 (off) or a finite width in units of the noise, got {}",
                self.test_denoise
            );
        }
        if self.ese.members == 0 || self.ese.members.is_multiple_of(2) || self.ese.delta <= 0.0 {
            bail!("ese.members must be odd and ese.delta positive");
        }
        if !(self.ese.max_log_b.is_finite() && self.ese.max_log_b > 0.0) {
            bail!("ese.max_log_b must be finite and positive");
        }
        if let Some([lo, hi]) = self.ese.range {
            let step = self.ese.step.unwrap_or(self.ese.delta);
            if !(lo.is_finite() && hi.is_finite() && lo < hi && step > 0.0) {
                bail!("ese.range must be an increasing [min, max] and ese.step positive");
            }
            if self.ese.shifts().len() > MAX_ESE_PASSES {
                bail!("ese.range / ese.step asks for over {MAX_ESE_PASSES} passes");
            }
        }
        if !(self.learning_rate > 0.0 && self.lr_decay > 0.0) {
            bail!("learning_rate and lr_decay must be positive");
        }
        if !(self.adam_epsilon > 0.0 && self.adam_epsilon < 1.0) {
            bail!("adam_epsilon must lie in (0, 1), got {}", self.adam_epsilon);
        }
        if 2 * self.loss_border() >= self.patch {
            bail!(
                "loss_border {} leaves nothing of a {} px patch to train on",
                self.loss_border(),
                self.patch
            );
        }
        if !(self.target_min_eta > 0.0 && self.target_min_eta <= 1.0) {
            bail!(
                "target_min_eta must lie in (0, 1], got {}",
                self.target_min_eta
            );
        }
        let a = &self.augment;
        if !(1..=16).contains(&a.max_downscale) {
            bail!(
                "augment.max_downscale must be 1 to 16, got {}",
                a.max_downscale
            );
        }
        if [a.brightness_scale, a.contrast_scale]
            .iter()
            .any(|[lo, hi]| !(lo.is_finite() && hi.is_finite() && 0.0 <= *lo && lo <= hi))
        {
            bail!(
                "augment.brightness_scale and contrast_scale must be [min, max] ranges of factors ≥ 0"
            );
        }
        if [a.noise, a.blur]
            .iter()
            .any(|[lo, hi]| !(lo.is_finite() && hi.is_finite() && 0.0 <= *lo && lo <= hi))
            || !(a.noise[1] <= 1.0 && a.blur[1] <= 16.0 && (0.0..=1.0).contains(&a.noise_shot))
        {
            bail!(
                "augment.noise must be a [min, max] range within [0, 1], augment.blur one \
                 within [0, 16] px, and augment.noise_shot lie in [0, 1]"
            );
        }
        let [v_lo, v_hi] = a.vignetting;
        if !(0.0 <= v_lo && v_lo <= v_hi && v_hi < 1.0) {
            bail!("augment.vignetting must be a [min, max] range of shares within [0, 1)");
        }
        let [q_lo, q_hi] = a.jpeg_quality;
        if !((0.0..=1.0).contains(&a.jpeg_share) && 1 <= q_lo && q_lo <= q_hi && q_hi <= 100) {
            bail!(
                "augment.jpeg_share must lie in [0, 1] and augment.jpeg_quality be a \
                 [min, max] range of qualities within [1, 100]"
            );
        }
        if !(0.0..1.0).contains(&self.texture_threshold) || self.texture_window.is_multiple_of(2) {
            bail!("texture_threshold must lie in [0, 1) and texture_window be odd");
        }
        if self.model == ModelKind::EpiShift {
            if self.multimodal {
                bail!("epishift trains on one disparity per pixel: set multimodal = false");
            }
            self.epishift.validate(self.patch)?;
        }
        Ok(())
    }

    /// The learning rate of the optimiser step that follows `done` finished steps (steps are
    /// counted from 1: with `lr_decay_steps = [s]`, steps 1..=s use `learning_rate`), ramped
    /// up linearly over the first `warmup_steps` (step k of the warm-up uses k / warmup_steps
    /// of it, as mmlf's schedule).
    pub fn learning_rate_after(&self, done: usize) -> f64 {
        let ramp = match self.warmup_steps {
            0 => 1.0,
            w => ((done + 1) as f64 / w as f64).min(1.0),
        };
        self.decayed_rate_after(done) * ramp
    }

    /// The learning rate after the step decay alone (what the log reports when it changes).
    pub fn decayed_rate_after(&self, done: usize) -> f64 {
        let drops = self.lr_decay_steps.iter().filter(|&&s| done >= s).count();
        self.learning_rate * self.lr_decay.powi(drops as i32)
    }

    /// Pixels at each crop edge that get no loss.
    pub fn loss_border(&self) -> usize {
        self.loss_border.unwrap_or_else(|| match self.model {
            ModelKind::EpiShift => self.epishift.feature_radius(),
            _ => self.net.receptive_radius(),
        })
    }

    /// Whether batch norm is frozen for the step that follows `done` finished steps.
    pub fn bn_frozen_after(&self, done: usize) -> bool {
        self.freeze_bn_after.is_some_and(|s| done >= s)
    }

    /// Modes per pixel in the targets: all (up to `max_modes`) or only the front-most.
    pub fn target_modes(&self) -> usize {
        if self.multimodal { self.max_modes } else { 1 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_the_thesis_constant_rate_after_warm_up_without_freezing() {
        let cfg = TrainConfig::default();
        // Linear warm-up over 1 000 steps: step 1 at 1e-6, step 500 at 5e-4, step 1 000 on.
        assert!((cfg.learning_rate_after(0) - 1e-6).abs() < 1e-15);
        assert!((cfg.learning_rate_after(499) - 5e-4).abs() < 1e-15);
        for done in [999, 1_000, 5_000, 1_000_000] {
            assert_eq!(cfg.learning_rate_after(done), 1e-3);
        }
        for done in [0, 1, 5_000, 1_000_000] {
            assert!(!cfg.bn_frozen_after(done));
        }
        assert_eq!(cfg.adam_epsilon, 1e-8);
        // The thesis net's receptive radius is mmlf's 11 px; the CPU recipe's 6 px.
        assert_eq!(cfg.loss_border(), 11);
        let small = NetConfig {
            stream_blocks: 2,
            head_blocks: 3,
            ..NetConfig::default()
        };
        assert_eq!(small.receptive_radius(), 6);
        let text = toml::to_string_pretty(&cfg).unwrap();
        assert!(!text.contains("freeze_bn_after"));
        let back: TrainConfig = toml::from_str(&text).unwrap();
        assert_eq!(back, cfg);
    }

    #[test]
    fn step_decay_and_freezing_from_toml() {
        let cfg: TrainConfig = toml::from_str(
            "learning_rate = 1e-3\nlr_decay_steps = [100, 300]\nlr_decay = 0.1\nfreeze_bn_after = 100\nwarmup_steps = 0\n",
        )
        .unwrap();
        cfg.validate().unwrap();
        let lr = |d| cfg.learning_rate_after(d);
        assert_eq!(lr(0), 1e-3);
        assert_eq!(lr(99), 1e-3);
        assert!((lr(100) - 1e-4).abs() < 1e-12);
        assert!((lr(299) - 1e-4).abs() < 1e-12);
        assert!((lr(300) - 1e-5).abs() < 1e-13);
        assert!(!cfg.bn_frozen_after(99));
        assert!(cfg.bn_frozen_after(100));
        let back: TrainConfig = toml::from_str(&toml::to_string_pretty(&cfg).unwrap()).unwrap();
        assert_eq!(back, cfg);
        let bad: TrainConfig = toml::from_str("lr_decay = 0.0").unwrap();
        assert!(bad.validate().is_err());
    }

    #[test]
    fn the_shipped_cpu_recipe_parses_and_keeps_its_measured_settings() {
        let cfg: TrainConfig = toml::from_str(include_str!("../configs/cpu_small.toml")).unwrap();
        cfg.validate().unwrap();
        assert_eq!(
            (cfg.warmup_steps, cfg.loss_border(), cfg.crop_margin),
            (0, 0, 0)
        );
        assert_eq!(cfg.texture_threshold, 0.0);
        assert_eq!(cfg.target, UnimodalTarget::Front);
        assert_eq!(cfg.augment.max_downscale, 1);
    }

    /// The field recipe differs from cpu_small only in depth, in the thesis' warm-up and Adam
    /// epsilon (the deeper net stalled without them) and in DPP's point estimate (a 5-bin
    /// mode), and its field reaches a point at 3.5 px in the outer views of a 9×9 grid (4
    /// steps × 3.5 px = 14 px).
    #[test]
    fn the_field_recipe_reaches_the_outer_views() {
        let small: TrainConfig = toml::from_str(include_str!("../configs/cpu_small.toml")).unwrap();
        let field: TrainConfig = toml::from_str(include_str!("../configs/cpu_field.toml")).unwrap();
        field.validate().unwrap();
        assert!(small.net.receptive_radius() < 14);
        assert_eq!(field.net.receptive_radius(), 14);
        let deeper = NetConfig {
            stream_blocks: 4,
            head_blocks: 9,
            ..small.net
        };
        assert_eq!(
            field,
            TrainConfig {
                net: deeper,
                warmup_steps: 1000,
                adam_epsilon: 1e-8,
                dpp: DppConfig {
                    mode_window: 2,
                    ..small.dpp.clone()
                },
                ..small
            }
        );
    }

    /// The cost recipe: the per-hypothesis net on 60 hypotheses over ±4.5 px, radius 4 px
    /// (the baseline's 9×9 window), no EPI shift (the targets must stay inside the
    /// hypotheses), sensor-noise augmentation and test-time denoising, the field recipe's
    /// schedule scaled to 1 000 steps.
    #[test]
    fn the_cost_recipe_reads_cost_volumes_and_refuses_epishift() {
        let cost: TrainConfig = toml::from_str(include_str!("../configs/cpu_cost.toml")).unwrap();
        cost.validate().unwrap();
        assert_eq!(cost.net.input, NetInput::Cost);
        assert_eq!(cost.net.cost_network, CostNetwork::PerHypothesis);
        assert_eq!((cost.dpp.bins, cost.dpp.min, cost.dpp.max), (60, -4.5, 4.5));
        assert_eq!(cost.augment.max_shift, 0.0);
        assert_eq!(
            cost.augment.noise,
            [0.0, 0.03],
            "chosen by the robustness benchmark"
        );
        assert_eq!(cost.test_denoise, 2.0, "chosen by the robustness benchmark");
        assert_eq!(cost.net.receptive_radius(), 4);
        assert_eq!(
            (
                cost.steps,
                cost.warmup_steps,
                cost.lr_decay_steps.as_slice()
            ),
            (1000, 250, &[750][..])
        );
        assert_eq!(TrainConfig::default().net.input, NetInput::Views);
        // One logit per hypothesis, and log b for UPR and ESE.
        let channels = |m: ModelKind| m.net_channels(NetInput::Cost, 60);
        assert_eq!(channels(ModelKind::Base), 60);
        assert_eq!(channels(ModelKind::Upr), 61);
        assert_eq!(channels(ModelKind::Ese), 61);
        assert_eq!(channels(ModelKind::Dpp), 60);
        assert_eq!(ModelKind::Upr.net_channels(NetInput::Views, 48), 2);
        let shift = TrainConfig {
            model: ModelKind::EpiShift,
            ..cost
        };
        let err = shift.validate().unwrap_err().to_string();
        assert!(err.contains("net.input"), "{err}");
    }

    /// ESE's cost recipe is the cost recipe with ESE's own keys only: the EPI-shift
    /// augmentation its passes need, `log b` kept high outside the interval, passes over
    /// each scene's range.
    #[test]
    fn the_ese_cost_recipe_differs_from_the_cost_recipe_in_ese_keys_only() {
        let read = |text| -> TrainConfig { toml::from_str(text).unwrap() };
        let cost = read(include_str!("../configs/cpu_cost.toml"));
        let ese = read(include_str!("../configs/cpu_cost_ese.toml"));
        ese.validate().unwrap();
        assert_eq!(ese.model, ModelKind::Ese);
        assert_eq!(ese.augment.max_shift, 3.0);
        assert_eq!(ese.ese.outside, EseOutside::Uncertain);
        assert!(ese.ese.scene_range);
        let mut back = ese.clone();
        back.model = cost.model;
        back.augment.max_shift = cost.augment.max_shift;
        back.ese = cost.ese.clone();
        assert_eq!(back, cost);
    }

    /// The GPU check's config is the thesis' recipe (the defaults) at batch 64 for 200 steps:
    /// only the batch and the run's bookkeeping differ, so its timings are the thesis net's.
    #[test]
    fn the_gpu_check_config_is_the_thesis_recipe_at_batch_64() {
        let gpu: TrainConfig = toml::from_str(include_str!("../configs/gpu_thesis.toml")).unwrap();
        gpu.validate().unwrap();
        assert_eq!(
            gpu,
            TrainConfig {
                batch: 64,
                steps: 200,
                checkpoint_every: 100,
                val_every: 1000,
                ..TrainConfig::default()
            }
        );
        assert!(gpu.batch * gpu.patch * gpu.patch <= MAX_BATCH_PIXELS);
    }

    #[test]
    fn ese_passes_are_symmetric_by_default_or_span_a_range() {
        let ese = EseConfig::default();
        assert_eq!(ese.shifts(), vec![-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0]);
        // mmlf's inference: arange(-3.5, 3.5, 0.1), 70 passes from -3.5 to 3.4.
        let mmlf = EseConfig {
            range: Some([-3.5, 3.5]),
            step: Some(0.1),
            ..EseConfig::default()
        };
        let s = mmlf.shifts();
        assert_eq!(s.len(), 70);
        assert_eq!(s[0], -3.5);
        assert!((s[69] - 3.4).abs() < 1e-4, "{}", s[69]);
        // A wide-baseline range at Δd = 1: -40, -39, …, 39.
        let wide = EseConfig {
            range: Some([-40.0, 40.0]),
            ..EseConfig::default()
        };
        assert_eq!(wide.shifts().len(), 80);
        let mut cfg = TrainConfig::default();
        cfg.ese.range = Some([-1e6, 1e6]);
        assert!(cfg.validate().unwrap_err().to_string().contains("passes"));
    }

    #[test]
    fn ese_passes_can_span_each_scenes_range() {
        let wide = Some([-40.1, 40.1]);
        let ese = EseConfig::default();
        assert_eq!(ese.scene_shifts(wide).len(), 7, "off by default");
        let on = EseConfig {
            scene_range: true,
            ..ese
        };
        let s = on.scene_shifts(wide);
        assert_eq!((s.len(), s[0]), (81, -40.1));
        assert!((s[80] - 39.9).abs() < 1e-3, "{}", s[80]);
        assert_eq!(on.scene_shifts(None).len(), 7);
        let fixed = EseConfig {
            range: Some([-1.0, 1.0]),
            ..on
        };
        assert_eq!(fixed.scene_shifts(wide), vec![-1.0, 0.0]);
    }

    #[test]
    fn epishift_defaults_are_the_thesis_and_the_cpu_recipe_parses() {
        let cfg = TrainConfig {
            model: ModelKind::EpiShift,
            ..TrainConfig::default()
        };
        cfg.validate().unwrap();
        let e = &cfg.epishift;
        assert_eq!(
            (
                e.feature_width,
                e.feature_blocks,
                e.unet_width,
                e.unet_depth
            ),
            (64, 4, 64, 5)
        );
        assert_eq!(
            (e.epsilon, e.alpha, e.class_target),
            (0.17, 2.5, ClassTarget::Rectangle)
        );
        assert_eq!(e.train_offsets(), vec![-3, -2, -1, 0, 1, 2, 3]);
        assert_eq!(cfg.loss_border(), 9);
        let recipe: TrainConfig =
            toml::from_str(include_str!("../configs/epishift_cpu.toml")).unwrap();
        recipe.validate().unwrap();
        assert_eq!(recipe.model, ModelKind::EpiShift);
        let bad = |f: fn(&mut TrainConfig)| {
            let mut c = cfg.clone();
            f(&mut c);
            c.validate().unwrap_err().to_string()
        };
        assert!(bad(|c| c.patch = 100).contains("2^unet_depth"));
        assert!(bad(|c| c.multimodal = true).contains("multimodal"));
        assert!(bad(|c| c.epishift.train_shifts = 4).contains("odd"));
        assert!(bad(|c| c.epishift.range = Some([-1e6, 1e6])).contains("shifts"));
        assert!(bad(|c| c.epishift.unet_depth = 8).contains("channels"));
    }

    #[test]
    fn huge_batches_and_patches_are_refused_before_they_allocate() {
        assert!(with("batch = 512\npatch = 96").is_ok());
        refused("batch = 1000000000", "batch");
        refused("patch = 100000", "patch");
        refused("batch = 2048\npatch = 96", "pixels");
    }

    /// The validation error of the config `text` (TOML), if any.
    fn with(text: &str) -> Result<(), String> {
        let cfg: TrainConfig = toml::from_str(text).unwrap();
        cfg.validate().map_err(|e| e.to_string())
    }

    /// The config `text` is refused with an error that contains `needle`.
    fn refused(text: &str, needle: &str) {
        let err = with(text).unwrap_err();
        assert!(err.contains(needle), "{text:?}: {err}");
    }

    #[test]
    fn test_rotations_are_one_to_four_turns_and_not_for_epishift() {
        assert_eq!(TrainConfig::default().test_rotations, 1);
        assert!(with("test_rotations = 4\nmodel = \"dpp\"").is_ok());
        refused("test_rotations = 0", "test_rotations");
        refused("test_rotations = 5", "1 to 4");
        let epishift = "model = \"epishift\"\npatch = 64\ntest_rotations = 4";
        refused(epishift, "epishift takes 1");
    }

    #[test]
    fn test_denoise_is_off_or_a_finite_width() {
        assert_eq!(TrainConfig::default().test_denoise, 0.0);
        assert!(with("test_denoise = 2.0").is_ok());
        refused("test_denoise = -1.0", "test_denoise");
        refused("test_denoise = inf", "test_denoise");
    }

    #[test]
    fn the_dpp_mode_window_must_fit_in_the_bins() {
        assert_eq!(TrainConfig::default().dpp.mode_window, 0);
        assert!(with("[dpp]\nmode_window = 53").is_ok());
        refused("[dpp]\nmode_window = 54", "mode_window");
    }
}
