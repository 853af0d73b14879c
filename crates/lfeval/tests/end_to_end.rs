//! End to end: write a tiny dataset with the lfformat writers, run `lfeval baseline` and
//! `lfeval truth`, evaluate both, and check the report files and the numbers.
//!
//! The scenes are fronto-parallel planes with a random texture at an integer disparity, so
//! every view is an exact integer shift of the centre view and the baseline must find the
//! right bin almost everywhere. A block of pixels gets a second ground-truth mode so the
//! multimodal KLD has pixels to average over.

use std::path::Path;
use std::process::Command;

use lfformat::pfm::{FloatImage, write_pfm};
use lfformat::{HciParameters, Mode, ModeMap, modes::write_modes_exr};
use serde_json::Value;

const SIZE: usize = 48;
const GRID: usize = 9;
const BORDER: &str = "6";

/// A deterministic texture value in [0, 1] per integer position and channel.
fn texture(x: i64, y: i64, c: u64) -> u8 {
    let mut h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ c.wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    (h >> 56) as u8
}

fn parameters(name: &str) -> HciParameters {
    HciParameters {
        focal_length_mm: 100.0,
        image_resolution_x_px: SIZE as u32,
        image_resolution_y_px: SIZE as u32,
        sensor_size_mm: 35.0,
        fstop: 100.0,
        num_cams_x: GRID as u32,
        num_cams_y: GRID as u32,
        baseline_mm: 10.0,
        focus_distance_m: 2.0,
        center_cam_x_m: 0.0,
        center_cam_y_m: 0.0,
        center_cam_z_m: 0.0,
        center_cam_rx_rad: 0.0,
        center_cam_ry_rad: 0.0,
        center_cam_rz_rad: 0.0,
        scene: name.into(),
        category: "test".into(),
        date: "2024-01-01".into(),
        version: "test".into(),
        cycles_seed: 0,
        disp_min: -3.6,
        disp_max: 3.6,
        frustum_disp_min: -3.5,
        frustum_disp_max: 3.5,
        depth_map_scale: 1.0,
    }
}

/// A plane at integer disparity `d`: a point at `(x, y)` in the centre view is at
/// `(x - du·d, y - dv·d)` in view `(u, v)`, so view `(u, v)` shows `T(x + du·d, y + dv·d)`.
fn write_scene(dir: &Path, d: i64) {
    std::fs::create_dir_all(dir).unwrap();
    let name = dir.file_name().unwrap().to_str().unwrap();
    parameters(name).write(&dir.join("parameters.cfg")).unwrap();
    let c = (GRID / 2) as i64;
    for v in 0..GRID {
        for u in 0..GRID {
            let (du, dv) = (u as i64 - c, v as i64 - c);
            let img = image::RgbImage::from_fn(SIZE as u32, SIZE as u32, |x, y| {
                let (tx, ty) = (i64::from(x) + du * d, i64::from(y) + dv * d);
                image::Rgb([0, 1, 2].map(|ch| texture(tx, ty, ch)))
            });
            img.save(dir.join(format!("input_Cam{:03}.png", v * GRID + u)))
                .unwrap();
        }
    }
    let disp = FloatImage::new(SIZE, SIZE, vec![d as f32; SIZE * SIZE]);
    write_pfm(&dir.join("gt_disp_lowres.pfm"), &disp).unwrap();
    let mode = |disparity: f32, eta: f32| Mode {
        disparity,
        depth: 2.0,
        eta,
        eta_exact: eta,
    };
    let mut modes = ModeMap::new(SIZE, SIZE);
    for y in 0..SIZE {
        for x in 0..SIZE {
            if (20..28).contains(&x) && (20..28).contains(&y) {
                modes.push_pixel(&[mode(d as f32, 0.6), mode(-2.5, 0.4)]);
            } else {
                modes.push_pixel(&[mode(d as f32, 1.0)]);
            }
        }
    }
    write_modes_exr(&dir.join("modes.exr"), &modes).unwrap();
}

