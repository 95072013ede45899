//! The house inside each folder: read file by file, with every `crate::`,
//! `super::` and `self::` path followed through the folder faces
//! (`mod.rs` files that hand on their children's names) to the file that
//! defines it, no files import each other in a circle, and the engine's
//! four parts point one way.
//! `architecture.rs` holds the top-level modules.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::architecture::{close_of, code, rust_files, top_level};

/// The engine's parts, lowest first: each imports only from those below.
const ENGINE_PARTS: [&str; 4] = ["model", "bound", "step", "run"];

/// A module's path from the crate root (`engine::bound::tracker`).
type Module = Vec<String>;

/// The module a file under `src` is (`mod.rs` is its folder's).
fn module_of(relative: &Path) -> Module {
    let mut parts: Vec<String> = relative
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

/// The paths a file's code names from the crate root: `crate::a::b`,
/// `super::x` and `self::y` (from `module`), with `use` groups expanded.
fn paths(text: &str, module: &Module) -> Vec<Module> {
    let code = code(text);
    let mut found = Vec::new();
    // `super` is the module's parent, `self` the module (a face's module
    // is its folder's).
    let parent = module[..module.len().saturating_sub(1)].to_vec();
    for (anchor, base) in [
        ("crate::", Vec::new()),
        ("super::", parent),
        ("self::", module.clone()),
    ] {
        for (at, _) in code.match_indices(anchor) {
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            expand(&code[at + anchor.len()..], &base, &mut found);
        }
    }
    found
}

/// The full paths of `rest` (after an anchor), under `base`.
fn expand(rest: &str, base: &Module, out: &mut Vec<Module>) {
    let mut path = base.clone();
    let mut rest = rest;
    loop {
        if let Some(group) = rest.strip_prefix('{') {
            let inner = close_of(rest, 0).map_or(group, |close| &rest[1..close]);
            for part in top_level(inner).iter().filter(|p| !p.trim().is_empty()) {
                expand(part.trim_start(), &path, out);
            }
            return;
        }
        if rest.starts_with('*') {
            path.push("*".to_string());
            break;
        }
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if name.is_empty() || name == "self" {
            break;
        }
        rest = &rest[name.len()..];
        if name == "super" {
            path.pop();
        } else {
            path.push(name);
        }
        match rest.strip_prefix("::") {
            Some(next) => rest = next,
            None => break,
        }
    }
    if !path.is_empty() {
        out.push(path);
    }
}

/// The file under `src` that defines module `module`, if one does.
fn file_of(src: &Path, module: &[String]) -> Option<PathBuf> {
    let joined: PathBuf = module.iter().collect();
    if module.is_empty() {
        return Some(PathBuf::from("lib.rs"));
    }
    let file = joined.with_extension("rs");
    let face = joined.join("mod.rs");
    [file, face].into_iter().find(|p| src.join(p).exists())
}

/// What each face hands on: for `engine`, `Mode` -> `engine::model`.
fn faces(src: &Path, files: &[PathBuf]) -> BTreeMap<Module, BTreeMap<String, Module>> {
    let mut out = BTreeMap::new();
    for file in files {
        let relative = file.strip_prefix(src).unwrap();
        let is_face = relative.ends_with("mod.rs") || relative == Path::new("lib.rs");
        if !is_face {
            continue;
        }
        let module = module_of(relative);
        let text = std::fs::read_to_string(file).unwrap();
        let mut names = BTreeMap::new();
        for statement in code(&text).split(';') {
            let statement = statement.trim();
            let Some(at) = statement.find(" use ") else {
                continue;
            };
            // The word before `use` (after any attribute) says who sees it.
            let visibility = statement[..at].split_whitespace().last().unwrap_or("");
            if !(visibility == "pub" || visibility.starts_with("pub(")) {
                continue;
            }
            let mut found = Vec::new();
            expand(statement[at + 5..].trim(), &module, &mut found);
            for path in found {
                let name = path.last().unwrap().clone();
                names.insert(name, path[..path.len() - 1].to_vec());
            }
        }
        out.insert(module, names);
    }
    out
}

/// The file that defines what `path` names: its deepest module's, or,
/// where that is a face handing the next name on, the file it comes from.
fn resolve(
    src: &Path,
    faces: &BTreeMap<Module, BTreeMap<String, Module>>,
    path: &[String],
    depth: usize,
) -> Option<PathBuf> {
    let known = (0..=path.len())
        .rev()
        .find(|&k| file_of(src, &path[..k]).is_some())
        .unwrap_or(0);
    let module = path[..known].to_vec();
    if let (true, Some(names), Some(next)) = (depth < 8, faces.get(&module), path.get(known)) {
        if let Some(from) = names.get(next) {
            let mut onward = from.clone();
            onward.extend_from_slice(&path[known..]);
            return resolve(src, faces, &onward, depth + 1);
        }
        // A glob (`pub use hybrid::*`) hands on what the face does not
        // name.
        if let Some(from) = names.get("*") {
            let mut onward = from.clone();
            onward.extend_from_slice(&path[known..]);
            return resolve(src, faces, &onward, depth + 1);
        }
    }
    file_of(src, &module)
}

/// Every file's imports, file to file (faces and the crate's root aside).
fn file_graph(src: &Path) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let faces = faces(src, &files);
    let mut graph = BTreeMap::new();
    for file in &files {
        let relative = file.strip_prefix(src).unwrap().to_path_buf();
        let is_face = relative.ends_with("mod.rs");
        if is_face || relative == Path::new("lib.rs") || relative == Path::new("main.rs") {
            continue;
        }
        let module = module_of(&relative);
        let text = std::fs::read_to_string(file).unwrap();
        let targets: BTreeSet<PathBuf> = paths(&text, &module)
            .iter()
            .filter_map(|path| resolve(src, &faces, path, 0))
            .filter(|target| *target != relative && !target.ends_with("lib.rs"))
            .collect();
        graph.insert(relative, targets);
    }
    graph
}

