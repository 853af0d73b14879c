//! `lfeval`: evaluate light-field depth predictions, or produce baseline / ground-truth
//! predictions to evaluate. See the crate README for formats and metric definitions.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use lfdata::bins::Bins;
use lfdata::metrics::kld::EPSILON;
use lfdata::prediction::Method;
use lfdata::scene_eval::EvalConfig;
use lfdata::truth::{EtaKind, Reference};
use lfeval::baseline::{BaselineConfig, DEFAULT_TEMPERATURE, DEFAULT_WINDOW};
use lfeval::pipeline::{self, EvalOptions};
use lfeval::report::{self, samples::PixelRequest};
use lfeval::robust;
use lfeval::slfc;
use lfformat::cli::{Generated, Workers};
use lfformat::dataset::{PARAMETERS_FILE, SceneDir, discover};
use lfformat::views::ViewSet;

/// Evaluates light-field disparity predictions against lfgen or HCI ground truth.
///
/// `lfeval DATASET PRED...` evaluates; `lfeval baseline` and `lfeval truth` write
/// predictions (a dataset folder literally named `baseline` or `truth` is written `./baseline`).
#[derive(Parser)]
#[command(
    name = "lfeval",
    version,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    eval: EvalArgs,
    #[command(flatten)]
    workers: Workers,
}

/// The command line, with `--threads` and `-q` accepted before or after the command name.
fn command() -> clap::Command {
    Workers::global(Cli::command())
}

#[derive(Subcommand)]
enum Command {
    /// Run the classical cost-volume baseline and write its predictions.
    Baseline(BaselineArgs),
    /// Run Sparse Light Field Coding (per-pixel Lasso over EPI atoms, several disparities per
    /// pixel) and write its predictions; resumes an interrupted run.
    Slfc(SlfcArgs),
    /// Write the ground truth as a method's predictions (checks a pipeline: scores 0).
    Truth(TruthArgs),
    /// Write seeded, corrupted copies of a dataset's scenes (noise, contrast, exposure,
    /// vignetting, JPEG) for `lfeval robustness`.
    Corrupt(CorruptArgs),
    /// Score every method on every corrupted copy: tables and a plot of BadPix against the
    /// corruption's strength.
    Robustness(RobustnessArgs),
    #[command(flatten)]
    Generated(Generated),
    /// Print docs/reference/cli-lfeval.md, generated from the flag definitions.
    #[command(hide = true)]
    Doc,
}

/// Options every command that reads a dataset shares.
#[derive(Args)]
struct Common {
    /// Only these split folders of DATASET (repeatable), e.g. --split val.
    #[arg(long = "split", value_name = "NAME")]
    splits: Vec<String>,
}

/// The disparity bins.
#[derive(Args)]
struct BinArgs {
    /// Number of disparity bins (default: 108; with --range auto, as many as keep the
    /// thesis' width of 7/108 px).
    #[arg(long)]
    bins: Option<usize>,
    /// Disparity range MIN,MAX of the bins, pixels, or `auto`: the union of the scenes'
    /// parameters.cfg ranges (disp_min, disp_max), for wide baselines.
    #[arg(long, value_name = "MIN,MAX|auto", default_value = "-3.5,3.5", allow_hyphen_values = true,
          value_parser = parse_range)]
    range: RangeArg,
}

/// `--range`: fixed, or the scenes' own.
#[derive(Clone, Copy, Debug)]
enum RangeArg {
    Fixed(f64, f64),
    Auto,
}

impl BinArgs {
    /// The bins for `scenes` (their `parameters.cfg` ranges with `--range auto`).
    fn bins(&self, scenes: &[SceneDir]) -> Result<Bins> {
        match self.range {
            RangeArg::Fixed(min, max) => {
                Bins::new(min, max, self.bins.unwrap_or(Bins::THESIS.count))
                    .map_err(anyhow::Error::msg)
            }
            RangeArg::Auto => {
                let ranges = scenes
                    .iter()
                    .map(|s| {
                        let p = lfformat::HciParameters::read(&s.path.join(PARAMETERS_FILE))?;
                        Ok((p.disp_min, p.disp_max))
                    })
                    .collect::<Result<Vec<_>>>()?;
                Bins::covering(ranges, self.bins).map_err(|m| anyhow::anyhow!("--range auto: {m}"))
            }
        }
    }
}

