//! The Kubernetes recipe (`deploy/k8s/`), offline: every manifest validates against the
//! Kubernetes API schemas (`kubernetes-validate --strict`, which `.ci/run` installs), a broken
//! one does not, and the exact shell commands of the shard and merge Jobs — run here for each
//! completion index, with only the binary, the folder and the dataset size swapped for small
//! ones — give a dataset byte-identical to one plain run.
//!
//! Skipped, with the reason printed, where `kubernetes-validate` is missing.

mod bin;

use bin::{TINY, files, lfgen, ok};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

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

#[test]
fn k8s_manifests_validate_and_their_commands_give_the_plain_dataset() {
    if Command::new("kubernetes-validate")
        .arg("--version")
        .output()
        .is_err()
    {
        println!("skipped: kubernetes-validate is missing (pip install kubernetes-validate)");
        return;
    }
    for name in ["volume.yaml", "shards-job.yaml", "merge-job.yaml"] {
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
