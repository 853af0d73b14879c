//! End-to-end tests of the `lfgen` binary: determinism, resume after a kill, shards, re-render,
//! the HCI files as other tools read them, and clear errors on bad input.

mod bin;

use bin::{TINY, files, generate, ok, stderr};
use lfformat::manifest::Manifest;
use lfformat::pfm::read_pfm;
use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn lfgen(args: &[&str], extra: &[&str]) -> Output {
    bin::lfgen(&[args, extra].concat())
}

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

#[test]
fn same_seed_is_byte_identical_across_thread_counts_and_seeds_differ() {
    let (a, b, c) = (tmp(), tmp(), tmp());
    ok(generate(a.path(), "2", &["--threads", "1"]));
    ok(generate(b.path(), "2", &["--threads", "2"]));
    ok(generate(c.path(), "2", &["--threads", "2", "--seed", "7"]));
    let (fa, fb, fc) = (files(a.path()), files(b.path()), files(c.path()));
    assert!(
        fa.contains_key("train/scene_0000/input_Cam004.png"),
        "{:?}",
        fa.keys()
    );
    assert_eq!(fa.keys().collect::<Vec<_>>(), fb.keys().collect::<Vec<_>>());
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{name} differs between 1 and 2 threads");
    }
    let view = "train/scene_0000/input_Cam004.png";
    assert_ne!(fa[view], fc[view], "another seed must give another scene");
}

/// The BVH's node and triangle tests run as scalar, SSE or AVX2 code, chosen at run time
/// (`LFGEN_SIMD` forces one): every kernel this CPU runs must render the same bytes, the
/// glass and semi-transparent shadow layers of the test scenes included.
#[test]
fn every_simd_kernel_renders_the_same_bytes() {
    let kernels = lfgen::render::Kernel::available();
    #[cfg(target_arch = "x86_64")]
    assert!(kernels.len() >= 2, "x86-64 always has SSE: {kernels:?}");
    let runs: Vec<(&str, BTreeMap<String, Vec<u8>>)> = kernels
        .iter()
        .map(|k| {
            let dir = tmp();
            ok(generate_simd(k.name(), dir.path(), "2"));
            (k.name(), files(dir.path()))
        })
        .collect();
    let (first, reference) = &runs[0];
    for (name, got) in &runs[1..] {
        assert_eq!(
            reference.keys().collect::<Vec<_>>(),
            got.keys().collect::<Vec<_>>()
        );
        for (file, bytes) in reference {
            assert!(bytes == &got[file], "{file}: {first} and {name} differ");
        }
    }
    let unknown = generate_simd("avx512", &tmp().path().join("x"), "1");
    assert!(!unknown.status.success());
    assert!(
        stderr(&unknown).contains("LFGEN_SIMD"),
        "{}",
        stderr(&unknown)
    );
}

/// [`generate`] with the BVH's SIMD kernel forced to `kernel`.
fn generate_simd(kernel: &str, out: &Path, scenes: &str) -> Output {
    let args = ["--scenes", scenes, "--out", out.to_str().unwrap()];
    bin::lfgen_simd(kernel, &[&args[..], TINY].concat())
}

/// The files of one scene generated with the defaults, with `args`, and with `args` on one
/// thread (the others use every core).
fn one_scene_without_and_with(args: &[&str]) -> [BTreeMap<String, Vec<u8>>; 3] {
    let (a, b, c) = (tmp(), tmp(), tmp());
    ok(generate(a.path(), "1", &[]));
    ok(generate(b.path(), "1", args));
    ok(generate(
        c.path(),
        "1",
        &[args, &["--threads", "1"]].concat(),
    ));
    [files(a.path()), files(b.path()), files(c.path())]
}

/// `render.gt_spp` through the CLI: the views stay byte for byte the same, the multimodal GT
/// takes its own samples, and the same config stays deterministic across thread counts.
#[test]
fn gt_spp_changes_the_ground_truth_and_not_the_views() {
    let [fa, fb, fc] = one_scene_without_and_with(&["--set", "render.gt_spp=16"]);
    let scene = "train/scene_0000/";
    for v in 0..9 {
        let view = format!("{scene}input_Cam{v:03}.png");
        assert!(fa[&view] == fb[&view], "{view} changed with gt_spp");
    }
    assert!(fa[&format!("{scene}modes.exr")] != fb[&format!("{scene}modes.exr")]);
    for (name, bytes) in &fb {
        assert!(bytes == &fc[name], "{name} differs between thread counts");
    }
}

