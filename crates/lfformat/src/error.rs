//! The crate's error type.
//!
//! Every error carries the path of the file involved, because a dataset holds thousands of
//! files and an error without a path sends the user hunting.

use std::fmt;
use std::path::{Path, PathBuf};

/// Every error names the file and the problem.
#[derive(Debug)]
pub enum Error {
    /// The operating system refused a read, write, rename or directory listing.
    Io {
        /// The file the operation was on.
        path: PathBuf,
        /// What the operating system reported.
        source: std::io::Error,
    },
    /// The file exists but its contents are not what the format requires.
    Format {
        /// The offending file.
        path: PathBuf,
        /// What is wrong with it, in words.
        message: String,
    },
}

/// Result alias for this crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Wraps an I/O error with the path it happened on.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// A format error for `path` described by `message`.
    pub fn format(path: &Path, message: impl Into<String>) -> Self {
        Self::Format {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// The file the error is about.
    pub fn path(&self) -> &Path {
        match self {
            Self::Io { path, .. } | Self::Format { path, .. } => path,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Format { path, message } => write!(f, "{}: {message}", path.display()),
        }
    }
}

/// No `source()`: the message already ends with the operating system's words, and a chain
/// printer (`anyhow`'s `{:#}`) would repeat them ("…: No such file or directory (os error 2):
/// No such file or directory (os error 2)").
impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_io_error_names_the_file_and_the_cause_once() {
        let e = Error::io(
            Path::new("/x/manifest.json"),
            std::io::Error::from(std::io::ErrorKind::NotFound),
        );
        assert_eq!(e.to_string(), "/x/manifest.json: entity not found");
        assert!(std::error::Error::source(&e).is_none());
    }
}
