//! Printing that cannot abort a run.
//!
//! `println!` and `eprintln!` panic when a write fails — a full disk behind a redirect, a
//! closed pipe — so a run whose data is fine would die with exit code 101 half-way through.
//! Every binary prints through [`say!`](crate::say) and [`note!`](crate::note) instead, under
//! one rule:
//! - standard error carries progress, warnings and the final error message; a failed write
//!   there is ignored, because losing a log line must not lose the data the run writes;
//! - standard output carries a command's result (a summary, a benchmark's figures, a table); a
//!   failed write there is an error naming standard output, so the command exits 1 rather
//!   than report success with its result lost.

use std::fmt;
use std::io::{self, Write};
use std::path::Path;

/// Writes `text` to standard output and flushes it; a failure is an error naming standard
/// output.
pub fn stdout(text: fmt::Arguments) -> crate::Result<()> {
    let mut out = io::stdout().lock();
    out.write_fmt(text)
        .and_then(|()| out.flush())
        .map_err(|e| crate::Error::io(Path::new("standard output"), e))
}

/// Writes `text` to standard error; a failure is ignored (see the module documentation).
pub fn stderr(text: fmt::Arguments) {
    let _ignored = io::stderr().lock().write_fmt(text);
}

/// `println!` for a command's result: evaluates to `lfformat::Result<()>`, an error when
/// standard output cannot be written.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::console::stdout(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `eprintln!` for progress, warnings and errors: never fails, never panics.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {
        $crate::console::stderr(format_args!("{}\n", format_args!($($arg)*)))
    };
}
