//! The same scene gives byte-identical `events.jsonl` and the same
//! `summary.json` apart from wall time, run after run.

fn run_to(dir: &std::path::Path, scene: &str) -> (Vec<u8>, serde_json::Value) {
    let scene = format!("{}/models/{scene}", env!("CARGO_MANIFEST_DIR"));
    let status = crate::support::command()
        .args(["run", &scene, "--out", dir.to_str().unwrap()])
        .output()
        .unwrap()
        .status;
    assert!(status.code().is_some_and(|c| c == 0 || c == 3));
    let log = std::fs::read(dir.join("events.jsonl")).unwrap();
    let mut summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    summary.as_object_mut().unwrap().remove("wall_seconds");
    summary.as_object_mut().unwrap().remove("log");
    (log, summary)
}

#[test]
fn runs_repeat_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    for scene in [
        "mechanism_impacting.json",
        "mechanism_angle.json",
        "mechanism_chattering.json",
    ] {
        let first = run_to(&dir.path().join("a"), scene);
        let second = run_to(&dir.path().join("b"), scene);
        assert!(!first.0.is_empty(), "{scene}: the log is empty");
        assert!(
            first.0 == second.0,
            "{scene}: events.jsonl differs between runs"
        );
        assert_eq!(
            first.1, second.1,
            "{scene}: summary.json differs between runs"
        );
    }
}