/// The circles of `graph`: its strongly connected parts of two files or
/// more, each sorted (Tarjan's algorithm).
fn circles(graph: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<String>> {
    struct Walk<'a> {
        graph: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, (usize, usize)>,
        stack: Vec<&'a PathBuf>,
        on_stack: BTreeSet<&'a PathBuf>,
        found: Vec<Vec<String>>,
    }
    fn visit<'a>(walk: &mut Walk<'a>, node: &'a PathBuf) {
        let n = walk.index.len();
        walk.index.insert(node, (n, n));
        walk.stack.push(node);
        walk.on_stack.insert(node);
        for next in walk.graph.get(node).into_iter().flatten() {
            let Some((next, _)) = walk.graph.get_key_value(next) else {
                continue;
            };
            if !walk.index.contains_key(next) {
                visit(walk, next);
                let low = walk.index[next].1.min(walk.index[node].1);
                walk.index.get_mut(node).unwrap().1 = low;
            } else if walk.on_stack.contains(next) {
                let low = walk.index[next].0.min(walk.index[node].1);
                walk.index.get_mut(node).unwrap().1 = low;
            }
        }
        let (own, low) = walk.index[node];
        if own == low {
            let mut part = Vec::new();
            while let Some(top) = walk.stack.pop() {
                walk.on_stack.remove(top);
                part.push(top.display().to_string());
                if top == node {
                    break;
                }
            }
            if part.len() > 1 {
                part.sort();
                walk.found.push(part);
            }
        }
    }
    let mut walk = Walk {
        graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        found: Vec::new(),
    };
    for node in graph.keys() {
        if !walk.index.contains_key(node) {
            visit(&mut walk, node);
        }
    }
    walk.found.sort();
    walk.found
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

#[test]
fn no_files_import_each_other_in_a_circle() {
    let found = circles(&file_graph(&src()));
    assert!(found.is_empty(), "files in a circle: {found:?}");
}

#[test]
fn the_engines_parts_point_one_way() {
    let part = |file: &Path| -> Option<usize> {
        let mut parts = file.iter().map(|p| p.to_string_lossy());
        (parts.next()? == "engine")
            .then(|| parts.next())
            .flatten()
            .and_then(|p| ENGINE_PARTS.iter().position(|e| *e == p))
    };
    let mut wrong = Vec::new();
    for (file, targets) in file_graph(&src()) {
        let Some(own) = part(&file) else { continue };
        for target in targets {
            if part(&target).is_some_and(|theirs| theirs > own) {
                wrong.push(format!("{} imports {}", file.display(), target.display()));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn paths_are_followed_through_faces_to_the_file_that_defines_them() {
    // The reading itself, on this crate: the engine's face hands `Mode`
    // on from `model`, whose face hands it on from `hybrid.rs` by a glob.
    let src = src();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let faces = faces(&src, &files);
    let path = |p: &str| p.split("::").map(str::to_string).collect::<Vec<_>>();
    let at = |p: &str| resolve(&src, &faces, &path(p), 0).unwrap();
    assert_eq!(at("engine::Mode"), Path::new("engine/model/hybrid.rs"));
    assert_eq!(
        at("engine::bound::ROUNDOFF_ULPS"),
        Path::new("engine/bound/error_set/mod.rs")
    );
    assert_eq!(
        at("engine::run::local::simulate_local"),
        Path::new("engine/run/local.rs")
    );
    // And a group over lines, `super::` among them, expanded in full.
    let found = paths(
        "use crate::engine::{\n  model::{Mode, names::Name},\n  Tolerances,\n};\nuse super::x::Y;\n",
        &path("a::b"),
    );
    let found: Vec<String> = found.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        found,
        [
            "engine::model::Mode",
            "engine::model::names::Name",
            "engine::Tolerances",
            "a::x::Y"
        ]
    );
    // A circle is found as one part, and a chain is none.
    let graph: BTreeMap<PathBuf, BTreeSet<PathBuf>> =
        [("a", "b"), ("b", "c"), ("c", "a"), ("d", "a")]
            .iter()
            .map(|(f, t)| (PathBuf::from(f), BTreeSet::from([PathBuf::from(t)])))
            .collect();
    assert_eq!(circles(&graph), [["a", "b", "c"]]);
}
