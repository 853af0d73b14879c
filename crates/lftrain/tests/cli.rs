//! The command line: `--threads` and `-q` before or after a command name, `--threads`' range,
//! `bench`'s flags (each does something: a combination that would ignore one is refused), and
//! the man page and completions. Each case fails at parsing or at the first file read, so the
//! tests run in milliseconds.

use std::process::{Command, Output};

fn lftrain(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lftrain"))
        .args(args)
        .output()
        .expect("lftrain runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A path that does not exist: a run that gets as far as reading it fails naming it.
const MISSING: &str = "/nonexistent/lftrain-cli-test";

/// The arguments parsed, and the run failed at reading `MISSING`, naming it.
fn reads_the_missing_path(args: &[&str]) {
    let out = lftrain(args);
    let err = stderr(&out);
    assert!(
        out.status.code() == Some(1) && err.starts_with("error: ") && err.contains(MISSING),
        "{args:?}: {:?} {err}",
        out.status
    );
}

/// The arguments are a usage error (exit 2) whose message contains `needle`.
fn refused(args: &[&str], needle: &str) {
    let out = lftrain(args);
    let err = stderr(&out);
    assert!(
        out.status.code() == Some(2) && err.contains(needle),
        "{args:?}: {:?} {err}",
        out.status
    );
}

#[test]
fn quiet_and_threads_go_before_or_after_the_command_name() {
    for args in [
        &[
            "-q",
            "--threads",
            "2",
            "predict",
            MISSING,
            MISSING,
            "--out",
            "p",
        ][..],
        &[
            "predict",
            MISSING,
            MISSING,
            "--out",
            "p",
            "--quiet",
            "--threads",
            "2",
        ],
        &["--threads", "1", "bench", "--loader", MISSING, "-q"],
    ] {
        reads_the_missing_path(args);
    }
}

#[test]
fn threads_outside_1_to_1024_is_a_usage_error_naming_the_flag() {
    for args in [
        &["--threads", "0", "bench", "--loader", MISSING][..],
        &["bench", "--loader", MISSING, "--threads", "1025"],
    ] {
        refused(args, "--threads <N>");
        refused(args, "1..=1024");
    }
}

#[test]
fn bench_refuses_the_flags_its_mode_would_ignore() {
    for flag in [["--steps", "3"], ["--grid", "5"]] {
        let args = [&["bench", "--loader", MISSING][..], &flag].concat();
        refused(&args, "'--loader <DATASET>' cannot be used with");
    }
    for flag in [
        ["--batches", "3"],
        ["--scene-pool", "4"],
        ["--pool-refresh", "2"],
    ] {
        let args = [&["bench"][..], &flag].concat();
        refused(&args, "--loader <DATASET>");
    }
}

#[test]
fn bench_takes_each_mode_with_its_own_flags() {
    reads_the_missing_path(&[
        "bench",
        "--loader",
        MISSING,
        "--batches",
        "3",
        "--scene-pool",
        "2",
        "--pool-refresh",
        "1",
        "--model",
        "dpp",
    ]);
    let config = format!("{MISSING}.toml");
    reads_the_missing_path(&["bench", "--config", &config, "--steps", "1", "--grid", "5"]);
}

#[test]
fn man_page_and_completions_come_from_the_flag_definitions() {
    let man = lftrain(&["man"]);
    let page = String::from_utf8_lossy(&man.stdout);
    assert!(
        man.status.success() && page.contains(".TH lftrain 1"),
        "{page}"
    );
    let bash = lftrain(&["completions", "bash"]);
    let script = String::from_utf8_lossy(&bash.stdout);
    assert!(
        bash.status.success() && script.contains("lftrain") && script.contains("--threads"),
        "{script}"
    );
}

/// A training run whose dataset is not there fails before it makes its run folder: no empty
/// `runs/…` is left behind to be mistaken for a run.
#[test]
fn a_run_on_a_missing_dataset_leaves_no_run_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs/r");
    let out_arg = out.to_str().unwrap();
    reads_the_missing_path(&["train", "--train", MISSING, "--out", out_arg]);
    assert!(!dir.path().join("runs").exists());
}
