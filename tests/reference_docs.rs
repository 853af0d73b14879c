//! The generated reference pages are current: docs/reference/cli.md (every command and flag)
//! and docs/reference/config.md (every config key and preset) equal what `lfgen doc` writes
//! from the code now.

use std::path::Path;
use std::process::Command;

/// Fails with the command that regenerates `page` when the committed file differs.
fn assert_current(page: &str, file: &str) {
    let out = Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(["doc", page])
        .output()
        .expect("lfgen runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed.as_bytes() == out.stdout,
        "{file} is out of date: run `lfgen doc {page} > {file}` to update"
    );
}

#[test]
fn the_cli_reference_is_generated_from_the_flag_definitions() {
    assert_current("cli", "docs/reference/cli.md");
}

#[test]
fn the_config_reference_is_generated_from_the_defaults() {
    assert_current("config", "docs/reference/config.md");
}
