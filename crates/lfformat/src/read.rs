//! Opening dataset files for reading, so that no file can hang or flood a reader.
//!
//! A path in a dataset may name a FIFO (opening it blocks until a writer comes, forever) or a
//! symlink to `/dev/zero` (reading it never ends). Every reader of this crate, and the
//! evaluation and training tools through it, opens files with [`open`], which accepts regular
//! files only (after following symlinks) and names the file otherwise; the checksum step
//! additionally reads no more than the size `manifest.json` records.

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// Opens `path` for reading if it is a regular file (a symlink to one is fine); a FIFO, device,
/// socket or folder is an error naming it, returned before anything could block.
pub fn open(path: &Path) -> Result<File> {
    let before = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    regular(path, &before)?;
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    // The path may have been replaced between the two looks: check what was opened.
    let opened = file.metadata().map_err(|e| Error::io(path, e))?;
    regular(path, &opened)?;
    Ok(file)
}

/// The contents of the regular file `path` ([`open`]).
pub fn bytes(path: &Path) -> Result<Vec<u8>> {
    let mut file = open(path)?;
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    Ok(bytes)
}

/// The contents of the regular file `path` ([`open`]) as UTF-8 text.
pub fn text(path: &Path) -> Result<String> {
    String::from_utf8(bytes(path)?).map_err(|_| Error::format(path, "not UTF-8 text"))
}

/// An error naming `path` unless `meta` describes a regular file.
fn regular(path: &Path, meta: &Metadata) -> Result<()> {
    if meta.is_file() {
        return Ok(());
    }
    Err(Error::format(
        path,
        format!(
            "{}, not a regular file: refusing to read it (it could block or never end)",
            kind(meta)
        ),
    ))
}

/// What a non-regular file is, in words.
#[cfg(unix)]
fn kind(meta: &Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn kind(meta: &Metadata) -> &'static str {
    if meta.is_dir() {
        "a folder"
    } else {
        "a special file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_and_links_to_them_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        std::fs::write(&path, "abc").unwrap();
        assert_eq!(text(&path).unwrap(), "abc");
        #[cfg(unix)]
        {
            let link = dir.path().join("link.txt");
            std::os::unix::fs::symlink(&path, &link).unwrap();
            assert_eq!(bytes(&link).unwrap(), b"abc");
        }
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_folders_are_refused_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let zero = dir.path().join("zero.pfm");
        std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
        let e = bytes(&zero).unwrap_err().to_string();
        assert!(
            e.contains("zero.pfm") && e.contains("a character device"),
            "{e}"
        );
        let e = open(dir.path()).unwrap_err().to_string();
        assert!(e.contains("a folder"), "{e}");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("gt.pfm");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let e = open(&fifo).unwrap_err().to_string();
        assert!(e.contains("gt.pfm") && e.contains("FIFO"), "{e}");
    }
}
