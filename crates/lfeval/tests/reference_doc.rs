//! docs/reference/cli-lfeval.md equals what `lfeval doc` writes from the flag definitions now.

use std::path::Path;
use std::process::Command;

#[test]
fn the_cli_reference_is_generated_from_the_flag_definitions() {
    let out = Command::new(env!("CARGO_BIN_EXE_lfeval"))
        .arg("doc")
        .output()
        .expect("lfeval runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = "docs/reference/cli-lfeval.md";
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(file);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed.as_bytes() == out.stdout,
        "{file} is out of date: run `lfeval doc > {file}` to update"
    );
}
