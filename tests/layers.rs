//! The layering of `src/` and of the crates it is built on (lfscene, lfrender, lfprocgen,
//! lfassets, lfformat), checked: each top-level module may name
//! (`crate::…`) only the modules below it, so data flows one way — util → camera, textures →
//! scene (description and import) → procgen / render → output, export, stats → config →
//! pipeline, dataset, bench.
//!
//! Why a test: the crate graph already keeps those crates from naming anything of `lfgen` or of
//! each other upwards, but within one crate the compiler allows any path, so a backward
//! import would otherwise go unnoticed until it has grown into a cycle. `lfgen` re-exports
//! lfscene's modules, lfrender (as `render`), lfprocgen (as `procgen`) and the catalogue (as
//! `catalog`: lfformat's schema with lfassets' converter) under the same names, so one table
//! covers all. Test modules (after `#[cfg(test)]`) may use anything, as they build fixtures
//! from the layers above.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::Path;

/// Top-level module → the modules it may name. Modules not listed (pipeline, dataset, bench,
/// main, lib) are the top and may name anything.
const ALLOWED: &[(&str, &[&str])] = &[
    ("util", &[]),
    ("camera", &["util"]),
    ("textures", &["util"]),
    ("scene", &["util", "camera", "textures"]),
    ("catalog", &["util"]),
    (
        "procgen",
        &["util", "camera", "textures", "scene", "catalog"],
    ),
    ("render", &["util", "camera", "textures", "scene"]),
    ("export", &["util", "camera", "scene"]),
    ("stats", &["util", "camera", "scene"]),
    ("output", &["util", "camera", "textures", "scene", "stats"]),
    (
        "config",
        &[
            "util", "camera", "textures", "scene", "procgen", "render", "output",
        ],
    ),
];

/// Modules named by `crate::NAME` or `use crate::{NAME, …}` in `code`.
fn named_modules(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
            .collect()
    };
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            out.extend(group.split(',').map(|p| ident(p.trim())));
        } else {
            out.insert(ident(rest));
        }
    }
    out.remove("");
    out
}

/// The part of a file outside its test module.
fn non_test(code: &str) -> &str {
    code.find("#[cfg(test)]").map_or(code, |i| &code[..i])
}

fn visit(dir: &Path, top: Option<&str>, edges: &mut BTreeMap<(String, String), String>) {
    for e in fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        let module = top.unwrap_or(&name).to_owned();
        if p.is_dir() {
            visit(&p, Some(&module), edges);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let code = fs::read_to_string(&p).unwrap();
            for to in named_modules(non_test(&code)) {
                if to != module {
                    edges.insert((module.clone(), to), p.display().to_string());
                }
            }
        }
    }
}

#[test]
fn no_module_names_a_layer_above_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut edges = BTreeMap::new();
    for src in ["src", "crates/lfscene/src"] {
        visit(&root.join(src), None, &mut edges);
    }
    // The renderer's crate is the `render` layer as a whole.
    visit(
        &root.join("crates/lfrender/src"),
        Some("render"),
        &mut edges,
    );
    assert!(edges.len() > 20, "the scan found the imports: {edges:?}");
    let allowed: BTreeMap<&str, &[&str]> = ALLOWED.iter().copied().collect();
    let backward: Vec<String> = edges
        .iter()
        .filter(|((from, to), _)| {
            allowed
                .get(from.as_str())
                .is_some_and(|ok| !ok.contains(&to.as_str()))
        })
        .map(|((from, to), file)| format!("{from} → {to} ({file})"))
        .collect();
    assert!(
        backward.is_empty(),
        "backward imports:\n{}",
        backward.join("\n")
    );
}

#[test]
fn the_scan_sees_single_and_grouped_imports() {
    let code =
        "use crate::scene::Shape;\nuse crate::{render, util::hash};\nlet x = crate::config::X;";
    let got: Vec<String> = named_modules(code).into_iter().collect();
    assert_eq!(got, ["config", "render", "scene", "util"]);
    assert_eq!(non_test("a\n#[cfg(test)]\nuse crate::x;"), "a\n");
}
