//! `lfgen`: the command-line entry point. A thin dispatcher: parse, load the config, call one
//! library function per command, report errors once.

use anyhow::{Context, Result, bail};
use clap::builder::{PossibleValue, PossibleValuesParser};
use clap::{Args, CommandFactory, FromArgMatches, Parser, Subcommand};
use lfformat::cli::{Generated, Workers};
use lfgen::config::{Config, PRESETS};
use lfgen::dataset::{self, GenerateOptions};
use lfgen::export::Target;
use std::path::{Path, PathBuf};

/// Generate multimodal light-field depth datasets: HCI-format light fields with 128-slice
/// multimodal ground truth, path-traced on the CPU.
#[derive(Parser, Debug)]
#[command(
    name = "lfgen",
    version,
    args_conflicts_with_subcommands = true,
    override_usage = "lfgen <COMMAND> [OPTIONS]\n       lfgen [GENERATE OPTIONS]",
    after_help = "Without a command, lfgen generates: `lfgen --scenes 4` is `lfgen generate \
                  --scenes 4` (see `lfgen generate --help`)."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    generate: GenerateArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a dataset of procedural rooms into train/ and val/ scene folders.
    Generate(GenerateArgs),
    /// Render a glTF 2.0 scene, or re-render a saved scene.json, into a scene folder.
    Render(RenderArgs),
    /// Union shard manifests (and verify scenes) into one manifest.json.
    Merge {
        /// Dataset folder.
        dataset: PathBuf,
    },
    /// Write a contact sheet per scene and an overview page into DATASET/previews/.
    Preview {
        /// Dataset folder (with manifest.json).
        dataset: PathBuf,
    },
    /// Write a saved scene (SCENE_DIR/scene.json) for POV-Ray, Blender or Mitsuba 3.
    Export(ExportArgs),
    /// Write the procedural seamless texture library as PNGs plus catalog.json.
    Textures {
        /// Number of textures.
        #[arg(long, default_value_t = 750)]
        count: u32,
        /// Output folder.
        #[arg(long, default_value = "textures")]
        out: PathBuf,
        /// Library seed (scene.texture_seed: the library the built-in scenes draw from).
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
    /// Download external model libraries and convert them into an asset catalogue.
    Assets {
        #[command(subcommand)]
        command: AssetsCommand,
    },
    /// Measure speed or image quality on built-in scenes; each run appends its figures to a
    /// results file.
    Bench {
        #[command(subcommand)]
        kind: BenchKind,
    },
    #[command(flatten)]
    Generated(Generated),
    /// Print a generated reference page of docs/reference/.
    #[command(hide = true)]
    Doc { page: DocPage },
}

/// The generated reference pages.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum DocPage {
    /// docs/reference/cli.md: every command and flag.
    Cli,
    /// docs/reference/config.md: every config key and preset.
    Config,
}

#[derive(Subcommand, Debug)]
enum AssetsCommand {
    /// Download a model library (apt-get) and write OUT/catalog.json, ATTRIBUTION.md and the
    /// models.
    Fetch(FetchArgs),
}

/// Model libraries `lfgen assets fetch` knows.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
enum AssetSource {
    /// Sweet Home 3D's furniture: Debian's sweethome3d-furniture and sweethome3d packages.
    Sweethome3d,
}

#[derive(Args, Debug)]
struct FetchArgs {
    /// Library to fetch.
    source: AssetSource,
    /// Output folder (the .deb files are cached in OUT/.cache/).
    #[arg(long, default_value = "assets/sweethome3d")]
    out: PathBuf,
    /// Also convert models under non-free licences (non-commercial, no-derivatives, unknown).
    #[arg(long)]
    nonfree: bool,
}

/// Options shared by every command that loads a config.
#[derive(Args, Debug, Clone)]
struct ConfigArgs {
    /// Config file (default: ./generator.toml if present, else the built-in defaults).
    #[arg(long, conflicts_with = "no_config")]
    config: Option<PathBuf>,
    /// Ignore ./generator.toml: start from the built-in defaults.
    #[arg(long)]
    no_config: bool,
    /// Named bundle of overrides applied before --set (repeatable; later ones win).
    #[arg(long, value_parser = preset_names())]
    preset: Vec<String>,
    /// Override any config key, e.g. --set camera.resolution=[64,64] (repeatable).
    #[arg(long = "set", value_name = "SECTION.KEY=VALUE")]
    sets: Vec<String>,
    #[command(flatten)]
    workers: Workers,
}

/// The presets the config knows, with their one-line descriptions, for parsing, `--help` and
/// completions.
fn preset_names() -> PossibleValuesParser {
    PossibleValuesParser::new(
        PRESETS
            .iter()
            .map(|p| PossibleValue::new(p.name).help(p.about)),
    )
}

