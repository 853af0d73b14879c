//! The SLURM recipe (`deploy/slurm/`) on a real single-node SLURM cluster that the test starts
//! itself (Debian's `slurm-wlm` and `munge`; `.ci/run` installs them): a 4-task array renders
//! a small dataset, one task is killed mid-scene and requeued, the merge job runs after the
//! array, and the result is byte-identical to one plain `lfgen` run.
//!
//! Where the daemons are missing or cannot start (not root), the test prints why and skips;
//! under CI, which installs them, that is a failure with the reason (`tests/skip`).

mod bin;
mod skip;

use bin::{files, lfgen, ok};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The dataset: big enough that a task is still rendering when it is requeued.
const SCENES: &str = "8";
const ARGS: &[&str] = &[
    "--set",
    "camera.resolution=[96,64]",
    "--set",
    "camera.grid=[3,3]",
    "--set",
    "render.spp=4",
    "--set",
    "scene.objects=10",
    "--set",
    "dataset.date=2026-01-01",
];
const TOOLS: [&str; 8] = [
    "munged",
    "mungekey",
    "slurmctld",
    "slurmd",
    "sbatch",
    "scontrol",
    "squeue",
    "sinfo",
];

/// Why the cluster cannot run here, if it cannot.
fn unavailable() -> Option<String> {
    let missing: Vec<&str> = TOOLS
        .into_iter()
        .filter(|t| {
            Command::new("which")
                .arg(t)
                .output()
                .map_or(true, |o| !o.status.success())
        })
        .collect();
    if !missing.is_empty() {
        return Some(format!(
            "missing {} (apt-get install slurm-wlm munge)",
            missing.join(", ")
        ));
    }
    let uid = Command::new("id").arg("-u").output().ok()?;
    (String::from_utf8_lossy(&uid.stdout).trim() != "0")
        .then(|| "slurmd needs root to start jobs as their user".into())
}

/// A port nobody listens on now.
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// munged, slurmctld and slurmd on this machine, configured under a temporary folder; stopped
/// when dropped.
struct Cluster {
    dir: tempfile::TempDir,
}

impl Cluster {
    /// Starts the daemons; `Err` (with their logs) where this machine cannot run them.
    fn start() -> Result<Self, String> {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        for sub in ["state", "spool", "log", "run", "munge"] {
            std::fs::create_dir(d.join(sub)).unwrap();
        }
        let key = d.join("munge/munge.key");
        run(Command::new("mungekey")
            .arg("-c")
            .arg("-f")
            .arg("-k")
            .arg(&key))?;
        let munge = |name: &str| d.join("munge").join(name);
        run(Command::new("munged")
            .arg(format!("--key-file={}", key.display()))
            .arg(format!("--socket={}", munge("sock").display()))
            .arg(format!("--pid-file={}", munge("pid").display()))
            .arg(format!("--log-file={}", munge("log").display()))
            .arg(format!("--seed-file={}", munge("seed").display()))
            .arg("--force"))?;
        let conf = format!(
            include_str!("slurm/slurm.conf.in"),
            dir = d.display(),
            ctld_port = free_port(),
            d_port = free_port(),
        );
        std::fs::write(d.join("slurm.conf"), conf).unwrap();
        let cluster = Self { dir };
        run(&mut cluster.cmd("slurmctld"))?;
        run(cluster.cmd("slurmd").args(["-N", "localhost"]))?;
        let t = Instant::now();
        while cluster.node_state() != "idle" {
            if t.elapsed() > Duration::from_secs(60) {
                return Err(format!("the node did not come up\n{}", cluster.logs()));
            }
            std::thread::sleep(Duration::from_millis(200));
        }
        Ok(cluster)
    }

    fn node_state(&self) -> String {
        let o = self.cmd("sinfo").args(["-h", "-o", "%t"]).output().unwrap();
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    }

