//! Running POV-Ray 3.7 from integration tests (shared by the test crates that compare with it;
//! each uses a part of it).
#![allow(dead_code)]

use std::path::Path;
use std::process::Command;

/// Whether the POV-Ray comparison can run; without `povray` on the PATH the test skips, or
/// fails under CI ([`skip`](crate::skip::skip)).
pub fn available() -> bool {
    let found = Command::new("povray")
        .arg("--version")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stderr).contains("POV-Ray"));
    if !found {
        crate::skip::skip("povray is not installed (apt-get install povray; .ci/run installs it)");
    }
    found
}

/// Renders `scene` (a file in `dir`, where its includes are) into `png` with the options
/// `args`, without display or console output; panics with POV-Ray's messages when it fails.
pub fn render(dir: &Path, scene: &str, png: &Path, args: &[String]) {
    let out = Command::new("povray")
        .current_dir(dir)
        .arg(format!("+I{scene}"))
        .arg(format!("+O{}", png.display()))
        .args(args)
        .args(["-D", "-GA"])
        .output()
        .expect("povray runs");
    assert!(
        out.status.success(),
        "povray {scene} {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}
