//! docs/reference/cli-lftrain.md equals what `lftrain doc` writes from the flag definitions now.

use std::path::Path;
use std::process::Command;

#[test]
fn the_cli_reference_is_generated_from_the_flag_definitions() {
    let out = Command::new(env!("CARGO_BIN_EXE_lftrain"))
        .arg("doc")
        .output()
        .expect("lftrain runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file = "docs/reference/cli-lftrain.md";
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(file);
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed.as_bytes() == out.stdout,
        "{file} is out of date: run `lftrain doc > {file}` to update"
    );
}
