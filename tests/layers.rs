//! The layering of the workspace, checked at three levels, so data flows one way and a
//! backward edge fails a test instead of growing into a cycle.
//!
//! - Crates: every package `cargo metadata` lists must stand in [`CRATES`] with the workspace
//!   crates it may depend on (any dependency kind). lfformat is the bottom; the generator's
//!   crates (lfscene, lfassets, lfprocgen, lfrender) and the data layer (lfdata) build on it;
//!   `lfgen` on the former, `lfeval` and `lftrain` — leaves beside each other — on the latter.
//! - Modules of every crate: the top-level modules that name each other (`crate::…`, in code,
//!   not in comments or test modules) form no cycle, except the few groups of peers in
//!   [`KNOWN_TANGLES`], which may not grow.
//! - Modules of `src/` and of the crates it is built on (lfscene, lfrender, lfprocgen, lfassets,
//!   lfformat): each top-level module may name only the modules below it in [`ALLOWED`] —
//!   util → camera, textures → scene (description and import) → procgen / render → output,
//!   export, stats → config → pipeline, dataset, bench. `lfgen` re-exports lfscene's modules,
//!   lfrender (as `render`), lfprocgen (as `procgen`) and the catalogue (as `catalog`: lfformat's
//!   schema with lfassets' converter) under the same names, so one table covers all. Test
//!   modules (after `#[cfg(test)]`) may use anything, as they build fixtures from the layers
//!   above.
//!
//! Why a test: the crate graph keeps crates from naming each other upwards only once an edge is
//! missing from a manifest, and within one crate the compiler allows any path.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// Workspace crate → the workspace crates it may depend on.
const CRATES: &[(&str, &[&str])] = &[
    ("lfformat", &[]),
    ("lfscene", &["lfformat"]),
    ("lfassets", &["lfformat"]),
    ("lfprocgen", &["lfformat", "lfscene"]),
    ("lfrender", &["lfformat", "lfscene"]),
    (
        "lfgen",
        &["lfformat", "lfscene", "lfassets", "lfprocgen", "lfrender"],
    ),
    ("lfdata", &["lfformat"]),
    ("lfeval", &["lfformat", "lfdata"]),
    ("lftrain", &["lfformat", "lfdata"]),
];

/// Crate → groups of its top-level modules that name each other: peers that share types both
/// ways (a network and its parts, a loss and its tensors, training and its validation). A
/// cycle elsewhere, or one that reaches beyond its group, fails.
const KNOWN_TANGLES: &[(&str, &[&str])] = &[
    ("lftrain", &["costnet", "epishift", "model"]),
    ("lftrain", &["loss", "shift_loss", "tensors"]),
    ("lftrain", &["log", "predict", "train", "validate"]),
];

/// Top-level module → the modules it may name. Modules not listed (pipeline, dataset, bench,
/// main, lib) are the top and may name anything.
const ALLOWED: &[(&str, &[&str])] = &[
    ("util", &[]),
    ("appearance", &[]),
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
    ("stats", &["util", "camera", "scene", "appearance"]),
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

/// The part of a file that makes a dependency: its code outside the test module, without `//`
/// comments (a doc link may point anywhere).
fn code_only(code: &str) -> String {
    let lines = non_test(code).lines();
    let code: Vec<&str> = lines
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect();
    code.join("\n")
}

/// Module edges `(from, to) → file` of the sources under `dir`: `from` is the top-level module
/// (`top`, or each file's or folder's own name), `to` each module the part `scan` keeps of a
/// file names.
fn visit(
    dir: &Path,
    top: Option<&str>,
    scan: fn(&str) -> String,
    edges: &mut BTreeMap<(String, String), String>,
) {
    for e in fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        let module = top.unwrap_or(&name).to_owned();
        if p.is_dir() {
            visit(&p, Some(&module), scan, edges);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let code = fs::read_to_string(&p).unwrap();
            for to in named_modules(&scan(&code)) {
                if to != module {
                    edges.insert((module.clone(), to), p.display().to_string());
                }
            }
        }
    }
}

/// A workspace package as `cargo metadata` describes it.
struct Package {
    name: String,
    /// The workspace crates it depends on (any kind: normal, build, dev).
    dependencies: BTreeSet<String>,
    /// The folder of its library (or, without one, its binary) root.
    src: PathBuf,
}

/// Every package of the workspace.
fn workspace() -> Vec<Package> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.toml");
    let out = Command::new(env!("CARGO"))
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .arg("--manifest-path")
        .arg(&manifest)
        .output()
        .expect("cargo runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cargo metadata failed: {stderr}");
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata writes JSON");
    let packages = meta["packages"].as_array().expect("a package list");
    let names: BTreeSet<&str> = packages.iter().filter_map(|p| p["name"].as_str()).collect();
    let list = |v: &Value, key: &str| v[key].as_array().cloned().unwrap_or_default();
    packages
        .iter()
        .map(|p| {
            let dependencies = list(p, "dependencies")
                .iter()
                .filter_map(|d| d["name"].as_str())
                .filter(|d| names.contains(d))
                .map(String::from)
                .collect();
            let targets = list(p, "targets");
            let kind = |t: &&Value, k: &str| list(t, "kind").iter().any(|x| x == k);
            let root = (targets.iter().find(|t| kind(t, "lib")))
                .or_else(|| targets.iter().find(|t| kind(t, "bin")))
                .and_then(|t| t["src_path"].as_str())
                .expect("a library or binary target");
            Package {
                name: p["name"].as_str().expect("a name").to_owned(),
                dependencies,
                src: Path::new(root)
                    .parent()
                    .expect("a source folder")
                    .to_owned(),
            }
        })
        .collect()
}

