//! Data-loss faults, made real: an output folder full of someone else's files, a write that
//! fails with ENOSPC (injected with `strace`), two processes into one dataset, and a deleted
//! manifest. Each test fails on a generator that deletes, publishes a truncated file, mixes
//! two runs or leaves unlisted scenes beside a new dataset.

mod bin;
mod skip;

use bin::{TINY, files, generate, lfgen, ok, stderr};
use lfformat::manifest::{Manifest, scene_entry_verifies};
use std::fs;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().expect("temp dir")
}

fn render(input: &Path, out: &Path) -> Output {
    let args = [
        &[
            "render",
            input.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ][..],
        TINY,
    ]
    .concat();
    lfgen(&args)
}

fn failed_with(out: &Output, needle: &str) {
    assert!(
        !out.status.success() && stderr(out).contains(needle),
        "expected a failure mentioning {needle:?}, got {:?}: {}",
        out.status,
        stderr(out)
    );
}

#[test]
fn render_never_replaces_a_folder_lfgen_did_not_write() {
    let d = tmp();
    let ds = d.path().join("ds");
    ok(generate(&ds, "1", &[]));
    let json = ds.join("train/scene_0000/scene.json");
    let before = files(&ds);
    // A dataset root.
    failed_with(&render(&json, &ds), "not a file of an lfgen scene");
    assert!(files(&ds) == before, "the dataset was changed");
    // A glTF's own folder.
    let gltf_dir = d.path().join("gltf");
    fs::create_dir(&gltf_dir).unwrap();
    for f in ["plane.gltf", "plane.bin"] {
        fs::copy(Path::new("tests/fixtures/gltf").join(f), gltf_dir.join(f)).unwrap();
    }
    let gltf_before = files(&gltf_dir);
    failed_with(
        &render(&gltf_dir.join("plane.gltf"), &gltf_dir),
        "plane.bin",
    );
    assert!(
        files(&gltf_dir) == gltf_before,
        "the glTF folder was changed"
    );
    // A regular file: refused before anything renders.
    let file = d.path().join("notes.txt");
    fs::write(&file, "keep me").unwrap();
    failed_with(&render(&json, &file), "not a folder");
    assert_eq!(fs::read_to_string(&file).unwrap(), "keep me");
    // A previous scene folder is replaced, leaving nothing beside it.
    let again = d.path().join("again");
    ok(render(&json, &again));
    fs::write(again.join("input_Cam000.png"), "stale").unwrap();
    ok(render(&json, &again));
    assert!(files(&again) == files(&ds.join("train/scene_0000")));
    let leftovers: Vec<_> = fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "left behind: {leftovers:?}");
}

/// Runs `lfgen` under `strace`, every `write` to `victim` failing with ENOSPC; `None` where
/// strace is missing or may not trace (a skip; a failure under CI).
fn with_full_disk_at(victim: &Path, args: &[&str]) -> Option<Output> {
    with_failing_writes(victim, "inject=write:error=ENOSPC", args)
}

/// [`with_full_disk_at`] with the writes that fail chosen by `inject`, strace's injection
/// expression (`:when=2` fails the second write to `victim` only).
fn with_failing_writes(victim: &Path, inject: &str, args: &[&str]) -> Option<Output> {
    let probe = Command::new("strace")
        .args(["-qq", "-o", "/dev/null", "true"])
        .status();
    if !probe.is_ok_and(|s| s.success()) {
        skip::skip("strace is missing or cannot trace here (.ci/run installs it)");
        return None;
    }
    let output = Command::new("strace")
        .args(["-f", "-qq", "-o", "/dev/null", "-e", "trace=write"])
        .args(["-e", inject, "-P"])
        .arg(victim)
        .arg(env!("CARGO_BIN_EXE_lfgen"))
        .args(args)
        .output()
        .expect("strace runs");
    Some(output)
}

