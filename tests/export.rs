//! `lfgen export`: the files each target gets, and clear errors on bad input. (The renderers
//! themselves are exercised by tests/povray.rs and scripts/validate.sh.)

mod bin;

use bin::{lfgen, ok};
use std::path::Path;

fn scene(dir: &Path) -> String {
    let ds = dir.join("ds");
    ok(lfgen(&[
        "--scenes",
        "1",
        "--out",
        ds.to_str().unwrap(),
        "--set",
        "camera.resolution=[24,16]",
        "--set",
        "camera.grid=[3,3]",
        "--set",
        "render.spp=1",
        "--set",
        "scene.objects=4",
        "--quiet",
    ]));
    ds.join("train/scene_0000").display().to_string()
}

#[test]
fn every_target_gets_its_files_and_the_selected_views() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = |t: &str| tmp.path().join(t).display().to_string();
    ok(lfgen(&[
        "export",
        "--to",
        "pov",
        &scene,
        "--out",
        &out("pov"),
        "--views",
        "0,8",
    ]));
    let cams = std::fs::read_to_string(tmp.path().join("pov/cameras.inc")).unwrap();
    assert!(
        cams.contains("#case (0)") && cams.contains("#case (8)") && !cams.contains("#case (4)")
    );
    for f in ["geometry.inc", "depth.pov", "scene.pov"] {
        assert!(tmp.path().join("pov").join(f).is_file(), "{f}");
    }
    ok(lfgen(&[
        "export",
        "--to",
        "mitsuba",
        &scene,
        "--out",
        &out("mi"),
        "--views",
        "center",
    ]));
    let xml = std::fs::read_to_string(tmp.path().join("mi/scene.xml")).unwrap();
    assert_eq!(xml.matches("<sensor").count(), 1);
    assert!(xml.contains("id=\"Cam004\"") && tmp.path().join("mi/depth.xml").is_file());
    ok(lfgen(&[
        "export",
        "--to",
        "blender",
        &scene,
        "--out",
        &out("bl"),
    ]));
    let json = std::fs::read_to_string(tmp.path().join("bl/blender_scene.json")).unwrap();
    let data: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(
        data["cameras"].as_array().unwrap().len(),
        9,
        "all views by default"
    );
    assert!(tmp.path().join("bl/scene.py").is_file());
    let meshes = std::fs::read_dir(tmp.path().join("bl/meshes"))
        .unwrap()
        .count();
    assert_eq!(meshes, data["objects"].as_array().unwrap().len());
}

#[test]
fn bad_targets_views_and_folders_are_named_in_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = scene(tmp.path());
    let out = tmp.path().join("x").display().to_string();
    let err = |args: &[&str]| {
        let o = lfgen(args);
        assert!(!o.status.success(), "{args:?} should fail");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    assert!(err(&["export", "--to", "luxcore", &scene, "--out", &out]).contains("luxcore"));
    let e = err(&[
        "export", "--to", "pov", &scene, "--out", &out, "--views", "9",
    ]);
    assert!(e.contains("view 9") && e.contains("9 views"), "{e}");
    let missing = tmp.path().join("nope").display().to_string();
    let e = err(&["export", "--to", "pov", &missing, "--out", &out]);
    assert!(e.contains("nope/scene.json"), "{e}");
}
