//! docs/reference/config.md, generated: every config key with its default and its meaning,
//! and the presets (`lfgen doc config`; a test compares the committed page with this).
//!
//! The meanings are generator.toml's comments, the file users copy and edit: a comment
//! describes the keys that follow it up to the next comment or blank line. The defaults are
//! `Config::default()`'s (a test keeps generator.toml's values equal to them), so the page
//! cannot drift from the code.

use crate::config::{Config, PRESETS};
use std::fmt::Write;

/// generator.toml, the documented defaults.
const GENERATOR_TOML: &str = include_str!("../generator.toml");

/// Keys that one comment of generator.toml describes.
struct Group {
    keys: Vec<String>,
    meaning: String,
}

/// The page, in Markdown.
pub fn config_markdown() -> String {
    let defaults = toml::Table::try_from(Config::default()).expect("defaults serialise");
    let mut md = String::from(
        "# Configuration reference\n\n\
         Generated from the code by `lfgen doc config` (do not edit by hand: run \
         `lfgen doc config > docs/reference/config.md`).\n\n\
         Every key is optional; a missing key takes its default. Set keys in a TOML file \
         (`--config FILE`; `./generator.toml` is used when present, `--no-config` ignores it), \
         with a preset (`--preset NAME`), or one at a time (`--set section.key=value`, applied \
         last).\n\n## Presets\n\n| Preset | What it does | Keys it sets |\n|---|---|---|\n",
    );
    for p in PRESETS {
        let sets: Vec<String> = p.sets.iter().map(|s| format!("`{s}`")).collect();
        let _ = writeln!(md, "| `{}` | {} | {} |", p.name, p.about, sets.join(" "));
    }
    for (section, groups) in groups(GENERATOR_TOML) {
        let keys = defaults[&section].as_table().expect("a section is a table");
        let _ = write!(
            md,
            "\n## [{section}]\n\n| Key | Default | Meaning |\n|---|---|---|\n"
        );
        for g in groups {
            let names: Vec<String> = g.keys.iter().map(|k| format!("`{k}`")).collect();
            let values: Vec<String> = (g.keys.iter())
                .map(|k| format!("`{}`", keys[k].to_string().replace('|', "\\|")))
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                names.join("<br>"),
                values.join("<br>"),
                g.meaning.replace('|', "\\|")
            );
        }
    }
    md
}

/// generator.toml's sections in order, each with its keys grouped under their comments.
fn groups(text: &str) -> Vec<(String, Vec<Group>)> {
    let mut sections: Vec<(String, Vec<Group>)> = Vec::new();
    let mut comment: Vec<&str> = Vec::new();
    // Whether the last line was a key, so that the next key joins its group.
    let mut in_group = false;
    for line in text.lines().map(str::trim) {
        if let Some(name) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            sections.push((name.to_owned(), Vec::new()));
            (comment, in_group) = (Vec::new(), false);
        } else if let Some(c) = line.strip_prefix('#') {
            comment.push(c.trim());
            in_group = false;
        } else if let Some((key, _)) = line.split_once('=') {
            let Some((_, groups)) = sections.last_mut() else {
                continue;
            };
            let key = key.trim().to_owned();
            match groups.last_mut() {
                Some(g) if in_group => g.keys.push(key),
                _ => groups.push(Group {
                    keys: vec![key],
                    meaning: comment.join(" "),
                }),
            }
            (comment, in_group) = (Vec::new(), true);
        } else {
            (comment, in_group) = (Vec::new(), false);
        }
    }
    sections
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every key of every section is on the page exactly once, with a meaning.
    #[test]
    fn every_key_is_documented_once_with_a_meaning() {
        let defaults = toml::Table::try_from(Config::default()).unwrap();
        let sections = groups(GENERATOR_TOML);
        for (section, keys) in &defaults {
            let (_, groups) = (sections.iter().find(|(s, _)| s == section))
                .unwrap_or_else(|| panic!("[{section}] missing"));
            for key in keys.as_table().unwrap().keys() {
                let holding: Vec<&Group> = groups.iter().filter(|g| g.keys.contains(key)).collect();
                assert_eq!(holding.len(), 1, "{section}.{key}");
                assert!(
                    !holding[0].meaning.is_empty(),
                    "{section}.{key} has no comment"
                );
            }
        }
    }
}
