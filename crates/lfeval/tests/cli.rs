//! The command line: `--threads` and `-q` before or after a command name, `--threads`' range,
//! and the man page and completions. Each case fails at parsing or at the first dataset read,
//! so the tests run in milliseconds.

use std::process::{Command, Output};

fn lfeval(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lfeval"))
        .args(args)
        .output()
        .expect("lfeval runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A dataset path that does not exist: a run that gets as far as reading it fails naming it.
const MISSING: &str = "/nonexistent/lfeval-cli-test";

/// The run parsed as meant: it went on to read `MISSING` as its dataset.
fn reads_the_missing_dataset(args: &[&str]) {
    let out = lfeval(args);
    let err = stderr(&out);
    assert!(
        out.status.code() == Some(1)
            && err.starts_with("error: ")
            && err.contains(&format!("{MISSING}: dataset folder does not exist")),
        "{args:?}: {:?} {err}",
        out.status
    );
}

#[test]
fn quiet_and_threads_go_before_or_after_the_command_name() {
    for args in [
        &["-q", "baseline", MISSING, "--out", "p"][..],
        &["--threads", "2", "-q", "baseline", MISSING, "--out", "p"],
        &["--threads=2", "truth", MISSING, "--out", "p"],
        &["baseline", MISSING, "--out", "p", "-q", "--threads", "2"],
        &["--quiet", "truth", "--threads", "1", MISSING, "--out", "p"],
        &["-q", "--threads", "2", MISSING, "pred"],
        &[MISSING, "pred", "--quiet", "--threads", "2"],
    ] {
        reads_the_missing_dataset(args);
    }
}

#[test]
fn after_a_double_dash_a_command_name_is_a_dataset() {
    let out = lfeval(&["-q", "--", "baseline", "pred"]);
    assert!(
        stderr(&out).contains("baseline: dataset folder does not exist"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn threads_outside_1_to_1024_is_a_usage_error_naming_the_flag() {
    for args in [
        &["--threads", "0", "baseline", MISSING, "--out", "p"][..],
        &["baseline", MISSING, "--out", "p", "--threads", "1025"],
        &[MISSING, "pred", "--threads", "0"],
    ] {
        let out = lfeval(args);
        let err = stderr(&out);
        assert!(
            out.status.code() == Some(2)
                && err.contains("--threads <N>")
                && err.contains("1..=1024"),
            "{args:?}: {:?} {err}",
            out.status
        );
    }
}

#[test]
fn man_page_and_completions_come_from_the_flag_definitions() {
    let man = lfeval(&["man"]);
    let page = String::from_utf8_lossy(&man.stdout);
    assert!(
        man.status.success() && page.contains(".TH lfeval 1"),
        "{page}"
    );
    let bash = lfeval(&["completions", "bash"]);
    let script = String::from_utf8_lossy(&bash.stdout);
    assert!(
        bash.status.success() && script.contains("lfeval") && script.contains("--threads"),
        "{script}"
    );
}
