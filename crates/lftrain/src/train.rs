//! The training loop: batches from the [`Loader`], Adam steps, progress, logging, validation
//! and checkpoints.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use burn::optim::{AdamConfig, GradientsParams, ModuleOptimizer};
use burn::prelude::*;
use indicatif::{ProgressBar, ProgressStyle};
use lfformat::dataset::discover;

use crate::config::{ModelKind, TrainConfig};
use crate::input::StackInput;
use crate::loader::{Loader, PoolConfig, TrainBatch};
use crate::log::{Record, TrainLog};
use crate::loss::loss;
use crate::model::{Network, StackNet, decode};
use crate::run::{CONFIG_FILE, RunDir, RunState, build_net, grid_of, seeded};
use crate::sample::Batch;
use crate::shift_loss::{ShiftTargets, epishift_loss};
use crate::shift_sample::ShiftBatch;
use crate::tensors::{shift_input, stack_tensors, target_tensors};
use crate::validate::{ValScene, ValScores, load_scenes, validate};

/// What `lftrain train` was asked to do.
#[derive(Clone, Debug)]
pub struct TrainArgs {
    /// Training dataset (any layout lfeval accepts).
    pub train: PathBuf,
    /// Validation dataset.
    pub val: Option<PathBuf>,
    /// Run folder.
    pub out: PathBuf,
    /// Continue from the run's checkpoint.
    pub resume: bool,
    /// No progress bar.
    pub quiet: bool,
    /// Loader pool.
    pub pool: PoolConfig,
    /// Total steps, overriding the config (also on `--resume`, to extend a finished run).
    pub steps: Option<usize>,
}

impl TrainArgs {
    /// A fresh run without a progress bar, for the config's steps (tests and scripts).
    pub fn quiet(train: &Path, val: Option<&Path>, out: &Path, pool: PoolConfig) -> Self {
        Self {
            train: train.to_path_buf(),
            val: val.map(Path::to_path_buf),
            out: out.to_path_buf(),
            resume: false,
            quiet: true,
            pool,
            steps: None,
        }
    }
}

/// The result of a run.
#[derive(Clone, Debug)]
pub struct TrainSummary {
    /// Every logged step.
    pub records: Vec<Record>,
    /// The last validation.
    pub last_val: Option<ValScores>,
    /// Mean seconds per optimiser step over this invocation.
    pub seconds_per_step: f64,
}

/// The device training runs on: the first enabled backend (wgpu when built with the `wgpu`
/// feature and a GPU is present, else the flex CPU backend).
pub fn default_device() -> Device {
    Device::default()
}

/// Trains `cfg` (ignored on `--resume`, where the run's stored config is used; only
/// `args.steps` applies then).
pub fn train(mut cfg: TrainConfig, args: &TrainArgs) -> Result<TrainSummary> {
    // The datasets are found and read before the run folder is made, so a wrong path leaves
    // nothing behind.
    let train_scenes = discover(&args.train, &[])?;
    let grid = grid_of(&train_scenes)?;
    let val = match &args.val {
        Some(v) => load_scenes(&discover(v, &[])?)?,
        None => Vec::new(),
    };
    let run = RunDir::new(&args.out);
    let (cfg, state) = if args.resume {
        let mut stored = run.config()?;
        if let Some(s) = args.steps {
            stored.steps = s;
            stored.write(&args.out.join(CONFIG_FILE))?;
        }
        (stored, run.state()?)
    } else {
        if let Some(s) = args.steps {
            cfg.steps = s;
        }
        if run.has_checkpoint() {
            bail!(
                "{}: already holds a run; use --resume or another folder",
                args.out.display()
            );
        }
        cfg.validate()?;
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("{}: cannot create", args.out.display()))?;
        cfg.write(&args.out.join(CONFIG_FILE))?;
        (cfg, RunState::default())
    };
    let base = default_device();
    if !args.quiet {
        // Names the backend: a wgpu build runs where BURN_DEVICE (or the first adapter) says.
        lfformat::note!("lftrain: training on {base:?}");
    }
    let device = base.clone().autodiff();
    let (net, optim) = if args.resume {
        let net = run.load_net(&cfg, grid, &device)?;
        (net, run.load_optimizer(adam(&cfg))?)
    } else {
        let net = seeded(&base, cfg.seed, || build_net(&cfg, grid, &device));
        (net, adam(&cfg))
    };
    let loader = Loader::start(train_scenes, cfg.clone(), args.pool, state.step as u64)?;
    let mut log = TrainLog::open(&args.out, args.resume, state.step)?;
    let mut trainer = Trainer {
        input: StackInput::of(&cfg),
        cfg,
        net,
        optim,
        device,
        base,
        state: RunState { grid, ..state },
        bn_frozen: false,
    };
    trainer.run(&loader, &val, &mut log, &run, args.quiet)
}