    /// A SLURM command talking to this cluster.
    fn cmd(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.dir.path().join("slurm.conf"));
        c
    }

    /// A job's fields from `scontrol show job` (`Key=Value` words).
    fn job(&self, id: &str) -> String {
        let o = self
            .cmd("scontrol")
            .args(["show", "job", id])
            .output()
            .unwrap();
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    fn wait(&self, what: &str, limit: Duration, mut done: impl FnMut() -> bool) {
        let t = Instant::now();
        while !done() {
            assert!(
                t.elapsed() < limit,
                "timed out waiting for {what}\n{}",
                self.logs()
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    fn logs(&self) -> String {
        let log = |n: &str| std::fs::read_to_string(self.dir.path().join("log").join(n));
        format!(
            "slurmctld: {}\nslurmd: {}",
            tail(&log("ctld.log").unwrap_or_default()),
            tail(&log("d.log").unwrap_or_default())
        )
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for pid in ["run/d.pid", "run/ctld.pid", "munge/pid"] {
            if let Ok(p) = std::fs::read_to_string(self.dir.path().join(pid)) {
                let _ = Command::new("kill").arg(p.trim()).status();
            }
        }
    }
}

fn tail(s: &str) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(15)..].join("\n")
}

/// Runs `c`: its output, or what went wrong.
fn run(c: &mut Command) -> Result<Output, String> {
    let o = c.output().map_err(|e| format!("{c:?}: {e}"))?;
    match o.status.success() {
        true => Ok(o),
        false => Err(format!(
            "{c:?}: {}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        )),
    }
}

fn run_ok(c: &mut Command) -> Output {
    run(c).unwrap_or_else(|e| panic!("{e}"))
}

/// `Key=value` of a `scontrol show job` listing.
fn field<'a>(job: &'a str, key: &str) -> Option<&'a str> {
    job.split_whitespace()
        .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
}

/// Whether shard 0 of 4 (scenes 0 and 4) is writing a scene now.
fn shard_0_writing(out: &Path) -> bool {
    [0, 4]
        .iter()
        .any(|i| out.join(format!("train/.scene_{i:04}.partial")).exists())
}

#[test]
fn slurm_array_with_a_requeued_task_and_a_merge_job_equals_one_plain_run() {
    if let Some(why) = unavailable() {
        return skip::skip(&why);
    }
    // A machine with the packages but without what the daemons need (a container without
    // root capabilities, say) skips too; once the cluster is up, every failure is the recipe's.
    let cluster = match Cluster::start() {
        Ok(c) => c,
        Err(why) => return skip::skip(&format!("the SLURM cluster did not start: {why}")),
    };
    let work = tempfile::tempdir().unwrap();
    let out = work.path().join("ds");
    let submit = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("deploy/slurm/submit.sh");
    let mut c = cluster.cmd(submit.to_str().unwrap());
    c.current_dir(work.path())
        .env("LFGEN", env!("CARGO_BIN_EXE_lfgen"))
        .env("LFGEN_CPUS", "1")
        .arg(&out)
        .arg("4")
        .args(["--scenes", SCENES])
        .args(ARGS);
    let ids = String::from_utf8(run_ok(&mut c).stdout).unwrap();
    let [array, merge]: [&str; 2] = ids.lines().collect::<Vec<_>>().try_into().unwrap();

    // Kill task 0 while it writes a scene, and put it back in the queue.
    let task = format!("{array}_0");
    cluster.wait("task 0 to write a scene", Duration::from_secs(120), || {
        field(&cluster.job(&task), "JobState") == Some("RUNNING") && shard_0_writing(&out)
    });
    let t = Instant::now();
    run_ok(cluster.cmd("scontrol").args(["requeue", &task]));
    // SLURM holds a requeued job back for two minutes (its begin time); start it at once.
    cluster.wait("task 0 to be requeued", Duration::from_secs(60), || {
        field(&cluster.job(&task), "JobState") == Some("PENDING")
    });
    run_ok(
        cluster
            .cmd("scontrol")
            .args(["update", &format!("JobId={task}"), "StartTime=now"]),
    );
    cluster.wait("the merge job", Duration::from_secs(600), || {
        let state = cluster.job(merge);
        let s = field(&state, "JobState").unwrap_or("");
        assert!(
            !matches!(s, "FAILED" | "CANCELLED" | "TIMEOUT")
                && !state.contains("DependencyNeverSatisfied"),
            "merge job {s}: {state}\n{}",
            cluster.logs()
        );
        s == "COMPLETED"
    });
    eprintln!("requeue to merged: {:.1} s", t.elapsed().as_secs_f64());
    let restarts = field(&cluster.job(&task), "Restarts").map(str::to_string);
    assert_eq!(restarts.as_deref(), Some("1"), "task 0 was not requeued");

    let mut sharded = files(&out);
    sharded.retain(|k, _| !k.starts_with("manifest.shard-"));
    let plain = work.path().join("plain");
    let mut args = vec![
        "--out",
        plain.to_str().unwrap(),
        "--scenes",
        SCENES,
        "--quiet",
    ];
    args.extend(ARGS);
    ok(lfgen(&args));
    assert!(
        sharded == files(&plain),
        "the SLURM dataset differs from one plain run"
    );
}
