//! Results do not move: every bundled scene writes the bytes it wrote
//! before the scene-model interface, the event labels and the numerics
//! module were introduced (recorded with the binary of commit 1cc238d in
//! tests/golden/bundled_scenes.json: the SHA-256 and size of each of
//! `events.jsonl`, `profiles.json` and `trace.csv`, and the summary's
//! status, event counts, final state and mode). A deliberate change of
//! results re-records the file; the failure message prints the new digest.

use sha2::{Digest, Sha256};

use crate::support::{flicker, models, read_json};

#[test]
fn every_bundled_scene_writes_the_recorded_bytes() {
    let golden = read_json(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/bundled_scenes.json"),
    );
    let recorded = golden.as_object().unwrap();
    let bundled =
        std::fs::read_dir(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models"))
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "json"))
            .count();
    assert_eq!(recorded.len(), bundled, "every bundled scene is recorded");
    let dir = tempfile::tempdir().unwrap();
    for (name, want) in recorded {
        let out = dir.path().join(name);
        let result = flicker(&[
            "run",
            &models(&format!("{name}.json")),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(
            matches!(result.status.code(), Some(0 | 3)),
            "{name}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
        for file in ["events.jsonl", "profiles.json", "trace.csv"] {
            let path = out.join(file);
            match want.get(file) {
                Some(digest) => {
                    let bytes = std::fs::read(&path).unwrap();
                    let sha: String = Sha256::digest(&bytes)
                        .iter()
                        .map(|b| format!("{b:02x}"))
                        .collect();
                    assert_eq!(
                        (sha.as_str(), bytes.len() as u64),
                        (
                            digest["sha256"].as_str().unwrap(),
                            digest["bytes"].as_u64().unwrap()
                        ),
                        "{name}/{file} moved"
                    );
                }
                None => assert!(!path.exists(), "{name} writes {file} now"),
            }
        }
        let summary = read_json(&out.join("summary.json"));
        for (key, value) in want["summary"].as_object().unwrap() {
            assert_eq!(&summary[key], value, "{name}: summary {key} moved");
        }
    }
}
