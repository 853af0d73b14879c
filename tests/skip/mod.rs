//! What an integration test does when an outside tool it drives (POV-Ray, strace, prlimit,
//! SLURM, kubernetes-validate) is missing or cannot start. `.ci/run` installs every one of
//! them, so under CI the test fails with the reason: a broken install step or a daemon that
//! does not come up cannot pass as a skipped test. On a developer's machine the test prints
//! the reason and passes without running.
#![allow(dead_code)]

use std::ffi::OsStr;

/// Ends a test that cannot run here because of `why`: a failure under CI (see [`under_ci`]),
/// otherwise a printed skip. The caller returns right after.
pub fn skip(why: &str) {
    skip_under(under_ci(std::env::var_os("CI").as_deref()), why);
}

/// Whether the value of the `CI` variable means a CI run: set, and neither empty, `0` nor
/// `false` (CI services set `CI=true`; `.ci/run` sets `CI=1`).
pub fn under_ci(value: Option<&OsStr>) -> bool {
    value.is_some_and(|v| !v.is_empty() && v != "0" && v != "false")
}

/// [`skip`] with the CI decision given.
pub fn skip_under(ci: bool, why: &str) {
    assert!(!ci, "cannot run under CI, which must run every test: {why}");
    println!("SKIPPED: {why}");
}