#[derive(Args)]
struct EvalArgs {
    /// Dataset root, split folder or scene folder.
    #[arg(required = true)]
    dataset: Option<PathBuf>,
    /// Prediction folders, one per method (named by the folder).
    #[arg(required = true)]
    predictions: Vec<PathBuf>,
    /// Report folder to write.
    #[arg(long, default_value = "lfeval_report")]
    out: PathBuf,
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    bins: BinArgs,
    /// Added to every KLD bin of both distributions before renormalising.
    #[arg(long, default_value_t = EPSILON)]
    epsilon: f64,
    /// Pixels left out at each image side.
    #[arg(long, default_value_t = 15)]
    border: usize,
    /// Score only the centred crop of this side, a fraction of the image side (the thesis:
    /// 0.5); predictions may cover the whole image or only the crop.
    #[arg(long, default_value_t = 1.0, value_parser = fraction)]
    crop: f64,
    /// Ground truth of the summary table, sparsification and error maps.
    #[arg(long, value_enum, default_value = "front")]
    reference: Reference,
    /// Which η is a mode's probability.
    #[arg(long, value_enum, default_value = "over")]
    eta: EtaKind,
    /// Samples of the sparsification curves.
    #[arg(long, default_value_t = 100)]
    sparsification_steps: usize,
    /// Plot posteriors at SCENE:X,Y (repeatable).
    #[arg(long = "pixel", value_name = "SCENE:X,Y")]
    pixels: Vec<PixelRequest>,
    /// Scenes (the first N) that get automatically chosen posterior plots.
    #[arg(long, default_value_t = 2)]
    plot_scenes: usize,
    /// Skip the per-scene BadPix maps.
    #[arg(long)]
    no_error_maps: bool,
}

#[derive(Args)]
struct BaselineArgs {
    /// Dataset root, split folder or scene folder.
    dataset: PathBuf,
    /// Prediction folder to write.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    bins: BinArgs,
    /// Views entering the photo-consistency cost.
    #[arg(long, default_value = "cross",
          value_parser = PossibleValuesParser::new(["cross", "star", "full"]).try_map(|s| s.parse::<ViewSet>()))]
    views: ViewSet,
    /// Softmax temperature, in units of the cost (colour variance, colours in [0, 1]).
    #[arg(long, default_value_t = DEFAULT_TEMPERATURE)]
    temperature: f64,
    /// Radius of the cost aggregation window (0: none).
    #[arg(long, default_value_t = DEFAULT_WINDOW)]
    window: usize,
    /// Do not write posteriors (they hold bins × pixels floats per scene).
    #[arg(long)]
    no_posterior: bool,
}

#[derive(Args)]
struct SlfcArgs {
    /// Dataset root, split folder or scene folder.
    dataset: PathBuf,
    /// Prediction folder to write (scenes already in it are skipped).
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    bins: BinArgs,
    /// Lasso weight α of the objective 1/(2n)·‖y − D w‖² + α‖w‖₁.
    #[arg(long, default_value_t = slfc::DEFAULT_ALPHA)]
    alpha: f64,
    /// EPI window radius in pixels.
    #[arg(long, default_value_t = slfc::DEFAULT_RADIUS)]
    radius: usize,
    /// Share of the centre view's profile variance the dictionary's generators (its
    /// principal components) hold.
    #[arg(long, default_value_t = slfc::DEFAULT_ENERGY, value_parser = fraction)]
    energy: f64,
    /// Lasso stopping tolerance: duality gap relative to the window's squared norm.
    #[arg(long, default_value_t = slfc::DEFAULT_TOL)]
    tol: f64,
    /// Estimate only the centred crop of this side, a fraction of the image side (the
    /// thesis: 0.5); evaluate with the same `--crop`.
    #[arg(long, default_value_t = 1.0, value_parser = fraction)]
    crop: f64,
}

/// A fraction in (0, 1].
fn fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(f) if f > 0.0 && f <= 1.0 => Ok(f),
        Ok(f) => Err(format!("{f} is not in (0, 1]")),
        Err(e) => Err(e.to_string()),
    }
}

#[derive(Args)]
struct TruthArgs {
    /// Dataset root, split folder or scene folder.
    dataset: PathBuf,
    /// Prediction folder to write.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    bins: BinArgs,
    /// Which mode becomes the disparity map.
    #[arg(long, value_enum, default_value = "front")]
    reference: Reference,
    /// Which η weights the posterior.
    #[arg(long, value_enum, default_value = "over")]
    eta: EtaKind,
}

