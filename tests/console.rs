//! A full disk behind standard output or standard error (`/dev/full`): a lost log line never
//! aborts a run, and a result that cannot reach standard output is a clean error — never the
//! panic of `println!` ("failed printing to stderr", exit code 101).

mod bin;

use bin::{TINY, files, generate, ok};
use std::fs::File;
use std::process::{Command, Output, Stdio};

/// Runs `lfgen args` with standard output to `/dev/full` when `stdout_full`, and standard
/// error always to `/dev/full`.
fn lfgen_into_full_disk(args: &[&str], stdout_full: bool) -> Output {
    let full = || Stdio::from(File::create("/dev/full").expect("/dev/full opens"));
    let stdout = if stdout_full { full() } else { Stdio::piped() };
    Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .stdout(stdout)
        .stderr(full())
        .output()
        .expect("lfgen runs")
}

#[test]
fn a_run_with_full_stdout_and_stderr_writes_the_same_dataset_and_exits_0() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("full");
    let mut args = vec!["--scenes", "1", "--out", out.to_str().unwrap()];
    args.extend(TINY.iter().filter(|a| **a != "--quiet"));
    let run = lfgen_into_full_disk(&args, true);
    assert_eq!(run.status.code(), Some(0));

    let plain = tmp.path().join("plain");
    ok(generate(&plain, "1", &[]));
    assert!(
        files(&out) == files(&plain),
        "the dataset differs from one written with a working stderr"
    );
}

#[test]
fn an_error_with_a_full_stderr_still_exits_1() {
    let run = lfgen_into_full_disk(&["--shard", "9/2"], true);
    assert_eq!(run.status.code(), Some(1));
}

#[test]
fn a_result_that_cannot_reach_stdout_is_an_error_naming_it() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("textures");
    let args = ["textures", "--count", "1", "--out", out.to_str().unwrap()];
    let run = Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .stdout(File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1));
    let err = String::from_utf8_lossy(&run.stderr);
    assert_eq!(
        err.trim(),
        "error: standard output: No space left on device (os error 28)"
    );
    assert!(out.join("catalog.json").is_file(), "{err}");
}

#[test]
fn help_into_a_full_disk_does_not_panic() {
    let run = lfgen_into_full_disk(&["--help"], true);
    assert_eq!(run.status.code(), Some(0));
}
