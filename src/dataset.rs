//! Many scenes: splits, shards, resume, the manifest and progress.
//!
//! A scene's split and folder are pure functions of its index and the config, so shards and
//! resumed runs agree on where every scene goes. After each published scene the manifest is
//! rewritten atomically, so a killed run loses at most the scene in flight.
//!
//! Two runs never share a dataset folder unknowingly: an unsharded run and `merge` hold
//! `.lfgen.lock` exclusively, shards hold it shared plus their own `.lfgen.shard-I-of-N.lock`
//! (see [`lfformat::lock`]), so shards on a shared filesystem run side by side while a second
//! unsharded run, a repeated shard or a merge under running shards fails at once. Scene folders
//! that no manifest lists (a deleted manifest, an older run) are never silently left beside a
//! new dataset: a run without `--resume` refuses such a folder, a resumed one re-renders those
//! in its range and refuses those outside it.

use crate::config::Config;
use crate::pipeline::{RenderJob, generate_scene, render_scene};
use crate::procgen::library::AssetLibrary;
use crate::stats::{DatasetSummary, SceneStats};
use anyhow::{Context, Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use lfformat::lock::Lock;
use lfformat::manifest::{Manifest, SceneEntry, scene_entry_verifies};
use std::collections::BTreeMap;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// What to generate and where.
#[derive(Clone, Debug)]
pub struct GenerateOptions {
    pub scenes: u64,
    pub out: PathBuf,
    /// `(i, n)`: render scenes with `index % n == i`.
    pub shard: (u64, u64),
    pub resume: bool,
    pub quiet: bool,
    /// A broken asset-catalogue entry is an error instead of a skipped entry.
    pub strict: bool,
}

/// Split of scene `index` (see `dataset.val_every`).
pub fn split_of(cfg: &Config, index: u64) -> &'static str {
    let every = cfg.dataset.val_every;
    if every > 0 && index % every == every - 1 {
        "val"
    } else {
        "train"
    }
}

/// Folder of scene `index`, relative to the dataset root.
pub fn scene_dir(cfg: &Config, index: u64) -> String {
    format!("{}/scene_{index:04}", split_of(cfg, index))
}

fn manifest_name((i, n): (u64, u64)) -> String {
    if n > 1 {
        format!("manifest.shard-{i}-of-{n}.json")
    } else {
        "manifest.json".into()
    }
}

/// Generates the dataset (or this shard of it).
pub fn generate(cfg: &Config, opts: &GenerateOptions) -> Result<()> {
    let _locks = lock_dataset(&opts.out, opts.shard)?;
    let manifest_path = opts.out.join(manifest_name(opts.shard));
    let mut manifest = open_manifest(cfg, opts, &manifest_path)?;
    check_unlisted_scenes(cfg, opts)?;
    if opts.shard.1 > 1 {
        check_one_layout(&opts.out, opts.shard.1)?;
        // Written at once so that a shard of another layout starting now sees this one.
        let fresh = !manifest_path.exists();
        manifest.write(&manifest_path)?;
        if let Err(e) = check_one_layout(&opts.out, opts.shard.1) {
            if fresh {
                let _ = fs::remove_file(&manifest_path);
            }
            return Err(e);
        }
    }
    let todo: Vec<u64> = (0..opts.scenes)
        .filter(|i| i % opts.shard.1 == opts.shard.0)
        .collect();
    let job = RenderJob::from_config(cfg, &cfg.dataset.render_date());
    let library = open_library(cfg, opts.strict)?;
    let [w, h] = cfg.camera.resolution;
    let views = cfg.camera.grid[0] * cfg.camera.grid[1];
    let per_scene = w as u64 * h as u64 * job.samples_per_pixel(views);
    let bar = progress_bar(todo.len() as u64 * per_scene, opts.quiet);
    let samples = AtomicU64::new(0);
    let (mut done, mut skipped) = (0, 0);
    for index in todo {
        let dir = scene_dir(cfg, index);
        if opts.resume
            && manifest
                .scenes
                .iter()
                .any(|e| e.index == index && scene_entry_verifies(&opts.out, e))
        {
            skipped += 1;
            samples.fetch_add(per_scene, Ordering::Relaxed);
            continue;
        }
        let started = Instant::now();
        let (mut desc, scene) = generate_scene(cfg, index, library.as_ref())
            .with_context(|| format!("scene {index}"))?;
        let before = samples.load(Ordering::Relaxed);
        let files = std::thread::scope(|s| {
            let ticker = s.spawn(|| tick(&bar, &samples, before + per_scene));
            let r = render_scene(
                &mut desc,
                &scene,
                &job,
                &opts.out.join(&dir),
                &opts.out,
                &samples,
            );
            samples.store(before + per_scene, Ordering::Relaxed);
            ticker.join().expect("progress thread");
            r
        })
        .with_context(|| format!("scene {index} ({dir})"))?;
        manifest.scenes.retain(|e| e.index != index);
        manifest.scenes.push(SceneEntry {
            index,
            split: split_of(cfg, index).into(),
            dir: dir.clone(),
            files,
        });
        manifest.scenes.sort_by_key(|e| e.index);
        manifest.splits = count_splits(&manifest.scenes);
        manifest.write(&manifest_path)?;
        log_timing(&opts.out, index, started.elapsed().as_secs_f64(), per_scene)?;
        done += 1;
        bar.set_message(format!("{done} scenes rendered, {skipped} verified"));
    }
    bar.finish_with_message(format!(
        "{done} scenes rendered, {skipped} verified and kept"
    ));
    if opts.shard.1 == 1 {
        write_readme(&opts.out, &manifest)?;
    }
    Ok(())
}

