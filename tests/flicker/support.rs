//! Helpers shared by the test modules that drive the `flicker` binary.

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

/// Run the binary with `args` and collect what it did.
pub fn flicker(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flicker"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The path of a bundled scene in `models/`.
pub fn models(name: &str) -> String {
    format!("{}/models/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A JSON file, parsed.
pub fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}
