//! The run folder: config, checkpoint and resume state, and building the network for a run.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use burn::module::{ModuleVisitor, Param};
use burn::optim::ModuleOptimizer;
use burn::prelude::*;
use lfformat::HciParameters;
use lfformat::dataset::{PARAMETERS_FILE, SceneDir};
use serde::{Deserialize, Serialize};

use crate::config::{CostNetwork, ModelKind, NetInput, TrainConfig};
use crate::costnet::CostNet;
use crate::epishift::EpiShiftNet;
use crate::input::StackInput;
use crate::model::{EpiNet, Network};

/// The config of a run, as written at its start.
pub const CONFIG_FILE: &str = "config.toml";
/// The folder of the latest checkpoint.
pub const CHECKPOINT_DIR: &str = "checkpoint";
const MODEL_FILE: &str = "model.bpk";
const OPTIMIZER_FILE: &str = "optimizer.bpk";
const STATE_FILE: &str = "state.json";

/// What besides the weights a resumed run needs.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RunState {
    /// Steps done.
    pub step: usize,
    /// Training seconds so far.
    pub elapsed_s: f64,
    /// Views per grid side the network was built for.
    pub grid: usize,
}

/// A run folder.
#[derive(Clone, Debug)]
pub struct RunDir {
    /// The folder.
    pub dir: PathBuf,
}

impl RunDir {
    /// The run at `dir` (not created yet).
    pub fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
        }
    }

    fn checkpoint(&self, file: &str) -> PathBuf {
        self.dir.join(CHECKPOINT_DIR).join(file)
    }

    /// The stored config.
    pub fn config(&self) -> Result<TrainConfig> {
        TrainConfig::read(&self.dir.join(CONFIG_FILE))
    }

    /// The stored state of the latest checkpoint.
    pub fn state(&self) -> Result<RunState> {
        let path = self.checkpoint(STATE_FILE);
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "{}: cannot read (no checkpoint in this run?)",
                path.display()
            )
        })?;
        serde_json::from_str(&text).with_context(|| format!("{}: invalid", path.display()))
    }

    /// Whether a checkpoint exists.
    pub fn has_checkpoint(&self) -> bool {
        self.checkpoint(STATE_FILE).exists()
    }

    /// Writes the weights, the optimiser state and `state`; the state file last, so that an
    /// interrupted write never leaves a state pointing at missing weights.
    pub fn save(&self, net: &Network, optim: &ModuleOptimizer, state: &RunState) -> Result<()> {
        let dir = self.dir.join(CHECKPOINT_DIR);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("{}: cannot create", dir.display()))?;
        let path = self.checkpoint(MODEL_FILE);
        // The inner network is stored, so that checkpoints of EPINET runs keep their layout.
        match net.clone() {
            Network::Epi(n) => n.save_file(&path),
            Network::Cost(n) => n.save_file(&path),
            Network::Shift(n) => n.save_file(&path),
        }
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e:?}", path.display()))?;
        let path = self.checkpoint(OPTIMIZER_FILE);
        optim
            .save(&path)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e:?}", path.display()))?;
        let path = self.checkpoint(STATE_FILE);
        std::fs::write(&path, serde_json::to_string_pretty(state)?)
            .with_context(|| format!("{}: cannot write", path.display()))
    }

    /// The network of this run with the checkpoint's weights, on `device`.
    pub fn load_net(&self, cfg: &TrainConfig, grid: usize, device: &Device) -> Result<Network> {
        let path = self.checkpoint(MODEL_FILE);
        let err = |e| anyhow::anyhow!("{}: cannot load weights: {e:?}", path.display());
        // Loading into the fresh (lazy) parameters draws nothing from the generator.
        Ok(match build_net(cfg, grid, device) {
            Network::Epi(n) => Network::Epi(n.try_load_file(&path).map_err(err)?),
            Network::Cost(n) => Network::Cost(n.try_load_file(&path).map_err(err)?),
            Network::Shift(n) => Network::Shift(n.try_load_file(&path).map_err(err)?),
        })
    }

    /// The optimiser state of the checkpoint.
    pub fn load_optimizer(&self, optim: ModuleOptimizer) -> Result<ModuleOptimizer> {
        let path = self.checkpoint(OPTIMIZER_FILE);
        optim
            .load(&path)
            .map_err(|e| anyhow::anyhow!("{}: cannot load optimiser state: {e:?}", path.display()))
    }
}

/// Seeds the backend's random numbers with `seed`, builds a module with `init` and draws
/// all its parameters while no other thread of the process draws from them. burn keeps one
/// generator per process and draws a parameter on its first use, so two networks trained at
/// once (tests in parallel, two trainings in one process) took each other's numbers, and
/// neither run was reproducible: a tiny cost-volume model's overfit test started from another
/// initial loss in each full test run (0.70–0.77; 0.69 alone) and once missed its bound
/// (MSE×100 11.7, where alone it reaches 0.04).
pub fn seeded<M: Module>(device: &Device, seed: u64, init: impl FnOnce() -> M) -> M {
    static BACKEND_RNG: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _alone = BACKEND_RNG
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    device.seed(seed);
    let module = init();
    module.visit(&mut DrawParams);
    module
}

/// Reads every parameter of a module once, which draws the lazily initialised ones.
struct DrawParams;

impl ModuleVisitor for DrawParams {
    fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
        param.val();
    }
    fn visit_int<const D: usize>(&mut self, param: &Param<Tensor<D, Int>>) {
        param.val();
    }
    fn visit_bool<const D: usize>(&mut self, param: &Param<Tensor<D, Bool>>) {
        param.val();
    }
}

/// A fresh network for `cfg` and an `grid × grid` camera grid.
pub fn build_net(cfg: &TrainConfig, grid: usize, device: &Device) -> Network {
    match cfg.model {
        ModelKind::EpiShift => Network::Shift(EpiShiftNet::new(&cfg.epishift, grid * 3, device)),
        _ if cfg.net.input == NetInput::Cost
            && cfg.net.cost_network == CostNetwork::PerHypothesis =>
        {
            let spread = cfg.model.has_spread();
            Network::Cost(CostNet::new(&cfg.net, cfg.dpp.bins, spread, device))
        }
        _ => Network::Epi(EpiNet::new(
            &cfg.net,
            StackInput::of(cfg).channels(grid),
            cfg.model.net_channels(cfg.net.input, cfg.dpp.bins),
            device,
        )),
    }
}

/// The camera grid side shared by all `scenes` (an error if they differ or are not square).
pub fn grid_of(scenes: &[SceneDir]) -> Result<usize> {
    let mut grid = None;
    for s in scenes {
        let path = s.path.join(PARAMETERS_FILE);
        let p = HciParameters::read(&path)?;
        let n = p.num_cams_x as usize;
        if p.num_cams_y as usize != n || n.is_multiple_of(2) {
            bail!(
                "{}: the four stacks need a square grid with an odd side",
                path.display()
            );
        }
        if grid.is_some_and(|g| g != n) {
            bail!(
                "{}: {n}x{n} views, other scenes have {}",
                path.display(),
                grid.unwrap_or(0)
            );
        }
        grid = Some(n);
    }
    grid.context("no scenes")
}