/// Runs lfeval, which must succeed; its standard output.
fn lfeval(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_lfeval"))
        .args(args)
        .output()
        .expect("lfeval runs");
    assert!(
        out.status.success(),
        "lfeval {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn number(v: &Value, path: &[&str]) -> f64 {
    let mut cur = v;
    for key in path {
        cur = &cur[*key];
    }
    cur.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number: {cur}"))
}

#[test]
fn baseline_and_truth_are_evaluated_end_to_end() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let ds = root.join("dataset");
    write_scene(&ds.join("val/scene_0000"), 1);
    write_scene(&ds.join("val/scene_0001"), -2);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (baseline, truth, report) = (
        root.join("baseline"),
        root.join("truth"),
        root.join("report"),
    );

    lfeval(&[
        "baseline",
        &s(&ds),
        "--out",
        &s(&baseline),
        "--split",
        "val",
        "--quiet",
    ]);
    // -q before the command name: the command still runs (not an evaluation of `truth`).
    lfeval(&["-q", "truth", &s(&ds), "--out", &s(&truth)]);
    for f in [
        "disp_maps/scene_0000.pfm",
        "posteriors/scene_0000.npz",
        "uncertainty/scene_0001.pfm",
        "runtimes/scene_0001.txt",
        "lfeval.json",
    ] {
        assert!(baseline.join(f).is_file(), "baseline wrote no {f}");
    }
    let table = lfeval(&[
        &s(&ds),
        &s(&baseline),
        &s(&truth),
        "--out",
        &s(&report),
        "--border",
        BORDER,
        "--pixel",
        "scene_0001:24,24",
        "--quiet",
    ]);
    // --quiet hides progress, not the result: the summary table still reaches stdout.
    assert!(
        table.contains("| baseline |") && table.contains("| truth |"),
        "{table}"
    );

    for f in [
        "metrics.json",
        "report.md",
        "report.html",
        "sparsification_badpix007.png",
        "sparsification_mse.png",
        "error_maps/baseline/scene_0000.png",
        "error_maps/truth/scene_0001.png",
        "posteriors/scene_0001_x24_y24.png",
    ] {
        let meta = std::fs::metadata(report.join(f)).unwrap_or_else(|_| panic!("{f} missing"));
        assert!(meta.len() > 100, "{f} is nearly empty");
    }
    let md = std::fs::read_to_string(report.join("report.md")).unwrap();
    assert!(
        md.contains("| baseline |") && md.contains("| truth |"),
        "{md}"
    );

    let metrics: Value =
        serde_json::from_slice(&std::fs::read(report.join("metrics.json")).unwrap()).unwrap();
    let methods = metrics["methods"].as_array().unwrap();
    let (base, gt) = (&methods[0]["summary"], &methods[1]["summary"]);
    assert_eq!(methods[0]["name"], "baseline");

    // The ground truth as prediction: zero error, zero KLD, on the Oracle.
    for key in ["mse_x100", "badpix_001", "badpix_007", "q25"] {
        assert_eq!(number(gt, &["unimodal", "front", key]), 0.0, "truth {key}");
    }
    assert!(number(gt, &["kld", "all"]).abs() < 1e-9);
    assert!(number(gt, &["sparsification", "badpix_007", "ause"]).abs() < 1e-12);
    // 8×8 multimodal pixels per scene, inside the 36×36 evaluated frame.
    assert_eq!(number(gt, &["kld", "pixels_multimodal"]), 128.0);
    assert_eq!(number(gt, &["kld", "pixels_all"]), 2.0 * 36.0 * 36.0);

    // The baseline on a textured integer-disparity plane: the right bin almost everywhere.
    let badpix = number(base, &["unimodal", "front", "badpix_007"]);
    assert!(badpix < 5.0, "baseline BadPix(0.07) = {badpix} %");
    let mse = number(base, &["unimodal", "front", "mse_x100"]);
    assert!(mse.is_finite() && mse < 1.0, "baseline MSE×100 = {mse}");
    for key in ["unimodal", "multimodal", "all"] {
        let k = number(base, &["kld", key]);
        assert!(k.is_finite() && k > 0.0, "baseline KLD {key} = {k}");
    }
    // Multimodal pixels: the baseline sees only the plane, so it misses the 0.4 mode.
    assert!(number(base, &["kld", "multimodal"]) > number(base, &["kld", "unimodal"]));
    let ause = number(base, &["sparsification", "badpix_007", "ause"]);
    assert!(ause.is_finite() && ause >= 0.0, "AuSE {ause}");
    let time = number(base, &["runtime_mean_s"]);
    assert!(time > 0.0 && time < 60.0, "runtime {time}");
}

