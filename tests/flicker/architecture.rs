//! The house points one way: read from the code's own `crate::` paths
//! (comments and test modules aside), every top-level module of `src/`
//! imports only from modules on lower layers, so no import circle can
//! form between them. A new module must be given a layer here.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first: a module may import from any lower layer,
/// none from its own or a higher one.
const LAYERS: [&[&str]; 12] = [
    &["numerics"],
    // The run's clock, a double-double of numerics' error-free sums.
    &["time"],
    // The generic engine and the model interface the tools ask (Family).
    &["engine"],
    // The expression compiler and its JIT: automata's flows as tapes,
    // series and machine code.
    &["expr"],
    // What a run returns and what controls it.
    &["runner"],
    // Scene files and what every kind of scene offers; the event log.
    &["scene", "log"],
    // Physics, each kind with its scene adapter and family.
    &["models"],
    &["plot"],
    // The tools over any model, and those that measure methods and models.
    &["analysis"],
    &["session"],
    &["prelude"],
    &["cli"],
];

pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// A file's code: its comments and every item under `#[cfg(test)]` (a
/// test module, or one method) taken out, the rest whole.
pub fn code(text: &str) -> String {
    // What follows `//` is a comment (or, rarely, a string's URL: no
    // import is lost, since none follows one on the same line).
    let mut code: String = text
        .lines()
        .map(|line| line.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    while let Some(at) = code.find("#[cfg(test)]") {
        let rest = &code[at..];
        // The item ends at its `;` or at the brace that closes its first.
        let end = match (rest.find(';'), rest.find('{')) {
            (Some(semi), Some(open)) if semi < open => semi + 1,
            (_, Some(open)) => close_of(rest, open).map_or(rest.len(), |close| close + 1),
            (Some(semi), None) => semi + 1,
            (None, None) => rest.len(),
        };
        code.replace_range(at..at + end, "");
    }
    code
}

/// Where the brace opened at `open` in `text` closes.
pub fn close_of(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i);
                }
            }
            _ => {}
        }
    }
    None
}

/// Every `crate::NAME` a file's code (not its comments, not its tests)
/// names, `use` groups over several lines and nested included.
fn imports(text: &str) -> BTreeSet<String> {
    named_after("crate::", text)
}

/// Every `NAME` that follows `prefix` (`crate::`, `flicker::`) in a file's
/// code, read as [`imports`] reads `crate::`.
pub fn named_after(prefix: &str, text: &str) -> BTreeSet<String> {
    let code = code(text);
    let mut names = BTreeSet::new();
    for (at, _) in code.match_indices(prefix) {
        // `flicker::` is also the tail of `_flicker::`: only a path's head counts.
        if code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &code[at + prefix.len()..];
        // `crate::{a::X, b::{Y, Z}}` names each of `a` and `b`.
        let heads: Vec<&str> = match rest.strip_prefix('{') {
            Some(_) => {
                let group = close_of(rest, 0).map_or(rest, |close| &rest[1..close]);
                top_level(group)
            }
            None => vec![rest],
        };
        for head in heads {
            let name: String = head
                .trim_start()
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !name.is_empty() {
                names.insert(name);
            }
        }
    }
    names
}

/// The comma-separated parts of `group` outside its inner braces.
pub fn top_level(group: &str) -> Vec<&str> {
    let (mut parts, mut depth, mut start) = (Vec::new(), 0, 0);
    for (i, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                parts.push(&group[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    parts.push(&group[start..]);
    parts
}

#[test]
fn imports_are_read_from_the_whole_file_and_across_lines() {
    let text = "use crate::{\n    engine::X,\n    numerics::{a, b},\n};\n\
                #[cfg(test)]\nfn only_in_tests() { crate::cli::x(); }\n\
                // crate::plot in a comment\n\
                fn later() { crate::time::now(); }\n\
                #[cfg(test)]\nmod tests { use crate::session::Y; }\n";
    let names: Vec<String> = imports(text).into_iter().collect();
    assert_eq!(names, ["engine", "numerics", "time"]);
}

/// Which top-level module imports which, with a file that does.
fn graph(src: &Path) -> BTreeMap<String, BTreeMap<String, PathBuf>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut edges: BTreeMap<String, BTreeMap<String, PathBuf>> = BTreeMap::new();
    for file in files {
        let relative = file.strip_prefix(src).unwrap();
        let top = relative
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .trim_end_matches(".rs")
            .to_string();
        if top == "lib" || top == "main" {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        let entry = edges.entry(top.clone()).or_default();
        for name in imports(&text) {
            if name != top {
                entry.entry(name).or_insert_with(|| relative.to_path_buf());
            }
        }
    }
    edges
}

/// Macros a module exports at the crate's root (`crate::names!`), with
/// the module that defines them: importing one imports from it.
const MACROS: [(&str, &str); 1] = [("names", "engine")];

fn layer(module: &str) -> Option<usize> {
    let module = MACROS
        .iter()
        .find(|(name, _)| *name == module)
        .map_or(module, |(_, defined_in)| defined_in);
    LAYERS.iter().position(|layer| layer.contains(&module))
}

/// A path of imports from `from` back to itself, if there is one.
fn circle(edges: &BTreeMap<String, BTreeMap<String, PathBuf>>, from: &str) -> Option<Vec<String>> {
    let mut stack = vec![vec![from.to_string()]];
    let mut seen = BTreeSet::new();
    while let Some(path) = stack.pop() {
        let last = path.last().unwrap();
        for next in edges.get(last).into_iter().flat_map(|e| e.keys()) {
            if next == from {
                let mut closed = path.clone();
                closed.push(next.clone());
                return Some(closed);
            }
            if seen.insert(next.clone()) {
                let mut longer = path.clone();
                longer.push(next.clone());
                stack.push(longer);
            }
        }
    }
    None
}

#[test]
fn every_import_points_down_and_no_circle_forms() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let edges = graph(&src);
    let mut wrong = Vec::new();
    for (module, imported) in &edges {
        let Some(own) = layer(module) else {
            wrong.push(format!("`{module}` has no layer: give it one in LAYERS"));
            continue;
        };
        for (target, file) in imported {
            match layer(target) {
                Some(l) if l < own => {}
                _ => wrong.push(format!(
                    "{} imports `{target}`, which is not below `{module}`{}",
                    file.display(),
                    circle(&edges, module)
                        .map(|c| format!(" (a circle: {})", c.join(" -> ")))
                        .unwrap_or_default()
                )),
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The reading itself: a comment, a doc link or a test module names a
/// module without importing it; code does, in a `use` or inline.
#[test]
fn only_code_counts_as_an_import() {
    let text = "//! [`x`]: crate::analysis::orbit::Orbit\nuse crate::engine::Mode;\n\
                use crate::{log::X, plot};\n\
                fn f() { crate::models::load(p); } // crate::cli\n\
                #[cfg(test)]\nmod tests { use crate::analysis::sweep; }\n";
    let found: Vec<String> = imports(text).into_iter().collect();
    assert_eq!(found, ["engine", "log", "models", "plot"]);
}
