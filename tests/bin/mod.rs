//! Running the `lfgen` binary from integration tests (shared by several test crates; each uses
//! a part of it).
#![allow(dead_code)]

use lfformat::region_masks::{MASK_STEMS, mask_file};
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::fs;
use std::path::Path;
use std::process::{Command, Output};

/// Runs `lfgen` with `args`.
pub fn lfgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .output()
        .expect("lfgen runs")
}

/// Runs `lfgen` with `args`, its BVH traced by the SIMD kernel `kernel` (`LFGEN_SIMD`).
pub fn lfgen_simd(kernel: &str, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .env("LFGEN_SIMD", kernel)
        .output()
        .expect("lfgen runs")
}

/// Asserts the run succeeded, showing its stderr otherwise.
pub fn ok(out: Output) -> Output {
    assert!(out.status.success(), "lfgen failed: {}", stderr(&out));
    out
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The files of a centre-GT scene folder with `views` views, sorted by name.
pub fn scene_files(views: u32) -> Vec<String> {
    let mut names: Vec<String> = (0..views).map(|i| format!("input_Cam{i:03}.png")).collect();
    names.extend(MASK_STEMS.iter().map(|stem| mask_file(stem, false)));
    names.extend(
        [
            "gt_depth_lowres.pfm",
            "gt_disp_lowres.pfm",
            "gt_mpi_lowres.npz",
            "gt_normals_lowres.exr",
            "objectids_lowres.png",
            "materialids_lowres.png",
            "classids_lowres.png",
            "valid_mask.png",
            "ids.json",
            "modes.exr",
            "parameters.cfg",
            "scene.json",
            "stats.json",
        ]
        .map(String::from),
    );
    names.sort();
    names
}

/// A tiny but complete dataset: every feature on, seconds to render.
pub const TINY: &[&str] = &[
    "--set",
    "camera.resolution=[40,32]",
    "--set",
    "camera.grid=[3,3]",
    "--set",
    "render.spp=2",
    "--set",
    "scene.objects=10",
    "--set",
    "dataset.date=2026-01-01",
    "--quiet",
];

/// Every file under `root` (relative path → bytes), excluding run timings.
pub fn files(root: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.file_name().unwrap() != "timings.jsonl" {
                out.insert(
                    p.strip_prefix(root).unwrap().display().to_string(),
                    fs::read(&p).unwrap(),
                );
            }
        }
    }
    out
}

pub fn generate(out: &Path, scenes: &str, extra: &[&str]) -> Output {
    let mut args = vec!["--scenes", scenes, "--out", out.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(TINY);
    lfgen(&args)
}

/// Why a bounded test cannot run when [`can_bound`] is false.
pub const NO_PRLIMIT: &str = "prlimit is missing (apt-get install util-linux; .ci/run installs it)";

/// Whether `prlimit` (util-linux) is here to bound the binary runs.
pub fn can_bound() -> bool {
    Command::new("prlimit").arg("--version").output().is_ok()
}

/// Runs `lfgen args` under a 4 GiB address space (as a user's `ulimit -v` or a cluster's
/// memory limit would hold it), 60 s of CPU and 120 s of wall time, from the temporary folder:
/// away from the repository's generator.toml, which lfgen would announce and apply. Paths in
/// `args` must be absolute.
pub fn bounded<S: AsRef<OsStr>>(args: &[S]) -> Output {
    Command::new("timeout")
        .args(["120", "prlimit", "--as=4294967296", "--cpu=60"])
        .arg(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .current_dir(std::env::temp_dir())
        .output()
        .expect("timeout and prlimit run")
}

/// [`bounded`], asserting it ended with exit code 0 or 1 (not a signal, abort or time-out),
/// a refusal with one `error:` cause and no panic. `what` is shown on failure. Returns the
/// exit code.
pub fn run_bounded<S: AsRef<OsStr>>(args: &[S], what: &str) -> i32 {
    let r = bounded(args);
    let err = stderr(&r);
    let code = r.status.code();
    assert!(
        matches!(code, Some(0 | 1)),
        "ended with {:?}: {err}\n{what}",
        r.status
    );
    if code == Some(1) {
        assert!(
            err.starts_with("error: ") && !err.contains("panicked"),
            "{err}\n{what}"
        );
    }
    code.unwrap()
}