#[test]
fn a_fifo_or_dev_zero_in_a_dataset_is_refused_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = tmp.path().join("dataset");
    let scene = ds.join("scene_a");
    write_scene(&scene, 1);
    let view = scene.join("input_Cam040.png");
    let out = tmp.path().join("truth");
    let s = |p: &Path| p.to_str().unwrap().to_string();
    for hostile in ["fifo", "zero"] {
        std::fs::remove_file(&view).unwrap();
        if hostile == "fifo" {
            assert!(
                Command::new("mkfifo")
                    .arg(&view)
                    .status()
                    .unwrap()
                    .success()
            );
        } else {
            std::os::unix::fs::symlink("/dev/zero", &view).unwrap();
        }
        let r = Command::new("timeout")
            .arg("20")
            .arg(env!("CARGO_BIN_EXE_lfeval"))
            .args(["baseline", &s(&ds), "--out", &s(&out), "--quiet"])
            .output()
            .expect("lfeval runs");
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{hostile}: {err}");
        assert!(
            err.contains("input_Cam040.png") && err.contains("not a regular file"),
            "{hostile}: {err}"
        );
    }
}

/// `lfeval ARGS` under `strace`, its `n`-th `fsync` failing with ENOSPC (a full disk seen when
/// the written bytes are flushed); `None` outside CI where strace cannot trace.
fn lfeval_with_full_disk_at_sync(n: usize, args: &[&str]) -> Option<std::process::Output> {
    let traces = Command::new("strace")
        .args(["-qq", "-o", "/dev/null", "true"])
        .status()
        .is_ok_and(|s| s.success());
    if !traces {
        assert!(
            std::env::var_os("CI").is_none(),
            "strace is missing or cannot trace (.ci/run installs it)"
        );
        eprintln!("skipped: strace is missing or cannot trace here");
        return None;
    }
    let out = Command::new("strace")
        .args(["-f", "-qq", "-o", "/dev/null", "-e", "trace=fsync", "-e"])
        .arg(format!("inject=fsync:error=ENOSPC:when={n}"))
        .arg(env!("CARGO_BIN_EXE_lfeval"))
        .args(args)
        .output()
        .expect("strace runs");
    Some(out)
}

#[test]
fn a_report_image_that_cannot_be_written_fails_the_run_and_leaves_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let ds = root.join("dataset");
    write_scene(&ds.join("scene_a"), 1);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (truth, report) = (root.join("truth"), root.join("report"));
    lfeval(&["truth", &s(&ds), "--out", &s(&truth), "--quiet"]);
    let eval = [&s(&ds), &s(&truth), "--out", &s(&report), "--quiet"];
    // The first file written is the error map; without them, the second (after
    // metrics.json) is the first sparsification chart.
    let cases = [
        (1, "error_maps/truth/scene_a.png", &[][..]),
        (2, "sparsification_badpix007.png", &["--no-error-maps"][..]),
    ];
    for (n, victim, extra) in cases {
        let Some(out) = lfeval_with_full_disk_at_sync(n, &[&eval[..], extra].concat()) else {
            return;
        };
        let err = String::from_utf8_lossy(&out.stderr);
        let path = report.join(victim);
        let name = path.file_name().unwrap().to_str().unwrap();
        assert!(
            out.status.code() == Some(1) && err.contains(name) && err.contains("No space left"),
            "{victim}: {:?}: {err}",
            out.status
        );
        let left: Vec<_> = std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|f| f.starts_with(name))
            .collect();
        assert!(left.is_empty(), "{victim}: left behind {left:?}");
        std::fs::remove_dir_all(&report).unwrap();
    }
}

