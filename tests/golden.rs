//! Golden checksums: a fixed small dataset, every glTF fixture rendered, and the three exports
//! of one scene, hashed file by file against the list recorded in `tests/golden/checksums.txt`.
//!
//! Why: moving code between modules or crates must change no output, and the other tests check
//! properties (disparity, η, round trips), not bytes. A change that *is* meant to change the
//! output (a new sampler, a renderer fix) re-records the list on purpose:
//!
//! ```sh
//! LFGEN_BLESS=1 cargo test --release --test golden
//! ```
//!
//! and the diff of `checksums.txt` then shows which files it changed. Absolute paths (the
//! temporary folder, the repository) are replaced by placeholders before hashing, so the list
//! holds on any checkout.

mod bin;

use bin::{TINY, files, lfgen, ok};
use lfformat::manifest::hex_sha256;
use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

const RECORD: &str = "tests/golden/checksums.txt";

/// The glTF fixtures that render (the hostile ones are refused and tested in tests/gltf.rs).
const GLTF: &[&str] = &[
    "plane.gltf",
    "mask.gltf",
    "pane.glb",
    "hierarchy.gltf",
    "spot.gltf",
];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Renders everything the record covers into `root`.
fn produce(root: &Path) {
    let ds = root.join("dataset");
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    let extra = [
        "--scenes",
        "2",
        "--out",
        &s(&ds),
        "--set",
        "render.gt_views=all",
        "--set",
        "render.write_exr=true",
    ];
    ok(lfgen(&[&extra[..], TINY].concat()));
    let scene = ds.join("train/scene_0000");
    for to in ["pov", "mitsuba", "blender"] {
        let out = root.join("export").join(to);
        let args = ["export", "--to", to, &s(&scene), "--out", &s(&out)];
        ok(lfgen(&[&args[..], TINY].concat()));
    }
    for name in GLTF {
        let input = repo().join("tests/fixtures/gltf").join(name);
        let out = root.join("gltf").join(name);
        let args = ["render", &s(&input), "--out", &s(&out)];
        ok(lfgen(&[&args[..], TINY].concat()));
    }
}

/// `bytes` with every occurrence of `from` replaced by `to`.
fn replace(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            out.extend_from_slice(to);
            i += from.len();
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}

/// Relative path → SHA-256 of the file with absolute paths replaced by placeholders.
fn checksums(root: &Path) -> BTreeMap<String, String> {
    let (tmp, repo) = (root.display().to_string(), repo().display().to_string());
    files(root)
        .into_iter()
        .map(|(name, bytes)| {
            let bytes = replace(&bytes, tmp.as_bytes(), b"<TMP>");
            let bytes = replace(&bytes, repo.as_bytes(), b"<REPO>");
            (name, hex_sha256(&bytes))
        })
        .collect()
}

fn parse(text: &str) -> BTreeMap<String, String> {
    text.lines()
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(|l| {
            let (hash, name) = l.split_once("  ").expect("`HASH  PATH` lines");
            (name.to_owned(), hash.to_owned())
        })
        .collect()
}

fn format(sums: &BTreeMap<String, String>) -> String {
    let mut text =
        String::from("# SHA-256 of every output of tests/golden.rs (re-record: LFGEN_BLESS=1).\n");
    for (name, hash) in sums {
        text += &format!("{hash}  {name}\n");
    }
    text
}

#[test]
fn outputs_match_the_recorded_checksums() {
    let tmp = tempfile::tempdir().unwrap();
    produce(tmp.path());
    let got = checksums(tmp.path());
    let record = repo().join(RECORD);
    if std::env::var_os("LFGEN_BLESS").is_some() {
        fs::create_dir_all(record.parent().unwrap()).unwrap();
        fs::write(&record, format(&got)).unwrap();
        println!("recorded {} checksums in {RECORD}", got.len());
        return;
    }
    let want = parse(&fs::read_to_string(&record).expect("tests/golden/checksums.txt exists"));
    let mut diff = Vec::new();
    for name in want
        .keys()
        .chain(got.keys())
        .collect::<std::collections::BTreeSet<_>>()
    {
        match (want.get(name), got.get(name)) {
            (Some(a), Some(b)) if a == b => {}
            (Some(_), Some(_)) => diff.push(format!("changed  {name}")),
            (Some(_), None) => diff.push(format!("missing  {name}")),
            (None, _) => diff.push(format!("new      {name}")),
        }
    }
    assert!(
        diff.is_empty(),
        "{} of {} files differ from {RECORD} (re-record with LFGEN_BLESS=1 only when the \
         change is meant):\n{}",
        diff.len(),
        want.len().max(got.len()),
        diff.join("\n")
    );
    assert!(
        got.len() > 100,
        "the record covers every output ({})",
        got.len()
    );
}
