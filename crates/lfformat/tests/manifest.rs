//! `manifest.json` and checksums: known SHA-256 values, atomic write, verification.

use std::collections::BTreeMap;

use lfformat::Error;
use lfformat::manifest::{FileEntry, Manifest, SceneEntry, scene_entry_verifies, sha256_file};

fn manifest() -> Manifest {
    Manifest {
        generator: "lfgen".into(),
        version: "0.1.0".into(),
        config_hash: "abc123".into(),
        seed: 42,
        config: serde_json::json!({"scenes": 110, "camera": {"grid": [9, 9]}}),
        splits: BTreeMap::from([("train".into(), 100), ("val".into(), 10)]),
        scenes: vec![SceneEntry {
            index: 0,
            split: "train".into(),
            dir: "train/scene_0000".into(),
            files: vec![FileEntry {
                path: "train/scene_0000/a.txt".into(),
                sha256: "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad".into(),
                bytes: 3,
            }],
        }],
    }
}

#[test]
fn sha256_matches_known_digests() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty");
    std::fs::write(&empty, b"").unwrap();
    let expected = "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855";
    assert_eq!(sha256_file(&empty).unwrap(), (expected.to_string(), 0));
    let abc = dir.path().join("abc");
    std::fs::write(&abc, b"abc").unwrap();
    let expected = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";
    assert_eq!(sha256_file(&abc).unwrap(), (expected.to_string(), 3));
}

#[test]
fn sha256_streams_files_larger_than_its_buffer() {
    use sha2::Digest;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big");
    let data: Vec<u8> = (0..200_003u32).map(|i| (i * 31 % 251) as u8).collect();
    std::fs::write(&path, &data).unwrap();
    let expected: String = sha2::Sha256::digest(&data)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    assert_eq!(sha256_file(&path).unwrap(), (expected, data.len() as u64));
}

#[test]
fn write_is_atomic_and_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("manifest.json");
    std::fs::write(&path, "old contents").unwrap();
    manifest().write(&path).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(
        names.len(),
        1,
        "a temporary file was left beside the manifest"
    );
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(json["splits"]["val"], 10);
    assert_eq!(json["scenes"][0]["files"][0]["bytes"], 3);
    assert_eq!(json["config"]["camera"]["grid"][1], 9);
    assert_eq!(Manifest::read(&path).unwrap(), manifest());
}

#[test]
fn corrupt_manifest_is_a_format_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("manifest.json");
    std::fs::write(&path, "{\"generator\": \"lfgen\"").unwrap();
    let err = Manifest::read(&path).unwrap_err();
    assert!(matches!(err, Error::Format { .. }));
    assert_eq!(err.path(), path);
}

#[test]
fn scene_verification_checks_presence_size_and_hash() {
    let dir = tempfile::tempdir().unwrap();
    let scene_dir = dir.path().join("train/scene_0000");
    std::fs::create_dir_all(&scene_dir).unwrap();
    let file = scene_dir.join("a.txt");
    let entry = &manifest().scenes[0];
    assert!(!scene_entry_verifies(dir.path(), entry), "missing file");
    std::fs::write(&file, b"abc").unwrap();
    assert!(scene_entry_verifies(dir.path(), entry));
    std::fs::write(&file, b"abd").unwrap();
    assert!(
        !scene_entry_verifies(dir.path(), entry),
        "same size, other bytes"
    );
    std::fs::write(&file, b"abcd").unwrap();
    assert!(!scene_entry_verifies(dir.path(), entry), "other size");
}
