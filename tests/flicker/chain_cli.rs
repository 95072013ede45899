//! Chain scenes through the command line: the files a run writes, in the
//! documented shapes and conventions, and bad scenes refused by field.

use std::path::Path;

use crate::support::{flicker, models, read_json};

fn run(scene: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["run", scene, "--out", out.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    flicker(&args)
}

#[test]
fn a_release_run_writes_summary_log_profiles_and_trace() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("release");
    let o = run(
        &models("chain_release_free_end.json"),
        &out,
        &["--t-end", "2.5"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["model"], "chain");
    assert_eq!(summary["method"], "exact");
    assert!(summary["momentum"].is_number());
    assert!(summary["momentum_balance_error"].as_f64().unwrap() < 1e-12);
    assert!(summary["max_energy_error"].as_f64().unwrap() < 1e-12);
    // 200 units of length 0.01 over [-1, 1], strain 0.1 at rest at t = 0.
    let profiles = read_json(&out.join("profiles.json"));
    let snapshots = profiles["snapshots"].as_array().unwrap();
    assert_eq!(snapshots.len(), 3);
    let first = &snapshots[0];
    assert_eq!(first["t"], 0.6667);
    for key in ["x", "strain", "displacement", "velocity"] {
        assert_eq!(first[key].as_array().unwrap().len(), 200, "{key}");
    }
    assert!((first["x"][0].as_f64().unwrap() + 0.995).abs() < 1e-12);
    assert!((first["x"][199].as_f64().unwrap() - 0.995).abs() < 1e-12);
    // Displacement is the running sum of unit strain times unit length.
    let strain: Vec<f64> = first["strain"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let y: Vec<f64> = first["displacement"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let mut sum = 0.0;
    for (e, y) in strain.iter().zip(&y) {
        assert!(*e >= -1e-12, "no strain below zero: {e}");
        sum += e * 0.01;
        assert!((sum - y).abs() < 1e-12);
    }
    // The trace: 300 rows at linspace(0, 2.5, 300), starting at rest with
    // the end displaced by 0.1 L = 0.2.
    let mut reader = csv::Reader::from_path(out.join("trace.csv")).unwrap();
    assert_eq!(
        reader.headers().unwrap(),
        vec!["t", "energy", "momentum", "right_end"]
    );
    let rows: Vec<Vec<f64>> = reader
        .records()
        .map(|r| r.unwrap().iter().map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 300);
    assert_eq!(rows[0][0], 0.0);
    assert_eq!(rows[299][0], 2.5);
    assert!((rows[0][3] - 0.2).abs() < 1e-12 && rows[0][2] == 0.0);
    let e0 = summary["energy_initial"].as_f64().unwrap();
    assert!(rows.iter().all(|r| (r[1] - e0).abs() < 1e-12 * e0));
    // Momentum falls as -(1.1 - 0) t until the wall feels the release
    // (docs/physics.md s.6). Collision pulses run ahead of c_b = 1: the end
    // unit first closes at about 0.45 (its node's speed), and a pulse
    // travels at about node speed / strain ahead = 4.5, so the wall, 2
    // away, feels nothing before t = 2 / 4.5 = 0.44.
    for r in rows.iter().filter(|r| r[0] < 0.4) {
        assert!((r[2] + 1.1 * r[0]).abs() < 1e-9, "{r:?}");
    }
    // Every log line names its unit and closing speed.
    let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    let first: serde_json::Value = serde_json::from_str(log.lines().next().unwrap()).unwrap();
    assert_eq!(first["unit"], 200, "the released end closes first");
    assert!(first["rel_velocity"].as_f64().unwrap() > 0.0);
    // The pictures: snapshots and the end beside the classical string, the
    // impacts in space and time.
    let classical = &profiles["classical"]["snapshots"][2]["strain"];
    assert_eq!(classical.as_array().unwrap().len(), 200);
    let o = flicker(&["plot", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for name in ["snapshots", "displacement", "end_displacement", "impacts"] {
        for extension in ["svg", "png"] {
            let path = out.join(format!("{name}.{extension}"));
            let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
            assert!(size > 1000, "{} is missing or empty", path.display());
        }
    }
    // Thinned to a picture's worth of dots, and said so.
    let map = std::fs::read_to_string(out.join("impacts.svg")).unwrap();
    assert!(map.contains("every") && map.matches("<circle").count() <= 20_000);
}

#[test]
fn the_ode_path_runs_the_same_scene_from_the_command_line() {
    // Both adaptive pairs. After the t = 0 cascade units 2-4 sit shut with
    // zero closing speed and open again; a fit's noise in their rate must
    // not read as closing (DOP853 once stopped here as Zeno).
    for method in ["dopri5", "dop853"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("cradle");
        let o = run(
            &models("chain_cradle.json"),
            &out,
            &["--method", method, "--rtol", "1e-12", "--atol", "1e-14"],
        );
        assert!(
            o.status.success(),
            "{method}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let summary = read_json(&out.join("summary.json"));
        assert_eq!(summary["method"], method);
        assert_eq!(summary["events"], 2, "{method}");
        let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
        let seqs: Vec<u64> = log
            .lines()
            .map(|l| {
                serde_json::from_str::<serde_json::Value>(l).unwrap()["seq"]
                    .as_u64()
                    .unwrap()
            })
            .collect();
        assert_eq!(seqs, vec![1, 2], "numbered across the legs between samples");
        let profiles = read_json(&out.join("profiles.json"));
        // At t = 1 (worked by hand): node 1's speed went through the shut
        // block to node 4 at t = 0, and on to node 5 when unit 5 closed near
        // t = 0.5. Velocities list nodes 1..=5, so v[0] is node 1, now about
        // at rest, and v[4] is node 5, the end, carrying the speed.
        let v = &profiles["snapshots"][1]["velocity"];
        assert!(
            (v[0].as_f64().unwrap()).abs() < 0.01 && v[4].as_f64().unwrap() > 0.99,
            "{method}: {v}"
        );
    }
}

#[test]
fn bad_chain_scenes_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let base = r#""model": "chain", "length": 2.0, "wave_speed": 1.0, "t_end": 1.0"#;
    for (body, field) in [
        (
            r#""units": 0, "load": {"before": 1.1, "after": 0.0}"#,
            "field units",
        ),
        (
            r#""units": 3, "load": {"before": 0.9, "after": 0.0}"#,
            "field load.before",
        ),
        (r#""units": 3, "load": {"before": 1.1}"#, "field load.after"),
        (
            r#""units": 3, "load": {"before": 1.1, "after": 0.0}, "initial": {"strain": [0.1, 0.1]}"#,
            "field initial.strain",
        ),
        (
            r#""units": 3, "load": {"before": 1.1, "after": 0.0}, "initial": {"velocity": [0, "x", 0]}"#,
            "field initial.velocity[1]",
        ),
        (
            r#""units": 3, "load": {"before": 1.1, "after": 0.0}, "snapshots": [2.0]"#,
            "field snapshots",
        ),
        (
            r#""units": 3, "load": {"before": 1.1, "after": 0.0}, "constraint": "yes""#,
            "field constraint",
        ),
        (
            r#""units": 3000, "load": {"before": 1.1, "after": 0.0}, "solver": {"method": "linear"}"#,
            "field solver.method",
        ),
        (
            r#""units": 3, "load": {"before": 1.1, "after": 0.0}, "colour": 1"#,
            "field colour",
        ),
    ] {
        let path = dir.path().join("bad.json");
        std::fs::write(&path, format!("{{{base}, {body}}}")).unwrap();
        let o = flicker(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            dir.path().join("o").to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{body}: {err}");
        assert!(err.contains(field), "{body}: {err}");
        assert!(err.contains("bad.json"), "{err}");
    }
    // Numbers fine one by one, but the chain's own overflow.
    let path = dir.path().join("huge.json");
    std::fs::write(
        &path,
        r#"{"model": "chain", "units": 3, "length": 2.0, "wave_speed": 1e200, "t_end": 1.0, "load": {"before": 1.1, "after": 0.0}}"#,
    )
    .unwrap();
    let o = flicker(&["check", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("field wave_speed") && err.contains("huge.json"),
        "{err}"
    );
    // The classical chain takes strains below zero.
    let path = dir.path().join("classical.json");
    std::fs::write(&path, format!(r#"{{{base}, "units": 3, "load": {{"before": 0.9, "after": 0.0}}, "constraint": false}}"#)).unwrap();
    let o = flicker(&["check", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn an_ensemble_finds_the_horizon_reproducibly() {
    let dir = tempfile::tempdir().unwrap();
    let scene = models("chain_release_free_end.json");
    let ensemble = |name: &str, seed: &str, threads: &str| {
        let out = dir.path().join(name);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_flicker"))
            .args([
                "run",
                &scene,
                "--out",
                out.to_str().unwrap(),
                "--quiet",
                "--no-events",
            ])
            .args(["--t-end", "1.5", "--ensemble", "3", "--seed", seed])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        read_json(&out.join("summary.json"))["ensemble"].clone()
    };
    let a = ensemble("a", "7", "1");
    let b = ensemble("b", "7", "2");
    assert_eq!(
        a, b,
        "the same seed gives the same ensemble on 1 or 2 threads"
    );
    let c = ensemble("c", "8", "2");
    assert_ne!(a["spread"], c["spread"], "another seed, other copies");
    // docs/physics.md s.7: 1e-12 grows to O(1) within a time of order one.
    let horizon = a["horizon"]
        .as_f64()
        .expect("the copies part before t = 1.5");
    assert!(horizon > 0.1 && horizon < 1.5, "horizon {horizon}");
    let spread = a["spread"].as_array().unwrap();
    let first = &spread[0];
    assert_eq!(first["t"], 0.0);
    assert!(
        first["unit_strain"].as_f64().unwrap() <= 2e-13,
        "1e-12 of 0.1 at most"
    );
    // Before the horizon the copies' unit strains and end displacements
    // agree to within 1e-3.
    for s in spread.iter().filter(|s| s["t"].as_f64().unwrap() < horizon) {
        assert!(s["unit_strain"].as_f64().unwrap() <= 1e-3);
        assert!(s["right_end"].as_f64().unwrap() <= 1e-3);
    }
    let rows = std::fs::read_to_string(dir.path().join("a/ensemble.csv")).unwrap();
    assert_eq!(rows.lines().count(), spread.len() + 1);
}

#[test]
fn ensembles_are_refused_where_they_do_not_apply() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for (scene, extra) in [
        ("mechanism_impacting.json", vec!["--ensemble", "3"]),
        ("chain_release_free_end.json", vec!["--ensemble", "1"]),
        (
            "chain_release_free_end.json",
            vec!["--ensemble", "3", "--perturb", "2"],
        ),
        (
            "chain_release_free_end.json",
            vec!["--ensemble", "3", "--method", "dopri5"],
        ),
        ("chain_release_free_end.json", vec!["--perturb", "1e-9"]),
    ] {
        let o = run(&models(scene), &out, &extra);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{scene} {extra:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
}
