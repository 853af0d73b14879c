//! Running the `lfgen` binary from integration tests (shared by several test crates; each uses
//! a part of it).
#![allow(dead_code)]

use std::process::{Command, Output};

/// Runs `lfgen` with `args`.
pub fn lfgen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
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
    names.extend(
        [
            "gt_depth_lowres.pfm",
            "gt_disp_lowres.pfm",
            "gt_mpi_lowres.npz",
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
