//! Writing files so that a failure is always seen, appending to logs so that a cut-off line
//! never spoils the next, and naming temporary files so that two processes never share one.
//!
//! Every writer of this crate (and of the generator) encodes into memory first and hands the
//! bytes to [`write_file`]: a buffered writer dropped without an explicit flush loses the error
//! of its last write (a full disk then publishes a truncated file that later checksums vouch
//! for), while one `write_all` plus `sync_all` reports every failure, with the path, at the
//! file it happened to.

use std::ffi::OsString;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, Result};

/// Writes `bytes` to `path` (created or truncated) and syncs them to disk; any error, the final
/// one included, names `path`.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let written = File::create(path).and_then(|mut file| {
        file.write_all(bytes)?;
        file.sync_all()
    });
    written.map_err(|e| Error::io(path, e))
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over `path`: readers see
/// the old contents or the new, never a part. The temporary name is unique to this process
/// and call ([`temp_name`]), so concurrent writers of one path cannot mix their bytes.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = temp_name(path);
    if let Err(e) = write_file(&tmp, bytes) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io(path, e)
    })
}

/// Appends `line` and a newline to the log file `path` (created if missing) in one write, under
/// an exclusive lock on the file so that processes sharing the log never interleave. A last line
/// without its newline (a write cut short by a full disk or a killed process) is cut off first:
/// appending to it would make one line of two.
pub fn append_line(path: &Path, line: &str) -> Result<()> {
    let io = |e| Error::io(path, e);
    let mut file = OpenOptions::new()
        .read(true)
        .append(true)
        .create(true)
        .open(path)
        .map_err(io)?;
    file.lock().map_err(io)?;
    let whole = whole_lines_len(&mut file).map_err(io)?;
    if whole < file.metadata().map_err(io)?.len() {
        file.set_len(whole).map_err(io)?;
    }
    file.write_all(format!("{line}\n").as_bytes()).map_err(io)
}

/// The length of `file` up to and including its last newline (0 if it has none).
fn whole_lines_len(file: &mut File) -> std::io::Result<u64> {
    let mut end = file.seek(SeekFrom::End(0))?;
    let mut chunk = [0u8; 4096];
    while end > 0 {
        let start = end.saturating_sub(chunk.len() as u64);
        let part = &mut chunk[..(end - start) as usize];
        file.seek(SeekFrom::Start(start))?;
        file.read_exact(part)?;
        if let Some(i) = part.iter().rposition(|&b| b == b'\n') {
            return Ok(start + i as u64 + 1);
        }
        end = start;
    }
    Ok(0)
}

/// `path` with `.tmp-<pid>-<n>` appended to its file name: unique among the processes on this
/// machine and among the calls of this one.
pub fn temp_name(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut name = OsString::from(path.as_os_str());
    name.push(format!(".tmp-{}-{n}", std::process::id()));
    name.into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_the_file_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        write_atomic(&path, b"old").unwrap();
        write_atomic(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "a temporary file was left behind");
    }

    #[test]
    fn temporary_names_differ_between_calls() {
        let p = Path::new("/x/manifest.json");
        let (a, b) = (temp_name(p), temp_name(p));
        assert_ne!(a, b);
        let pid = std::process::id().to_string();
        assert!(a.to_string_lossy().contains(&pid));
        assert!(a.to_string_lossy().starts_with("/x/manifest.json.tmp-"));
    }

    #[test]
    fn appended_lines_never_join_a_cut_off_last_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("log.jsonl");
        append_line(&path, "{\"a\":1}").unwrap();
        append_line(&path, "{\"a\":2}").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"{\"a\":1}\n{\"a\":2}\n");
        // A write cut short after a few bytes of the third line.
        let mut cut = std::fs::read(&path).unwrap();
        cut.extend_from_slice(b"{\"a\":");
        std::fs::write(&path, &cut).unwrap();
        append_line(&path, "{\"a\":3}").unwrap();
        assert_eq!(
            std::fs::read(&path).unwrap(),
            b"{\"a\":1}\n{\"a\":2}\n{\"a\":3}\n"
        );
        // A log of one cut-off line, longer than a read chunk.
        std::fs::write(&path, vec![b'x'; 10_000]).unwrap();
        append_line(&path, "y").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"y\n");
    }

    #[test]
    fn a_failed_write_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing/a.bin");
        let e = write_file(&path, b"x").unwrap_err();
        assert!(e.to_string().contains("missing/a.bin"), "{e}");
        let e = write_atomic(&path, b"x").unwrap_err();
        assert!(e.to_string().contains("missing/a.bin"), "{e}");
    }
}
