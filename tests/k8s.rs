//! The Kubernetes recipe (`deploy/k8s/`), offline: every manifest validates against the
//! Kubernetes API schemas (`kubernetes-validate --strict`, which `.ci/run` installs), a broken
//! one does not, and the exact shell commands of the shard and merge Jobs — run here for each
//! completion index, with only the binary, the folder and the dataset size swapped for small
//! ones — give a dataset byte-identical to one plain run. The fields that make the recipe
//! work on a one-node cluster as shipped are checked by name, and `run.sh` is run against a
//! scripted `kubectl`: it stops at a failed Job and merges only after every shard completed.
//!
//! Where `kubernetes-validate` is missing the test prints why and skips; under CI, which
//! installs it, that is a failure (`tests/skip`).

mod bin;
mod skip;

use bin::{TINY, files, lfgen, ok};
use serde_json::Value;
use std::fs::Permissions;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

const MANIFESTS: [&str; 4] = [
    "volume.yaml",
    "shards-job.yaml",
    "merge-job.yaml",
    "copy-pod.yaml",
];

fn recipe(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("deploy/k8s")
        .join(name)
}

fn validate(path: &Path) -> (bool, String) {
    let o = Command::new("kubernetes-validate")
        .args(["--strict", "--quiet"])
        .arg(path)
        .output()
        .expect("kubernetes-validate runs");
    let text =
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr);
    (o.status.success(), text)
}

/// A manifest as JSON (through the validator's own PyYAML).
fn manifest(name: &str) -> Value {
    let o = Command::new("python3")
        .args([
            "-c",
            "import json, sys, yaml; print(json.dumps(yaml.safe_load(open(sys.argv[1]))))",
        ])
        .arg(recipe(name))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The container's command line, as `sh -c` would run it.
fn shell_command(job: &Value) -> String {
    let c = &job["spec"]["template"]["spec"]["containers"][0];
    let words: Vec<String> = c["command"]
        .as_array()
        .unwrap()
        .iter()
        .chain(c["args"].as_array().into_iter().flatten())
        .map(|w| w.as_str().unwrap().to_string())
        .collect();
    match words.first().map(String::as_str) {
        Some("/bin/sh") => words[2].clone(),
        _ => words.join(" "),
    }
}

/// Whether `kubernetes-validate` (and the PyYAML it brings, which [`manifest`] uses) is
/// here; if not, the test skips, or fails under CI.
fn validator() -> bool {
    let found = Command::new("kubernetes-validate")
        .arg("--version")
        .output()
        .is_ok();
    if !found {
        skip::skip("kubernetes-validate is missing (pip install kubernetes-validate)");
    }
    found
}

/// The pod template's first container of a Job, or the container of a Pod.
fn container(manifest: &Value) -> &Value {
    let pod = match manifest["kind"].as_str() {
        Some("Pod") => manifest,
        _ => &manifest["spec"]["template"],
    };
    &pod["spec"]["containers"][0]
}

#[test]
fn k8s_manifests_validate_and_their_commands_give_the_plain_dataset() {
    if !validator() {
        return;
    }
    for name in MANIFESTS {
        let (passed, text) = validate(&recipe(name));
        assert!(passed, "{name}: {text}");
    }
    // The validator is not a rubber stamp: a misspelt field fails.
    let tmp = tempfile::tempdir().unwrap();
    let broken = tmp.path().join("broken.yaml");
    let text = std::fs::read_to_string(recipe("shards-job.yaml")).unwrap();
    std::fs::write(&broken, text.replace("completionMode:", "completionMod:")).unwrap();
    assert!(!validate(&broken).0, "a misspelt field passed validation");

    let shards = manifest("shards-job.yaml");
    let n = shards["spec"]["completions"].as_u64().unwrap();
    assert_eq!(shards["spec"]["completionMode"], "Indexed");
    assert_eq!(shards["spec"]["parallelism"].as_u64(), Some(n));
    let command = shell_command(&shards);
    assert!(
        command.contains(&format!("--shard \"$JOB_COMPLETION_INDEX/{n}\"")),
        "{command}"
    );
    assert!(
        command.contains("--resume"),
        "a retried pod must resume: {command}"
    );

    // Run each pod's command here, as Kubernetes would (JOB_COMPLETION_INDEX = 0 .. n-1).
    let out = tmp.path().join("data");
    let bin = env!("CARGO_BIN_EXE_lfgen");
    let tiny: Vec<&str> = TINY.iter().copied().filter(|a| *a != "--quiet").collect();
    let small = |c: &str| {
        c.replacen("exec lfgen", &format!("exec {bin}"), 1)
            .replace("/data/", &format!("{}/", out.display()))
            .replace("--scenes 110", &format!("--scenes 6 {}", tiny.join(" ")))
    };
    for index in 0..n {
        let r = Command::new("/bin/sh")
            .args(["-c", &small(&command)])
            .env("JOB_COMPLETION_INDEX", index.to_string())
            .output()
            .unwrap();
        ok(r);
    }
    let merge = shell_command(&manifest("merge-job.yaml"));
    let merge = merge
        .replacen("lfgen", bin, 1)
        .replace("/data/", &format!("{}/", out.display()));
    ok(Command::new("/bin/sh")
        .args(["-c", &merge])
        .output()
        .unwrap());

    let mut sharded = files(&out.join("lfgen"));
    sharded.retain(|k, _| !k.starts_with("manifest.shard-"));
    let plain = tmp.path().join("plain");
    let mut args = vec!["--out", plain.to_str().unwrap(), "--scenes", "6"];
    args.extend(TINY);
    ok(lfgen(&args));
    assert!(
        sharded == files(&plain),
        "the Kubernetes recipe's dataset differs from one plain run"
    );
}

/// The causes of a recipe that did not work as shipped: an image that was always pulled (so a
/// locally built one was never used), a claim that needed ReadWriteMany and named no class, and
/// a shard that failed for good leaving the Job running.
#[test]
fn k8s_manifests_run_a_local_image_on_a_one_node_cluster_and_fail_fast() {
    if !validator() {
        return;
    }
    for name in ["shards-job.yaml", "merge-job.yaml", "copy-pod.yaml"] {
        let c = container(&manifest(name)).clone();
        assert_eq!(c["image"], "lfgen:latest", "{name}");
        assert_eq!(c["imagePullPolicy"], "IfNotPresent", "{name}");
        assert_eq!(
            c["volumeMounts"][0]["mountPath"], "/data",
            "{name} mounts the dataset volume"
        );
    }
    let volume = manifest("volume.yaml");
    assert_eq!(volume["metadata"]["name"], "lfgen-data");
    assert_eq!(volume["spec"]["storageClassName"], "local-path");
    assert_eq!(
        volume["spec"]["accessModes"],
        serde_json::json!(["ReadWriteOnce"])
    );
    let shards = manifest("shards-job.yaml");
    assert_eq!(shards["spec"]["backoffLimitPerIndex"], 3);
    assert_eq!(
        shards["spec"]["maxFailedIndexes"], 0,
        "one shard that fails for good must fail the Job"
    );
    assert!(shards["spec"]["activeDeadlineSeconds"].as_u64().is_some());
    // One pod fits a laptop: its CPU request is the threads it runs.
    let c = container(&shards);
    assert_eq!(c["resources"]["requests"]["cpu"], "4");
    assert!(shell_command(&shards).contains("--threads 4"));
    assert_eq!(manifest("merge-job.yaml")["spec"]["backoffLimit"], 2);
}

/// Runs `deploy/k8s/run.sh` against a scripted `kubectl` that logs its arguments, has no claim
/// yet and answers `get job/NAME` with the lines of `NAME` in `states`, one per look (the last
/// one repeated): the script's exit status, its stderr and the log.
fn run_sh(states: &[(&str, &[&str])]) -> (Option<i32>, String, String) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for (job, lines) in states {
        std::fs::write(dir.join(job), lines.join("\n") + "\n").unwrap();
    }
    let kubectl = dir.join("kubectl");
    std::fs::write(
        &kubectl,
        r#"#!/bin/sh
echo "$*" >> "$FAKE/log"
case "$1 $2" in
"get pvc") exit 1 ;;
"get job/"*)
    f="$FAKE/${2#job/}"
    head -n 1 "$f"
    [ "$(wc -l < "$f")" -gt 1 ] && sed -i 1d "$f"
    ;;