#[derive(Args, Debug)]
struct GenerateArgs {
    /// Number of scenes (default: dataset.scenes of the config). Every 11th scene
    /// (dataset.val_every) goes to val/, the rest to train/; a smaller dataset puts its last
    /// scene in val/.
    #[arg(long)]
    scenes: Option<u64>,
    /// Output dataset folder (default: dataset.out of the config).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Dataset seed (overrides dataset.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Render only scenes with index % N == I, e.g. 0/4; `lfgen merge` joins the shards.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Keep scenes whose files verify against the manifest, redo the rest.
    #[arg(long)]
    resume: bool,
    /// A broken or hostile asset-catalogue entry (scene.catalog) is an error instead of a
    /// skipped entry with a warning.
    #[arg(long)]
    strict: bool,
    #[command(flatten)]
    common: ConfigArgs,
}

#[derive(Args, Debug)]
struct RenderArgs {
    /// A glTF 2.0 scene (.gltf or .glb), or a scene.json written by lfgen.
    scene: PathBuf,
    /// Output scene folder.
    #[arg(long)]
    out: PathBuf,
    /// glTF camera (or camera node) name for the centre view (default: gltf.camera).
    #[arg(long)]
    camera: Option<String>,
    #[command(flatten)]
    common: ConfigArgs,
}

#[derive(Args, Debug)]
struct ExportArgs {
    /// Target renderer.
    #[arg(long, value_enum)]
    to: Target,
    /// Scene folder holding scene.json.
    scene_dir: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Views as off-axis cameras: all, center, or a list such as 0,40,80.
    #[arg(long, default_value = "all")]
    views: String,
    /// The config's render.max_depth and render.rr_depth set the renderers' path limits.
    #[command(flatten)]
    common: ConfigArgs,
}

#[derive(Subcommand, Debug)]
enum BenchKind {
    /// Rays/s and the cost of the 128-slice ground truth, on built-in scene 0 at 192².
    Speed {
        #[command(flatten)]
        results: ResultsArg,
        #[command(flatten)]
        common: ConfigArgs,
    },
    /// Image quality: the centre view's PSNR against a converged render, the
    /// photo-consistency residual and the time, shared and independent shading side by side.
    Quality(QualityArgs),
}

#[derive(Args, Debug)]
struct QualityArgs {
    /// Built-in scenes to measure.
    #[arg(long, value_delimiter = ',', default_value = "0,1,2")]
    scenes: Vec<u64>,
    /// Image side in pixels (the reference takes 16× as long at 512² as at 128²).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(16..=4096))]
    size: u32,
    /// Also write each scene's centre views (reference, shared, independent, and each
    /// shading's second render `*_again`, whose difference from the first is the view's own
    /// noise; linear EXR and tone-mapped PNG) into this folder.
    #[arg(long)]
    images: Option<PathBuf>,
    #[command(flatten)]
    results: ResultsArg,
    #[command(flatten)]
    common: ConfigArgs,
}

/// Where a benchmark's record goes.
#[derive(Args, Debug)]
struct ResultsArg {
    /// Results file the run appends its figures to, one JSON line (docs/reference/results.md).
    #[arg(long, value_name = "FILE", default_value = lfformat::results::DEFAULT_PATH)]
    results: PathBuf,
}

/// The command line, with the generation flags of bare `lfgen` hidden from `lfgen --help`
/// (they are `lfgen generate`'s, listed there).
fn command() -> clap::Command {
    Cli::command().mut_args(|a| a.hide(true))
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
    let Some(chosen) = cli.command else {
        return generate(cli.generate);
    };
    match chosen {
        Command::Generate(a) => generate(a),
        Command::Render(a) => {
            let cfg = load(&a.common)?;
            let camera = a.camera.as_deref();
            let quiet = a.common.workers.quiet;
            lfgen::pipeline::render_file(&cfg, &a.scene, camera, &a.out, quiet)
        }
        Command::Textures { count, out, seed } => {
            let cat = lfgen::output::texture_library::write_library(&out, count, seed)?;
            lfformat::say!(
                "{}: {} textures and catalog.json",
                out.display(),
                cat.textures.len()
            )?;
            Ok(())
        }
        Command::Preview { dataset } => {
            let n = lfgen::output::preview::write_contact_sheets(&dataset)?;
            lfformat::say!(
                "{}: {n} contact sheets and index.html",
                dataset.join("previews").display()
            )?;
            Ok(())
        }
        Command::Assets {
            command: AssetsCommand::Fetch(a),
        } => {
            let summary = match a.source {
                AssetSource::Sweethome3d => lfgen::catalog::sweethome3d::fetch(&a.out, a.nonfree)?,
            };
            lfformat::console::stdout(format_args!("{summary}"))?;
            Ok(())
        }
        Command::Merge { dataset } => {
            let m = dataset::merge(&dataset)?;
            lfformat::say!(
                "{}: manifest.json with {} verified scenes",
                dataset.display(),
                m.scenes.len()
            )?;
            Ok(())
        }
        Command::Bench { kind } => bench(kind),
        Command::Export(a) => {
            let cfg = load(&a.common)?;
            let views = lfgen::export::extract::ViewSelection::parse(&a.views)?;
            let limits = lfgen::export::PathLimits {
                max_depth: cfg.render.max_depth,
                rr_depth: cfg.render.rr_depth,
            };
            lfgen::export::export_scene_dir(&a.scene_dir, a.to, &a.out, &views, limits)
        }
        Command::Generated(g) => Ok(g.print(command())?),
        Command::Doc { page } => {
            let text = match page {
                DocPage::Cli => cli_markdown(),
                DocPage::Config => lfgen::reference::config_markdown(),
            };
            lfformat::console::stdout(format_args!("{text}"))?;
            Ok(())
        }
    }
}

