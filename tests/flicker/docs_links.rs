//! The pages a newcomer reads hold together: every link in `README.md` and
//! `docs/` resolves, every file of the repository they name exists, and
//! the README stays a five-minute read (under 12 KB; the rest lives in
//! `docs/` by topic).

use std::path::PathBuf;

/// The folders of the repository a page may name a file in.
const ROOTS: [&str; 11] = [
    "src/",
    "tests/",
    "models/",
    "docs/",
    "examples/",
    "benches/",
    "schemas/",
    "python/",
    ".ci/",
    "fuzz/",
    ".cargo/",
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `README.md` and every page under `docs/`.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![root().join("README.md")];
    for entry in std::fs::read_dir(root().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            pages.push(path);
        }
    }
    pages
}

/// The targets of the Markdown links and images in `text` (`[..](target)`),
/// but web addresses and anchors.
fn links(text: &str) -> Vec<&str> {
    text.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &text[at + 2..];
            let target = &rest[..rest.find(')')?];
            let target = target.split('#').next().unwrap();
            (!target.is_empty() && !target.contains("://") && !target.starts_with("mailto:"))
                .then_some(target)
        })
        .collect()
}

/// The repository files `text` names by path (`src/engine/bound/tracker.rs`), but
/// placeholders (`src/engine/FILE.rs`) and patterns.
fn named_files(text: &str) -> Vec<&str> {
    let is_path = |c: char| c.is_ascii_alphanumeric() || "_./-".contains(c);
    text.split(|c: char| !is_path(c))
        .map(|word| word.trim_end_matches('.'))
        .filter(|word| ROOTS.iter().any(|r| word.starts_with(r)))
        .filter(|word| {
            let last = word.rsplit('/').next().unwrap();
            let stem = last.split('.').next().unwrap();
            last.contains('.') && !(stem.len() > 1 && stem.chars().all(|c| c.is_ascii_uppercase()))
        })
        .collect()
}

#[test]
fn every_link_and_every_named_file_in_the_readme_and_docs_resolves() {
    let mut missing = Vec::new();
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        let name = page.strip_prefix(root()).unwrap().display().to_string();
        for target in links(&text) {
            if !page.parent().unwrap().join(target).exists() {
                missing.push(format!("{name}: link to {target}"));
            }
        }
        for file in named_files(&text) {
            if !root().join(file).exists() {
                missing.push(format!("{name}: names {file}"));
            }
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn the_readme_is_a_five_minute_read_that_links_every_page() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(readme.len() < 12_000, "README.md is {} bytes", readme.len());
    for page in pages().iter().skip(1) {
        let name = page.strip_prefix(root()).unwrap().display().to_string();
        assert!(
            readme.contains(&format!("]({name})")),
            "README.md does not link {name}"
        );
    }
}

#[test]
fn the_checks_see_what_they_look_for() {
    let text = "see [the page](docs/a.md#part) and `src/engine/bound/tracker.rs`, \
                src/engine/FILE.rs, [web](https://x.org) and tests/fixtures/x.json.";
    assert_eq!(links(text), ["docs/a.md"]);
    assert_eq!(
        named_files(text),
        [
            "docs/a.md",
            "src/engine/bound/tracker.rs",
            "tests/fixtures/x.json"
        ]
    );
}