esac
exit 0
"#,
    )
    .unwrap();
    std::fs::set_permissions(&kubectl, Permissions::from_mode(0o755)).unwrap();
    let o = Command::new(recipe("run.sh"))
        .env("FAKE", dir)
        .env("KUBECTL", &kubectl)
        .env("LFGEN_POLL", "0")
        .output()
        .unwrap();
    let log = std::fs::read_to_string(dir.join("log")).unwrap();
    (o.status.code(), bin::stderr(&o), log)
}

#[test]
fn k8s_run_sh_stops_at_a_failed_shard_job() {
    let (code, err, log) = run_sh(&[(
        "lfgen-shards",
        &["", "FailureTarget", "FailureTarget Failed"],
    )]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("run.sh: job/lfgen-shards failed"), "{err}");
    assert_eq!(log.matches("get job/lfgen-shards").count(), 3, "{log}");
    assert!(
        !log.contains("merge-job.yaml"),
        "merged after a failed shard: {log}"
    );
}

#[test]
fn k8s_run_sh_merges_once_every_shard_completed() {
    let (code, err, log) = run_sh(&[
        ("lfgen-shards", &["", "SuccessCriteriaMet Complete"]),
        ("lfgen-merge", &["Complete"]),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let steps: Vec<&str> = log
        .lines()
        .map(|l| l.split(" -o ").next().unwrap())
        .collect();
    let apply = |name: &str| format!("apply -f {}", recipe(name).display());
    assert_eq!(
        steps,
        [
            "get pvc lfgen-data".to_string(),
            apply("volume.yaml"),
            "delete job lfgen-shards lfgen-merge --ignore-not-found --cascade=foreground".into(),
            apply("shards-job.yaml"),
            "get job/lfgen-shards".into(),
            "get job/lfgen-shards".into(),
            apply("merge-job.yaml"),
            "get job/lfgen-merge".into(),
        ]
    );
}
