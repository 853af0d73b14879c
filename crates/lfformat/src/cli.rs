//! What the command lines of `lfgen`, `lftrain` and `lfeval` share, defined once so that a
//! flag means the same and reads the same in all three: the worker threads and quiet flags,
//! and the shell completions, man page and Markdown reference each binary generates from its
//! own flag definitions.

use std::ffi::OsString;
use std::path::Path;

use clap::builder::RangedU64ValueParser;

/// More worker threads than this only cost memory (each keeps per-pixel buffers).
pub const MAX_THREADS: usize = 1024;

/// `--threads` and `-q`, flattened into every command that does parallel work.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct Workers {
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N", value_parser = threads())]
    pub threads: Option<usize>,
    /// No progress bar or progress messages (results, warnings and errors still print).
    #[arg(short, long)]
    pub quiet: bool,
}

/// `--threads`' values: 1 to [`MAX_THREADS`], checked while parsing, so a bad value is a usage
/// error naming the flag and the range before any work starts.
fn threads() -> RangedU64ValueParser<usize> {
    RangedU64ValueParser::new().range(1..=MAX_THREADS as u64)
}

impl Workers {
    /// Sizes rayon's global thread pool by `--threads`; call once, before any parallel work.
    pub fn apply(&self) -> Result<(), rayon::ThreadPoolBuildError> {
        match self.threads {
            Some(n) => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build_global(),
            None => Ok(()),
        }
    }

    /// Makes `--threads` and `-q` global in `cmd`, for a binary whose top level holds them
    /// (`Workers` flattened there): they may then come before or after a command name.
    pub fn global(cmd: clap::Command) -> clap::Command {
        cmd.mut_arg("threads", |a| a.global(true))
            .mut_arg("quiet", |a| a.global(true))
    }
}

/// `args` (the whole command line, program name first) as clap should read them, for a
/// binary whose top level takes arguments of its own beside its commands (bare `lfgen`
/// generates, bare `lfeval DATASET PRED...` evaluates).
///
/// Once clap has read an option at such a top level it reads every further word as a
/// top-level argument, never as a command name: `lfeval -q baseline DIR` would evaluate a
/// dataset named `baseline`. Options written before a command name that the command takes
/// too (its own or global ones) are therefore moved after the name, where they mean the same.
/// Anything else is left for clap to read, or refuse, as written; `--` still makes the next
/// word an argument.
pub fn options_after_command(cmd: &clap::Command, mut args: Vec<OsString>) -> Vec<OsString> {
    let word = |i: usize| args.get(i).and_then(|w| w.to_str());
    let mut options = Vec::new();
    let mut i = 1;
    while let Some((arg, takes_value)) = word(i).and_then(|w| top_level_option(cmd, w)) {
        options.push(arg);
        i += 1 + usize::from(takes_value);
    }
    let taken = word(i)
        .and_then(|w| cmd.find_subcommand(w))
        .is_some_and(|sub| {
            options
                .iter()
                .all(|a| a.is_global_set() || sub.get_arguments().any(|b| b.get_id() == a.get_id()))
        });
    if !options.is_empty() && taken {
        let name = args.remove(i);
        args.insert(1, name);
    }
    args
}

/// The top-level option `word` names (`--name`, `--name=value` or `-c`), and whether the
/// next word is its value.
fn top_level_option<'a>(cmd: &'a clap::Command, word: &str) -> Option<(&'a clap::Arg, bool)> {
    let (name, inline_value) = word
        .split_once('=')
        .map_or((word, false), |(n, _)| (n, true));
    let arg = cmd.get_arguments().find(|a| {
        let long = a
            .get_long()
            .is_some_and(|l| name.strip_prefix("--") == Some(l));
        long || a.get_short().is_some_and(|c| word == format!("-{c}"))
    })?;
    Some((arg, arg.get_action().takes_values() && !inline_value))
}

/// A disparity range `MIN,MAX` in pixels, finite with MIN ≤ MAX, as `--range` takes it in
/// `lftrain predict` and `lfeval`; the error shows `example` and what was given.
pub fn parse_range(s: &str, example: &str) -> Result<[f64; 2], String> {
    let bad = || format!("expected MIN,MAX (finite, MIN ≤ MAX) such as {example}, got {s:?}");
    let (lo, hi) = s.split_once(',').ok_or_else(bad)?;
    let num = |v: &str| v.trim().parse::<f64>().map_err(|_| bad());
    let r = [num(lo)?, num(hi)?];
    if !(r[0].is_finite() && r[1].is_finite() && r[0] <= r[1]) {
        return Err(bad());
    }
    Ok(r)
}

/// The commands every binary offers for its shell and its manual.
#[derive(clap::Subcommand, Debug, Clone, Copy)]
pub enum Generated {
    /// Print the shell completion script for SHELL, to save where the shell loads completions.
    Completions {
        /// Shell to complete in.
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff), to pipe into `man -l -` or save in a man directory.
    Man,
}