#[test]
fn a_failed_write_names_its_file_and_publishes_nothing() {
    for victim in ["input_Cam004.png", "modes.exr", "gt_mpi_lowres.npz"] {
        let d = tmp();
        let out = d.path().join("ds");
        let partial = out.join("train/.scene_0000.partial").join(victim);
        let mut args = vec!["--scenes", "1", "--out", out.to_str().unwrap()];
        args.extend_from_slice(TINY);
        let Some(r) = with_full_disk_at(&partial, &args) else {
            return;
        };
        failed_with(&r, victim);
        failed_with(&r, "No space left on device");
        assert!(
            !out.join("train/scene_0000").exists(),
            "{victim}: a scene with a failed write was published"
        );
        let listed = Manifest::read(&out.join("manifest.json")).map_or(0, |m| m.scenes.len());
        assert_eq!(listed, 0, "{victim}: the manifest lists a broken scene");
        // The next run completes the dataset as if nothing had happened.
        ok(generate(&out, "1", &["--resume"]));
        let reference = tmp();
        ok(generate(reference.path(), "1", &[]));
        assert!(files(&out) == files(reference.path()), "{victim}");
    }
}

#[test]
fn a_failed_preview_write_fails_the_run() {
    let d = tmp();
    let out = d.path().join("ds");
    let mut args = vec!["--scenes", "1", "--out", out.to_str().unwrap()];
    args.extend_from_slice(TINY);
    let Some(r) = with_full_disk_at(&out.join("preview.png"), &args) else {
        return;
    };
    failed_with(&r, "preview.png");
}

fn spawn(out: &Path, extra: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_lfgen"))
        .args(["--scenes", "3", "--out", out.to_str().unwrap()])
        .args(extra)
        .args(TINY)
        .stderr(Stdio::piped())
        .spawn()
        .expect("lfgen starts")
}

/// Starts both runs at once and returns their outputs.
fn race(out: &Path, a: &[&str], b: &[&str]) -> (Output, Output) {
    let (pa, pb) = (spawn(out, a), spawn(out, b));
    (
        pa.wait_with_output().unwrap(),
        pb.wait_with_output().unwrap(),
    )
}

#[test]
fn two_runs_into_one_folder_never_mix() {
    let (d, seed1) = (tmp(), tmp());
    ok(generate(seed1.path(), "3", &["--seed", "1"]));
    let out = d.path().join("ds");
    let (a, b) = race(&out, &["--seed", "1"], &["--seed", "2"]);
    let (winner, loser) = match (a.status.success(), b.status.success()) {
        (true, false) => ("1", &b),
        (false, true) => ("2", &a),
        _ => panic!(
            "exactly one run must win: {:?} {:?}\n{}\n{}",
            a.status,
            b.status,
            stderr(&a),
            stderr(&b)
        ),
    };
    failed_with(loser, "in use by another lfgen run");
    let reference = tmp();
    ok(generate(reference.path(), "3", &["--seed", winner]));
    assert!(
        files(&out) == files(reference.path()),
        "the winner's dataset is not intact"
    );
    if winner == "1" {
        assert!(files(&out) == files(seed1.path()));
    }
    // The same shard twice is refused; two different shards run side by side and merge into
    // the plain dataset.
    let sharded = d.path().join("sharded");
    let (a, b) = race(&sharded, &["--shard", "0/2"], &["--shard", "0/2"]);
    assert!(
        a.status.success() != b.status.success(),
        "{}\n{}",
        stderr(&a),
        stderr(&b)
    );
    failed_with(if a.status.success() { &b } else { &a }, "shard");
    let (a, b) = race(
        &d.path().join("both"),
        &["--shard", "0/2"],
        &["--shard", "1/2"],
    );
    ok(a);
    ok(b);
    ok(lfgen(&["merge", d.path().join("both").to_str().unwrap()]));
    let mut merged = files(&d.path().join("both"));
    merged.retain(|k, _| !k.starts_with("manifest.shard-"));
    let plain = tmp();
    ok(generate(plain.path(), "3", &[]));
    assert!(
        merged == files(plain.path()),
        "merged shards differ from one run"
    );
    // A shard of another split layout, and an unsharded run, are refused beside shards.
    let r = generate(&d.path().join("both"), "3", &["--shard", "0/3"]);
    failed_with(&r, "2-way split");
}

