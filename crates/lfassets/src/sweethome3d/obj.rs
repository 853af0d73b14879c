//! OBJ and MTL files of a library, read as lines: which `.mtl` files and textures a model
//! needs, which material names it uses that no `.mtl` file defines (Sweet Home 3D's built-in
//! ones), and the rewrites that keep every reference inside the output folder.

use super::library::{Library, join_zip, parent_dir, read_entry, safe_relative};
use std::collections::{BTreeSet, HashMap, HashSet};

/// Lines of a text file as bytes, without the line end.
fn lines(bytes: &[u8]) -> impl Iterator<Item = &[u8]> {
    bytes
        .split(|&b| b == b'\n')
        .map(|l| l.strip_suffix(b"\r").unwrap_or(l))
}

/// The argument of a `keyword arg…` line, if the line is one.
fn statement(line: &[u8], keyword: &str) -> Option<String> {
    let text = String::from_utf8_lossy(line);
    let text = text.trim_start();
    let rest = text.strip_prefix(keyword)?;
    if !rest.starts_with([' ', '\t']) {
        return None;
    }
    let arg = rest.trim();
    (!arg.is_empty()).then(|| arg.to_string())
}

/// The archive file a reference (`mtllib`, `map_Kd` …) names, if it is a clean relative path
/// ([`safe_relative`]) to a file of the archive: the whole argument, else its last word (map
/// options such as `-s 1 1 1` come first, and disk paths with blanks such as
/// `/Users/x/Living room rug.jpg` end with the file's name). Other absolute paths from the
/// authors' disks (`C:/Documents and Settings/…`) and missing files give `None`.
fn resolve(lib: &Library, dir: &str, arg: &str) -> Option<Reference> {
    let last = arg.split_whitespace().last().unwrap_or("");
    [arg, last].into_iter().find_map(|a| {
        safe_relative(a)?;
        let name = join_zip(dir, a).filter(|n| lib.names.contains(n))?;
        Some(Reference {
            name,
            path: a.to_string(),
            whole: a == arg,
        })
    })
}

/// A file a reference names.
struct Reference {
    /// Its archive name.
    name: String,
    /// The path as written, relative to the referring file.
    path: String,
    /// Whether that is the whole argument (else its last word, after options or a disk path).
    whole: bool,
}

/// `text` with the lines that are keys of `new` replaced by their values, or `None` when
/// there are none.
fn rewrite(text: &[u8], new: &HashMap<Vec<u8>, String>) -> Option<Vec<u8>> {
    if new.is_empty() {
        return None;
    }
    let mut out = Vec::with_capacity(text.len() + 64 * new.len());
    for (i, line) in text.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            out.push(b'\n');
        }
        match new.get(line.strip_suffix(b"\r").unwrap_or(line)) {
            Some(replacement) => out.extend_from_slice(replacement.as_bytes()),
            None => out.extend_from_slice(line),
        }
    }
    Some(out)
}

/// A line commented out because the file it names is not in the library.
fn missing_line(line: &[u8]) -> String {
    format!(
        "# lfgen: file missing from the library: {}",
        String::from_utf8_lossy(line)
    )
}

/// What the converter learnt of one OBJ and its materials.
pub(super) struct ObjPlan {
    /// The OBJ with an `mtllib` for its built-in names and missing `mtllib`s commented out.
    pub(super) obj: Vec<u8>,
    /// Built-in material names the OBJ uses (not defined by its `.mtl` files).
    pub(super) builtin: BTreeSet<String>,
    /// `.mtl` files and textures it needs (archive names).
    pub(super) needs: BTreeSet<String>,
    /// `.mtl` files rewritten: references to missing textures commented out, the others
    /// reduced to the plain relative path (`map_Kd rug.jpg`, no options or disk path before it).
    pub(super) patched: HashMap<String, Vec<u8>>,
    /// References to files absent from the library (or outside it).
    pub(super) missing: usize,
}

/// Reads the OBJ `obj_name` (bytes `obj`) and the `.mtl` files it names. Built-in material
/// names it uses go to a `mtllib builtin_file` line put in front of it.
pub(super) fn plan_obj(
    lib: &mut Library,
    obj_name: &str,
    obj: &[u8],
    builtin_file: &str,
) -> ObjPlan {
    let dir = parent_dir(obj_name).to_string();
    let mut plan = ObjPlan {
        obj: Vec::new(),
        builtin: BTreeSet::new(),
        needs: BTreeSet::new(),
        patched: HashMap::new(),
        missing: 0,
    };
    let mut missing_libs = HashMap::new();
    let mut defined = HashSet::new();
    let mut used = BTreeSet::new();
    for line in lines(obj) {
        if let Some(name) = statement(line, "usemtl") {
            used.insert(name);
            continue;
        }
        let Some(arg) = statement(line, "mtllib") else {
            continue;
        };
        let Some(Reference { name: mtl, .. }) = resolve(lib, &dir, &arg) else {
            missing_libs.insert(line.to_vec(), missing_line(line));
            plan.missing += 1;
            continue;
        };
        plan_mtl(lib, mtl, &mut plan, &mut defined);
    }
    plan.builtin = used.into_iter().filter(|n| !defined.contains(n)).collect();
    if !plan.builtin.is_empty() {
        plan.obj.extend_from_slice(
            format!("# lfgen: materials Sweet Home 3D supplies itself\nmtllib {builtin_file}\n")
                .as_bytes(),
        );
    }
    match rewrite(obj, &missing_libs) {
        Some(patched) => plan.obj.extend_from_slice(&patched),
        None => plan.obj.extend_from_slice(obj),
    }
    plan
}

/// Reads the `.mtl` file `mtl` an OBJ names (an unreadable one is passed over): the material
/// names it defines go to `defined`, its textures to `plan.needs`, its rewrite (if its texture
/// references need one) to `plan.patched`.
fn plan_mtl(lib: &mut Library, mtl: String, plan: &mut ObjPlan, defined: &mut HashSet<String>) {
    let Ok(text) = read_entry(&mut lib.zip, &mtl) else {
        return;
    };
    let mtl_dir = parent_dir(&mtl).to_string();
    let mut new_lines = HashMap::new();
    for l in lines(&text) {
        if let Some(name) = statement(l, "newmtl") {
            defined.insert(name);
        }
        let s = String::from_utf8_lossy(l);
        let mut it = s.trim_start().splitn(2, [' ', '\t']);
        let key = it.next().unwrap_or("");
        let lower = key.to_ascii_lowercase();
        let map = lower.starts_with("map_")
            || matches!(lower.as_str(), "bump" | "disp" | "decal" | "refl");
        if let (true, Some(arg)) = (map, it.next()) {
            match resolve(lib, &mtl_dir, arg.trim()) {
                Some(file) => {
                    if !file.whole {
                        new_lines.insert(l.to_vec(), format!("{key} {}", file.path));
                    }
                    plan.needs.insert(file.name);
                }
                None => {
                    new_lines.insert(l.to_vec(), missing_line(l));
                    plan.missing += 1;
                }
            }
        }
    }
    if let Some(patched) = rewrite(&text, &new_lines) {
        plan.patched.insert(mtl.clone(), patched);
    }
    plan.needs.insert(mtl);
}
