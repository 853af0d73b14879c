//! `lftrain`: train the thesis' posterior models and write predictions for `lfeval`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use lfformat::cli::{Generated, Workers};
use lftrain::config::{ModelKind, TrainConfig};
use lftrain::loader::PoolConfig;
use lftrain::predict::{Overrides, predict_dataset_over};
use lftrain::train::{TrainArgs, bench_loader, bench_steps, train};

/// Training allocates and frees every activation and gradient tensor each step. With glibc's
/// allocator those large blocks go back to the kernel and fault in again as zeroed pages on the
/// next step: a quarter of a CPU step's time was page faults and `brk` (perf, `lftrain bench
/// --config configs/cpu_field.toml`). mimalloc keeps them in its own pools.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// mimalloc's `mi_option_purge_delay`: its index in mimalloc v3's `mi_option_e`, the library
/// libmimalloc-sys 0.1.49 builds but does not name (the test below checks the index by the
/// option's documented default).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Even mimalloc hands freed pages back to the kernel a second after they empty, and a step
/// takes longer than that: each step's large tensors then fault in as freshly zeroed huge
/// pages again, 16 % of a `cpu_cost.toml` step in the kernel's `clear_page` (perf). Never
/// purging keeps them; the process holds its peak working set, which it reaches every step
/// anyway. Set before the first large allocation.
fn keep_freed_pages() {
    // SAFETY: sets a plain integer option; mimalloc reads it on its next purge decision.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) }
}

#[derive(Parser)]
#[command(
    version,
    about = "Train light-field depth models (BASE, UPR, ESE, DPP, EPI-Shift)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    #[command(flatten)]
    workers: Workers,
}

/// The command line, with `--threads` and `-q` accepted before or after the command name.
fn command() -> clap::Command {
    Workers::global(Cli::command())
}

#[derive(Subcommand)]
enum Command {
    /// Train a model; writes RUN/config.toml, RUN/checkpoint/, RUN/log.csv, log.json, loss.png.
    Train(TrainCmd),
    /// Apply a trained run to a dataset; writes lfeval's prediction folders under --out.
    Predict {
        /// Run folder of `lftrain train`.
        run: PathBuf,
        /// Dataset root, split folder or scene folder.
        dataset: PathBuf,
        /// Prediction folder to write (one method for lfeval).
        #[arg(long)]
        out: PathBuf,
        /// Disparity range MIN,MAX the shifts cover (epishift: default each scene's
        /// parameters.cfg; ese: default its config's passes).
        #[arg(long, value_name = "MIN,MAX", allow_hyphen_values = true, value_parser = parse_range)]
        range: Option<[f32; 2]>,
        /// EPI-Shift coarse to fine: scenes whose largest |disparity| exceeds PX are first
        /// solved on views scaled down to bring it within PX (overrides the run's
        /// epishift.coarse_max; 0: off).
        #[arg(long, value_name = "PX")]
        coarse_max: Option<f32>,
        /// Average BASE, UPR, ESE and DPP over the light field turned by the first N quarter
        /// turns, 1 to 4 (overrides the run's test_rotations; 1: off).
        #[arg(long, value_name = "N")]
        rotations: Option<usize>,
        /// DPP's point estimate: the most likely mode over 2R + 1 bins (overrides the run's
        /// dpp.mode_window; 0: the most probable bin, as the thesis).
        #[arg(long, value_name = "R")]
        mode_window: Option<usize>,
        /// Predict, denoise every view through that prediction with its 3x3 angular neighbours
        /// (weights within K times the noise measured between the views), predict again
        /// (overrides the run's test_denoise; 0: off).
        #[arg(long, value_name = "K")]
        denoise: Option<f32>,
    },
    /// Seconds per training step of a configuration on random input (no data loading), or
    /// with --loader the crops/s of the data loader alone.
    Bench {
        /// Training config file (TOML; keys left out keep their defaults).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Model; overrides the config file.
        #[arg(long, value_enum)]
        model: Option<ModelKind>,
        /// Views per grid side (not with --loader).
        #[arg(long, default_value_t = 9, conflicts_with = "loader")]
        grid: usize,
        /// Timed steps, after one warm-up step (not with --loader).
        #[arg(long, default_value_t = 5, conflicts_with = "loader")]
        steps: usize,
        /// Time the data loader alone on this dataset instead (crops/s, no training).
        #[arg(long, value_name = "DATASET")]
        loader: Option<PathBuf>,
        /// Timed batches of --loader, after the first.
        #[arg(long, default_value_t = 50, requires = "loader")]
        batches: usize,
        /// Scenes held in memory by --loader.
        #[arg(long, default_value_t = 16, requires = "loader")]
        scene_pool: usize,
        /// Batches between two scene replacements of --loader.
        #[arg(long, default_value_t = 8, requires = "loader")]
        pool_refresh: usize,
        /// Results file the run appends its figures to, one JSON line (docs/reference/results.md).
        #[arg(long, value_name = "FILE", default_value = lfformat::results::DEFAULT_PATH)]
        results: PathBuf,
    },
    #[command(flatten)]
    Generated(Generated),
    /// Print docs/reference/cli-lftrain.md, generated from the flag definitions.
    #[command(hide = true)]
    Doc,
}