/// A scene without `gt_disp_lowres.pfm` (an HCI test scene) is left out of the scores with a
/// warning naming it and listed in metrics.json; one whose ground truth is there but no
/// regular file (a FIFO) is an error naming the file, never a silently skipped scene.
#[test]
fn a_scene_without_ground_truth_is_named_and_one_with_a_broken_ground_truth_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let ds = tmp.path().join("dataset");
    write_scene(&ds.join("scene_a"), 1);
    write_scene(&ds.join("scene_b"), 1);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (truth, report) = (tmp.path().join("truth"), tmp.path().join("report"));
    lfeval(&["truth", &s(&ds), "--out", &s(&truth), "--quiet"]);
    let gt = ds.join("scene_b/gt_disp_lowres.pfm");
    std::fs::remove_file(&gt).unwrap();
    let run = || {
        Command::new("timeout")
            .arg("60")
            .arg(env!("CARGO_BIN_EXE_lfeval"))
            .args([&s(&ds), &s(&truth), "--out", &s(&report), "--quiet"])
            .output()
            .expect("lfeval runs")
    };
    let r = run();
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(
        err.contains("warning: 1 scene(s) without gt_disp_lowres.pfm") && err.contains("scene_b"),
        "{err}"
    );
    let metrics: Value =
        serde_json::from_slice(&std::fs::read(report.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["skipped_scenes"], serde_json::json!(["scene_b"]));
    assert!(Command::new("mkfifo").arg(&gt).status().unwrap().success());
    let r = run();
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(1), "{err}");
    assert!(
        err.contains("scene_b/gt_disp_lowres.pfm") && err.contains("not a regular file"),
        "{err}"
    );
}

/// `lfeval corrupt` then `lfeval robustness`: every copy keeps the ground truth byte for byte,
/// the noise has its σ and repeats with its seed, and the ground truth scored on every copy
/// (as a method) makes a table of zeros.
#[test]
fn corrupted_copies_and_the_robustness_table() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let ds = root.join("dataset");
    write_scene(&ds.join("val/scene_0000"), 1);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let corrupt = |out: &Path, seed: &str| {
        lfeval(&["-q", "corrupt", &s(&ds), "--out", &s(out), "--seed", seed]);
    };
    let (a, b, c) = (root.join("a"), root.join("b"), root.join("c"));
    corrupt(&a, "3");
    corrupt(&b, "3");
    corrupt(&c, "4");
    let read = |p: &Path| std::fs::read(p).unwrap();
    let scene = |copy: &Path, name: &str| copy.join(name).join("val/scene_0000");
    let view = "input_Cam040.png";
    let noisy = scene(&a, "noise_10").join(view);
    assert_eq!(read(&noisy), read(&scene(&b, "noise_10").join(view)));
    assert_ne!(read(&noisy), read(&scene(&c, "noise_10").join(view)));
    for gt in ["gt_disp_lowres.pfm", "modes.exr", "parameters.cfg"] {
        let original = read(&ds.join("val/scene_0000").join(gt));
        assert_eq!(read(&scene(&a, "jpeg_30").join(gt)), original, "{gt}");
    }
    // The σ of the added noise, away from the clipped ends of the range.
    let pixels = |p: &Path| image::open(p).unwrap().to_rgb8().into_raw();
    let (clean, noise) = (pixels(&scene(&a, "clean").join(view)), pixels(&noisy));
    let diffs: Vec<f64> = (clean.iter().zip(&noise))
        .filter(|(c, _)| (40..=215).contains(*c))
        .map(|(&c, &n)| n as f64 - c as f64)
        .collect();
    let sd = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    assert!((sd - 10.0).abs() < 0.6, "σ {sd}");

    let truth = root.join("truth");
    for entry in std::fs::read_dir(&a).unwrap() {
        let copy = entry.unwrap().path();
        if copy.is_dir() {
            let name = copy.file_name().unwrap().to_str().unwrap().to_string();
            lfeval(&["-q", "truth", &s(&copy), "--out", &s(&truth.join(name))]);
        }
    }
    let report = root.join("robustness");
    let table = lfeval(&["-q", "robustness", &s(&a), &s(&truth), "--out", &s(&report)]);
    assert!(table.contains("| noise_10 | 0.000 |"), "{table}");
    let json: Value = serde_json::from_slice(&read(&report.join("robustness.json"))).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 12);
    assert!(
        rows.iter().all(|r| r["scores"][0]["badpix_007"] == 0.0),
        "{json}"
    );
    assert!(
        std::fs::metadata(report.join("robustness.png"))
            .unwrap()
            .len()
            > 1000
    );
}