/// The mutable state of a training run.
struct Trainer {
    cfg: TrainConfig,
    /// `cfg`'s input, resolved once (its hypotheses) instead of every step.
    input: StackInput,
    net: Network,
    optim: ModuleOptimizer,
    device: Device,
    base: Device,
    state: RunState,
    /// Whether `net`'s batch norms have been frozen (`freeze_bn_after`).
    bn_frozen: bool,
}

impl Trainer {
    /// Steps until `cfg.steps`.
    fn run(
        &mut self,
        loader: &Loader,
        val: &[ValScene],
        log: &mut TrainLog,
        run: &RunDir,
        quiet: bool,
    ) -> Result<TrainSummary> {
        let bar = progress(self.cfg.steps, self.state.step, quiet);
        let start = Instant::now();
        let (first, mut last_val) = (self.state.step, None);
        while self.state.step < self.cfg.steps {
            let done = self.state.step;
            let lr = self.cfg.decayed_rate_after(done);
            if done > 0 && lr != self.cfg.decayed_rate_after(done - 1) {
                bar.println(format!("step {}: learning rate {lr:e}", done + 1));
            }
            // Also on the first step after --resume past the freeze: the checkpoint holds the
            // trained values, not the frozen state.
            if self.cfg.bn_frozen_after(done) && !self.bn_frozen {
                self.net = self.net.clone().freeze_batch_norm();
                self.bn_frozen = true;
                bar.println(format!("step {}: batch norm frozen", done + 1));
            }
            let t0 = Instant::now();
            let batch = loader.next_batch()?;
            let loss = self.step(&batch)?;
            self.state.step += 1;
            let dt = t0.elapsed().as_secs_f64();
            self.state.elapsed_s += dt;
            let step = self.state.step;
            let mut record = Record {
                step,
                loss,
                samples_per_s: batch.size() as f64 / dt,
                elapsed_s: self.state.elapsed_s,
                ..Record::default()
            };
            let end = step == self.cfg.steps;
            if !val.is_empty() && (end || every(step, self.cfg.val_every)) {
                let v = validate(&self.cfg, &self.net.valid(), val, &self.base);
                record = record.with_val(v);
                last_val = Some(v);
                bar.println(format!(
                    "step {step}: validation MSE×100 {} BadPix(0.07) {} KLD {}",
                    fmt(v.mse_x100),
                    fmt(v.badpix_007),
                    fmt(v.kld)
                ));
            }
            bar.set_message(format!(
                "loss {loss:.4}  {:.1} samples/s",
                record.samples_per_s
            ));
            bar.inc(1);
            log.push(record)?;
            if end || every(step, self.cfg.checkpoint_every) {
                run.save(&self.net, &self.optim, &self.state)?;
                log.flush()?;
            }
        }
        bar.finish();
        let steps = (self.state.step - first).max(1);
        Ok(TrainSummary {
            records: log.records.clone(),
            last_val,
            seconds_per_step: start.elapsed().as_secs_f64() / steps as f64,
        })
    }

    /// The loss of `batch` (scalar tensor with its graph).
    fn loss(&self, batch: &TrainBatch) -> Result<Tensor<1>> {
        Ok(match (&self.net, batch) {
            (Network::Epi(net), TrainBatch::Stacks(b)) => self.stacks_loss(net, b),
            (Network::Cost(net), TrainBatch::Stacks(b)) => self.stacks_loss(net, b),
            (Network::Shift(net), TrainBatch::Shifts(b)) => {
                let (class, reg) = net.forward(shift_input(b, &self.device));
                let offsets = self.cfg.epishift.train_offsets();
                let targets = ShiftTargets::of(b, &offsets, &self.device);
                epishift_loss(&self.cfg.epishift, class, reg, &targets)
            }
            _ => bail!("internal error: the batch does not fit the network"),
        })
    }

    /// The loss of a network on the four stacks.
    fn stacks_loss(&self, net: &impl StackNet, b: &Batch) -> Tensor<1> {
        let raw = net.forward(stack_tensors(b, &self.device));
        let out = decode(raw, self.cfg.model, &self.input);
        loss(&self.cfg, out, &target_tensors(b, &self.cfg, &self.device))
    }