/// `render.final_gather` (on by default) through the CLI: the second fill pass changes the
/// views' light but not the ground truth (the GT comes from the camera streams alone), and it
/// stays deterministic across thread counts (the gathered sums merge in the same fixed order as
/// the fill's).
#[test]
fn a_final_gather_changes_the_views_not_the_ground_truth_and_stays_deterministic() {
    let runs: [&[&str]; 3] = [&[], &["--preset", "fast"], &["--threads", "1"]];
    let [gathered, plain, one_thread] = runs.map(|args| {
        let d = tmp();
        ok(generate(d.path(), "1", args));
        files(d.path())
    });
    let scene = "train/scene_0000/";
    let view = format!("{scene}input_Cam004.png");
    assert!(
        plain[&view] != gathered[&view],
        "the gather left {view} unchanged"
    );
    for gt in ["modes.exr", "gt_disp_lowres.pfm"] {
        let name = format!("{scene}{gt}");
        assert!(
            plain[&name] == gathered[&name],
            "{name} changed with the gather"
        );
    }
    for (name, bytes) in &gathered {
        assert!(
            bytes == &one_thread[name],
            "{name} differs between thread counts"
        );
    }
}

#[test]
fn scene_folder_has_every_hci_and_multimodal_file() {
    let d = tmp();
    ok(generate(d.path(), "1", &[]));
    let scene = d.path().join("train/scene_0000");
    let mut names: Vec<String> = fs::read_dir(&scene)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let expected = bin::scene_files(9);
    assert_eq!(names, expected);
    let manifest = Manifest::read(&d.path().join("manifest.json")).unwrap();
    assert_eq!(manifest.scenes.len(), 1);
    assert_eq!(manifest.scenes[0].files.len(), expected.len());
}

#[test]
fn gt_for_all_views_writes_per_view_files_consistent_with_the_centre() {
    let d = tmp();
    ok(generate(d.path(), "1", &["--set", "render.gt_views=all"]));
    let scene = d.path().join("train/scene_0000");
    for v in 0..9 {
        for f in [
            "gt_disp_lowres_Cam{v:03}.pfm",
            "gt_depth_lowres_Cam{v:03}.pfm",
            "modes_Cam{v:03}.exr",
        ] {
            let name = f.replace("{v:03}", &format!("{v:03}"));
            assert!(scene.join(&name).exists(), "{name} missing");
        }
    }
    for (plain, per_view) in [
        ("gt_disp_lowres.pfm", "gt_disp_lowres_Cam004.pfm"),
        ("modes.exr", "modes_Cam004.exr"),
    ] {
        assert_eq!(
            fs::read(scene.join(plain)).unwrap(),
            fs::read(scene.join(per_view)).unwrap()
        );
    }
    // A corner view sees the scene from elsewhere: its GT differs from the centre's.
    assert_ne!(
        fs::read(scene.join("gt_depth_lowres_Cam000.pfm")).unwrap(),
        fs::read(scene.join("gt_depth_lowres.pfm")).unwrap()
    );
}

/// A minimal INI reader written here, independent of lfformat's.
fn ini(path: &Path) -> BTreeMap<String, String> {
    let mut section = String::new();
    let mut out = BTreeMap::new();
    for line in fs::read_to_string(path).unwrap().lines().map(str::trim) {
        if let Some(s) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            section = s.to_string();
        } else if let Some((k, v)) = line.split_once('=') {
            out.insert(format!("{section}.{}", k.trim()), v.trim().to_string());
        }
    }
    out
}

