//! A dataset file that is a FIFO, a symlink to `/dev/zero`, or longer than `manifest.json`
//! records: scene discovery (whose checksum step every lfeval and lftrain command runs) and
//! the readers must refuse it at once, naming the file, instead of blocking or reading forever.
#![cfg(target_os = "linux")]

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use lfformat::dataset::{PARAMETERS_FILE, discover};
use lfformat::manifest::{FileEntry, Manifest, SceneEntry, sha256_file};

const GT: &str = "gt_disp_lowres.pfm";

/// A one-scene dataset `root/val/scene_0000` listed in `manifest.json`.
fn dataset(root: &Path) -> std::path::PathBuf {
    let scene = root.join("val/scene_0000");
    std::fs::create_dir_all(&scene).unwrap();
    std::fs::write(scene.join(PARAMETERS_FILE), "").unwrap();
    std::fs::write(scene.join(GT), b"PFMDATA").unwrap();
    let files = [PARAMETERS_FILE, GT]
        .iter()
        .map(|name| {
            let (sha256, bytes) = sha256_file(&scene.join(name)).unwrap();
            FileEntry {
                path: format!("val/scene_0000/{name}"),
                sha256,
                bytes,
            }
        })
        .collect();
    Manifest {
        generator: "test".into(),
        version: "0".into(),
        config_hash: String::new(),
        seed: 0,
        config: serde_json::Value::Null,
        splits: Default::default(),
        scenes: vec![SceneEntry {
            index: 0,
            split: "val".into(),
            dir: "val/scene_0000".into(),
            files,
        }],
    }
    .write(&root.join("manifest.json"))
    .unwrap();
    scene
}

/// `f()`'s error text, failing the test if it succeeds or takes longer than ten seconds (a
/// reader blocked on a FIFO or reading `/dev/zero` never returns).
fn refused_quickly<T: Send + 'static>(
    f: impl FnOnce() -> lfformat::Result<T> + Send + 'static,
) -> String {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f().err().map(|e| e.to_string()));
    });
    rx.recv_timeout(Duration::from_secs(10))
        .expect("the reader hung")
        .expect("the hostile file was accepted")
}

#[test]
fn a_fifo_in_a_dataset_is_refused_naming_it() {
    let d = tempfile::tempdir().unwrap();
    let scene = dataset(d.path());
    std::fs::remove_file(scene.join(GT)).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(scene.join(GT))
        .status()
        .unwrap();
    assert!(made.success());
    let root = d.path().to_path_buf();
    let e = refused_quickly(move || discover(&root, &[]));
    assert!(e.contains(GT) && e.contains("FIFO"), "{e}");
    let gt = scene.join(GT);
    let e = refused_quickly(move || lfformat::pfm::read_pfm(&gt));
    assert!(e.contains(GT) && e.contains("FIFO"), "{e}");
}

#[test]
fn a_symlink_to_dev_zero_in_a_dataset_is_refused_naming_it() {
    let d = tempfile::tempdir().unwrap();
    let scene = dataset(d.path());
    std::fs::remove_file(scene.join(GT)).unwrap();
    std::os::unix::fs::symlink("/dev/zero", scene.join(GT)).unwrap();
    let root = d.path().to_path_buf();
    let e = refused_quickly(move || discover(&root, &[]));
    assert!(e.contains(GT) && e.contains("character device"), "{e}");
    let gt = scene.join(GT);
    let e = refused_quickly(move || lfformat::pfm::read_pfm(&gt));
    assert!(e.contains(GT) && e.contains("character device"), "{e}");
}

#[test]
fn a_file_longer_than_the_manifest_records_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let scene = dataset(d.path());
    std::fs::write(scene.join(GT), vec![b'P'; 1 << 20]).unwrap();
    let root = d.path().to_path_buf();
    let e = refused_quickly(move || discover(&root, &[]));
    assert!(e.contains(GT) && e.contains("more than the 7 bytes"), "{e}");
}

#[test]
fn a_listed_scene_whose_folder_or_parameters_are_gone_is_an_error_naming_it() {
    let d = tempfile::tempdir().unwrap();
    let root = d.path();
    dataset(root);
    let path = root.join("manifest.json");
    let mut manifest = Manifest::read(&path).unwrap();
    let mut gone = manifest.scenes[0].clone();
    gone.index = 1;
    gone.dir = "val/scene_0001".into();
    manifest.scenes.push(gone);
    manifest.write(&path).unwrap();
    for dir in [root.to_path_buf(), root.join("val")] {
        let e = discover(&dir, &[]).unwrap_err().to_string();
        assert!(
            e.contains("val/scene_0001") && e.contains("its folder is missing"),
            "{e}"
        );
    }
    std::fs::create_dir(root.join("val/scene_0001")).unwrap();
    let e = discover(root, &["val".into()]).unwrap_err().to_string();
    assert!(
        e.contains("scene_0001/parameters.cfg") && e.contains("its parameters.cfg is missing"),
        "{e}"
    );
    // The scene that is there may still be read on its own.
    assert_eq!(
        discover(&root.join("val/scene_0000"), &[]).unwrap().len(),
        1
    );
}