    /// One Adam step on `batch`; returns its loss.
    fn step(&mut self, batch: &TrainBatch) -> Result<f64> {
        let loss = self.loss(batch)?;
        let value = loss.clone().into_scalar::<f32>() as f64;
        if !value.is_finite() {
            bail!("step {}: the loss is {value}", self.state.step + 1);
        }
        let grads = GradientsParams::from_grads(loss.backward(), &self.net);
        let net = self.net.clone();
        self.net = self
            .optim
            .step(self.cfg.learning_rate_after(self.state.step), net, grads);
        Ok(value)
    }
}

/// Adam with `cfg`'s ε.
fn adam(cfg: &TrainConfig) -> ModuleOptimizer {
    AdamConfig::new()
        .with_epsilon(cfg.adam_epsilon as f32)
        .init()
}

/// Whether `step` is a multiple of a non-zero `period`.
fn every(step: usize, period: usize) -> bool {
    period > 0 && step.is_multiple_of(period)
}

fn fmt(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| format!("{v:.3}"))
}

/// The progress bar (hidden with `quiet` or when stderr is not a terminal).
fn progress(total: usize, done: usize, quiet: bool) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(total as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} steps  {msg}  [{elapsed} < {eta}]")
            .expect("valid template"),
    );
    bar.set_position(done as u64);
    bar
}

/// Mean seconds per optimiser step of `cfg`'s network on random `grid × grid` input (no data
/// loading), after one warm-up step, and the network's parameter count: what `lftrain bench`
/// reports.
pub fn bench_steps(cfg: &TrainConfig, grid: usize, steps: usize) -> Result<(f64, usize)> {
    let base = default_device();
    let device = base.clone().autodiff();
    let (p, b, modes) = (cfg.patch, cfg.batch, cfg.target_modes());
    let noise = |len: usize, scale: f32| -> Vec<f32> {
        (0..len)
            .map(|i| ((i.wrapping_mul(2_654_435_761) % 1000) as f32 / 1000.0 - 0.5) * scale)
            .collect()
    };
    let plane = b * p * p;
    let batch = if cfg.model == ModelKind::EpiShift {
        let s = cfg.epishift.train_shifts;
        TrainBatch::Shifts(ShiftBatch {
            size: b,
            patch: p,
            stack_channels: grid * 3,
            shifts: s,
            horizontal: noise(plane * (s + 2) * grid * 3, 1.0),
            vertical: noise(plane * (s + 2) * grid * 3, 1.0),
            centre: noise(plane * 3, 1.0),
            disparity: noise(plane, 6.0),
            weight: vec![1.0; plane],
            clip: vec![1.0; plane * s],
            loss_pixels: plane,
        })
    } else {
        let channels = StackInput::of(cfg).channels(grid);
        TrainBatch::Stacks(Batch {
            size: b,
            patch: p,
            stack_channels: channels,
            modes,
            stacks: std::array::from_fn(|_| noise(plane * channels, 1.0)),
            disparity: noise(plane * modes, 6.0),
            eta: vec![1.0 / modes as f32; plane * modes],
            loss_pixels: plane,
        })
    };
    let mut trainer = Trainer {
        cfg: cfg.clone(),
        input: StackInput::of(cfg),
        net: seeded(&base, cfg.seed, || build_net(cfg, grid, &device)),
        optim: adam(cfg),
        device,
        base,
        state: RunState::default(),
        bn_frozen: false,
    };
    trainer.step(&batch)?;
    let start = Instant::now();
    for _ in 0..steps {
        trainer.step(&batch)?;
    }
    let seconds = start.elapsed().as_secs_f64() / steps.max(1) as f64;
    Ok((seconds, trainer.net.num_params()))
}

/// Throughput of the data pipeline alone: the [`Loader`] (background thread, rayon workers)
/// on `dataset` with `cfg`'s batch, patch and augmentations, nobody training. Returns the
/// seconds until the first batch (pool loading included) and crops per second over the next
/// `batches` batches.
pub fn bench_loader(
    cfg: &TrainConfig,
    dataset: &std::path::Path,
    pool: PoolConfig,
    batches: usize,
) -> Result<(f64, f64)> {
    let scenes = discover(dataset, &[])?;
    let start = Instant::now();
    let loader = Loader::start(scenes, cfg.clone(), pool, 0)?;
    loader.next_batch()?;
    let first = start.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let mut crops = 0;
    for _ in 0..batches {
        crops += loader.next_batch()?.size();
    }
    Ok((first, crops as f64 / t0.elapsed().as_secs_f64()))
}
