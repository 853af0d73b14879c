//! `lftrain`: train the thesis' posterior models and write predictions for `lfeval`.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Args, CommandFactory, Parser, Subcommand};
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
    /// Worker threads (default: all cores).
    #[arg(long, global = true)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(short, long, global = true)]
    quiet: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Train a model; writes RUN/config.toml, RUN/checkpoint/, RUN/log.csv, log.json, loss.png.
    Train(TrainCmd),
    /// Apply a trained run to a dataset; writes lfeval's prediction folders under --out.
    Predict {
        /// Run folder of `lftrain train`.
        run: PathBuf,
        /// Dataset (root with split folders, split folder, or scene folder).
        dataset: PathBuf,
        /// Output folder (one lfeval method).
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
    },
    /// Seconds per training step of a configuration on random input (no data loading), or
    /// with --loader the crops/s of the data loader alone.
    Bench {
        /// TOML config (network, batch, patch, model).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Model; overrides the config file.
        #[arg(long, value_enum)]
        model: Option<ModelKind>,
        /// Views per grid side.
        #[arg(long, default_value_t = 9)]
        grid: usize,
        /// Timed steps (after one warm-up step).
        #[arg(long, default_value_t = 5)]
        steps: usize,
        /// Time the data loader alone on this dataset instead (crops/s, no training).
        #[arg(long)]
        loader: Option<PathBuf>,
        /// Timed batches of --loader (after the first).
        #[arg(long, default_value_t = 50)]
        batches: usize,
        /// Scenes held in memory by the loader (--loader).
        #[arg(long, default_value_t = 16)]
        scene_pool: usize,
        /// Batches between two scene replacements (--loader).
        #[arg(long, default_value_t = 8)]
        pool_refresh: usize,
        /// Results file the run appends its figures to, one JSON line (docs/reference/results.md).
        #[arg(long, value_name = "FILE", default_value = lfformat::results::DEFAULT_PATH)]
        results: PathBuf,
    },
    /// Print a shell completion script, e.g. `lftrain completions bash > lftrain.bash`.
    Completions { shell: clap_complete::Shell },
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
    /// Training dataset.
    #[arg(long)]
    train: PathBuf,
    /// Validation dataset (validated every `val_every` steps through lfeval's metrics).
    #[arg(long)]
    val: Option<PathBuf>,
    /// Run folder.
    #[arg(long)]
    out: PathBuf,
    /// TOML config (see README); fields left out keep their defaults.
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
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            lfformat::note!("lftrain: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    if let Some(n) = cli.threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()?;
    }
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
                quiet: cli.quiet,
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
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "lftrain", &mut script);
            let text = String::from_utf8_lossy(&script);
            lfformat::console::stdout(format_args!("{text}"))?;
        }
        Command::Doc => {
            let options = clap_markdown::MarkdownOptions::new()
                .title("`lftrain` command-line reference".into())
                .show_footer(false);
            let md = clap_markdown::help_markdown_command_custom(&Cli::command(), &options);
            let md = md.replacen(
                "\n\n",
                "\n\nGenerated from the flag definitions by `lftrain doc` (do not edit by hand: \
                 run `lftrain doc > docs/reference/cli-lftrain.md`).\n\n",
                1,
            );
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
        } => {
            let overrides = Overrides {
                range,
                coarse_max,
                rotations,
                mode_window,
            };
            let n = predict_dataset_over(&run, &dataset, &out, cli.quiet, &overrides)?;
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
    let bad = || format!("expected MIN,MAX such as -40,40, got {s:?}");
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let num = |v: &str| v.trim().parse::<f32>().map_err(|_| bad());
    let r = [num(lo)?, num(hi)?];
    if !(r[0].is_finite() && r[1].is_finite() && r[0] <= r[1]) {
        return Err(bad());
    }
    Ok(r)
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
