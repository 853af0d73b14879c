//! Batches prepared on a background thread ahead of the optimiser, from a bounded pool of
//! scenes in memory.
//!
//! Memory is bounded twice: at most `scene_pool` scenes are held (a random one is replaced by a
//! random other scene every `pool_refresh` batches, so a large dataset is still visited
//! evenly), and at most `prefetch` finished batches wait in the channel. The samples of a batch
//! are built in parallel with rayon.

use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use anyhow::{Context, Result, bail};
use lfformat::dataset::SceneDir;
use rand::RngExt;
use rand_pcg::Pcg32;
use rayon::prelude::*;

use crate::config::{ModelKind, TrainConfig};
use crate::input::StackInput;
use crate::sample::{Batch, Draw, make_sample};
use crate::scene::{Scene, Unimodal};
use crate::shift_sample::{ShiftBatch, make_shift_sample};

/// A batch of either kind of network input.
#[derive(Clone, Debug, PartialEq)]
pub enum TrainBatch {
    /// The four stacks (BASE, UPR, ESE, DPP).
    Stacks(Batch),
    /// Integer-shifted cross stacks (EPI-Shift).
    Shifts(ShiftBatch),
}

impl TrainBatch {
    /// Crops in the batch.
    pub fn size(&self) -> usize {
        match self {
            TrainBatch::Stacks(b) => b.size,
            TrainBatch::Shifts(b) => b.size,
        }
    }
}

/// Pool and refresh sizes of the loader.
#[derive(Clone, Copy, Debug)]
pub struct PoolConfig {
    /// Scenes held in memory.
    pub scenes: usize,
    /// Batches between two scene replacements.
    pub refresh: usize,
}

/// The receiving end of the background loader; dropping it stops the thread.
pub struct Loader {
    rx: Receiver<Result<TrainBatch>>,
    handle: Option<JoinHandle<()>>,
}

impl Loader {
    /// Starts loading batches of `scenes` under `cfg`; `stream` separates the random streams
    /// of resumed runs from the original one.
    pub fn start(
        scenes: Vec<SceneDir>,
        cfg: TrainConfig,
        pool: PoolConfig,
        stream: u64,
    ) -> Result<Self> {
        if scenes.is_empty() {
            bail!("no training scenes");
        }
        let (tx, rx) = sync_channel(cfg.prefetch.max(1));
        let handle = std::thread::Builder::new()
            .name("lftrain-loader".into())
            .spawn(move || run(scenes, cfg, pool, stream, tx))
            .context("cannot start the loader thread")?;
        Ok(Self {
            rx,
            handle: Some(handle),
        })
    }

    /// The next batch (blocks until ready).
    pub fn next_batch(&self) -> Result<TrainBatch> {
        self.rx
            .recv()
            .context("the loader thread stopped unexpectedly")?
    }
}

impl Drop for Loader {
    fn drop(&mut self) {
        // Closing the channel makes the thread's next send fail, which ends it.
        let (_, dead) = sync_channel(1);
        drop(std::mem::replace(&mut self.rx, dead));
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// Refuses a scene smaller than the training crop, naming both (a crop cannot be drawn from
/// it; the thesis' 96² patches need scenes of at least 96², so the quick preset's 128² fits).
fn fits_patch(scene: &Scene, patch: usize) -> Result<()> {
    let (w, h) = (scene.lf.width, scene.lf.height);
    if w < patch || h < patch {
        bail!(
            "{}: the scene is {w}x{h}, smaller than the {patch}x{patch} training patch \
             (lower `patch` or render larger scenes)",
            scene.dir.display()
        );
    }
    Ok(())
}

/// The loader thread: fills the pool, then sends batches until the receiver is gone.
fn run(
    dirs: Vec<SceneDir>,
    cfg: TrainConfig,
    pool_cfg: PoolConfig,
    stream: u64,
    tx: SyncSender<Result<TrainBatch>>,
) {
    let mut rng = Pcg32::new(cfg.seed, stream);
    let input = StackInput::of(&cfg);
    let load = |d: &SceneDir| {
        let scene = Scene::load(&d.path, &d.name, cfg.target_modes(), Unimodal::of(&cfg))?;
        fits_patch(&scene, cfg.patch)?;
        Ok(scene.with_texture_mask(cfg.texture_window, cfg.texture_threshold))
    };
    let initial: Vec<&SceneDir> = dirs.iter().take(pool_cfg.scenes.max(1)).collect();
    let mut pool = match initial
        .into_par_iter()
        .map(load)
        .collect::<Result<Vec<_>>>()
    {
        Ok(p) => p,
        Err(e) => {
            let _ = tx.send(Err(e));
            return;
        }
    };
    for batch_index in 0u64.. {
        let refresh = pool_cfg.refresh.max(1) as u64;
        if dirs.len() > pool.len() && batch_index > 0 && batch_index % refresh == 0 {
            let slot = rng.random_range(0..pool.len());
            match load(&dirs[rng.random_range(0..dirs.len())]) {
                Ok(s) => pool[slot] = s,
                Err(e) => {
                    let _ = tx.send(Err(e));
                    return;
                }
            }
        }
        let seeds: Vec<u64> = (0..cfg.batch).map(|_| rng.random()).collect();
        let draws: Vec<(&Scene, Draw)> = seeds
            .into_iter()
            .map(|seed| {
                let mut r = Pcg32::new(seed, stream);
                let scene = &pool[r.random_range(0..pool.len())];
                let size = (scene.lf.width, scene.lf.height);
                let draw = Draw::random(&cfg.augment, cfg.patch, cfg.crop_margin, size, &mut r);
                (scene, draw)
            })
            .collect();
        let (patch, border) = (cfg.patch, cfg.loss_border());
        let batch = if cfg.model == ModelKind::EpiShift {
            let offsets = cfg.epishift.train_offsets();
            let samples = draws
                .into_par_iter()
                .map(|(scene, draw)| make_shift_sample(scene, &draw, patch, border, &offsets))
                .collect();
            TrainBatch::Shifts(ShiftBatch::from_samples(samples, patch, offsets.len()))
        } else {
            let samples = draws
                .into_par_iter()
                .map(|(scene, draw)| make_sample(scene, &draw, patch, border, &input))
                .collect();
            TrainBatch::Stacks(Batch::from_samples(samples, patch, cfg.target_modes()))
        };
        if tx.send(Ok(batch)).is_err() {
            return;
        }
    }
}