#[test]
fn a_deleted_manifest_never_leaves_unlisted_scenes_beside_a_new_dataset() {
    let (d, reference) = (tmp(), tmp());
    ok(generate(reference.path(), "3", &[]));
    let out = d.path().join("ds");
    ok(generate(&out, "3", &["--seed", "9"]));
    fs::remove_file(out.join("manifest.json")).unwrap();
    let before = files(&out);
    let r = generate(&out, "3", &[]);
    failed_with(&r, "no manifest lists");
    failed_with(&r, "--resume");
    assert!(files(&out) == before, "a refused run changed the folder");
    // Fewer scenes than the folder holds: the extra ones would be left beside the manifest
    // (scene 2, and scene 1, which a 2-scene dataset puts in val/).
    let r = generate(&out, "2", &["--resume"]);
    failed_with(&r, "2 scene folder(s)");
    // Resuming the same size re-renders every unlisted scene: the result is the plain dataset.
    ok(generate(&out, "3", &["--resume"]));
    assert!(files(&out) == files(reference.path()));
    let m = Manifest::read(&out.join("manifest.json")).unwrap();
    assert_eq!(m.scenes.len(), 3);
    assert!(m.scenes.iter().all(|e| scene_entry_verifies(&out, e)));
}

#[test]
fn resume_with_nothing_to_do_keeps_the_readme_and_empty_entries_never_verify() {
    let d = tmp();
    ok(generate(d.path(), "2", &[]));
    let readme = fs::read_to_string(d.path().join("README.md")).unwrap();
    assert!(readme.contains("Scenes: 2 ("), "{readme}");
    ok(generate(d.path(), "2", &["--resume"]));
    assert_eq!(
        fs::read_to_string(d.path().join("README.md")).unwrap(),
        readme
    );
    let mut m = Manifest::read(&d.path().join("manifest.json")).unwrap();
    m.scenes[0].files.clear();
    assert!(!scene_entry_verifies(d.path(), &m.scenes[0]));
}

/// A glTF node scaled by 1e25 used to panic inside the BVH build (obvhs' quantised nodes
/// overflow); it is refused, naming the file, before anything is built.
#[test]
fn a_gltf_node_scaled_beyond_any_room_is_refused_not_a_panic() {
    let d = tmp();
    let src = Path::new("tests/fixtures/gltf");
    let mut doc: serde_json::Value =
        serde_json::from_slice(&fs::read(src.join("plane.gltf")).unwrap()).unwrap();
    doc["nodes"][1]["scale"] = serde_json::json!([1e25, 1e25, 1.0]);
    fs::write(d.path().join("huge.gltf"), doc.to_string()).unwrap();
    fs::copy(src.join("plane.bin"), d.path().join("plane.bin")).unwrap();
    let out = d.path().join("out");
    let r = render(&d.path().join("huge.gltf"), &out);
    assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
    failed_with(&r, "huge.gltf");
    failed_with(&r, "matrix");
    assert!(!stderr(&r).contains("panicked"));
    assert!(!out.exists());
}