#[test]
fn parameters_cfg_formula_reproduces_gt_disp_from_gt_depth() {
    let d = tmp();
    ok(generate(d.path(), "1", &[]));
    let scene = d.path().join("train/scene_0000");
    let cfg = ini(&scene.join("parameters.cfg"));
    let f = |k: &str| {
        cfg[k]
            .parse::<f64>()
            .unwrap_or_else(|_| panic!("{k} = {}", cfg[k]))
    };
    let (w, h) = (
        f("intrinsics.image_resolution_x_px"),
        f("intrinsics.image_resolution_y_px"),
    );
    assert_eq!((w, h), (40.0, 32.0));
    assert_eq!(f("extrinsics.num_cams_x"), 3.0);
    let f_px = f("intrinsics.focal_length_mm") * w.max(h) / f("intrinsics.sensor_size_mm");
    let b = f("extrinsics.baseline_mm") / 1000.0;
    let zf = f("extrinsics.focus_distance_m");
    let depth = read_pfm(&scene.join("gt_depth_lowres.pfm")).unwrap();
    let disp = read_pfm(&scene.join("gt_disp_lowres.pfm")).unwrap();
    assert_eq!((depth.width, depth.height), (40, 32));
    for (z, d) in depth.data.iter().zip(&disp.data) {
        let expected = f_px * b * (1.0 / *z as f64 - 1.0 / zf);
        assert!(
            (expected - *d as f64).abs() < 1e-4 * expected.abs().max(1.0),
            "{d} vs {expected}"
        );
    }
    // disp_min/max bound the GT, rounded outwards to tenths plus 0.1 as HCI writes them, and
    // lie within the configured range [-3.5, 3.5] widened by that rounding.
    let (lo, hi) = (f("meta.disp_min"), f("meta.disp_max"));
    let finite = disp
        .data
        .iter()
        .filter(|d| d.is_finite())
        .map(|&d| d as f64);
    let (min, max) = finite.fold((f64::MAX, f64::MIN), |(a, b), d| (a.min(d), b.max(d)));
    assert!(
        ((min * 10.0).floor() / 10.0 - 0.1 - lo).abs() < 1e-9,
        "{lo} for min {min}"
    );
    assert!(
        ((max * 10.0).ceil() / 10.0 + 0.1 - hi).abs() < 1e-9,
        "{hi} for max {max}"
    );
    assert!(lo >= -3.7 && hi <= 3.7, "{lo} {hi}");
}

#[test]
fn killed_run_resumes_to_the_same_bytes_and_never_leaves_half_scenes() {
    let (reference, killed) = (tmp(), tmp());
    ok(generate(reference.path(), "3", &[]));
    let out = killed.path().to_str().unwrap();
    let mut args = vec!["--scenes", "3", "--out", out];
    args.extend_from_slice(TINY);
    let mut child = Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(&args)
        .spawn()
        .unwrap();
    // Kill it as soon as the first scene is published: later scenes are then in flight.
    let manifest = killed.path().join("manifest.json");
    while !manifest.exists() && child.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    // Whatever was published is complete; partial work only ever sits in hidden folders.
    if let Ok(m) = Manifest::read(&killed.path().join("manifest.json")) {
        assert!(
            m.scenes
                .iter()
                .all(|e| lfformat::manifest::scene_entry_verifies(killed.path(), e))
        );
    }
    // Damage one published scene by hand as well: resume must redo it.
    let rerun = generate(killed.path(), "3", &[]);
    assert!(
        !rerun.status.success() && stderr(&rerun).contains("--resume"),
        "{}",
        stderr(&rerun)
    );
    ok(generate(killed.path(), "3", &["--resume"]));
    fs::remove_file(killed.path().join("train/scene_0001/modes.exr")).unwrap();
    ok(generate(killed.path(), "3", &["--resume"]));
    let (a, b) = (files(reference.path()), files(killed.path()));
    assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
    assert!(a == b, "resumed dataset differs from an uninterrupted run");
}

#[test]
fn shards_merge_into_the_unsharded_dataset() {
    let (whole, sharded) = (tmp(), tmp());
    ok(generate(whole.path(), "3", &[]));
    ok(generate(sharded.path(), "3", &["--shard", "0/2"]));
    ok(generate(sharded.path(), "3", &["--shard", "1/2"]));
    assert!(sharded.path().join("manifest.shard-1-of-2.json").exists());
    ok(lfgen(&["merge", sharded.path().to_str().unwrap()], &[]));
    let (a, mut b) = (files(whole.path()), files(sharded.path()));
    b.retain(|k, _| !k.starts_with("manifest.shard-"));
    assert!(a == b, "merged shards differ from one run");
}