/// docs/reference/cli.md: every command and flag, from the definitions above.
fn cli_markdown() -> String {
    let generated = "Generated from the flag definitions by `lfgen doc cli` (do not edit by \
                     hand: run `lfgen doc cli > docs/reference/cli.md`). `lftrain` and \
                     `lfeval`: [cli-lftrain.md](cli-lftrain.md), [cli-lfeval.md](cli-lfeval.md).";
    lfformat::cli::reference(&command(), generated)
}

/// Runs a benchmark and appends its record to the results file.
fn bench(kind: BenchKind) -> Result<()> {
    let (figures, results) = match kind {
        BenchKind::Speed { results, common } => (lfgen::bench::speed(&load(&common)?)?, results),
        BenchKind::Quality(a) => {
            let cfg = load(&a.common)?;
            let images = a.images.as_deref();
            (
                lfgen::bench::quality(&cfg, &a.scenes, a.size, images)?,
                a.results,
            )
        }
    };
    lfformat::results::Record::now("lfgen", figures).append(&results.results)?;
    lfformat::note!("figures appended to {}", results.results.display());
    Ok(())
}

/// Loads the config and sets up the thread pool. An implicit ./generator.toml is announced, so
/// a file left in the working directory never changes a run unnoticed.
fn load(a: &ConfigArgs) -> Result<Config> {
    a.workers.apply().context("cannot set --threads")?;
    let default = Path::new("generator.toml");
    let path = match (&a.config, a.no_config) {
        (Some(path), _) => Some(path.as_path()),
        (None, false) if default.exists() => {
            lfformat::note!(
                "using ./generator.toml (pass --config FILE to choose another, --no-config to \
                 ignore it)"
            );
            Some(default)
        }
        (None, _) => None,
    };
    Config::load(path, &a.preset, &a.sets)
}

/// Scene folders are numbered with four or more digits; ten million scenes is far beyond any
/// dataset and keeps the progress arithmetic in range.
const MAX_SCENES: u64 = 10_000_000;

fn generate(a: GenerateArgs) -> Result<()> {
    let mut cfg = load(&a.common)?;
    if let Some(line) = cfg.resolve_catalog(Path::new(".")) {
        lfformat::note!("{line}");
    }
    if let Some(seed) = a.seed {
        cfg.dataset.seed = seed;
    }
    let shard = match &a.shard {
        Some(s) => parse_shard(s)?,
        None => (0, 1),
    };
    let scenes = a.scenes.unwrap_or(cfg.dataset.scenes);
    if scenes > MAX_SCENES {
        bail!("--scenes {scenes}: at most {MAX_SCENES}");
    }
    let opts = GenerateOptions {
        scenes,
        out: a.out.unwrap_or_else(|| PathBuf::from(&cfg.dataset.out)),
        shard,
        resume: a.resume,
        quiet: a.common.workers.quiet,
        strict: a.strict,
    };
    dataset::generate(&cfg, &opts)?;
    lfformat::note!("{}", next_steps(&cfg, &opts));
    Ok(())
}

/// Where the data is and what to run on it next.
fn next_steps(cfg: &Config, opts: &GenerateOptions) -> String {
    let out = opts.out.display();
    let (i, n) = opts.shard;
    if n > 1 {
        return format!(
            "shard {i}/{n} written to {out}; once every shard is done: lfgen merge {out}"
        );
    }
    let val = (0..opts.scenes)
        .filter(|&k| dataset::split_of(cfg, k, opts.scenes) == "val")
        .count() as u64;
    let train = opts.scenes - val;
    let mut text = format!("dataset written to {out}: {train} scenes in train/, {val} in val/");
    if val == 0 {
        text += "\nno val/ split: it needs at least 2 scenes (and dataset.val_every > 0)";
        return text;
    }
    text += &format!(
        "\nnext, train a model and evaluate it beside the classical baseline:\n  \
         lftrain train --model base --config crates/lftrain/configs/quickstart.toml \
         --train {out}/train --val {out}/val --out runs/quickstart\n  \
         lftrain predict runs/quickstart {out}/val --out predictions/model\n  \
         lfeval baseline {out}/val --out predictions/baseline\n  \
         lfeval {out}/val predictions/model predictions/baseline --out report"
    );
    text
}

fn parse_shard(s: &str) -> Result<(u64, u64)> {
    let parsed = s
        .split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parsed {
        Some((i, n)) if n > 0 && i < n => Ok((i, n)),
        _ => bail!("--shard {s:?}: expected I/N with 0 <= I < N"),
    }
}
