//! Results do not move: every bundled scene under `models/`, in every
//! folder (automata, stress cases, sweeps), writes the bytes recorded in
//! tests/golden/bundled_scenes.json: the SHA-256 and size of each of
//! `events.jsonl`, `profiles.json` and `trace.csv` (a sweep's CSV), and the
//! summary's status, event counts, final state and mode. The top-level
//! scenes were recorded with the binary of commit 1cc238d, before the
//! scene-model interface, the event labels and the numerics module; the
//! automata, stress cases and sweeps when issue 24 fixed the event
//! semantics and the clock. A deliberate change of results re-records the
//! file (`FLICKER_RECORD_GOLDEN=1 cargo test --release golden`), and its
//! commit says which scenes moved and why.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde_json::{Map, Value, json};
use sha2::{Digest, Sha256};

use crate::support::{flicker, read_json};

/// The summary's fields that are results (not wall time or paths).
const SUMMARY_FIELDS: [&str; 6] = [
    "events",
    "events_by_guard",
    "final_mode",
    "final_state",
    "status",
    "t_reached",
];

/// Every bundled scene, by its path under `models/` without `.json`.
fn bundled(dir: &Path, under: &str, out: &mut BTreeMap<String, PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            bundled(&path, &format!("{under}{name}/"), out);
        } else if path.extension().is_some_and(|x| x == "json") {
            out.insert(format!("{under}{name}"), path);
        }
    }
}

/// What one bundled scene writes: each output file's digest and size, and
/// the summary's results.
fn written(scene: &Path, out: &Path) -> Value {
    let text = std::fs::read_to_string(scene).unwrap();
    let is_sweep = flicker::analysis::sweep::is_sweep(&serde_json::from_str(&text).unwrap());
    let mut record = Map::new();
    if is_sweep {
        let csv = out.join("sweep.csv");
        let result = flicker(&[
            "sweep",
            scene.to_str().unwrap(),
            "--out",
            csv.to_str().unwrap(),
        ]);
        assert!(
            result.status.success(),
            "{}",
            String::from_utf8_lossy(&result.stderr)
        );
        record.insert("sweep.csv".into(), digest(&csv));
        return Value::Object(record);
    }
    let result = flicker(&[
        "run",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(
        matches!(result.status.code(), Some(0 | 3)),
        "{}: {}",
        scene.display(),
        String::from_utf8_lossy(&result.stderr)
    );
    for file in ["events.jsonl", "profiles.json", "trace.csv"] {
        let path = out.join(file);
        if path.exists() {
            record.insert(file.into(), digest(&path));
        }
    }
    let summary = read_json(&out.join("summary.json"));
    let results: Map<String, Value> = SUMMARY_FIELDS
        .iter()
        .filter_map(|k| summary.get(*k).map(|v| (k.to_string(), v.clone())))
        .collect();
    record.insert("summary".into(), Value::Object(results));
    Value::Object(record)
}

fn digest(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap();
    let sha: String = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    json!({"sha256": sha, "bytes": bytes.len()})
}

#[test]
fn every_bundled_scene_writes_the_recorded_bytes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("tests/golden/bundled_scenes.json");
    let mut scenes = BTreeMap::new();
    bundled(&root.join("models"), "", &mut scenes);
    let dir = tempfile::tempdir().unwrap();
    let now: Map<String, Value> = scenes
        .iter()
        .map(|(name, path)| {
            let out = dir.path().join(name.replace('/', "_"));
            std::fs::create_dir_all(&out).unwrap();
            (name.clone(), written(path, &out))
        })
        .collect();
    if std::env::var_os("FLICKER_RECORD_GOLDEN").is_some() {
        let text = serde_json::to_string_pretty(&Value::Object(now)).unwrap();
        std::fs::write(&file, text + "\n").unwrap();
        return;
    }
    let recorded = read_json(&file);
    let recorded = recorded.as_object().unwrap();
    let names = |m: &Map<String, Value>| m.keys().cloned().collect::<Vec<_>>();
    assert_eq!(
        names(recorded),
        names(&now),
        "every bundled scene is recorded"
    );
    for (name, want) in recorded {
        let got = &now[name];
        for (file, value) in want.as_object().unwrap() {
            if file == "summary" {
                for (key, v) in value.as_object().unwrap() {
                    assert_eq!(&got[file][key], v, "{name}: summary {key} moved");
                }
            } else {
                assert_eq!(&got[file], value, "{name}/{file} moved");
            }
        }
        assert_eq!(
            got.as_object().unwrap().len(),
            want.as_object().unwrap().len(),
            "{name} writes other files now: {got}"
        );
    }
}