#[test]
fn rerendering_scene_json_reproduces_the_scene() {
    let d = tmp();
    ok(generate(d.path(), "1", &[]));
    let scene = d.path().join("train/scene_0000");
    let again = d.path().join("again");
    let json = scene.join("scene.json");
    ok(lfgen(
        &[
            "render",
            json.to_str().unwrap(),
            "--out",
            again.to_str().unwrap(),
        ],
        TINY,
    ));
    assert!(files(&scene) == files(&again), "re-render differs");
}

#[test]
fn bad_input_gives_clear_errors_and_no_scene() {
    let d = tmp();
    let out = d.path().join("ds");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["--set", "render.sppp=4"], "render.sppp"),
        (&["--set", "render.spp=many"], "render"),
        (&["--set", "camera.grid=[4,4]"], "odd"),
        (&["--preset", "huge"], "invalid value 'huge'"),
        (&["--shard", "3/2"], "--shard"),
    ];
    for (args, needle) in cases {
        let r = lfgen(
            &[&["--scenes", "1", "--out", o][..], args].concat(),
            &["--quiet"],
        );
        assert!(
            !r.status.success() && stderr(&r).contains(needle),
            "{args:?}: {}",
            stderr(&r)
        );
    }
    let bad_toml = d.path().join("bad.toml");
    fs::write(&bad_toml, "[render]\nspp = = 3\n").unwrap();
    let r = lfgen(
        &["--config", bad_toml.to_str().unwrap(), "--out", o],
        &["--quiet"],
    );
    assert!(
        !r.status.success() && stderr(&r).contains("bad.toml"),
        "{}",
        stderr(&r)
    );
    let unknown = d.path().join("unknown.toml");
    fs::write(&unknown, "[render]\nspp = 3\ncolour = true\n").unwrap();
    let r = lfgen(
        &["--config", unknown.to_str().unwrap(), "--out", o],
        &["--quiet"],
    );
    assert!(
        !r.status.success() && stderr(&r).contains("colour"),
        "{}",
        stderr(&r)
    );
    let blocker = d.path().join("file");
    fs::write(&blocker, "not a folder").unwrap();
    let under_file: PathBuf = blocker.join("ds");
    let r = generate(&under_file, "1", &[]);
    assert!(
        !r.status.success() && stderr(&r).contains("cannot create output folder"),
        "{}",
        stderr(&r)
    );
    assert!(
        !out.join("train").exists(),
        "a failed run must not leave scenes"
    );
    let r = lfgen(
        &[
            "render",
            d.path().join("missing.json").to_str().unwrap(),
            "--out",
            o,
        ],
        &[],
    );
    assert!(
        !r.status.success() && stderr(&r).contains("missing.json"),
        "{}",
        stderr(&r)
    );
    // A bad --set is blamed on itself, not on the defaults it was applied to.
    let r = lfgen(
        &["--scenes", "1", "--out", o, "--set", "render.spp=many"],
        &[],
    );
    assert!(
        stderr(&r).contains("--set render.spp=many"),
        "{}",
        stderr(&r)
    );
    // Every cause once: the OS error is not repeated by the error chain.
    let r = lfgen(&["preview", d.path().join("none").to_str().unwrap()], &[]);
    let err = stderr(&r);
    assert!(
        !r.status.success() && err.matches("os error 2").count() == 1,
        "{err}"
    );
}