/// The nodes `graph` reaches from `from` in one or more steps.
fn reachable<'a>(graph: &BTreeMap<&'a str, BTreeSet<&'a str>>, from: &str) -> BTreeSet<&'a str> {
    let mut seen = BTreeSet::new();
    let mut todo: Vec<&str> = graph.get(from).into_iter().flatten().copied().collect();
    while let Some(n) = todo.pop() {
        if seen.insert(n) {
            todo.extend(graph.get(n).into_iter().flatten().copied());
        }
    }
    seen
}

/// The groups of nodes of `graph` that reach each other (cycles), each sorted, without repeats.
fn tangles<'a>(graph: &BTreeMap<&'a str, BTreeSet<&'a str>>) -> BTreeSet<Vec<&'a str>> {
    let reach: BTreeMap<&str, BTreeSet<&str>> =
        graph.keys().map(|&m| (m, reachable(graph, m))).collect();
    let back = |m: &str, n: &str| reach.get(n).is_some_and(|r| r.contains(m));
    reach
        .iter()
        .map(|(&m, r)| {
            r.iter()
                .copied()
                .filter(|&n| back(m, n))
                .collect::<Vec<_>>()
        })
        .filter(|group| !group.is_empty())
        .collect()
}

#[test]
fn every_crate_depends_only_on_the_crates_below_it() {
    let allowed: BTreeMap<&str, &[&str]> = CRATES.iter().copied().collect();
    let packages = workspace();
    let names: BTreeSet<&str> = packages.iter().map(|p| p.name.as_str()).collect();
    let placed: BTreeSet<&str> = allowed.keys().copied().collect();
    assert_eq!(
        names, placed,
        "every workspace crate has its place in CRATES"
    );
    let outside: Vec<String> = packages
        .iter()
        .flat_map(|p| {
            let ok = allowed[p.name.as_str()];
            (p.dependencies.iter())
                .filter(|d| !ok.contains(&d.as_str()))
                .map(|d| format!("{} → {d}", p.name))
        })
        .collect();
    assert!(
        outside.is_empty(),
        "dependencies outside the layering:\n{}",
        outside.join("\n")
    );
}

#[test]
fn no_crate_has_a_module_cycle_beyond_its_known_tangles() {
    let mut found = Vec::new();
    let mut scanned = 0;
    for p in workspace() {
        let mut edges = BTreeMap::new();
        visit(&p.src, None, code_only, &mut edges);
        scanned += edges.len();
        let mut graph: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
        for (from, to) in edges.keys() {
            graph.entry(from).or_default().insert(to);
        }
        let known: Vec<&[&str]> = (KNOWN_TANGLES.iter())
            .filter(|(c, _)| *c == p.name)
            .map(|(_, g)| *g)
            .collect();
        let cycles = tangles(&graph);
        for group in &cycles {
            if !known.iter().any(|k| group.iter().all(|m| k.contains(m))) {
                found.push(format!("{}: {}", p.name, group.join(" ↔ ")));
            }
        }
        for k in known {
            let still = cycles.iter().any(|g| k.iter().all(|m| g.contains(m)));
            assert!(
                still,
                "{}: {k:?} no longer tangled; drop it from KNOWN_TANGLES",
                p.name
            );
        }
    }
    assert!(
        scanned > 200,
        "the scan found the imports of every crate ({scanned})"
    );
    assert!(found.is_empty(), "module cycles:\n{}", found.join("\n"));
}

#[test]
fn no_module_names_a_layer_above_it() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut edges = BTreeMap::new();
    for src in ["src", "crates/lfscene/src"] {
        visit(
            &root.join(src),
            None,
            |c| non_test(c).to_owned(),
            &mut edges,
        );
    }
    // The renderer's crate is the `render` layer as a whole.
    visit(
        &root.join("crates/lfrender/src"),
        Some("render"),
        |c| non_test(c).to_owned(),
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

#[test]
fn the_cycle_finder_groups_modules_that_reach_each_other() {
    let graph: BTreeMap<&str, BTreeSet<&str>> = [
        ("a", vec!["b"]),
        ("b", vec!["c", "d"]),
        ("c", vec!["a"]),
        ("d", vec!["e"]),
        ("e", vec![]),
    ]
    .into_iter()
    .map(|(m, to)| (m, to.into_iter().collect()))
    .collect();
    let found: Vec<Vec<&str>> = tangles(&graph).into_iter().collect();
    assert_eq!(found, [vec!["a", "b", "c"]]);
    assert_eq!(
        code_only("use crate::a;\n/// [`crate::b`]\n"),
        "use crate::a;"
    );
}
