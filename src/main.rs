//! `lfgen`: the command-line entry point. A thin dispatcher: parse, load the config, call one
//! library function per command, report errors once.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use lfgen::config::Config;
use lfgen::dataset::{self, GenerateOptions};
use std::path::PathBuf;

/// Generate multimodal light-field depth datasets (HCI format + 128-slice multimodal GT).
#[derive(Parser, Debug)]
#[command(version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    generate: GenerateArgs,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a glTF 2.0 scene, or re-render a saved scene.json, into a scene folder.
    Render(RenderArgs),
    /// Union shard manifests (and verify scenes) into one manifest.json.
    Merge {
        /// Dataset folder.
        dataset: PathBuf,
    },
    /// Measure rays/s and the cost of the 128-slice ground truth on a fixed built-in scene.
    Bench(BenchArgs),
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
    /// Write a contact sheet per scene and an overview page into DATASET/previews/.
    Preview {
        /// Dataset folder (with manifest.json).
        dataset: PathBuf,
    },
    /// Download external model libraries and convert them into an asset catalogue.
    Assets {
        #[command(subcommand)]
        command: AssetsCommand,
    },
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
    /// Config file (default: ./generator.toml if present, else built-in defaults).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Named override bundle applied before --set: full, quick, wide, clean (repeatable).
    #[arg(long)]
    preset: Vec<String>,
    /// Override any config key, e.g. --set camera.resolution=[64,64] (repeatable).
    #[arg(long = "set", value_name = "SECTION.KEY=VALUE")]
    sets: Vec<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Args, Debug)]
struct GenerateArgs {
    /// Number of scenes (default: dataset.scenes of the config).
    #[arg(long)]
    scenes: Option<u64>,
    /// Output dataset folder (default: dataset.out of the config).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Dataset seed (overrides dataset.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Render only scenes with index % N == I, e.g. 0/4.
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
    /// Target renderer: pov, blender or mitsuba.
    #[arg(long)]
    to: String,
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

#[derive(Args, Debug)]
struct BenchArgs {
    /// Image quality instead of speed: PSNR against a converged render, the photo-consistency
    /// residual and the time, shared and independent shading side by side.
    #[arg(long)]
    quality: bool,
    /// Built-in scenes of the quality benchmark.
    #[arg(long, value_delimiter = ',', default_value = "0,1,2")]
    scenes: Vec<u64>,
    /// Quality benchmark: image side in pixels (the default is the size of issue 14's
    /// measurements; at the dataset's 512² the auto baseline is narrower, so more glossy
    /// lobes are shared, and the reference takes 16× as long).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(16..=4096))]
    size: u32,
    /// Quality benchmark: also write each scene's centre views (reference, shared,
    /// independent, and each shading's second render `*_again`, whose difference from the
    /// first is the view's own noise; linear EXR and tone-mapped PNG) into this folder.
    #[arg(long)]
    images: Option<std::path::PathBuf>,
    #[command(flatten)]
    common: ConfigArgs,
}

fn main() {
    if let Err(e) = run(Cli::parse()) {
        lfformat::note!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Some(Command::Render(a)) => {
            let cfg = load(&a.common)?;
            let camera = a.camera.as_deref();
            lfgen::pipeline::render_file(&cfg, &a.scene, camera, &a.out, a.common.quiet)
        }
        Some(Command::Textures { count, out, seed }) => {
            let cat = lfgen::output::texture_library::write_library(&out, count, seed)?;
            lfformat::say!(
                "{}: {} textures and catalog.json",
                out.display(),
                cat.textures.len()
            )?;
            Ok(())
        }
        Some(Command::Preview { dataset }) => {
            let n = lfgen::output::preview::write_contact_sheets(&dataset)?;
            lfformat::say!(
                "{}: {n} contact sheets and index.html",
                dataset.join("previews").display()
            )?;
            Ok(())
        }
        Some(Command::Assets {
            command: AssetsCommand::Fetch(a),
        }) => {
            let summary = match a.source {
                AssetSource::Sweethome3d => lfgen::catalog::sweethome3d::fetch(&a.out, a.nonfree)?,
            };
            lfformat::console::stdout(format_args!("{summary}"))?;
            Ok(())
        }
        Some(Command::Merge { dataset }) => {
            let m = dataset::merge(&dataset)?;
            lfformat::say!(
                "{}: manifest.json with {} verified scenes",
                dataset.display(),
                m.scenes.len()
            )?;
            Ok(())
        }
        Some(Command::Bench(a)) => {
            let cfg = load(&a.common)?;
            match a.quality {
                true => lfgen::bench::quality(&cfg, &a.scenes, a.size, a.images.as_deref()),
                false => lfgen::bench::run(&cfg),
            }
        }
        Some(Command::Export(a)) => {
            let cfg = load(&a.common)?;
            let target = lfgen::export::Target::parse(&a.to)?;
            let views = lfgen::export::extract::ViewSelection::parse(&a.views)?;
            let limits = lfgen::export::PathLimits {
                max_depth: cfg.render.max_depth,
                rr_depth: cfg.render.rr_depth,
            };
            lfgen::export::export_scene_dir(&a.scene_dir, target, &a.out, &views, limits)
        }
        None => generate(cli.generate),
    }
}

/// Loads the config and sets up the thread pool.
fn load(a: &ConfigArgs) -> Result<Config> {
    if let Some(n) = a.threads {
        if n == 0 || n > MAX_THREADS {
            bail!("--threads {n}: expected 1 to {MAX_THREADS}");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot set --threads")?;
    }
    let default = PathBuf::from("generator.toml");
    let path = a
        .config
        .clone()
        .or_else(|| default.exists().then_some(default));
    Config::load(path.as_deref(), &a.preset, &a.sets)
}

/// More worker threads than this only cost memory (each keeps per-pixel buffers).
const MAX_THREADS: usize = 1024;

/// Scene folders are numbered with four or more digits; ten million scenes is far beyond any
/// dataset and keeps the progress arithmetic in range.
const MAX_SCENES: u64 = 10_000_000;

fn generate(a: GenerateArgs) -> Result<()> {
    let mut cfg = load(&a.common)?;
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
        quiet: a.common.quiet,
        strict: a.strict,
    };
    dataset::generate(&cfg, &opts)?;
    lfformat::note!("dataset written to {}", opts.out.display());
    Ok(())
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
