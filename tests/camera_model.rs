//! The camera model end to end (`--preset camera`): its views are a function of the seed alone
//! (the same bytes on 1 and 2 threads), they differ from the clean render, and the clean views
//! it writes beside them are byte for byte the views of a run without the model.

mod bin;

use bin::{files, generate, ok};

#[test]
fn camera_views_are_seeded_and_the_clean_views_are_the_plain_render() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        ok(generate(&out, "2", extra));
        files(&out)
    };
    let camera = ["--preset", "camera", "--set", "sensor.write_clean=true"];
    let plain = run("plain", &[]);
    let one = run("one", &[&["--threads", "1"], &camera[..]].concat());
    let two = run("two", &[&["--threads", "2"], &camera[..]].concat());
    assert_eq!(one, two, "the camera model depends on the seed only");
    let mut views = 0;
    for (path, bytes) in &plain {
        if !path.contains("input_Cam") {
            continue;
        }
        let clean = path.replace("input_Cam", "clean_Cam");
        assert_eq!(one.get(&clean), Some(bytes), "{clean} is the plain render");
        assert_ne!(one.get(path), Some(bytes), "{path} went through the camera");
        views += 1;
    }
    assert_eq!(views, 2 * 9);
    // Each scene's draw is in its stats.json, within the preset's ranges; a plain run has none.
    let stats = |set: &std::collections::BTreeMap<String, Vec<u8>>| -> Vec<serde_json::Value> {
        let all = set.iter().filter(|(p, _)| p.ends_with("stats.json"));
        all.map(|(_, b)| serde_json::from_slice(b).unwrap())
            .collect()
    };
    let draws: Vec<serde_json::Value> = stats(&one)
        .into_iter()
        .map(|s| s["camera"].clone())
        .collect();
    assert_eq!(draws.len(), 2);
    for d in &draws {
        let n = |key: &str| {
            d[key]
                .as_f64()
                .unwrap_or_else(|| panic!("camera.{key} in {d}"))
        };
        assert!((100.0..=1600.0).contains(&n("iso")), "{d}");
        assert!(
            n("exposure_ev").abs() <= 0.5 && (0.0..=0.5).contains(&n("vignetting")),
            "{d}"
        );
        let wb = d["white_balance_ev"].as_array().unwrap();
        assert!(
            wb.len() == 2 && wb.iter().all(|v| v.as_f64().unwrap().abs() <= 0.15),
            "{d}"
        );
    }
    assert_ne!(draws[0], draws[1], "each scene draws its own capture");
    assert!(stats(&plain).iter().all(|s| s.get("camera").is_none()));
}