/// The asset library of `scene.catalog`, checked once; each skipped entry is reported on one
/// warning line.
fn open_library(cfg: &Config, strict: bool) -> Result<Option<AssetLibrary>> {
    if cfg.scene.catalog.is_empty() {
        return Ok(None);
    }
    let path = Path::new(&cfg.scene.catalog);
    lfformat::note!("checking the asset catalogue {} …", path.display());
    let library = AssetLibrary::open(path, strict)?;
    for line in &library.skipped {
        lfformat::note!("warning: {}: skipped {line}", path.display());
    }
    lfformat::note!(
        "{}: {} assets usable, {} skipped",
        path.display(),
        library.len(),
        library.skipped.len()
    );
    Ok(Some(library))
}

/// Keeps the progress bar moving while a scene renders; stops when `end` samples are done.
fn tick(bar: &ProgressBar, samples: &AtomicU64, end: u64) {
    loop {
        let n = samples.load(Ordering::Relaxed);
        bar.set_position(n);
        if n >= end {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
    }
}

fn progress_bar(total: u64, quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    let style = "{elapsed_precise} [{bar:30}] {percent}% {human_pos}/{human_len} camera rays, {per_sec}, ETA {eta} — {msg}";
    bar.set_style(
        ProgressStyle::with_template(style)
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}

/// The existing manifest when resuming (same config only), else a fresh one.
fn open_manifest(cfg: &Config, opts: &GenerateOptions, path: &Path) -> Result<Manifest> {
    let fresh = Manifest {
        generator: "lfgen".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        config_hash: cfg.hash(),
        seed: cfg.dataset.seed,
        config: serde_json::to_value(cfg)?,
        splits: BTreeMap::new(),
        scenes: Vec::new(),
    };
    if !path.exists() {
        return Ok(fresh);
    }
    let old = Manifest::read(path)?;
    if !opts.resume && !old.scenes.is_empty() {
        bail!(
            "{} already holds a dataset ({} scenes): pass --resume to complete it, or choose another --out",
            opts.out.display(),
            old.scenes.len()
        );
    }
    if old.config_hash != fresh.config_hash {
        bail!(
            "{}: the dataset was generated with a different config; resume needs the same config",
            path.display()
        );
    }
    Ok(Manifest {
        splits: count_splits(&old.scenes),
        scenes: old.scenes,
        ..fresh
    })
}

fn count_splits(scenes: &[SceneEntry]) -> BTreeMap<String, u64> {
    let mut m = BTreeMap::new();
    for e in scenes {
        *m.entry(e.split.clone()).or_insert(0) += 1;
    }
    m
}

/// Creates `out` and takes the dataset's locks: `.lfgen.lock` exclusively for an unsharded run,
/// shared plus the shard's own lock for a shard. Creating the lock file is also the early check
/// that the folder is writable.
fn lock_dataset(out: &Path, (i, n): (u64, u64)) -> Result<Vec<Lock>> {
    if out.exists() && !out.is_dir() {
        bail!(
            "--out {} is a file, not a folder: choose a folder for the dataset",
            out.display()
        );
    }
    fs::create_dir_all(out)
        .with_context(|| format!("cannot create output folder {}", out.display()))?;
    let dataset = out.join(DATASET_LOCK);
    if n == 1 {
        return Ok(vec![Lock::exclusive(&dataset).context(LOCK_HELP)?]);
    }
    let shared = Lock::shared(&dataset).context(LOCK_HELP)?;
    let shard = Lock::exclusive(&out.join(format!(".lfgen.shard-{i}-of-{n}.lock")))
        .context("this shard is being generated by another run")?;
    Ok(vec![shard, shared])
}

/// The dataset-wide lock file (see the module docs).
const DATASET_LOCK: &str = ".lfgen.lock";

const LOCK_HELP: &str = "another lfgen run is writing this dataset (an unsharded run or a \
                         merge excludes every other run; shards exclude only their own shard)";

/// Fails if `out` holds shard manifests of a split into other than `n` shards: their scene
/// indices overlap this run's.
fn check_one_layout(out: &Path, n: u64) -> Result<()> {
    for name in manifest_names(out)? {
        let other = name
            .strip_prefix("manifest.shard-")
            .and_then(|r| r.strip_suffix(".json"))
            .and_then(|r| r.split_once("-of-"))
            .and_then(|(_, m)| m.parse::<u64>().ok());
        if let Some(m) = other.filter(|&m| m != n) {
            bail!(
                "{} holds {name} of a {m}-way split; this run is {n}-way: shards of one dataset \
                 must use one N",
                out.display()
            );
        }
    }
    Ok(())
}

/// `manifest.json` and `manifest.shard-*.json` in `out`, sorted.
fn manifest_names(out: &Path) -> Result<Vec<String>> {
    let mut names = Vec::new();
    for entry in fs::read_dir(out).with_context(|| format!("cannot list {}", out.display()))? {
        let name = entry?.file_name().to_string_lossy().into_owned();
        if name == "manifest.json"
            || (name.starts_with("manifest.shard-") && name.ends_with(".json"))
        {
            names.push(name);
        }
    }
    names.sort();
    Ok(names)
}

/// Scene folders under `out` (`SPLIT/scene_NNNN`, any split folder) with their indices.
fn scene_folders(out: &Path) -> Result<Vec<(String, u64)>> {
    let mut found = Vec::new();
    for split in fs::read_dir(out).with_context(|| format!("cannot list {}", out.display()))? {
        let split = split?;
        if !split.file_type()?.is_dir() {
            continue;
        }
        let split_name = split.file_name().to_string_lossy().into_owned();
        for scene in fs::read_dir(split.path())
            .with_context(|| format!("cannot list {}", split.path().display()))?
        {
            let name = scene?.file_name().to_string_lossy().into_owned();
            if let Some(index) = name.strip_prefix("scene_").and_then(|n| n.parse().ok()) {
                found.push((format!("{split_name}/{name}"), index));
            }
        }
    }
    found.sort();
    Ok(found)
}

/// Refuses scene folders that no manifest of `out` lists: those that are no scene of this
/// dataset (index past `--scenes`, or in another split's folder) always, and this run's own
/// without `--resume` (the dataset is incomplete or damaged, and a new run would leave folders
/// beside it that its manifest does not describe; `--resume` renders them again). Another
/// shard's unlisted scenes are that shard's to redo.
fn check_unlisted_scenes(cfg: &Config, opts: &GenerateOptions) -> Result<()> {
    let mut listed = std::collections::BTreeSet::new();
    for name in manifest_names(&opts.out)? {
        let m = Manifest::read(&opts.out.join(&name))?;
        listed.extend(m.scenes.into_iter().map(|e| e.dir));
    }
    let stray: Vec<String> = scene_folders(&opts.out)?
        .into_iter()
        .filter(|(dir, index)| {
            let foreign = *index >= opts.scenes || *dir != scene_dir(cfg, *index);
            let mine = index % opts.shard.1 == opts.shard.0;
            !listed.contains(dir) && (foreign || (mine && !opts.resume))
        })
        .map(|(dir, _)| dir)
        .collect();
    let Some(first) = stray.first() else {
        return Ok(());
    };
    let remedy = if opts.resume {
        "they are not scenes of this dataset: remove them, or choose another --out"
    } else {
        "the dataset is incomplete or damaged: pass --resume to verify and complete it \
         (unlisted scenes are rendered again), or choose another --out"
    };
    bail!(
        "{} holds {} scene folder(s) that no manifest lists ({first}{}): {remedy}",
        opts.out.display(),
        stray.len(),
        if stray.len() > 1 { ", …" } else { "" }
    )
}

/// Render timings live outside the scene folders so those stay byte-reproducible.
fn log_timing(out: &Path, index: u64, seconds: f64, samples: u64) -> Result<()> {
    let path = out.join("timings.jsonl");
    let line = serde_json::json!({ "scene": index, "seconds": seconds, "camera_rays_per_second": samples as f64 / seconds });
    let mut f = fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("cannot write {}", path.display()))?;
    writeln!(f, "{line}").with_context(|| format!("cannot write {}", path.display()))
}

/// Unions `manifest.json` and every `manifest.shard-*.json` of `out` into `manifest.json`,
/// keeping only scenes whose files verify.
pub fn merge(out: &Path) -> Result<Manifest> {
    if !out.is_dir() {
        bail!("{}: no such dataset folder", out.display());
    }
    let _lock = Lock::exclusive(&out.join(DATASET_LOCK)).context(LOCK_HELP)?;
    let mut parts = Vec::new();
    for name in manifest_names(out)? {
        parts.push(Manifest::read(&out.join(&name))?);
    }
    let mut merged = parts
        .first()
        .cloned()
        .with_context(|| format!("{}: no manifest to merge", out.display()))?;
    let mut scenes = BTreeMap::new();
    for p in &parts {
        if p.config_hash != merged.config_hash {
            bail!(
                "{}: shards were generated with different configs",
                out.display()
            );
        }
        for e in &p.scenes {
            if scene_entry_verifies(out, e) {
                scenes.insert(e.index, e.clone());
            }
        }
    }
    merged.scenes = scenes.into_values().collect();
    merged.splits = count_splits(&merged.scenes);
    merged.write(&out.join("manifest.json"))?;
    write_readme(out, &merged)?;
    Ok(merged)
}

/// A short human-readable description at the dataset root.
fn write_readme(out: &Path, m: &Manifest) -> Result<()> {
    let splits: Vec<String> = m.splits.iter().map(|(k, v)| format!("{v} {k}")).collect();
    let text = format!(
        "# lfgen dataset\n\nGenerated by {} {} with seed {} (config hash `{}`).\n\n\
         Scenes: {} ({}). Each scene folder is an HCI 4D light-field benchmark scene \
         (`parameters.cfg`, `input_CamNNN.png`, `gt_disp_lowres.pfm`, `gt_depth_lowres.pfm`) plus \
         multimodal ground truth (`modes.exr`, `gt_mpi_lowres.npz`), `scene.json` and `stats.json`.\n\
         `manifest.json` lists every file with its SHA-256. `preview.png`: per scene, the centre \
         view, the HCI disparity, the number of modes with η > 0.3 and η of the front mode. \
         `summary.json`: multimodal shares, mode counts, disparity range, exposure and placement \
         over all scenes.\n",
        m.generator,
        m.version,
        m.seed,
        m.config_hash,
        m.scenes.len(),
        splits.join(", ")
    );
    lfformat::files::write_atomic(&out.join("README.md"), text.as_bytes())?;
    let dirs: Vec<String> = m.scenes.iter().map(|e| e.dir.clone()).collect();
    write_summary(out, &dirs)?;
    crate::output::preview::write_preview(out, &dirs)
}

/// `summary.json`: the dataset-wide statistics over every scene's `stats.json`.
fn write_summary(out: &Path, dirs: &[String]) -> Result<()> {
    let stats = dirs
        .iter()
        .map(|d| {
            let path = out.join(d).join("stats.json");
            let text = fs::read_to_string(&path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            serde_json::from_str::<SceneStats>(&text)
                .with_context(|| format!("{}: not valid scene statistics", path.display()))
        })
        .collect::<Result<Vec<_>>>()?;
    let summary = DatasetSummary::new(&stats);
    let text = serde_json::to_string_pretty(&summary)? + "\n";
    Ok(lfformat::files::write_atomic(
        &out.join("summary.json"),
        text.as_bytes(),
    )?)
}
