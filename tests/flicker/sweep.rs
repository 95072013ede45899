//! Sweeps: every point against the closed form, the same CSV whatever the
//! thread count, and shards that merge into the single run byte for byte.

use crate::support::flicker;
use std::path::Path;

fn small_sweep(dir: &Path) -> String {
    let path = dir.join("sweep.json");
    std::fs::write(
        &path,
        r#"{"scene": {"model": "mechanism", "formulation": "strain", "eta": 1.0,
                      "initial": {"energy": 0.1, "phase": "apex"}, "t_end": 50.0},
            "grid": [{"key": "eta", "from": 0.5, "to": 1.5, "count": 7},
                     {"key": "initial.energy", "values": [-0.01, 1e-3, 0.1, 1.0]}]}"#,
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn every_point_matches_the_closed_form_period() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let out = dir.path().join("all.csv");
    let result = flicker(&["sweep", &sweep, "--out", out.to_str().unwrap()]);
    assert_eq!(
        result.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let mut reader = csv::Reader::from_path(&out).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 28);
    let mut checked = 0;
    for r in &rows {
        let (eta, h0) = (
            r[col("eta")].parse::<f64>().unwrap(),
            r[col("initial.energy")].parse::<f64>().unwrap(),
        );
        if h0 < 0.0 && eta <= 1.0 {
            // No state has negative energy below critical load: refused, not run.
            assert!(r[col("status")].starts_with("invalid"), "{r:?}");
            continue;
        }
        assert!(r[col("status")] == *"completed", "{r:?}");
        if h0 > 0.0 && r[col("events")].parse::<u64>().unwrap() > 1 {
            let measured: f64 = r[col("impact_period")].parse().unwrap();
            let exact = 2.0 * (2.0 * h0).sqrt().atan2(1.0 - eta);
            assert!(
                (measured - exact).abs() < 1e-12 * exact.max(1.0),
                "eta {eta}, H0 {h0}: {measured} vs {exact}"
            );
            checked += 1;
        }
    }
    assert!(checked >= 20);
}

#[test]
fn shards_merge_into_the_single_run_and_threads_do_not_matter() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    assert!(
        flicker(&["sweep", &sweep, "--threads", "1", "--out", &path("one.csv")])
            .status
            .success()
    );
    assert!(
        flicker(&["sweep", &sweep, "--threads", "2", "--out", &path("two.csv")])
            .status
            .success()
    );
    assert_eq!(
        std::fs::read(path("one.csv")).unwrap(),
        std::fs::read(path("two.csv")).unwrap()
    );
    for i in 0..3 {
        let shard = format!("{i}/3");
        assert!(
            flicker(&[
                "sweep",
                &sweep,
                "--shard",
                &shard,
                "--out",
                &path(&format!("s{i}.csv"))
            ])
            .status
            .success()
        );
    }
    let merged = flicker(&[
        "merge",
        &sweep,
        &path("s2.csv"),
        &path("s0.csv"),
        &path("s1.csv"),
        "--out",
        &path("merged.csv"),
    ]);
    assert!(
        merged.status.success(),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    assert_eq!(
        std::fs::read(path("merged.csv")).unwrap(),
        std::fs::read(path("one.csv")).unwrap()
    );
    // A missing shard is refused, naming the first missing point.
    let partial = flicker(&[
        "merge",
        &sweep,
        &path("s0.csv"),
        &path("s1.csv"),
        "--out",
        &path("bad.csv"),
    ]);
    assert_eq!(partial.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&partial.stderr).contains("point 2 is missing"));
}

#[test]
fn bad_sweeps_and_shards_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let bad_shard = flicker(&["sweep", &sweep, "--shard", "3/3"]);
    assert_eq!(bad_shard.status.code(), Some(2));
    let typo = dir.path().join("typo.json");
    std::fs::write(
        &typo,
        r#"{"scene": {"model": "mechanism", "formulation": "strain", "eta": 1.0,
                      "initial": {"energy": 0.1, "phase": "impact"}, "t_end": 5.0},
            "grid": [{"key": "etta", "values": [1.0]}]}"#,
    )
    .unwrap();
    let result = flicker(&["sweep", typo.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("typo.json") && stderr.contains("etta"),
        "{stderr}"
    );
}

#[test]
fn the_bundled_sweep_loads_and_its_points_match_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let bundled = format!(
        "{}/models/sweeps/impact_period.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = dir.path().join("part.csv");
    let result = flicker(&[
        "sweep",
        &bundled,
        "--shard",
        "7/50",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let mut reader = csv::Reader::from_path(&out).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 200);
    assert!(
        rows.iter().all(|r| &r[3] == "completed"),
        "every point completes"
    );
    let checked: Vec<f64> = rows
        .iter()
        .filter(|r| !r[8].is_empty())
        .map(|r| r[8].parse().unwrap())
        .collect();
    assert!(
        checked.len() > 150,
        "only {} rows have a period to check",
        checked.len()
    );
    assert!(
        checked.iter().all(|e| *e < 1e-10),
        "period errors {checked:?}"
    );
}
