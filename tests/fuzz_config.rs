//! A mutation fuzzer for the generator config: thousands of damaged copies of `generator.toml`
//! (hostile numbers, wrong types, missing and unknown keys, emptied or grown arrays) must each
//! be refused with an error naming the file, or generate and render a scene — never panic,
//! hang or allocate without bound.
//!
//! Most cases run in-process (load, validate, generate the scene, render one 8×8 view) under a
//! per-case watchdog; a sample also runs through the `lfgen` binary under a time and
//! address-space limit, where an abort or a hang would show as a signal or a time-out.

mod bin;
mod mutate;
mod skip;

use bin::{can_bound, run_bounded};
use lfgen::config::Config;
use lfgen::pipeline::{RenderJob, generate_scene};
use mutate::mutate;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::Value;
use std::path::Path;
use std::sync::atomic::AtomicU64;
use std::sync::mpsc;
use std::time::Duration;

/// `generator.toml` (the documented defaults) as JSON: the fuzzer's seed file.
fn seed_config() -> Value {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("generator.toml"))
            .unwrap();
    serde_json::to_value(toml::from_str::<toml::Table>(&text).unwrap()).unwrap()
}

/// JSON back to TOML; TOML has no null, so a nulled key or element is left out (a missing key,
/// which the loader must handle too).
fn to_toml(v: &Value) -> Option<toml::Value> {
    Some(match v {
        Value::Null => return None,
        Value::Bool(b) => toml::Value::Boolean(*b),
        Value::Number(n) => match n.as_i64() {
            Some(i) => toml::Value::Integer(i),
            None => toml::Value::Float(n.as_f64().unwrap()),
        },
        Value::String(s) => toml::Value::String(s.clone()),
        Value::Array(a) => toml::Value::Array(a.iter().filter_map(to_toml).collect()),
        Value::Object(m) => toml::Value::Table(
            m.iter()
                .filter_map(|(k, v)| Some((k.clone(), to_toml(v)?)))
                .collect(),
        ),
    })
}

/// What became of one mutated config.
#[derive(Debug)]
enum Outcome {
    /// TOML cannot say it (a top-level value that is not a table).
    Unwritable,
    Refused,
    /// Loaded, but the generator refused the scene it made: an error, not a panic, but a gap
    /// in the config's validation (what it accepts must generate).
    Ungenerated,
    Rendered,
}

/// Loads `text` as a config file, generates scene 0 and renders its centre view at 8×8, 1 spp
/// (a valid config may ask for 16384² views legitimately; the render is shrunk so thousands
/// fit in a test). A refusal must name the file.
fn run_in_process(text: &str, file: &Path) -> Outcome {
    std::fs::write(file, text).unwrap();
    let cfg = match Config::load(Some(file), &[], &[]) {
        Ok(cfg) => cfg,
        Err(e) => {
            let msg = format!("{e:#}");
            assert!(msg.contains(&file.display().to_string()), "unnamed: {msg}");
            return Outcome::Refused;
        }
    };
    let (mut desc, scene) = match generate_scene(&cfg, 0, None) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("a valid config did not generate: {e:#}\n{text}");
            return Outcome::Ungenerated;
        }
    };
    let mut settings = RenderJob::from_config(&cfg, "2026-01-01")
        .render
        .view_settings(&desc);
    settings.spp = 1;
    desc.camera.resolution = [8, 8];
    let centre = desc.camera.center_view();
    let out = scene.render_view(
        &desc.camera,
        &desc.slices,
        &settings,
        centre,
        true,
        &AtomicU64::new(0),
    );
    assert_eq!(out.image.pixels.len(), 64);
    Outcome::Rendered
}

/// The mutated config `case` as TOML text, or `None` where TOML cannot hold it.
fn mutated(seed: &Value, rng: &mut Pcg64) -> Option<String> {
    let mut v = seed.clone();
    for _ in 0..rng.random_range(1..=3) {
        mutate(&mut v, rng);
    }
    match to_toml(&v)? {
        toml::Value::Table(t) => toml::to_string(&t).ok(),
        _ => None,
    }
}

#[test]
fn thousands_of_mutated_configs_are_refused_or_rendered_never_a_panic_or_a_hang() {
    const CASES: usize = 2000;
    let seed = seed_config();
    let mut rng = Pcg64::seed_from_u64(17);
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("generator.toml");
    let cases: Vec<Option<String>> = (0..CASES).map(|_| mutated(&seed, &mut rng)).collect();
    let (tx, rx) = mpsc::channel();
    let worker_file = file.clone();
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let worker = std::thread::spawn(move || {
        for (i, text) in cases.into_iter().enumerate() {
            let outcome = match &text {
                None => Ok(Outcome::Unwritable),
                Some(t) => std::panic::catch_unwind(|| run_in_process(t, &worker_file)),
            };
            tx.send((i, text, outcome)).unwrap();
        }
    });
    let mut counts = std::collections::BTreeMap::new();
    for _ in 0..CASES {
        // Generous for one tiny scene on a loaded 2-core machine; a hang shows as this.
        let (i, text, outcome) = match rx.recv_timeout(Duration::from_secs(60)) {
            Ok(r) => r,
            Err(_) => {
                let last = std::fs::read_to_string(&file).unwrap_or_default();
                panic!("a mutated config took over 60 s (hang?):\n{last}");
            }
        };
        match outcome {
            Ok(o) => *counts.entry(format!("{o:?}")).or_insert(0) += 1,
            Err(_) => {
                std::panic::set_hook(quiet);
                panic!("case {i} panicked:\n{}", text.unwrap_or_default());
            }
        }
    }
    std::panic::set_hook(quiet);
    worker.join().unwrap();
    eprintln!("{CASES} mutated configs: {counts:?}, 0 panics, 0 hangs");
    assert!(
        !counts.contains_key("Ungenerated"),
        "accepted configs that do not generate: {counts:?}"
    );
    // The fuzzer must reach every stage, or it tests nothing past the loader.
    for stage in ["Refused", "Rendered"] {
        assert!(
            counts.get(stage).copied().unwrap_or(0) > 100,
            "{stage}: {counts:?}"
        );
    }
}

/// `lfgen --config` of mutated files under `prlimit` (4 GiB address space, 60 s CPU), views
/// shrunk to 8×8 by `--set`: every run ends with exit code 0 or 1 and a one-line cause.
#[test]
fn mutated_configs_through_the_binary_exit_0_or_1_within_bounds() {
    if !can_bound() {
        skip::skip(bin::NO_PRLIMIT);
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let seed = seed_config();
    let mut rng = Pcg64::seed_from_u64(18);
    let mut codes = std::collections::BTreeMap::new();
    for case in 0..40 {
        let Some(text) = mutated(&seed, &mut rng) else {
            continue;
        };
        let path = dir.path().join(format!("config_{case}.toml"));
        std::fs::write(&path, &text).unwrap();
        let out = dir.path().join(format!("out_{case}"));
        let mut args = vec![
            "--config".as_ref(),
            path.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ];
        for a in [
            "--scenes",
            "1",
            "--quiet",
            "--set",
            "camera.resolution=[8,8]",
            "--set",
            "camera.grid=[3,3]",
            "--set",
            "render.spp=1",
            "--set",
            "dataset.date=2026-01-01",
        ] {
            args.push(a.as_ref());
        }
        let code = run_bounded(&args, &format!("case {case}:\n{text}"));
        *codes.entry(code).or_insert(0) += 1;
    }
    eprintln!("mutated configs through lfgen: exit codes {codes:?}");
}
