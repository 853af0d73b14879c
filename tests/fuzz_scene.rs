//! A mutation fuzzer for `scene.json` and the config: thousands of damaged scene descriptions
//! (hostile numbers, wrong types, missing and unknown fields, emptied or grown arrays) must each
//! be refused with an error or render, never panic, loop or allocate without bound.
//!
//! Most cases run in-process (parse, validate, build the BVH, render one small view) so that
//! thousands fit in seconds; a sample also runs through the `lfgen` binary under a time and
//! address-space limit, where an abort or a hang would show as a signal or a time-out.

mod bin;
mod mutate;
mod skip;

use bin::{can_bound, run_bounded};
use lfgen::config::Config;
use lfgen::render::RenderScene;
use lfgen::render::integrator::PathSettings;
use lfgen::render::slices::SliceAssignment;
use lfgen::render::view::{Adaptive, RenderSettings};
use lfgen::scene::SceneDesc;
use lfgen::scene::assets::Assets;
use mutate::mutate;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::Value;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::AtomicU64;

/// A small generated scene as JSON: the fuzzer's seed file.
fn seed_scene() -> Value {
    let cfg = Config::load(
        None,
        &[],
        &[
            "camera.resolution=[16,12]".into(),
            "camera.grid=[3,3]".into(),
            "scene.objects=6".into(),
            "dataset.date=2026-01-01".into(),
        ],
    )
    .unwrap();
    let (desc, _) = lfgen::pipeline::generate_scene(&cfg, 0, None).unwrap();
    serde_json::to_value(desc).unwrap()
}

/// What became of one mutated scene.
#[derive(Debug, PartialEq)]
enum Outcome {
    Unparsed,
    Invalid,
    Unbuildable,
    Rendered,
}

/// Parses, validates, builds and renders the centre view at 8×8, 1 spp (a valid scene may ask
/// for 16384² views legitimately; the render is shrunk so thousands fit in a test).
fn run_in_process(v: Value) -> Outcome {
    let Ok(mut desc) = serde_json::from_value::<SceneDesc>(v) else {
        return Outcome::Unparsed;
    };
    if desc.validate().is_err() {
        return Outcome::Invalid;
    }
    let Ok(assets) = Assets::load(&desc) else {
        return Outcome::Unbuildable;
    };
    let Ok(scene) = RenderScene::build_with(&desc, &assets) else {
        return Outcome::Unbuildable;
    };
    desc.camera.resolution = [8, 8];
    let settings = RenderSettings {
        path: PathSettings {
            max_depth: 3,
            rr_depth: 2,
            footprint: 0.0,
            glass_light: lfgen::render::integrator::GlassLight::Caustics,
            split_glass: true,
        },
        spp: 1,
        gt_spp: 1,
        seed: 0,
        scene_index: 0,
        mode_epsilon: 0.01,
        shade_all_hits: false,
        slice_assignment: SliceAssignment::Surface,
        adaptive: Adaptive::default(),
    };
    let center = desc.camera.center_view();
    let out = scene.render_view(
        &desc.camera,
        &desc.slices,
        &settings,
        center,
        true,
        &AtomicU64::new(0),
    );
    assert_eq!(out.image.pixels.len(), 64);
    Outcome::Rendered
}

#[test]
fn thousands_of_mutated_scene_files_are_refused_or_rendered_never_a_panic() {
    let seed = seed_scene();
    let mut rng = Pcg64::seed_from_u64(13);
    let mut counts = std::collections::BTreeMap::new();
    let mut panics = Vec::new();
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    for case in 0..3000 {
        let mut v = seed.clone();
        for _ in 0..rng.random_range(1..=3) {
            mutate(&mut v, &mut rng);
        }
        let text = v.to_string();
        match catch_unwind(AssertUnwindSafe(|| run_in_process(v))) {
            Ok(o) => *counts.entry(format!("{o:?}")).or_insert(0) += 1,
            Err(_) => panics.push((case, text)),
        }
    }
    std::panic::set_hook(quiet);
    eprintln!(
        "3000 mutated scene.json files: {counts:?}, {} panics",
        panics.len()
    );
    assert!(
        panics.is_empty(),
        "{} mutated scenes panicked; the first (case {}):\n{}",
        panics.len(),
        panics[0].0,
        panics[0].1
    );
    // The fuzzer must reach every stage, or it tests nothing past the parser.
    for stage in ["Unparsed", "Invalid", "Rendered"] {
        assert!(
            counts.get(stage).copied().unwrap_or(0) > 50,
            "{stage}: {counts:?}"
        );
    }
}