/// `name`s of every entry directly in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn an_unsharded_run_never_overwrites_shards_that_were_not_merged() {
    let (d, plain) = (tmp(), tmp());
    let out = d.path().join("ds");
    ok(generate(&out, "2", &["--seed", "1", "--shard", "0/2"]));
    ok(generate(&out, "2", &["--seed", "1", "--shard", "1/2"]));
    // Lock files come and go with the runs; everything else must stay.
    let data = |out: &Path| {
        let mut f = files(out);
        f.retain(|k, _| !k.ends_with(".lock"));
        f
    };
    let before = data(&out);
    // Another seed, without and with --resume: refused, nothing touched.
    let r = generate(&out, "2", &["--seed", "2"]);
    failed_with(&r, "not merged");
    failed_with(&r, "lfgen merge");
    failed_with(&r, "--resume");
    failed_with(&r, "another --out");
    let r = generate(&out, "2", &["--seed", "2", "--resume"]);
    failed_with(&r, "manifest.shard-0-of-2.json");
    failed_with(&r, "another config or seed");
    assert!(data(&out) == before, "a refused run changed the shards");
    // The shards' own seed with --resume keeps their scenes (nothing rendered again) and
    // completes the plain dataset.
    ok(generate(&out, "2", &["--seed", "1", "--resume"]));
    let timings = fs::read_to_string(out.join("timings.jsonl")).unwrap();
    assert_eq!(timings.lines().count(), 2, "scenes were rendered again");
    let mut joined = files(&out);
    joined.retain(|k, _| !k.starts_with("manifest.shard-"));
    ok(generate(plain.path(), "2", &["--seed", "1"]));
    assert!(joined == files(plain.path()), "not the plain dataset");
    // A shard of another seed beside the finished dataset is refused too.
    fs::remove_file(out.join("manifest.shard-1-of-2.json")).unwrap();
    let r = generate(&out, "2", &["--seed", "2", "--shard", "1/2", "--resume"]);
    failed_with(&r, "another config or seed");
}

#[test]
fn a_folder_that_is_no_dataset_is_never_written_into() {
    let d = tmp();
    let proj = d.path().join("proj");
    fs::create_dir(&proj).unwrap();
    fs::write(proj.join("README.md"), "notes").unwrap();
    fs::write(proj.join("summary.json"), "{\"mine\": 1}").unwrap();
    fs::write(proj.join("preview.png"), b"\x89PNG not really").unwrap();
    let before = files(&proj);
    for extra in [&[][..], &["--resume"][..]] {
        let r = generate(&proj, "1", extra);
        failed_with(&r, "not an lfgen dataset");
        failed_with(&r, "README.md");
        assert!(files(&proj) == before, "the user's files were changed");
        assert_eq!(names(&proj), ["README.md", "preview.png", "summary.json"]);
    }
    // An empty folder, and a dataset whose manifest was lost, are lfgen's to write.
    let empty = d.path().join("empty");
    fs::create_dir(&empty).unwrap();
    ok(generate(&empty, "1", &[]));
    fs::remove_file(empty.join("manifest.json")).unwrap();
    ok(generate(&empty, "1", &["--resume"]));
}

#[test]
fn render_never_removes_temporary_names_it_did_not_make() {
    let d = tmp();
    let ds = d.path().join("ds");
    ok(generate(&ds, "1", &[]));
    let json = ds.join("train/scene_0000/scene.json");
    let out = d.path().join("out");
    for name in [".out.partial", ".out.old"] {
        let mine = d.path().join(name);
        fs::create_dir(&mine).unwrap();
        fs::write(mine.join("notes.txt"), "keep me").unwrap();
        let r = render(&json, &out);
        failed_with(&r, name);
        failed_with(&r, "did not make it");
        assert_eq!(
            fs::read_to_string(mine.join("notes.txt")).unwrap(),
            "keep me"
        );
        assert_eq!(names(&mine), ["notes.txt"]);
        assert!(!out.exists(), "{name}: a refused render wrote the scene");
        fs::rename(&mine, d.path().join(format!("kept{name}"))).unwrap();
    }
    // With the names free, a render and a re-render replace only their own folders.
    ok(render(&json, &out));
    ok(render(&json, &out));
    assert!(files(&out) == files(&ds.join("train/scene_0000")));
    assert_eq!(
        names(d.path()),
        ["ds", "kept.out.old", "kept.out.partial", "out"]
    );
}

