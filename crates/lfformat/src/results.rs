//! Measurements as data: every benchmark run appends one JSON line to a results file
//! (`results/bench.jsonl` unless told otherwise; the schema is in docs/reference/results.md).
//!
//! A record carries what makes a figure checkable later — when (UTC), on which commit, by which
//! command line and on how many cores it was measured — so documentation cites figures from the
//! file instead of keeping a diary, and a script can render any table from it.

use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Where `lfgen bench` and `lftrain bench` append their records by default (relative to the
/// working directory).
pub const DEFAULT_PATH: &str = "results/bench.jsonl";

/// One benchmark run.
#[derive(Debug, Serialize)]
pub struct Record {
    /// The program that measured: `lfgen` or `lftrain`.
    pub tool: String,
    /// When the run ended, UTC, RFC 3339 to the second.
    pub date: String,
    /// `git rev-parse HEAD` in the working directory, or `unknown` outside a checkout.
    pub commit: String,
    /// The full command line, program first.
    pub command: Vec<String>,
    pub machine: Machine,
    /// The run's figures, named by the benchmark (numbers, not formatted text).
    pub figures: serde_json::Value,
}

/// The machine a record was measured on.
#[derive(Debug, Serialize)]
pub struct Machine {
    /// Logical cores available to the process.
    pub cores: usize,
    pub os: String,
    pub arch: String,
}

impl Record {
    /// A record of `figures` measured now by `tool`, from this process's command line.
    pub fn now(tool: &str, figures: serde_json::Value) -> Self {
        Self {
            tool: tool.into(),
            date: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
            commit: git_commit(),
            command: std::env::args().collect(),
            machine: Machine {
                cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
                os: std::env::consts::OS.into(),
                arch: std::env::consts::ARCH.into(),
            },
            figures,
        }
    }

    /// Appends the record as one line to `path`, creating the file and its folder. The line is
    /// written with a single call, so records of runs that end together do not interleave.
    pub fn append(&self, path: &Path) -> crate::Result<()> {
        let io = |e| crate::Error::io(path, e);
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| crate::Error::io(dir, e))?;
        }
        let mut line = serde_json::to_string(self).expect("a record serialises");
        line.push('\n');
        let mut file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(io)?;
        file.write_all(line.as_bytes()).map_err(io)?;
        file.sync_all().map_err(io)
    }
}

/// The commit checked out in the working directory, or `unknown`.
fn git_commit() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two runs append two lines, each a complete record; a file in place of the folder is an
    /// error naming the path.
    #[test]
    fn records_append_one_line_each_and_name_the_file_on_failure() {
        let d = tempfile::tempdir().unwrap();
        let path = d.path().join("results/bench.jsonl");
        for x in [1.5, 2.5] {
            Record::now("lfgen", serde_json::json!({ "x": x }))
                .append(&path)
                .unwrap();
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<serde_json::Value> = text
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1]["figures"]["x"], 2.5);
        assert_eq!(lines[0]["tool"], "lfgen");
        assert!(lines[0]["date"].as_str().unwrap().ends_with('Z'));
        assert!(lines[0]["machine"]["cores"].as_u64().unwrap() >= 1);
        let blocked = d.path().join("file");
        std::fs::write(&blocked, "").unwrap();
        let err = Record::now("lfgen", serde_json::json!({}))
            .append(&blocked.join("bench.jsonl"))
            .unwrap_err();
        assert!(err.to_string().contains("file"), "{err}");
    }
}
