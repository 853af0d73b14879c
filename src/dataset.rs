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
use lfformat::manifest::{Manifest, SceneEntry, scene_entry_verifies, verify_scene_entry};
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

/// Split of scene `index` of a dataset of `scenes` scenes (see `dataset.val_every`): every
/// `val_every`-th scene goes to `val`, and a dataset too small to hold one such scene still
/// gets a `val` split: its last scene (none when it has a single scene). The rule depends on
/// the total count alone, so every shard of a dataset agrees on it.
pub fn split_of(cfg: &Config, index: u64, scenes: u64) -> &'static str {
    let every = cfg.dataset.val_every;
    let val = match every {
        0 => false,
        _ if scenes < every => scenes >= 2 && index == scenes - 1,
        _ => index % every == every - 1,
    };
    if val { "val" } else { "train" }
}

/// Folder of scene `index` of a dataset of `scenes` scenes, relative to the dataset root.
pub fn scene_dir(cfg: &Config, index: u64, scenes: u64) -> String {
    format!("{}/scene_{index:04}", split_of(cfg, index, scenes))
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
    check_dataset_or_empty(&opts.out)?;
    let _locks = lock_dataset(&opts.out, opts.shard)?;
    let manifest_path = opts.out.join(manifest_name(opts.shard));
    let mut manifest = open_manifest(cfg, opts, &manifest_path)?;
    let shard_scenes = check_other_manifests(opts, &manifest.config_hash)?;
    check_unlisted_scenes(cfg, opts)?;
    if opts.shard.1 > 1 {
        check_one_layout(&opts.out, opts.shard.1)?;
        // Written at once so that a shard of another layout starting now sees this one.
        let fresh = !manifest_path.exists();
        mark_dataset(&opts.out)?;
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
    let per_scene = w as u64 * h as u64 * job.render.samples_per_pixel(views);
    let bar = progress_bar(todo.len() as u64 * per_scene, opts.quiet);
    let samples = AtomicU64::new(0);
    let (mut done, mut skipped, mut unsaved) = (0, 0, false);
    for index in todo {
        let dir = scene_dir(cfg, index, opts.scenes);
        let kept = opts.resume.then(|| {
            let candidates = manifest.scenes.iter().chain(&shard_scenes);
            candidates
                .filter(|e| e.index == index)
                .find(|e| scene_entry_verifies(&opts.out, e))
                .cloned()
        });
        if let Some(entry) = kept.flatten() {
            unsaved |= !manifest.scenes.contains(&entry);
            record(&mut manifest, entry);
            skipped += 1;
            samples.fetch_add(per_scene, Ordering::Relaxed);
            continue;
        }
        let started = Instant::now();
        let (mut desc, scene) = generate_scene(cfg, index, library.as_ref())
            .with_context(|| format!("scene {index}"))?;
        mark_dataset(&opts.out)?;
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
        let split = split_of(cfg, index, opts.scenes).into();
        record(
            &mut manifest,
            SceneEntry {
                index,
                split,
                dir,
                files,
            },
        );
        manifest.write(&manifest_path)?;
        unsaved = false;
        log_timing(&opts.out, index, started.elapsed().as_secs_f64(), per_scene)?;
        done += 1;
        bar.set_message(format!("{done} scenes rendered, {skipped} verified"));
    }
    bar.finish_with_message(format!(
        "{done} scenes rendered, {skipped} verified and kept"
    ));
    if unsaved {
        manifest.write(&manifest_path)?;
    }
    if opts.shard.1 == 1 {
        write_readme(&opts.out, &manifest)?;
    }
    Ok(())
}

/// Puts `entry` into `manifest` in place of any entry of its scene.
fn record(manifest: &mut Manifest, entry: SceneEntry) {
    manifest.scenes.retain(|e| e.index != entry.index);
    manifest.scenes.push(entry);
    manifest.scenes.sort_by_key(|e| e.index);
    manifest.splits = count_splits(&manifest.scenes);
}

/// The asset library of `scene.catalog`, checked once; each skipped entry is reported on one
/// warning line.
fn open_library(cfg: &Config, strict: bool) -> Result<Option<AssetLibrary>> {
    if cfg.scene.catalog.is_empty() {
        return Ok(None);
    }
    if cfg.scene.catalog == crate::procgen::settings::AUTO_CATALOG {
        bail!("scene.catalog = \"auto\": call Config::resolve_catalog before generating");
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

/// The file that marks a folder as an lfgen dataset, written before the first file of the
/// dataset: runs write into a folder only if it is new, empty, marked or holds a manifest, so
/// a folder of the user's (their `README.md`, `summary.json`, …) is never written into.
const DATASET_MARKER: &str = ".lfgen-dataset";

/// Fails, before anything is created or written, if `out` is an existing folder that holds
/// files but is no lfgen dataset (no [`DATASET_MARKER`], no manifest). The lock files of a run
/// killed before it wrote anything do not count.
fn check_dataset_or_empty(out: &Path) -> Result<()> {
    if !out.is_dir() {
        return Ok(());
    }
    let mut foreign = Vec::new();
    for entry in fs::read_dir(out).with_context(|| format!("cannot list {}", out.display()))? {
        let name = entry?.file_name().to_string_lossy().into_owned();
        let lock =
            name == DATASET_LOCK || (name.starts_with(".lfgen.shard-") && name.ends_with(".lock"));
        if name == DATASET_MARKER || name == "manifest.json" || shard_count(&name).is_some() {
            return Ok(());
        }
        if !lock {
            foreign.push(name);
        }
    }
    foreign.sort();
    let Some(first) = foreign.first() else {
        return Ok(());
    };
    bail!(
        "--out {} is not an lfgen dataset and not empty (it holds {first:?}{}): lfgen writes a \
         dataset only into a new or empty folder, or one it made; choose another --out",
        out.display(),
        if foreign.len() > 1 { ", …" } else { "" }
    )
}

/// Writes [`DATASET_MARKER`] into `out` unless it is there. Created in place, never under a
/// temporary name that a concurrent run would take for a foreign file; its presence is all
/// that counts, so a write cut short still marks the folder.
fn mark_dataset(out: &Path) -> Result<()> {
    let path = out.join(DATASET_MARKER);
    let text = b"This folder is an lfgen dataset (see manifest.json and README.md).\n";
    let created = fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&path);
    match created {
        Ok(mut file) => file.write_all(text),
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => Err(e),
    }
    .with_context(|| format!("cannot write {}", path.display()))
}

/// Checks the other manifests of `out` against this run, and returns the scenes of shard
/// manifests that an unsharded `--resume` may keep. Every manifest must be of this config and
/// seed: a run of another would overwrite their scenes. An unsharded run without `--resume`
/// also refuses shards that were not merged: their scenes are a dataset of their own.
fn check_other_manifests(opts: &GenerateOptions, config_hash: &str) -> Result<Vec<SceneEntry>> {
    let own = manifest_name(opts.shard);
    let mut others = Vec::new();
    for name in manifest_names(&opts.out)? {
        if name != own {
            others.push((Manifest::read(&opts.out.join(&name))?, name));
        }
    }
    let unsharded = opts.shard.1 == 1;
    if unsharded && !opts.resume {
        refuse_unmerged_shards(&opts.out, &others)?;
    }
    if let Some((m, name)) = others.iter().find(|(m, _)| m.config_hash != config_hash) {
        bail!(
            "{}: a dataset of another config or seed (seed {}, {} scene(s)) is in this folder, \
             and this run would overwrite its scenes: run with its config and seed to complete \
             it, or choose another --out",
            opts.out.join(name).display(),
            m.seed,
            m.scenes.len()
        );
    }
    Ok(match unsharded {
        true => others.into_iter().flat_map(|(m, _)| m.scenes).collect(),
        false => Vec::new(),
    })
}

/// Fails if any of `manifests` (those beside an unsharded run's own) lists scenes.
fn refuse_unmerged_shards(out: &Path, manifests: &[(Manifest, String)]) -> Result<()> {
    let listing: Vec<&(Manifest, String)> = manifests
        .iter()
        .filter(|(m, _)| !m.scenes.is_empty())
        .collect();
    let Some((first, _)) = listing.first() else {
        return Ok(());
    };
    let names: Vec<&str> = listing.iter().map(|(_, n)| n.as_str()).collect();
    let scenes: usize = listing.iter().map(|(m, _)| m.scenes.len()).sum();
    bail!(
        "{} holds {scenes} scene(s) of a sharded run that was not merged ({}; seed {}): run \
         `lfgen merge {}` to join them into one dataset, pass --resume with their config and \
         seed to complete the dataset from them, or choose another --out",
        out.display(),
        names.join(", "),
        first.seed,
        out.display()
    )
}

/// The dataset-wide lock file (see the module docs).
const DATASET_LOCK: &str = ".lfgen.lock";

const LOCK_HELP: &str = "another lfgen run is writing this dataset (an unsharded run or a \
                         merge excludes every other run; shards exclude only their own shard)";

/// Fails if `out` holds shard manifests of a split into other than `n` shards: their scene
/// indices overlap this run's.
fn check_one_layout(out: &Path, n: u64) -> Result<()> {
    for name in manifest_names(out)? {
        if let Some(m) = shard_count(&name).filter(|&m| m != n) {
            bail!(
                "{} holds {name} of a {m}-way split; this run is {n}-way: shards of one dataset \
                 must use one N",
                out.display()
            );
        }
    }
    Ok(())
}

/// `N` of a shard manifest's name `manifest.shard-I-of-N.json`.
fn shard_count(name: &str) -> Option<u64> {
    name.strip_prefix("manifest.shard-")
        .and_then(|r| r.strip_suffix(".json"))
        .and_then(|r| r.split_once("-of-"))
        .and_then(|(_, m)| m.parse().ok())
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
            let foreign = *index >= opts.scenes || *dir != scene_dir(cfg, *index, opts.scenes);
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
    let line = serde_json::json!({ "scene": index, "seconds": seconds, "camera_rays_per_second": samples as f64 / seconds });
    Ok(lfformat::files::append_line(
        &out.join("timings.jsonl"),
        &line.to_string(),
    )?)
}

/// Unions `manifest.json` and every `manifest.shard-*.json` of `out` into `manifest.json`.
/// Every shard of the split must have run and every listed scene must verify: a missing shard
/// or a damaged scene fails the merge, naming each, and writes nothing, so a merge job never
/// reports success on a smaller dataset.
pub fn merge(out: &Path) -> Result<Manifest> {
    if !out.is_dir() {
        bail!("{}: no such dataset folder", out.display());
    }
    let _lock = Lock::exclusive(&out.join(DATASET_LOCK)).context(LOCK_HELP)?;
    let names = manifest_names(out)?;
    check_every_shard_ran(out, &names)?;
    let mut parts = Vec::new();
    for name in &names {
        parts.push(Manifest::read(&out.join(name))?);
    }
    let mut merged = parts
        .first()
        .cloned()
        .with_context(|| format!("{}: no manifest to merge", out.display()))?;
    if parts.iter().any(|p| p.config_hash != merged.config_hash) {
        bail!(
            "{}: shards were generated with different configs",
            out.display()
        );
    }
    merged.scenes = verified_scenes(out, parts.into_iter().flat_map(|p| p.scenes))?;
    merged.splits = count_splits(&merged.scenes);
    merged.write(&out.join("manifest.json"))?;
    write_readme(out, &merged)?;
    Ok(merged)
}

/// Fails if `names` hold shard manifests of an `N`-way split but not all `N` of them: a shard
/// that never ran (each writes its manifest as it starts) would leave its scenes out.
fn check_every_shard_ran(out: &Path, names: &[String]) -> Result<()> {
    let Some(n) = names.iter().find_map(|name| shard_count(name)) else {
        return Ok(());
    };
    let missing: Vec<String> = (0..n)
        .map(|i| manifest_name((i, n)))
        .filter(|name| !names.contains(name))
        .collect();
    if let Some(first) = missing.first() {
        bail!(
            "{} has no {first}{}: {} of the {n} shards never ran; run them (--shard I/{n}, with \
             --resume), then merge",
            out.display(),
            if missing.len() > 1 { " and others" } else { "" },
            missing.len()
        );
    }
    Ok(())
}

/// One entry per scene index among `entries`, each verified against its files; fails naming
/// every scene of which no entry verifies, and why.
fn verified_scenes(
    out: &Path,
    entries: impl Iterator<Item = SceneEntry>,
) -> Result<Vec<SceneEntry>> {
    let mut good = BTreeMap::new();
    let mut damaged = BTreeMap::new();
    for e in entries {
        if good.contains_key(&e.index) {
            continue;
        }
        match verify_scene_entry(out, &e) {
            Ok(()) => {
                damaged.remove(&e.index);
                good.insert(e.index, e);
            }
            Err(why) => {
                damaged.insert(e.index, format!("scene {} ({}): {why}", e.index, e.dir));
            }
        }
    }
    if !damaged.is_empty() {
        let list: Vec<String> = damaged.into_values().collect();
        bail!(
            "{}: {} scene(s) do not verify, so nothing was merged:\n  {}\nrender them again \
             with their shard's command and --resume (it redoes scenes that do not verify), \
             then merge",
            out.display(),
            list.len(),
            list.join("\n  ")
        );
    }
    Ok(good.into_values().collect())
}

/// A short human-readable description at the dataset root.
fn write_readme(out: &Path, m: &Manifest) -> Result<()> {
    mark_dataset(out)?;
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
    let dirs: Vec<String> = m.scenes.iter().map(|e| e.dir.clone()).collect();
    let summary = write_summary(out, &dirs)?;
    let text = text + &appearance_note(summary.appearance.as_ref());
    lfformat::files::write_atomic(&out.join("README.md"), text.as_bytes())?;
    crate::output::preview::write_preview(out, &dirs)
}

/// The README's paragraph on the centre views' appearance: median and quartiles over scenes.
fn appearance_note(a: Option<&crate::stats::AppearanceSummary>) -> String {
    let Some(a) = a else {
        return String::new();
    };
    let q = |v: &[f64; 5], scale: f64| {
        format!(
            "{:.1} ({:.1}–{:.1})",
            v[2] * scale,
            v[1] * scale,
            v[3] * scale
        )
    };
    format!(
        "\nAppearance of the centre views, median (quartiles) over scenes, on 8-bit luminance: \
         local contrast (median |residual of a 3×3 mean filter|) {} levels; flat 16×16 blocks \
         (residual std < 1.5 levels) {} %; mean luminance {}; noise σ (Immerkær) {} levels. \
         `summary.json` has min, quartiles and max.\n",
        q(&a.local_contrast, 1.0),
        q(&a.flat_share, 100.0),
        q(&a.mean_luminance, 1.0),
        q(&a.noise, 1.0),
    )
}

/// `summary.json`: the dataset-wide statistics over every scene's `stats.json`.
fn write_summary(out: &Path, dirs: &[String]) -> Result<DatasetSummary> {
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
    lfformat::files::write_atomic(&out.join("summary.json"), text.as_bytes())?;
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn val_scenes(cfg: &Config, scenes: u64) -> Vec<u64> {
        (0..scenes)
            .filter(|&i| split_of(cfg, i, scenes) == "val")
            .collect()
    }

    /// Every dataset of two or more scenes has a val split; from `val_every` scenes on it is
    /// the fixed every-11th rule, so full-size datasets keep their split.
    #[test]
    fn small_datasets_put_their_last_scene_in_val_and_large_ones_every_eleventh() {
        let mut cfg = Config::default();
        assert_eq!(val_scenes(&cfg, 1), Vec::<u64>::new());
        assert_eq!(val_scenes(&cfg, 2), [1]);
        assert_eq!(val_scenes(&cfg, 4), [3]);
        assert_eq!(val_scenes(&cfg, 10), [9]);
        assert_eq!(val_scenes(&cfg, 11), [10]);
        assert_eq!(val_scenes(&cfg, 21), [10]);
        assert_eq!(
            val_scenes(&cfg, 110),
            (0..10).map(|k| 11 * k + 10).collect::<Vec<_>>()
        );
        cfg.dataset.val_every = 0;
        assert_eq!(val_scenes(&cfg, 4), Vec::<u64>::new());
    }
}