#[test]
fn merge_refuses_damaged_or_missing_shards_instead_of_dropping_them() {
    let (d, plain) = (tmp(), tmp());
    let out = d.path().join("ds");
    ok(generate(&out, "4", &["--shard", "0/2"]));
    ok(generate(&out, "4", &["--shard", "1/2"]));
    let shard = Manifest::read(&out.join("manifest.shard-1-of-2.json")).unwrap();
    let (one, three) = (&shard.scenes[0], &shard.scenes[1]);
    // One flipped byte in scene 1, one deleted file in scene 3.
    let flipped = out.join(&one.files[0].path);
    let mut bytes = fs::read(&flipped).unwrap();
    bytes[0] ^= 1;
    fs::write(&flipped, bytes).unwrap();
    fs::remove_file(out.join(&three.files[0].path)).unwrap();
    let r = lfgen(&["merge", out.to_str().unwrap()]);
    assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
    failed_with(&r, "2 scene(s) do not verify");
    for e in [one, three] {
        failed_with(&r, &format!("scene {} ({})", e.index, e.dir));
        failed_with(&r, &e.files[0].path);
    }
    assert!(
        !out.join("manifest.json").exists(),
        "a merge of damaged shards wrote a manifest"
    );
    // The shard's --resume renders the damaged scenes again; then the merge is the plain run.
    ok(generate(&out, "4", &["--shard", "1/2", "--resume"]));
    ok(lfgen(&["merge", out.to_str().unwrap()]));
    let mut merged = files(&out);
    merged.retain(|k, _| !k.starts_with("manifest.shard-"));
    ok(generate(plain.path(), "4", &[]));
    assert!(
        merged == files(plain.path()),
        "merged shards differ from one run"
    );
    // A shard that never ran fails the merge, naming it.
    fs::remove_file(out.join("manifest.shard-0-of-2.json")).unwrap();
    let r = lfgen(&["merge", out.to_str().unwrap()]);
    failed_with(&r, "no manifest.shard-0-of-2.json");
}

/// Every line of `timings.jsonl` under `out` is one JSON object; their number.
fn whole_timing_lines(out: &Path) -> usize {
    let text = fs::read_to_string(out.join("timings.jsonl")).unwrap();
    assert!(text.ends_with('\n'), "a cut-off last line: {text:?}");
    for line in text.lines() {
        let parsed = serde_json::from_str::<serde_json::Value>(line);
        assert!(
            parsed.is_ok_and(|v| v.is_object()),
            "a broken line: {line:?}"
        );
    }
    text.lines().count()
}

#[test]
fn a_timing_line_cut_short_is_never_appended_to() {
    // A line cut off by a kill or a full disk, then a resumed run.
    let d = tmp();
    ok(generate(d.path(), "1", &[]));
    let log = d.path().join("timings.jsonl");
    let mut text = fs::read(&log).unwrap();
    text.extend_from_slice(b"{\"scene\": 1, \"sec");
    fs::write(&log, text).unwrap();
    ok(generate(d.path(), "2", &["--resume"]));
    assert_eq!(whole_timing_lines(d.path()), 2);
    // The second write to the log fails with ENOSPC: the run fails naming it, and the resumed
    // run leaves only whole lines.
    let d = tmp();
    let out = d.path().join("ds");
    let mut args = vec!["--scenes", "2", "--out", out.to_str().unwrap()];
    args.extend_from_slice(TINY);
    let inject = "inject=write:error=ENOSPC:when=2";
    let Some(r) = with_failing_writes(&out.join("timings.jsonl"), inject, &args) else {
        return;
    };
    failed_with(&r, "timings.jsonl");
    failed_with(&r, "No space left on device");
    ok(generate(&out, "2", &["--resume"]));
    assert!(whole_timing_lines(&out) >= 1);
}