impl Generated {
    /// Writes the completion script or man page of `cmd` (the binary's whole command line)
    /// to standard output.
    pub fn print(self, mut cmd: clap::Command) -> crate::Result<()> {
        let mut bytes = Vec::new();
        match self {
            Self::Completions { shell } => {
                let name = cmd.get_name().to_string();
                clap_complete::generate(shell, &mut cmd, name, &mut bytes);
            }
            Self::Man => clap_mangen::Man::new(cmd)
                .render(&mut bytes)
                .map_err(|e| crate::Error::io(Path::new("man page"), e))?,
        }
        crate::console::stdout(format_args!("{}", String::from_utf8_lossy(&bytes)))
    }
}

/// The Markdown reference of every command and flag of `cmd`, under the title "`NAME`
/// command-line reference", with `note` (how the page is generated) as its first paragraph.
pub fn reference(cmd: &clap::Command, note: &str) -> String {
    let options = clap_markdown::MarkdownOptions::new()
        .title(format!("`{}` command-line reference", cmd.get_name()))
        .show_footer(false);
    let md = clap_markdown::help_markdown_command_custom(cmd, &options);
    md.replacen("\n\n", &format!("\n\n{note}\n\n"), 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

    /// A binary shaped like lfeval: a top level with arguments of its own beside commands.
    #[derive(Parser, Debug)]
    #[command(name = "bin", args_conflicts_with_subcommands = true)]
    struct Cli {
        #[command(subcommand)]
        command: Option<Command>,
        dataset: Option<String>,
        #[arg(long)]
        split: Option<String>,
        #[arg(long)]
        border: Option<u32>,
        #[command(flatten)]
        workers: Workers,
    }

    #[derive(Subcommand, Debug)]
    enum Command {
        Run {
            dataset: Option<String>,
            #[arg(long)]
            split: Option<String>,
        },
        #[command(flatten)]
        Generated(Generated),
    }

    fn parse(args: &[&str]) -> Result<Cli, clap::Error> {
        let cmd = Workers::global(Cli::command());
        let args = options_after_command(&cmd, args.iter().map(OsString::from).collect());
        Cli::from_arg_matches(&cmd.try_get_matches_from(args)?)
    }

    #[test]
    fn a_range_is_two_finite_numbers_in_order() {
        assert_eq!(parse_range("-3.5, 3.5", "-1,1"), Ok([-3.5, 3.5]));
        assert_eq!(parse_range("2,2", "-1,1"), Ok([2.0, 2.0]));
        for bad in ["3,-3", "nan,1", "1,inf", "1", "a,b", ""] {
            let e = parse_range(bad, "-1,1").unwrap_err();
            assert!(
                e.contains("such as -1,1") && e.contains(&format!("{bad:?}")),
                "{e}"
            );
        }
    }

    #[test]
    fn threads_takes_1_to_1024_and_refuses_the_rest_naming_the_flag_and_range() {
        for (n, expected) in [("1", 1), ("1024", MAX_THREADS)] {
            let cli = parse(&["bin", "--threads", n, "run"]).unwrap();
            assert_eq!(cli.workers.threads, Some(expected));
        }
        for bad in ["0", "1025", "-1", "many"] {
            let e = parse(&["bin", &format!("--threads={bad}"), "run"]).unwrap_err();
            assert_eq!(e.exit_code(), 2, "{bad}");
            assert!(e.to_string().contains("--threads <N>"), "{bad}: {e}");
        }
        let e = parse(&["bin", "--threads", "0", "run"]).unwrap_err();
        assert!(e.to_string().contains("1..=1024"), "{e}");
    }

    #[test]
    fn options_the_command_takes_are_read_before_or_after_its_name() {
        for args in [
            &["bin", "-q", "--threads", "3", "--split=val", "run", "d"][..],
            &[
                "bin",
                "--split",
                "val",
                "--threads=3",
                "--quiet",
                "run",
                "d",
            ],
            &[
                "bin",
                "run",
                "d",
                "--threads",
                "3",
                "--quiet",
                "--split",
                "val",
            ],
        ] {
            let cli = parse(args).unwrap();
            let Some(Command::Run { dataset, split }) = &cli.command else {
                panic!("{args:?}: {cli:?}");
            };
            assert!(
                cli.workers.quiet
                    && cli.workers.threads == Some(3)
                    && dataset.as_deref() == Some("d")
                    && split.as_deref() == Some("val"),
                "{args:?}: {cli:?}"
            );
        }
    }

    #[test]
    fn other_words_are_read_as_written() {
        // The top level's own arguments; after `--`, a command name is one of them.
        for (args, dataset) in [
            (&["bin", "-q", "d"][..], "d"),
            (&["bin", "-q", "--", "run"], "run"),
            (&["bin", "--border", "3", "--", "run"], "run"),
        ] {
            let cli = parse(args).unwrap();
            assert!(
                cli.command.is_none() && cli.dataset.as_deref() == Some(dataset),
                "{args:?}: {cli:?}"
            );
        }
        // An option the command does not take stays where it was: clap refuses it there.
        let e = parse(&["bin", "--border", "3", "run", "d"]).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{e}");
    }

    #[test]
    fn the_reference_is_titled_by_the_binary_and_opens_with_the_note() {
        let page = reference(&Cli::command(), "Generated by a test.");
        assert!(
            page.starts_with("# `bin` command-line reference\n\nGenerated by a test.\n\n"),
            "{page}"
        );
        assert!(
            page.contains("--threads <N>") && page.contains("## `bin man`"),
            "{page}"
        );
    }
}
