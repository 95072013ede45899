//! The session is the front ends' one door: every subcommand of the
//! command line and every function of the Python binding is listed here
//! with the door it goes through, and the front ends' code names nothing
//! of the library below the session but the log and picture files. A new
//! subcommand or function fails here until it is given its door.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use clap::CommandFactory;

use crate::architecture::{code, named_after, rust_files};

/// Each subcommand, the file that runs it, and the names of its doors
/// (each must be in that file's code); an empty list for those that only
/// read or write files.
const SUBCOMMANDS: [(&str, &str, &[&str]); 18] = [
    ("run", "run.rs", &["RunRequest", ".prepare(", "run.run("]),
    ("compare", "compare.rs", &["CompareRequest", "comparison"]),
    ("compare-models", "compare_models.rs", &["ModelsRequest"]),
    ("advise", "advise.rs", &["session::probe("]),
    ("stress", "stress.rs", &["session::stress("]),
    ("sweep", "sweep.rs", &["SweepRun::new(", "session::load("]),
    ("merge", "sweep.rs", &["session::merge("]),
    ("check", "check.rs", &["session::read("]),
    ("orbit", "orbit.rs", &["SearchRequest", "search.orbit("]),
    (
        "continue",
        "continuation.rs",
        &["SearchRequest", ".branch("],
    ),
    ("lyapunov", "lyapunov.rs", &["SpectrumRequest"]),
    (
        "diagram",
        "diagram.rs",
        &["DiagramRequest", "prepared.run("],
    ),
    ("basins", "basins.rs", &["BasinsRequest", "prepared.run("]),
    (
        "plot",
        "plot.rs",
        &["session::mechanism_portrait(", "session::state_plane("],
    ),
    // Files only: the schema of the scenes the registry knows, a log read
    // back.
    ("schema", "mod.rs", &[]),
    ("events", "events.rs", &[]),
    // Not subcommands of their own, but clap lists them.
    ("help", "mod.rs", &[]),
    ("version", "mod.rs", &[]),
];

/// Each function the Python module offers, and the names of its doors
/// (each must be in that function's body).
const PYTHON: [(&str, &[&str]); 9] = [
    ("run", &["RunRequest", ".prepare(", "run.run("]),
    ("check", &["read(", "check_lines("]),
    ("compare", &["CompareRequest", "comparison.run("]),
    ("sweep", &["read(", "SweepRun::new("]),
    ("orbit", &["asked(", ".orbit("]),
    ("continuation", &["asked(", ".branch("]),
    ("lyapunov", &["SpectrumRequest", ".spectrum("]),
    ("diagram", &["DiagramRequest", "prepared.run("]),
    ("basins", &["BasinsRequest", "prepared.run("]),
];

/// What of the library a front end may name: the session, and the log and
/// picture files it reads and writes.
const ALLOWED: [&str; 3] = ["session", "log", "plot"];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn every_subcommand_goes_through_its_door() {
    let listed: BTreeSet<String> = flicker::cli::Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .chain(["help", "version"].map(String::from))
        .collect();
    let tabled: BTreeSet<String> = SUBCOMMANDS.iter().map(|(c, ..)| c.to_string()).collect();
    assert_eq!(
        listed, tabled,
        "every subcommand, and only those, is given its door in SUBCOMMANDS"
    );
    let cli = root().join("src/cli");
    for (command, file, doors) in SUBCOMMANDS {
        let text = code(&read(&cli.join(file)));
        for door in doors {
            assert!(
                text.contains(door),
                "`flicker {command}`: src/cli/{file} does not go through `{door}`"
            );
        }
    }
}

#[test]
fn every_python_function_goes_through_its_door() {
    let native = root().join("python/src");
    let lib = code(&read(&native.join("lib.rs")));
    let offered: BTreeSet<String> = lib
        .match_indices("wrap_pyfunction!(")
        .map(|(at, _)| {
            let name = &lib[at + "wrap_pyfunction!(".len()..];
            let name = name.split(',').next().unwrap();
            name.rsplit("::").next().unwrap().trim().to_string()
        })
        .collect();
    let tabled: BTreeSet<String> = PYTHON.iter().map(|(f, _)| f.to_string()).collect();
    assert_eq!(
        offered, tabled,
        "every Python function, and only those, is given its door in PYTHON"
    );
    let mut files = Vec::new();
    rust_files(&native, &mut files);
    let texts: Vec<String> = files.iter().map(|f| code(&read(f))).collect();
    for (function, doors) in PYTHON {
        let body = texts
            .iter()
            .find_map(|text| body_of(text, function))
            .unwrap_or_else(|| panic!("no `fn {function}` in python/src"));
        for door in doors {
            assert!(
                body.contains(door),
                "Python's `{function}` does not go through `{door}`"
            );
        }
    }
}

/// The body of the function `name` defined in `code` (`fn name(` or
/// `fn name<`), if it is.
fn body_of<'c>(code: &'c str, name: &str) -> Option<&'c str> {
    let at = [format!("fn {name}("), format!("fn {name}<")]
        .iter()
        .find_map(|head| code.find(head.as_str()))?;
    let open = at + code[at..].find('{')?;
    let close = crate::architecture::close_of(code, open)?;
    Some(&code[open..close])
}

#[test]
fn the_front_ends_name_nothing_below_the_session_but_files() {
    let mut wrong = Vec::new();
    let mut check = |dir: PathBuf, prefix: &str, own: &str| {
        let mut files = Vec::new();
        rust_files(&dir, &mut files);
        for file in files {
            for name in named_after(prefix, &read(&file)) {
                if !ALLOWED.contains(&name.as_str()) && name != own {
                    wrong.push(format!("{} names `{prefix}{name}`", file.display()));
                }
            }
        }
    };
    check(root().join("src/cli"), "crate::", "cli");
    check(root().join("python/src"), "flicker::", "");
    assert!(
        wrong.is_empty(),
        "a front end reaches past the session:\n{}",
        wrong.join("\n")
    );
}

/// The reading can fail: a front end that named the engine, or a
/// function whose body lacks its door, is seen.
#[test]
fn the_reading_sees_a_front_end_that_goes_around() {
    let around = "use crate::session::Registry;\nfn f() { crate::engine::simulate(); }";
    assert!(named_after("crate::", around).contains("engine"));
    let python = "use flicker::{session::Scene, runner::Limits};";
    let names = named_after("flicker::", python);
    assert!(names.contains("runner") && names.contains("session"));
    // `_flicker::` is the module's own name, not the library's.
    assert!(named_after("flicker::", "fn _flicker::x() {}").is_empty());
    let body = body_of(
        "fn run<'py>(x: u8) { a(); }\nfn other() { RunRequest }",
        "run",
    );
    assert_eq!(body, Some("{ a(); "));
}