#[derive(Args)]
struct CorruptArgs {
    /// Dataset root, split folder or scene folder (e.g. the held-out split).
    dataset: PathBuf,
    /// New folder for the copies: OUT/<corruption>/[<split>/]<scene>/.
    #[arg(long)]
    out: PathBuf,
    #[command(flatten)]
    common: Common,
    /// Seed of the noise (with the scene name and the view).
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

#[derive(Args)]
struct RobustnessArgs {
    /// The folder `lfeval corrupt` wrote.
    corrupted: PathBuf,
    /// One folder per method, holding a prediction folder per corrupted copy, named as it
    /// (METHOD/clean, METHOD/noise_2, …); the method is named by the folder.
    #[arg(required = true)]
    methods: Vec<PathBuf>,
    /// Report folder to write (robustness.md, robustness.json, robustness.png).
    #[arg(long, default_value = "lfeval_robustness")]
    out: PathBuf,
}

/// `MIN,MAX`, or `auto` (the scenes' own ranges).
fn parse_range(s: &str) -> Result<RangeArg, String> {
    if s.trim() == "auto" {
        return Ok(RangeArg::Auto);
    }
    let [min, max] = lfformat::cli::parse_range(s, "-3.5,3.5 or auto")?;
    Ok(RangeArg::Fixed(min, max))
}

fn main() {
    let cmd = command();
    let args = lfformat::cli::options_after_command(&cmd, std::env::args_os().collect());
    let cli = Cli::from_arg_matches(&cmd.get_matches_from(args)).unwrap_or_else(|e| e.exit());
    if let Err(e) = run(cli) {
        lfformat::note!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    cli.workers
        .apply()
        .context("cannot set up the worker threads")?;
    let quiet = cli.workers.quiet;
    match cli.command {
        Some(Command::Baseline(a)) => baseline(a, quiet),
        Some(Command::Slfc(a)) => run_slfc(a, quiet),
        Some(Command::Truth(a)) => truth(a, quiet),
        Some(Command::Corrupt(a)) => {
            let scenes = discover(&a.dataset, &a.common.splits)?;
            robust::corrupt_dataset(&scenes, &a.out, a.seed)?;
            lfformat::note!("corrupted copies written to {}", a.out.display());
            Ok(())
        }
        Some(Command::Robustness(a)) => {
            let bench = robust::benchmark::score(&a.corrupted, &a.methods, quiet)?;
            bench.write(&a.out)?;
            let table = bench.table("BadPix(0.07) %", |s| s.badpix_007);
            lfformat::console::stdout(format_args!("{}", table.to_markdown()))?;
            lfformat::note!(
                "report written to {}",
                a.out.join("robustness.md").display()
            );
            Ok(())
        }
        Some(Command::Generated(g)) => Ok(g.print(command())?),
        Some(Command::Doc) => {
            let note = "Generated from the flag definitions by `lfeval doc` (do not edit by \
                        hand: run `lfeval doc > docs/reference/cli-lfeval.md`).";
            let md = lfformat::cli::reference(&command(), note);
            Ok(lfformat::console::stdout(format_args!("{md}"))?)
        }
        None => evaluate(cli.eval, quiet),
    }
}

fn evaluate(a: EvalArgs, quiet: bool) -> Result<()> {
    let dataset = a.dataset.expect("clap requires DATASET");
    let scenes = discover(&dataset, &a.common.splits)?;
    let methods = a
        .predictions
        .iter()
        .map(|p| Method::new(p))
        .collect::<Result<Vec<_>>>()?;
    if a.sparsification_steps == 0 {
        anyhow::bail!("--sparsification-steps must be at least 1");
    }
    let opts = EvalOptions {
        config: EvalConfig {
            bins: a.bins.bins(&scenes)?,
            epsilon: a.epsilon,
            border: a.border,
            eta: a.eta,
            reference: a.reference,
            sparsification_steps: a.sparsification_steps,
            crop: a.crop,
        },
        out: a.out.clone(),
        pixels: a.pixels,
        auto_plot_scenes: a.plot_scenes,
        error_maps: !a.no_error_maps,
        quiet,
    };
    std::fs::create_dir_all(&a.out)
        .with_context(|| format!("{}: cannot create", a.out.display()))?;
    let eval = pipeline::evaluate_dataset(&dataset, scenes, methods, &opts)?;
    report::write_all(&eval, &a.out)?;
    let table = report::table::main_table(&eval).to_markdown();
    lfformat::console::stdout(format_args!("{table}"))?;
    lfformat::note!("report written to {}", a.out.join("report.html").display());
    Ok(())
}

fn run_slfc(a: SlfcArgs, quiet: bool) -> Result<()> {
    let scenes = discover(&a.dataset, &a.common.splits)?;
    for (name, value) in [("--alpha", a.alpha), ("--tol", a.tol)] {
        if !(value.is_finite() && value > 0.0) {
            anyhow::bail!("{name} must be positive, got {value}");
        }
    }
    let cfg = slfc::SlfcConfig {
        bins: a.bins.bins(&scenes)?,
        radius: a.radius,
        energy: a.energy,
        lasso: slfc::lasso::LassoSettings {
            alpha: a.alpha,
            tol: a.tol,
            ..slfc::SlfcConfig::default().lasso
        },
        crop: a.crop,
    };
    pipeline::slfc_dataset(&a.dataset, &scenes, &a.out, &cfg, quiet)
}

fn baseline(a: BaselineArgs, quiet: bool) -> Result<()> {
    let scenes = discover(&a.dataset, &a.common.splits)?;
    if !(a.temperature.is_finite() && a.temperature > 0.0) {
        anyhow::bail!("--temperature must be positive, got {}", a.temperature);
    }
    let cfg = BaselineConfig {
        bins: a.bins.bins(&scenes)?,
        views: a.views,
        temperature: a.temperature,
        window: a.window,
    };
    pipeline::baseline_dataset(&a.dataset, &scenes, &a.out, &cfg, !a.no_posterior, quiet)
}

fn truth(a: TruthArgs, quiet: bool) -> Result<()> {
    let scenes = discover(&a.dataset, &a.common.splits)?;
    let settings = (a.reference, a.eta, a.bins.bins(&scenes)?);
    pipeline::truth_dataset(&a.dataset, &scenes, &a.out, settings, quiet)
}
