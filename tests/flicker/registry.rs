//! A kind of scene from outside the crate (the ball of
//! `examples/registered_ball`) registered beside the built-in models and
//! taken by `check`, `run` and `sweep` through the scene-model interface,
//! with its bounces checked against the closed form of a dropped ball.

use clap::Parser;
use flicker::cli::{Cli, dispatch, exit::Code};
use flicker::scene::Registry;

#[path = "../../examples/registered_ball/main.rs"]
mod registered_ball;

fn example(file: &str) -> String {
    format!(
        "{}/examples/registered_ball/{file}",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn flicker(registry: &Registry, args: &[&str]) -> Code {
    let cli = Cli::try_parse_from(std::iter::once("flicker").chain(args.iter().copied())).unwrap();
    match dispatch(cli, registry) {
        Ok(code) => code,
        Err(failure) => failure.code,
    }
}

/// Time of the first bounce and the Zeno point of a ball dropped from rest
/// at `h` with restitution `e`: `t1 = sqrt(2 h / g)`, and the bounce
/// flights `2 e^k v1 / g` sum to `t1 (1 + e) / (1 - e)`.
fn closed_form(h: f64, e: f64) -> (f64, f64) {
    let t1 = (2.0 * h / 9.81f64).sqrt();
    (t1, t1 * (1.0 + e) / (1.0 - e))
}

#[test]
fn a_registered_model_runs_through_check_run_and_sweep() {
    let registry = registered_ball::registry();
    assert_eq!(
        flicker(&registry, &["check", &example("ball.json")]),
        Code::Ok
    );

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ball");
    let code = flicker(
        &registry,
        &[
            "run",
            &example("ball.json"),
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ],
    );
    // The bounces pile up (zeno) and the ball settles: exit 0.
    assert_eq!(code, Code::Ok);
    let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    let events: Vec<serde_json::Value> = log
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let (t1, zeno) = closed_form(1.0, 0.8);
    // Exact flights: the first bounce to round-off, and the bounce k at
    // t1 + 2 t1 (e + ... + e^k), each a few ulps.
    assert!((events[0]["t"].as_f64().unwrap() - t1).abs() < 1e-15);
    for (k, event) in events.iter().take(20).enumerate() {
        let exact = t1 + 2.0 * t1 * (1..=k).map(|j| 0.8f64.powi(j as i32)).sum::<f64>();
        assert!(
            (event["t"].as_f64().unwrap() - exact).abs() < 1e-13,
            "bounce {k}"
        );
    }
    // It settles at the Zeno point, to the run's time resolution.
    let settle = events.iter().find(|e| e["guard"] == "settle").unwrap();
    assert!((settle["t"].as_f64().unwrap() - zeno).abs() < 1e-9);

    let csv = dir.path().join("sweep.csv");
    let code = flicker(
        &registry,
        &[
            "sweep",
            &example("ball_sweep.json"),
            "--out",
            csv.to_str().unwrap(),
        ],
    );
    assert_eq!(code, Code::Ok);
    let mut reader = csv::Reader::from_path(&csv).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 20, "5 restitutions x 4 heights");
    for row in &rows {
        let (e, h): (f64, f64) = (row[1].parse().unwrap(), row[2].parse().unwrap());
        let first: f64 = row[5].parse().unwrap();
        let (t1, zeno) = closed_form(h, e);
        assert!((first - t1).abs() < 1e-15, "{row:?}");
        if zeno < 10.0 {
            // Piled up before t_end = 10, then settled.
            assert!(row[3].starts_with("zeno"), "{row:?}");
        } else {
            // Still bouncing at t_end: every bounce t1 + 2 t1 (e + ... + e^k)
            // up to it, counted.
            let bounces = (0..)
                .map(|k| t1 + 2.0 * t1 * (1..=k).map(|j| e.powi(j)).sum::<f64>())
                .take_while(|t| *t <= 10.0)
                .count();
            assert_eq!(&row[3], "completed", "{row:?}");
            assert_eq!(row[4].parse::<usize>().unwrap(), bounces, "{row:?}");
        }
    }
}

#[test]
fn the_built_in_registry_refuses_the_unregistered_model_naming_the_known_ones() {
    let result =
        flicker::scene::Registry::builtin().load(std::path::Path::new(&example("ball.json")));
    let error = result.unwrap_err().to_string();
    assert!(
        error.contains("unknown model \"ball\"") && error.contains("\"mechanism\""),
        "{error}"
    );
    // And a registry that knows the ball still knows the rest.
    let registry = registered_ball::registry();
    let mechanism = format!(
        "{}/models/mechanism_impacting.json",
        env!("CARGO_MANIFEST_DIR")
    );
    assert!(registry.load(std::path::Path::new(&mechanism)).is_ok());
}

#[test]
fn the_registered_models_schema_joins_the_scene_schema() {
    let schema = registered_ball::registry().schema().unwrap();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let ball: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(example("ball.json")).unwrap()).unwrap();
    assert!(validator.is_valid(&ball));
    // A restitution of one never settles: the schema refuses it, as does
    // the validator (exit 2).
    let mut bouncy = ball.clone();
    bouncy["restitution"] = 1.0.into();
    assert!(!validator.is_valid(&bouncy));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bouncy.json");
    std::fs::write(&path, bouncy.to_string()).unwrap();
    assert_eq!(
        flicker(
            &registered_ball::registry(),
            &["check", path.to_str().unwrap()]
        ),
        Code::BadInput
    );
    // The built-in models' scenes still pass it.
    let mechanism: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(format!(
            "{}/models/mechanism_impacting.json",
            env!("CARGO_MANIFEST_DIR")
        ))
        .unwrap(),
    )
    .unwrap();
    assert!(validator.is_valid(&mechanism));
}