#[test]
fn preview_sheets_summary_and_texture_library() {
    let d = tmp();
    ok(generate(d.path(), "2", &[]));
    let summary: serde_json::Value =
        serde_json::from_slice(&fs::read(d.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["scenes"], 2);
    assert!(summary["objects_placed"].as_u64().unwrap() > 0);
    ok(lfgen(&["preview", d.path().to_str().unwrap()], &[]));
    // Two scenes: the first trains, the last is the small dataset's val scene.
    for name in ["train_scene_0000.png", "val_scene_0001.png", "index.html"] {
        assert!(d.path().join("previews").join(name).is_file(), "{name}");
    }
    let t = tmp();
    let out = t.path().join("tex");
    ok(lfgen(
        &["textures", "--count", "20", "--out", out.to_str().unwrap()],
        &[],
    ));
    let catalog: serde_json::Value =
        serde_json::from_slice(&fs::read(out.join("catalog.json")).unwrap()).unwrap();
    assert_eq!(catalog["textures"].as_array().unwrap().len(), 20);
}

/// Windows and doors open the room, yet every pixel of every view still ends on a surface at a
/// finite depth: the daylight behind a window, the corridor behind a door.
#[test]
fn rays_through_windows_and_doors_end_on_a_surface() {
    let dir = tmp();
    let out = dir.path().join("ds");
    let extra = [
        "--set",
        "scene.windows=[2,2]",
        "--set",
        "scene.door=1.0",
        "--set",
        "render.gt_views=all",
    ];
    ok(generate(&out, "3", &extra));
    let mut seen = [false; 2];
    for i in 0..3 {
        // Three scenes: the last is the small dataset's val scene.
        let split = if i == 2 { "val" } else { "train" };
        let scene = out.join(format!("{split}/scene_{i:04}"));
        let json = fs::read_to_string(scene.join("scene.json")).unwrap();
        // Not every wanted opening fits a narrow room; each scene gets some.
        let kinds = ["outside_sky", "outside_corridor"].map(|k| json.contains(k));
        assert!(kinds.iter().any(|&k| k), "scene {i} has no opening");
        seen = [seen[0] | kinds[0], seen[1] | kinds[1]];
        for view in [0, 4, 8] {
            let depth = read_pfm(&scene.join(format!("gt_depth_lowres_Cam{view:03}.pfm"))).unwrap();
            let bad = depth
                .data
                .iter()
                .position(|z| !(z.is_finite() && *z > 0.0 && *z < 100.0));
            assert_eq!(
                bad,
                None,
                "scene {i} view {view}: depth {:?}",
                bad.map(|p| depth.data[p])
            );
        }
    }
    assert_eq!(seen, [true, true], "windows and doors");
}

/// The one record a benchmark run appended to the results file `path` (asserting it is the
/// only line).
fn only_record(path: &Path) -> serde_json::Value {
    let text = fs::read_to_string(path).unwrap();
    assert_eq!(text.lines().count(), 1, "{text}");
    serde_json::from_str(text.trim_end()).unwrap()
}

/// `lfgen bench quality` end to end at a tiny size: the converged row and both shadings, each
/// with the share of its error that is its view's own noise, and shared shading's cache noise
/// share. The independent estimator has no
/// shared part, so all of its error is its own: at 128² the bench finds 100 % (linear); on
/// 576 pixels a few fireflies make the estimate itself noisy (68 % here), while a second render
/// that repeated the first one's samples would give 0 %. An image size below the bench's
/// minimum is refused by name.
#[test]
fn the_quality_bench_scores_both_shadings_with_their_error_budget() {
    let images = tmp();
    let dir = images.path().to_str().unwrap();
    let results = images.path().join("results.jsonl");
    let args = ["bench", "quality", "--size", "24", "--scenes", "0"];
    let extra = [
        "--images",
        dir,
        "-q",
        "--results",
        results.to_str().unwrap(),
    ];
    let out = ok(lfgen(&args, &extra));
    let table = String::from_utf8_lossy(&out.stdout).into_owned();
    let row = |name: &str| -> Vec<String> {
        let line = (table.lines())
            .find(|l| l.starts_with(&format!("0 | {name}")))
            .unwrap_or_else(|| panic!("no {name} row in:\n{table}"));
        line.split(" | ").map(str::to_owned).collect()
    };
    assert!(row("converged").len() >= 5, "{table}");
    let share = |cells: &[String], column: usize| -> f64 {
        let linear = cells[column].split(" % / ").next().unwrap();
        linear
            .parse()
            .unwrap_or_else(|_| panic!("share {:?}", cells[column]))
    };
    let (independent, shared) = (row("Independent"), row("Shared"));
    assert!(share(&independent, 6) >= 50.0, "{table}");
    assert!((0.0..=100.0).contains(&share(&shared, 6)), "{table}");
    // The cache's noise: shared shading's alone (the independent estimator reads no cache).
    assert!((0.0..=100.0).contains(&share(&shared, 8)), "{table}");
    assert_eq!(independent[8], "–", "{table}");
    for name in [
        "reference",
        "shared",
        "shared_again",
        "shared_other_cache",
        "independent",
    ] {
        let path = images.path().join(format!("scene0_{name}.png"));
        assert!(path.exists(), "{} missing", path.display());
    }
    // The run's figures, as one record of the results file.
    let record = only_record(&results);
    assert_eq!(record["tool"], "lfgen");
    assert_eq!(record["command"][1], "bench", "{record}");
    let rows = record["figures"]["rows"].as_array().unwrap();
    let shared = rows.iter().find(|r| r["shading"] == "shared").unwrap();
    assert!(shared["psnr_linear"].as_f64().unwrap() > 0.0, "{record}");
    assert_eq!(record["figures"]["size"], 24);
    let small = lfgen(&["bench", "quality", "--size", "8"], &[]);
    assert!(!small.status.success());
    assert!(stderr(&small).contains("--size"), "{}", stderr(&small));
}

/// `lfgen bench speed` writes one record with a rate for every kind of ray query the
/// renderer makes (built-in scene 0 has ceiling lights, so shadow rays are measured too) and
/// the ground truth's cost; the figures are rates, not pass/fail thresholds.
#[test]
fn the_speed_bench_records_every_query_kind() {
    let dir = tmp();
    let results = dir.path().join("results.jsonl");
    let extra = [
        "-q",
        "--set",
        "render.spp=1",
        "--results",
        results.to_str().unwrap(),
    ];
    // The run names the kernel it measured, here the one LFGEN_SIMD forces: the second best
    // this CPU has (SSE on an AVX2 machine), so it is not the one chosen anyway.
    let all = lfgen::render::Kernel::available();
    let kernel = all[all.len().saturating_sub(2)];
    let name = kernel.name();
    ok(bin::lfgen_simd(
        name,
        &[&["bench", "speed"][..], &extra].concat(),
    ));
    let record = only_record(&results);
    let figures = &record["figures"];
    assert_eq!(figures["kernel"], name, "{record}");
    for key in [
        "closest_mrays_per_s",
        "all_hits_mrays_per_s",
        "incoherent_closest_mrays_per_s",
        "shadow_mrays_per_s",
        "all_hits_cost_ratio",
        "gt_overhead_ratio",
    ] {
        let value = figures[key]
            .as_f64()
            .unwrap_or_else(|| panic!("{key} in {record}"));
        assert!(value.is_finite() && value > 0.0, "{key} = {value}");
    }
}

/// A dataset of any size from 2 scenes on has a val/ split (the last scene below 11 scenes),
/// shards agree on it, and the run ends by saying where the data is and what to run next; one
/// scene says why there is no val/. `lfgen generate` is bare `lfgen`.
#[test]
fn small_datasets_get_a_val_split_and_the_run_names_the_next_commands() {
    let (whole, sharded, named) = (tmp(), tmp(), tmp());
    let out = ok(generate(whole.path(), "2", &[]));
    let m = Manifest::read(&whole.path().join("manifest.json")).unwrap();
    let dirs: Vec<&str> = m.scenes.iter().map(|e| e.dir.as_str()).collect();
    assert_eq!(dirs, ["train/scene_0000", "val/scene_0001"]);
    let said = stderr(&out);
    let val = format!("{}/val", whole.path().display());
    assert!(said.contains("1 scenes in train/, 1 in val/"), "{said}");
    assert!(
        said.contains("lftrain train --model base")
            && said.contains(&format!(
                "--train {}/train --val {val}",
                whole.path().display()
            )),
        "{said}"
    );
    assert!(said.contains(&format!("lfeval baseline {val}")), "{said}");
    for shard in ["0/2", "1/2"] {
        let said = stderr(&ok(generate(sharded.path(), "2", &["--shard", shard])));
        assert!(said.contains("lfgen merge"), "{said}");
    }
    ok(lfgen(&["merge", sharded.path().to_str().unwrap()], &[]));
    let mut b = files(sharded.path());
    b.retain(|k, _| !k.starts_with("manifest.shard-"));
    assert!(
        files(whole.path()) == b,
        "merged shards differ from one run"
    );
    let o = named.path().to_str().unwrap();
    ok(lfgen(&["generate", "--scenes", "2", "--out", o], TINY));
    assert!(
        files(whole.path()) == files(named.path()),
        "generate differs from bare lfgen"
    );
    let one = tmp();
    let said = stderr(&ok(generate(one.path(), "1", &[])));
    assert!(said.contains("no val/ split"), "{said}");
    assert!(!one.path().join("val").exists());
}

/// A ./generator.toml picked up from the working directory is announced; --no-config ignores
/// it, and --config with --no-config is refused.
#[test]
fn an_implicit_generator_toml_is_announced_and_no_config_ignores_it() {
    let d = tmp();
    fs::write(d.path().join("generator.toml"), "[render]\nspp = 0\n").unwrap();
    let run = |extra: &[&str]| {
        let args = [
            &["--scenes", "1", "--out", "ds", "--set", "render.sppp=1"],
            extra,
        ]
        .concat();
        Command::new(env!("CARGO_BIN_EXE_lfgen"))
            .args(args)
            .current_dir(d.path())
            .output()
            .unwrap()
    };
    let implicit = stderr(&run(&[]));
    assert!(implicit.contains("using ./generator.toml"), "{implicit}");
    assert!(implicit.contains("generator.toml"), "{implicit}");
    let ignored = stderr(&run(&["--no-config"]));
    assert!(!ignored.contains("generator.toml"), "{ignored}");
    let both = run(&["--no-config", "--config", "x.toml"]);
    assert!(!both.status.success() && stderr(&both).contains("--no-config"));
}

/// `lfgen --help` leads with `generate` and a one-line description per command; every help
/// text is free of issue numbers; completions and the man page come from the same definitions.
#[test]
fn the_help_lists_commands_and_completions_and_man_page_are_generated() {
    let help = String::from_utf8(ok(lfgen(&["--help"], &[])).stdout).unwrap();
    let first = help
        .lines()
        .skip_while(|l| l != &"Commands:")
        .nth(1)
        .unwrap();
    assert!(first.trim_start().starts_with("generate "), "{help}");
    assert!(
        !help.contains("--scenes <SCENES>"),
        "generation flags belong to generate --help: {help}"
    );
    let all = String::from_utf8(ok(lfgen(&["doc", "cli"], &[])).stdout).unwrap();
    let numbered = all
        .char_indices()
        .any(|(i, c)| c == '#' && all[i + 1..].starts_with(|d: char| d.is_ascii_digit()));
    assert!(
        !numbered && !all.contains("issue"),
        "a help text names an issue"
    );
    let bash = String::from_utf8(ok(lfgen(&["completions", "bash"], &[])).stdout).unwrap();
    assert!(bash.contains("quick fast wide clean") && bash.contains("pov blender mitsuba"));
    let man = String::from_utf8(ok(lfgen(&["man"], &[])).stdout).unwrap();
    assert!(man.contains(".TH lfgen 1"), "{man}");
}

/// An option written before a command name that the command takes applies to it, as lftrain's
/// and lfeval's do; one the command does not take is refused, naming both.
#[test]
fn options_before_a_command_name_apply_to_the_command() {
    let missing = "/nonexistent/lfgen-cli-test.gltf";
    for args in [
        &["-q", "--threads", "1", "render", missing, "--out", "o"][..],
        &["render", missing, "--out", "o", "-q", "--threads", "1"],
    ] {
        let r = lfgen(args, &[]);
        assert!(
            r.status.code() == Some(1) && stderr(&r).contains(missing),
            "{args:?}: {}",
            stderr(&r)
        );
    }
    let r = lfgen(&["-q", "merge", "d"], &[]);
    assert!(
        r.status.code() == Some(2) && stderr(&r).contains("'merge' cannot be used with '--quiet'"),
        "{}",
        stderr(&r)
    );
}