#[derive(Args)]
struct TrainCmd {
    /// Model; overrides the config file.
    #[arg(long, value_enum)]
    model: Option<ModelKind>,
    /// Train on all modes weighted by η (lfgen datasets) instead of the front-most one.
    #[arg(long)]
    multimodal: bool,
    /// Training dataset: root, split folder or scene folder.
    #[arg(long)]
    train: PathBuf,
    /// Validation dataset (validated every `val_every` steps through lfeval's metrics).
    #[arg(long)]
    val: Option<PathBuf>,
    /// Run folder to write (with --resume: to continue).
    #[arg(long)]
    out: PathBuf,
    /// Training config file (TOML; keys left out keep their defaults).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Continue the run in --out from its checkpoint (its stored config is used).
    #[arg(long)]
    resume: bool,
    /// Total steps; overrides the config file (with --resume: extends the run).
    #[arg(long)]
    steps: Option<usize>,
    /// Scenes held in memory by the loader.
    #[arg(long, default_value_t = 16)]
    scene_pool: usize,
    /// Batches between two scene replacements in the pool.
    #[arg(long, default_value_t = 8)]
    pool_refresh: usize,
}

fn main() -> ExitCode {
    keep_freed_pages();
    let cli = Cli::from_arg_matches(&command().get_matches()).unwrap_or_else(|e| e.exit());
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            lfformat::note!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    cli.workers.apply()?;
    match cli.command {
        Command::Train(t) => {
            let mut cfg = match &t.config {
                Some(path) => TrainConfig::read(path)?,
                None => TrainConfig::default(),
            };
            if let Some(m) = t.model {
                cfg.model = m;
            }
            cfg.multimodal |= t.multimodal;
            let args = TrainArgs {
                train: t.train,
                val: t.val,
                out: t.out,
                resume: t.resume,
                quiet: cli.workers.quiet,
                pool: PoolConfig {
                    scenes: t.scene_pool,
                    refresh: t.pool_refresh,
                },
                steps: t.steps,
            };
            let summary = train(cfg, &args)?;
            lfformat::note!(
                "lftrain: {} steps logged, {:.3} s per step",
                summary.records.len(),
                summary.seconds_per_step
            );
        }
        Command::Bench {
            config,
            model,
            grid,
            steps,
            loader,
            batches,
            scene_pool,
            pool_refresh,
            results,
        } => {
            let mut cfg = match &config {
                Some(path) => TrainConfig::read(path)?,
                None => TrainConfig::default(),
            };
            if let Some(m) = model {
                cfg.model = m;
            }
            if let Some(dataset) = loader {
                let pool = PoolConfig {
                    scenes: scene_pool,
                    refresh: pool_refresh,
                };
                let (first, crops) = bench_loader(&cfg, &dataset, pool, batches)?;
                lfformat::say!(
                    "loader ({} threads): batch {} of {}x{} crops: first batch after {first:.2} s, \
                     then {crops:.1} crops/s ({:.3} s per batch) over {batches} batches",
                    rayon::current_num_threads(),
                    cfg.batch,
                    cfg.patch,
                    cfg.patch,
                    cfg.batch as f64 / crops
                )?;
                let figures = serde_json::json!({
                    "bench": "loader",
                    "threads": rayon::current_num_threads(),
                    "batch": cfg.batch,
                    "patch": cfg.patch,
                    "batches": batches,
                    "first_batch_s": first,
                    "crops_per_s": crops,
                });
                return record(figures, &results);
            }
            let (s, params) = bench_steps(&cfg, grid, steps)?;
            lfformat::say!(
                "{} ({params} parameter values incl. batch-norm statistics): batch {} of {}x{} patches, {grid}x{grid} views, \
                 on {:?}: {s:.3} s per step ({:.1} samples/s)",
                cfg.model.name(),
                cfg.batch,
                cfg.patch,
                cfg.patch,
                lftrain::train::default_device(),
                cfg.batch as f64 / s
            )?;
            let figures = serde_json::json!({
                "bench": "steps",
                "model": cfg.model.name(),
                "threads": rayon::current_num_threads(),
                "device": format!("{:?}", lftrain::train::default_device()),
                "parameters": params,
                "batch": cfg.batch,
                "patch": cfg.patch,
                "grid": grid,
                "steps": steps,
                "seconds_per_step": s,
                "samples_per_s": cfg.batch as f64 / s,
            });
            record(figures, &results)?;
        }
        Command::Generated(g) => g.print(command())?,
        Command::Doc => {
            let note = "Generated from the flag definitions by `lftrain doc` (do not edit by \
                        hand: run `lftrain doc > docs/reference/cli-lftrain.md`).";
            let md = lfformat::cli::reference(&command(), note);
            lfformat::console::stdout(format_args!("{md}"))?;
        }
        Command::Predict {
            run,
            dataset,
            out,
            range,
            coarse_max,
            rotations,
            mode_window,
            denoise,
        } => {
            let overrides = Overrides {
                range,
                coarse_max,
                rotations,
                mode_window,
                denoise,
            };
            let n = predict_dataset_over(&run, &dataset, &out, cli.workers.quiet, &overrides)?;
            lfformat::note!("lftrain: {n} scenes written to {}", out.display());
        }
    }
    Ok(())
}

/// Appends a benchmark's figures to the results file.
fn record(figures: serde_json::Value, path: &std::path::Path) -> Result<()> {
    lfformat::results::Record::now("lftrain", figures).append(path)?;
    lfformat::note!("lftrain: figures appended to {}", path.display());
    Ok(())
}

/// `MIN,MAX` in pixels, MIN ≤ MAX.
fn parse_range(s: &str) -> std::result::Result<[f32; 2], String> {
    let r = lfformat::cli::parse_range(s, "-40,40")?.map(|v| v as f32);
    match r.iter().all(|v| v.is_finite()) {
        true => Ok(r),
        false => Err(format!("{s:?} is beyond single precision")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The index names the purge delay: its default in mimalloc v3's `options.c` (1 000 ms)
    /// unless the environment overrides it, and what `keep_freed_pages` sets.
    #[test]
    fn the_purge_delay_option_is_the_one_set() {
        let get = || unsafe { libmimalloc_sys::mi_option_get(MI_OPTION_PURGE_DELAY) };
        if std::env::var_os("MIMALLOC_PURGE_DELAY").is_none() {
            assert_eq!(get(), 1000);
        }
        keep_freed_pages();
        assert_eq!(get(), -1);
    }
}