/// `lfgen render` of mutated files under `prlimit` (4 GiB address space, 60 s CPU): every run
/// ends with exit code 0 or 1, no signal, no time-out.
#[test]
fn mutated_scene_files_through_the_binary_exit_0_or_1_within_bounds() {
    if !can_bound() {
        skip::skip(bin::NO_PRLIMIT);
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mut seed = seed_scene();
    // One view at 8×8 keeps valid cases quick; the mutations may still change both.
    seed["camera"]["resolution"] = serde_json::json!([8, 8]);
    seed["camera"]["grid"] = serde_json::json!([1, 1]);
    let mut rng = Pcg64::seed_from_u64(14);
    let mut codes = std::collections::BTreeMap::new();
    for case in 0..60 {
        let mut v = seed.clone();
        mutate(&mut v, &mut rng);
        let path = dir.path().join(format!("scene_{case}.json"));
        std::fs::write(&path, v.to_string()).unwrap();
        let out = dir.path().join(format!("out_{case}"));
        let args = [
            "render".as_ref(),
            path.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--set".as_ref(),
            "render.spp=1".as_ref(),
            "--quiet".as_ref(),
        ];
        let code = run_bounded(&args, &format!("case {case}: {v}"));
        *codes.entry(code).or_insert(0) += 1;
    }
    eprintln!("60 mutated scene.json files through lfgen render: exit codes {codes:?}");
}

/// Mutated `--set` values for every numeric config key: an error or a run, never a panic or a
/// huge allocation (the run itself is not started: `bench`-free `--scenes 0`).
#[test]
fn hostile_config_values_are_refused_with_the_key_named() {
    let cases = [
        "render.slices=4294967295",
        "render.spp=4294967295",
        "render.gt_spp=4294967295",
        "render.max_depth=100000",
        "render.glossy_share=-1",
        "render.glossy_share=nan",
        "render.glossy_min_width=-0.1",
        "render.glossy_min_width=inf",
        "camera.grid=[0,0]",
        "camera.grid=[35,35]",
        "camera.resolution=[4294967295,1]",
        // Found by the config fuzzer (tests/fuzz_config.rs): accepted, then the generator
        // made an invalid scene or none.
        "camera.focal_length_mm=1e-30",
        "scene.environment=[1e308,0,0]",
        "scene.room_width=[1,1e25]",
        "scene.objects=4294967295",
        "render.exposure=1e308",
        "render.fill_vertices=0",
        "render.fill_vertices=9",
        "render.fill_light_samples=0",
        "render.fill_light_samples=65",
    ];
    for set in cases {
        let d = tempfile::tempdir().unwrap();
        let r = bin::lfgen(&[
            "--scenes",
            "1",
            "--out",
            d.path().to_str().unwrap(),
            "--quiet",
            "--set",
            set,
        ]);
        let key = set.split('=').next().unwrap();
        assert!(
            r.status.code() == Some(1) && bin::stderr(&r).contains(key),
            "{set}: {:?} {}",
            r.status,
            bin::stderr(&r)
        );
        assert!(
            std::fs::read_dir(d.path()).unwrap().next().is_none(),
            "{set}: a refused run left files"
        );
    }
    // A value outside --threads' range is a usage error (exit 2), refused while parsing.
    for (args, needle, code) in [
        (&["--scenes", "18446744073709551615"][..], "--scenes", 1),
        (&["--threads", "100000"][..], "--threads <N>", 2),
    ] {
        let d = tempfile::tempdir().unwrap();
        let mut all = args.to_vec();
        all.extend(["--out", d.path().to_str().unwrap(), "--quiet"]);
        let r = bin::lfgen(&all);
        assert!(
            r.status.code() == Some(code) && bin::stderr(&r).contains(needle),
            "{args:?}: {}",
            bin::stderr(&r)
        );
    }
}

/// One hand-made damage to a scene's JSON.
type Damage = Box<dyn Fn(&mut Value)>;

/// The hostile `scene.json` values a probe found (panics, aborts, endless loops, NaN output
/// with exit 0): each is now refused, naming the field.
#[test]
fn each_known_hostile_scene_value_is_refused_naming_the_field() {
    let seed = seed_scene();
    let shaped = |v: &Value| {
        v["objects"]
            .as_array()
            .unwrap()
            .iter()
            .position(|o| o["shape"]["segments"].is_number())
            .expect("the seed scene has a tessellated shape")
    };
    let round = shaped(&seed);
    let forward = seed["camera"]["forward"].clone();
    let cases: Vec<(&str, Damage)> = vec![
        (
            "camera.grid",
            Box::new(|v| v["camera"]["grid"] = serde_json::json!([0, 0])),
        ),
        (
            "camera.grid",
            Box::new(|v| v["camera"]["grid"] = serde_json::json!([4, 4])),
        ),
        (
            "slices.count",
            Box::new(|v| v["slices"]["count"] = serde_json::json!(0)),
        ),
        (
            "slices.count",
            Box::new(|v| v["slices"]["count"] = serde_json::json!(4000000000u32)),
        ),
        (
            "camera.resolution",
            Box::new(|v| v["camera"]["resolution"] = serde_json::json!([4294967295u32, 8])),
        ),
        (
            "segments",
            Box::new(move |v| {
                v["objects"][round]["shape"]["segments"] = serde_json::json!(4000000000u32)
            }),
        ),
        (
            "focal_length_mm",
            Box::new(|v| v["camera"]["focal_length_mm"] = 0.into()),
        ),
        (
            "focus_distance_m",
            Box::new(|v| v["camera"]["focus_distance_m"] = 0.into()),
        ),
        (
            "camera.forward",
            Box::new(|v| v["camera"]["forward"] = serde_json::json!([0.0, 0.0, 0.0])),
        ),
        (
            "camera.up",
            Box::new(move |v| v["camera"]["up"] = forward.clone()),
        ),
        (
            "z_near < z_far",
            Box::new(|v| {
                let near = v["slices"]["z_near"].clone();
                v["slices"]["z_near"] = v["slices"]["z_far"].clone();
                v["slices"]["z_far"] = near;
            }),
        ),
        (
            "opacity",
            Box::new(|v| {
                v["materials"][0]["opacity"] = serde_json::json!({"type": "constant", "value": -5})
            }),
        ),
        (
            "ior",
            Box::new(|v| {
                v["materials"][0]["model"] = serde_json::json!({"type": "glass", "ior": 0.0})
            }),
        ),
        ("colour", Box::new(|v| v["colour"] = true.into())),
        // Values of the wrong type are refused while reading, naming the field too.
        (
            "camera.resolution[0]",
            Box::new(|v| v["camera"]["resolution"] = serde_json::json!([-32, 32])),
        ),
        (
            "camera.resolution",
            Box::new(|v| v["camera"]["resolution"] = serde_json::json!("32x32")),
        ),
        (
            "camera.resolution[1]",
            Box::new(|v| v["camera"]["resolution"] = serde_json::json!([32, 32.5])),
        ),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (i, (needle, damage)) in cases.iter().enumerate() {
        let mut v = seed.clone();
        damage(&mut v);
        let path = dir.path().join(format!("case_{i}.json"));
        std::fs::write(&path, v.to_string()).unwrap();
        let out = dir.path().join(format!("out_{i}"));
        let r = bin::lfgen(&[
            "render",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        let err = bin::stderr(&r);
        assert!(
            r.status.code() == Some(1) && err.contains(needle) && err.contains("case_"),
            "case {i} ({needle}): {:?} {err}",
            r.status
        );
        assert!(!out.exists(), "case {i}: a refused scene left a folder");
    }
}
