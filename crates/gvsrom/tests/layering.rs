//! The library's layering (`docs/architecture.md`): every module of `src/` uses only modules of
//! its own layer listed before it or of a lower layer — never a higher one — so no two modules
//! import each other. Read from the source text: every `crate::module` path in library code
//! (`use` lines, paths, intra-doc links; test modules, inline or in a file of their own, excepted)
//! is an edge.

mod common;

use common::rust_files;
use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The modules of `src/`, bottom first: a module may use only those before it.
const ORDER: &[(&str, &[&str])] = &[
    (
        "files",
        &[
            "error",
            "output",
            "progress",
            "npy",
            "provenance",
            "reduced_model",
        ],
    ),
    (
        "scenario",
        &["scenario", "presets", "csv_input", "plausibility"],
    ),
    ("build", &["build", "layout"]),
    (
        "runs",
        &[
            "statics",
            "simulate",
            "modes",
            "linearize",
            "dataset",
            "compare",
        ],
    ),
    ("reduction", &["reduce"]),
    ("figures", &["plot", "figures"]),
    ("studies", &["reproduce"]),
    ("front-end", &["cli"]),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The top-level module a source file belongs to, from its path relative to `src/`.
fn module_of(rel: &Path) -> String {
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_str()
        .unwrap();
    first.trim_end_matches(".rs").to_string()
}

/// The library code of a file: its text without `#[cfg(test)]` items (a test module may use
/// anything: it is not part of the library).
fn library_code(text: &str) -> String {
    let mut out = String::new();
    let mut skip_depth: Option<i64> = None;
    let mut depth = 0i64;
    let mut pending_test = false;
    for line in text.lines() {
        let trimmed = line.trim_start();
        if skip_depth.is_none() && trimmed.starts_with("#[cfg(test)]") {
            pending_test = true;
            continue;
        }
        let opens = line.matches('{').count() as i64;
        let closes = line.matches('}').count() as i64;
        if pending_test {
            // the item after the attribute: skip to its closing brace (or its `;`)
            pending_test = false;
            if opens > closes {
                skip_depth = Some(depth);
                depth += opens - closes;
            }
            continue;
        }
        depth += opens - closes;
        if let Some(d) = skip_depth {
            if depth <= d {
                skip_depth = None;
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The modules `code` declares as test-only out-of-line modules: `NAME` of every
/// `#[cfg(test)] [pub(…)] mod NAME;` (the module is then a file, e.g. `scenario/tests.rs`).
fn test_module_decls(code: &str) -> Vec<String> {
    let mut out = vec![];
    let mut pending_test = false;
    for line in code.lines() {
        let t = line.trim();
        if t.starts_with("#[cfg(test)]") {
            pending_test = true;
            continue;
        }
        if pending_test {
            let decl = match t.strip_prefix("pub") {
                Some(rest) if rest.starts_with('(') => rest.split_once(')').map_or("", |(_, r)| r),
                Some(rest) => rest,
                None => t,
            };
            if let Some(name) = decl
                .trim()
                .strip_prefix("mod ")
                .and_then(|r| r.strip_suffix(';'))
            {
                out.push(name.trim().to_string());
            }
        }
        pending_test = false;
    }
    out
}

/// The files of `files` that are test-only modules declared by another file of `files` (see
/// [`test_module_decls`]): test code as a whole, like an inline `#[cfg(test)] mod tests { … }`.
fn test_only_files(files: &[PathBuf]) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    for f in files {
        // the directory of the file's submodules: its own for `mod.rs`, else `dir/stem/`
        let dir = match f.file_stem().and_then(|s| s.to_str()) {
            Some("mod" | "lib" | "main") => f.parent().unwrap().to_path_buf(),
            Some(stem) => f.parent().unwrap().join(stem),
            None => continue,
        };
        for name in test_module_decls(&fs::read_to_string(f).unwrap()) {
            let file = [
                dir.join(format!("{name}.rs")),
                dir.join(&name).join("mod.rs"),
            ]
            .into_iter()
            .find(|p| p.is_file());
            let file = file.unwrap_or_else(|| panic!("{}: no file of `mod {name};`", f.display()));
            out.insert(file);
        }
    }
    out
}

/// The modules named by `crate::NAME` paths in `code`, including grouped `use crate::{a, b::c}`.
fn crate_paths(code: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    paths_after("crate::", code, modules)
}

/// The names of `modules` that follow `prefix` in `code` (`prefix` then `NAME` or `{a, b::c}`).
fn paths_after(prefix: &str, code: &str, modules: &BTreeSet<String>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut rest = code;
    while let Some(i) = rest.find(prefix) {
        rest = &rest[i + prefix.len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for item in group[..end].split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if modules.contains(&name) {
                    found.insert(name);
                }
            }
        } else {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if modules.contains(&name) {
                found.insert(name);
            }
        }
    }
    found
}

/// module → (file, module it names) for every edge of the library code.
fn edges() -> BTreeMap<String, BTreeSet<(String, String)>> {
    let root = src();
    let mut files = vec![];
    rust_files(&root, &mut files);
    let modules: BTreeSet<String> = files
        .iter()
        .map(|f| module_of(f.strip_prefix(&root).unwrap()))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let tests_only = test_only_files(&files);
    let mut out: BTreeMap<String, BTreeSet<(String, String)>> = BTreeMap::new();
    for f in &files {
        let rel = f.strip_prefix(&root).unwrap();
        let from = module_of(rel);
        if from == "lib" || from == "main" || tests_only.contains(f) {
            continue;
        }
        let code = library_code(&fs::read_to_string(f).unwrap());
        let entry = out.entry(from.clone()).or_default();
        for to in crate_paths(&code, &modules) {
            if to != from {
                entry.insert((rel.display().to_string(), to));
            }
        }
    }
    out
}

fn rank(module: &str) -> Option<usize> {
    ORDER
        .iter()
        .flat_map(|(_, ms)| ms.iter())
        .position(|m| *m == module)
}

#[test]
fn every_module_of_the_library_has_its_place_in_the_layering() {
    let unplaced: Vec<String> = edges()
        .keys()
        .filter(|m| rank(m).is_none())
        .cloned()
        .collect();
    assert!(
        unplaced.is_empty(),
        "modules missing from ORDER (place each in its layer, here and in docs/architecture.md): {unplaced:?}"
    );
}

#[test]
fn no_library_module_uses_a_module_above_it() {
    let mut upward = vec![];
    for (from, tos) in edges() {
        let Some(r) = rank(&from) else { continue };
        for (file, to) in tos {
            if rank(&to).is_none_or(|t| t > r) {
                upward.push(format!(
                    "{file} uses `crate::{to}`, which is above `{from}`"
                ));
            }
        }
    }
    assert!(upward.is_empty(), "upward imports:\n{}", upward.join("\n"));
}

#[test]
fn the_edge_finder_sees_grouped_paths_and_skips_test_modules() {
    let modules: BTreeSet<String> = ["build", "scenario", "reduce"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let code = library_code(
        "use crate::{build::Built, scenario};\nfn f() {}\n#[cfg(test)]\nmod tests {\n    use crate::reduce;\n    fn g() { if true { } }\n}\nfn h() { crate::reduce::x(); }\n",
    );
    let found = crate_paths(&code, &modules);
    assert_eq!(
        found.into_iter().collect::<Vec<_>>(),
        vec!["build", "reduce", "scenario"],
        "the grouped use and the call after the test module count; {code}"
    );
    let only_test = library_code("#[cfg(test)]\nmod tests {\n    use crate::reduce;\n}\n");
    assert!(crate_paths(&only_test, &modules).is_empty());
}

#[test]
fn out_of_line_test_modules_are_test_code() {
    let code = "mod parse;\n#[cfg(test)]\nmod tests;\n#[cfg(test)]\npub(crate) mod test_util;\n#[cfg(test)]\nmod inline {\n}\nmod types;\n";
    assert_eq!(test_module_decls(code), vec!["tests", "test_util"]);
}

/// Every directory of `src/` (a module split into files), with its files' sibling edges: file →
/// the sibling files it names by `super::NAME` in library code.
fn sibling_edges() -> Vec<(PathBuf, BTreeMap<String, BTreeSet<String>>)> {
    let root = src();
    let mut files = vec![];
    rust_files(&root, &mut files);
    let tests_only = test_only_files(&files);
    let mut by_dir: BTreeMap<PathBuf, Vec<PathBuf>> = BTreeMap::new();
    for f in &files {
        by_dir
            .entry(f.parent().unwrap().to_path_buf())
            .or_default()
            .push(f.clone());
    }
    let mut out = vec![];
    for (dir, fs_) in by_dir {
        if dir == root {
            continue;
        }
        let stem = |f: &Path| f.file_stem().unwrap().to_str().unwrap().to_string();
        let mut siblings: BTreeSet<String> = fs_.iter().map(|f| stem(f)).collect();
        siblings.remove("mod");
        for e in fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                siblings.insert(stem(&p));
            }
        }
        let mut edges = BTreeMap::new();
        for f in &fs_ {
            let name = stem(f);
            if name == "mod" || tests_only.contains(f) {
                continue;
            }
            let code = library_code(&fs::read_to_string(f).unwrap());
            let mut to = paths_after("super::", &code, &siblings);
            to.remove(&name);
            edges.insert(name, to);
        }
        out.push((dir, edges));
    }
    out
}

/// A circle in `edges`, as the names along it, if there is one.
fn circle(edges: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        n: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            let mut c = path[i..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for m in edges.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, edges, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    edges
        .keys()
        .find_map(|n| visit(n, edges, &mut vec![], &mut done))
}

#[test]
fn no_two_files_of_a_module_use_each_other_in_a_circle() {
    let mut circles = vec![];
    for (dir, edges) in sibling_edges() {
        if let Some(c) = circle(&edges) {
            circles.push(format!("{}: {}", dir.display(), c.join(" → ")));
        }
    }
    assert!(
        circles.is_empty(),
        "files of one module that use each other (through `super::NAME`):\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_circle_finder_finds_a_circle_and_only_a_circle() {
    let e = |pairs: &[(&str, &[&str])]| -> BTreeMap<String, BTreeSet<String>> {
        pairs
            .iter()
            .map(|(a, bs)| (a.to_string(), bs.iter().map(|b| b.to_string()).collect()))
            .collect()
    };
    assert_eq!(
        circle(&e(&[("a", &["b"]), ("b", &["c"]), ("c", &["a"])])),
        Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
    );
    assert_eq!(
        circle(&e(&[("a", &["b", "c"]), ("b", &["c"]), ("c", &[])])),
        None
    );
}
