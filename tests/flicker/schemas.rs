//! The shipped JSON Schemas agree with flicker itself: every bundled scene
//! passes the scene schema, bad scenes fail it, every log line a run writes
//! passes the event schema, and `flicker check` accepts and refuses the same.

use std::path::Path;

use serde_json::Value;

fn schema(name: &str) -> jsonschema::Validator {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("schemas")
        .join(name);
    let value: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    jsonschema::validator_for(&value).unwrap()
}

fn check(path: &Path) -> Option<i32> {
    crate::support::command()
        .args(["check", path.to_str().unwrap()])
        .output()
        .unwrap()
        .status
        .code()
}

#[test]
fn bundled_scenes_pass_the_scene_schema_and_check() {
    let validator = schema("scene.schema.json");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut seen = 0;
    for dir in [root.clone(), root.join("stress"), root.join("automata")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "json") {
                let scene: Value =
                    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
                let errors: Vec<String> = validator
                    .iter_errors(&scene)
                    .map(|e| e.to_string())
                    .collect();
                assert!(errors.is_empty(), "{}: {errors:?}", path.display());
                assert_eq!(check(&path), Some(0), "{}", path.display());
                seen += 1;
            }
        }
    }
    assert!(seen >= 18);
}

#[test]
fn bad_scenes_fail_both_the_schema_and_check() {
    let validator = schema("scene.schema.json");
    let dir = tempfile::tempdir().unwrap();
    let good = r#"{"model": "mechanism", "formulation": "strain", "eta": 1.2, "initial": {"strain": 0.1, "strain_rate": 0}, "t_end": 1}"#;
    let bad = [
        good.replace("\"t_end\": 1", "\"t_end\": 0"),
        good.replace("\"strain\": 0.1", "\"strain\": -0.1"),
        good.replace("\"eta\": 1.2", "\"eta\": 1.2, \"colour\": 1"),
        good.replace("strain_rate", "rate"),
        good.replace("\"formulation\": \"strain\"", "\"formulation\": \"polar\""),
        good.replace(
            "\"t_end\": 1",
            "\"t_end\": 1, \"solver\": {\"method\": \"rk4\"}",
        ),
    ];
    let path = dir.path().join("scene.json");
    std::fs::write(&path, good).unwrap();
    assert!(validator.is_valid(&serde_json::from_str(good).unwrap()));
    assert_eq!(check(&path), Some(0));
    for text in bad {
        let value: Value = serde_json::from_str(&text).unwrap();
        assert!(!validator.is_valid(&value), "the schema accepts {text}");
        std::fs::write(&path, &text).unwrap();
        assert_eq!(check(&path), Some(2), "flicker check accepts {text}");
    }
}

#[test]
fn every_logged_event_passes_the_event_schema() {
    let validator = schema("event.schema.json");
    let dir = tempfile::tempdir().unwrap();
    for scene in [
        "mechanism_impacting.json",
        "mechanism_angle.json",
        "mechanism_chattering.json",
        "chain_cradle.json",
        "continuum_release_paper.json",
    ] {
        let out = dir.path().join(scene);
        let scene = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("models")
            .join(scene);
        let status = crate::support::command()
            .args([
                "run",
                scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--t-end",
                "50",
            ])
            .status()
            .unwrap();
        assert!(status.success());
        let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
        assert!(!log.is_empty());
        for line in log.lines() {
            let value: Value = serde_json::from_str(line).unwrap();
            let errors: Vec<String> = validator
                .iter_errors(&value)
                .map(|e| e.to_string())
                .collect();
            assert!(errors.is_empty(), "{line}: {errors:?}");
        }
    }
}

#[test]
fn the_shipped_scene_schema_is_the_registrys() {
    // Each model's definition lives beside the model (src/models/*/
    // scene.schema.json); the shipped file is what `flicker schema` prints.
    let shipped: Value = serde_json::from_str(
        &std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("schemas/scene.schema.json"),
        )
        .unwrap(),
    )
    .unwrap();
    assert_eq!(
        shipped,
        flicker::scene::Registry::builtin().schema().unwrap()
    );
    let printed = crate::support::command().arg("schema").output().unwrap();
    assert_eq!(printed.status.code(), Some(0));
    let printed: Value = serde_json::from_slice(&printed.stdout).unwrap();
    assert_eq!(printed, shipped);
}