/// `--crop 0.5` scores only the centred 24² of the 48² scene: a prediction wrong only outside
/// it scores zero, one written for the crop alone (disparity and Laplace posterior) is placed
/// there, and without `--crop` that crop-sized prediction is refused by name.
#[test]
fn a_crop_scores_only_the_centre_and_takes_crop_sized_predictions() {
    use lfdata::posterior::{PosteriorForm, PosteriorMap};
    use lfdata::prediction::{ScenePrediction, write_prediction};
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let ds = root.join("dataset");
    write_scene(&ds.join("val/scene_0000"), 1);
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let (outside, small) = (root.join("outside"), root.join("small"));
    // Right (d = 1) on columns and rows 12..36, 3 px off around them.
    let centre = |i: usize| (12..36).contains(&(i % SIZE)) && (12..36).contains(&(i / SIZE));
    let wrong = (0..SIZE * SIZE).map(|i| if centre(i) { 1.0 } else { 4.0 });
    let prediction = |size: usize, data: Vec<f32>, posterior| ScenePrediction {
        disparity: FloatImage::new(size, size, data),
        uncertainty: None,
        posterior,
        runtime_s: Some(1.0),
    };
    let full = prediction(SIZE, wrong.collect(), None);
    write_prediction(&outside, "scene_0000", &full).unwrap();
    let laplace = PosteriorMap {
        width: 24,
        height: 24,
        form: PosteriorForm::Laplace {
            mu: vec![1.0; 24 * 24],
            log_b: vec![-3.0; 24 * 24],
        },
    };
    let crop_only = prediction(24, vec![1.0; 24 * 24], Some(laplace));
    write_prediction(&small, "scene_0000", &crop_only).unwrap();

    let report = root.join("report");
    let args = [&s(&ds), &s(&outside), &s(&small), "--out", &s(&report)];
    let table = lfeval(&[&args[..], &["--crop", "0.5", "--border", BORDER, "-q"]].concat());
    assert!(table.contains("only the centred 0.5 × 0.5 crop"), "{table}");
    let metrics: Value =
        serde_json::from_slice(&std::fs::read(report.join("metrics.json")).unwrap()).unwrap();
    for m in metrics["methods"].as_array().unwrap() {
        let summary = &m["summary"];
        for key in ["mse_x100", "badpix_007"] {
            let v = number(summary, &["unimodal", "front", key]);
            assert_eq!(v, 0.0, "{} {key}", m["name"]);
        }
    }
    let small_kld = &metrics["methods"][1]["summary"]["kld"];
    // Every crop pixel has a distribution; the 8×8 two-mode block lies inside the crop.
    assert_eq!(number(small_kld, &["pixels_all"]), 24.0 * 24.0);
    assert_eq!(number(small_kld, &["pixels_multimodal"]), 64.0);

    let whole = root.join("whole");
    let out = Command::new(env!("CARGO_BIN_EXE_lfeval"))
        .args([&s(&ds), &s(&small), "--out", &s(&whole), "-q"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success(),
        "a crop-sized prediction passed without --crop"
    );
    assert!(err.contains("scene_0000") && err.contains("24x24"), "{err}");
    let bad = Command::new(env!("CARGO_BIN_EXE_lfeval"))
        .args([&s(&ds), &s(&outside), "--out", &s(&whole), "--crop", "0"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&bad.stderr).contains("not in (0, 1]"));
}
