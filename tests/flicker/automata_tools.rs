//! Every tool takes automata: `compare` and `stress` measure each method
//! against the exact propagator or Taylor's method at machine precision,
//! `--ensemble` perturbs the initial states, `plot phase SCENE` draws any
//! two states, and the Rust builder makes the same automaton as its file.
//! Each checked against the physics, not against flicker's own output.

use std::path::Path;

use serde_json::Value;

use crate::automata::{automaton, f};
use crate::support::{SvgChart, flicker, read_json};

/// `flicker compare` on the forced impact oscillator (affine in the state
/// and driven by `cos(w t)`, so the reference is the exact linear
/// propagator, the forcing's sine carried with the state): every completed
/// run's final error lies within its own stated bound plus the
/// reference's, Taylor's error falls with its tolerance, and every run has
/// the reference's 51 impacts.
#[test]
fn compare_measures_every_method_against_the_exact_propagator() {
    let dir = tempfile::tempdir().unwrap();
    let out = flicker(&[
        "compare",
        &automaton("impact_oscillator.json"),
        "--tolerances",
        "1e-6,1e-9,1e-12",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("reference: the exact linear propagator"),
        "{text}"
    );
    let mut reader = csv::Reader::from_path(dir.path().join("compare.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut taylor = Vec::new();
    let mut rows = 0;
    for record in reader.records() {
        let r = record.unwrap();
        rows += 1;
        assert_eq!(&r[col("status")], "completed", "{r:?}");
        assert_eq!(&r[col("events")], "51", "{r:?}");
        let (error, bound) = (
            r[col("final_error")].parse::<f64>().unwrap(),
            r[col("error_bound")].parse::<f64>().unwrap(),
        );
        // The reference's own bound at machine precision is far below
        // every setting's: 1e-12 of the state covers it.
        assert!(error <= bound + 1e-12, "{r:?}");
        if &r[col("method")] == "taylor" {
            taylor.push(error);
        }
    }
    assert_eq!(
        rows, 10,
        "the linear propagator, and taylor, dopri5 and dop853 at three tolerances"
    );
    assert!(taylor[0] > taylor[1] && taylor[1] > taylor[2], "{taylor:?}");
}

/// `flicker stress models/automata`: every method of every bundled
/// automaton either passes within its own bounds or says why it cannot be
/// trusted; none drifts beyond its bounds or gives other events unasked.
#[test]
fn stress_over_the_bundled_automata_finds_no_quiet_wrong_answer() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/automata");
    let out = flicker(&["stress", dir.to_str().unwrap(), "--markdown"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let table = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<&str> = table
        .lines()
        .filter(|l| l.starts_with("| ") && !l.starts_with("| case"))
        .collect();
    assert!(rows.len() >= 25, "{table}");
    for row in &rows {
        assert!(!row.contains("DRIFTED") && !row.contains("WRONG"), "{row}");
    }
    let passed = rows.iter().filter(|r| r.contains("| passed |")).count();
    assert!(passed >= 20, "{passed} passed:\n{table}");
    // Every automaton passes with its default method.
    for case in [
        "bouncing_ball",
        "chain4",
        "impact_oscillator",
        "mechanism",
        "mechanism_charts",
        "rocking_block",
        "rocking_block_linear",
    ] {
        assert!(
            rows.iter()
                .any(|r| r.starts_with(&format!("| {case} |")) && r.contains("| passed |")),
            "{case}:\n{table}"
        );
    }
}

/// `flicker run --ensemble` of the strain mechanism (`mechanism.json`, eta
/// 1.2, from strain 0.5 at rest), perturbation `p`: each copy starts within
/// `0.5 p` of the scene in strain and rate, so energies differ by at most
/// `0.3 p` (`dH = (eps0 + 1 - eta) d eps0`), the impact period by
/// `|dT/dH| 0.3 p` per impact (`dT/dH = (2/omega) c / ((s^2 + c^2) s)`,
/// `s = sqrt(2 H)`, `c = 1 - eta`), and the strain by at most the largest
/// rate `omega A = 0.3` times the accumulated shift: the spread grows with
/// time under `0.3 * (t / T) |dT/dH| 0.3 p` (plus the starting `p`), the
/// rate's as well (the largest acceleration is 0.3 too), and the horizon,
/// where a spread first passes 1e-3 of its state's scale (the rate's 0.3),
/// comes no earlier than that line allows. The same seed gives the same ensemble on
/// one thread or two.
#[test]
fn an_automaton_ensemble_drifts_as_the_period_depends_on_the_energy() {
    let p = 1e-5;
    let (h, eta, omega) = (0.025_f64, 1.2_f64, 1.0_f64);
    let (s, c) = ((2.0 * h).sqrt(), 1.0 - eta);
    let period = 2.0 / omega * s.atan2(c);
    let dt_dh = (2.0 / omega * c / ((s * s + c * c) * s)).abs();
    let slope = 0.3 * dt_dh * 0.3 * p / period;
    let dir = tempfile::tempdir().unwrap();
    let ensemble = |name: &str, threads: &str| -> Value {
        let out = dir.path().join(name);
        let o = crate::support::command()
            .args([
                "run",
                &automaton("mechanism.json"),
                "--out",
                out.to_str().unwrap(),
            ])
            .args([
                "--quiet",
                "--no-events",
                "--ensemble",
                "8",
                "--perturb",
                &p.to_string(),
            ])
            .args(["--seed", "3"])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let csv = std::fs::read_to_string(out.join("ensemble.csv")).unwrap();
        assert!(csv.starts_with("t,strain,strain_rate\n"), "{csv}");
        read_json(&out.join("summary.json"))["ensemble"].clone()
    };
    let one = ensemble("one", "1");
    assert_eq!(one, ensemble("two", "2"));
    let spread = one["spread"].as_array().unwrap();
    assert_eq!(spread.len(), 101);
    // The rate's spread grows as fast: the largest acceleration
    // omega^2 A is 0.3 too.
    for row in spread {
        let t = f(&row["t"]);
        for state in ["strain", "strain_rate"] {
            let d = f(&row[state]);
            assert!(
                d <= slope * t + 2.0 * p,
                "t {t}: {state} spread {d} above {}",
                slope * t
            );
        }
    }
    let first = f(&spread[0]["strain"]);
    let last = f(&spread[100]["strain"]);
    assert!(first <= p && last > 10.0 * first, "{first} -> {last}");
    // The scales are the largest magnitudes: the apex strain 0.5, the
    // impact speed 0.3.
    let scale = &one["scale"];
    assert!((f(&scale["strain"]) - 0.5).abs() < 2.0 * p, "{scale}");
    assert!((f(&scale["strain_rate"]) - 0.3).abs() < 2.0 * p, "{scale}");
    let horizon = f(&one["horizon"]);
    let earliest = (1e-3 * 0.3 - 2.0 * p) / slope;
    assert!(
        horizon >= earliest && horizon < 1000.0,
        "horizon {horizon}, earliest {earliest}"
    );
}

/// `flicker plot phase bouncing_ball.json --x y --y v`: each flight is
/// drawn on its own parabola `v^2 + 2 g y = const` (to the picture's
/// resolution), under the drop's `2 g h`, and each bounce as a jump that
/// keeps the height; a flight per bounce and one more.
#[test]
fn a_phase_plane_of_any_two_states_follows_the_flights_and_jumps() {
    let dir = tempfile::tempdir().unwrap();
    let picture = dir.path().join("ball.svg");
    let out = flicker(&[
        "plot",
        "phase",
        &automaton("bouncing_ball.json"),
        "--x",
        "y",
        "--y",
        "v",
        "--out",
        picture.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    let events: usize = said
        .split(" with ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{said}"));
    let chart = SvgChart::read(&picture);
    let (dy, dv) = chart.pixel_size();
    let g = 9.81;
    let flights = chart.polylines("#1F77B4", "2");
    assert_eq!(flights.len(), events + 1, "{said}");
    for (k, flight) in flights.iter().enumerate() {
        let levels: Vec<f64> = flight
            .iter()
            .map(|p| {
                let (y, v) = chart.value(*p);
                v * v + 2.0 * g * y
            })
            .collect();
        let (lo, hi) = levels
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), l| {
                (a.min(*l), b.max(*l))
            });
        // A pixel in y moves the level by 2 g dy, in v by about 2 |v| dv.
        let slack = 2.0 * g * dy + 2.0 * (2.0 * g).sqrt() * dv;
        assert!(hi - lo <= 2.0 * slack, "flight {k}: levels {lo}..{hi}");
        assert!(hi <= 2.0 * g * 1.0 + slack, "flight {k} above the drop");
    }
    // A bounce keeps the height and turns the speed up: vertical jumps
    // (dashed segments drawn width 1) at y = 0.
    let jumps = chart.polylines("#1F77B4", "1");
    assert!(!jumps.is_empty());
    for segment in &jumps {
        for p in segment {
            let (y, _) = chart.value(*p);
            assert!(y.abs() <= 2.0 * dy, "a jump away from the floor: y {y}");
        }
    }
    let bad = flicker(&[
        "plot",
        "phase",
        &automaton("bouncing_ball.json"),
        "--x",
        "height",
        "--y",
        "v",
        "--out",
        picture.to_str().unwrap(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no state `height` (its states: y, v)"));
}

/// The Rust builder makes the automaton its file makes: the same events,
/// bit for bit, for the bouncing ball; and a builder error names the field
/// as the file's would.
#[test]
fn the_builder_makes_the_same_automaton_as_the_file() {
    use flicker::engine::Limits;
    use flicker::models::automaton::{AutomatonBuilder, TransitionBuilder};
    let built = AutomatonBuilder::new()
        .parameter("g", 9.81)
        .parameter("e", 0.8)
        .state("y", 1.0)
        .state("v", 0.0)
        .mode(
            "flight",
            [("y", "v"), ("v", "-g")],
            [TransitionBuilder::new("bounce", "y")
                .falling()
                .barrier()
                .reset("v", "-e * v")],
        )
        .energy("v^2 / 2 + g * y");
    let scene = built.scene(10.0).unwrap();
    let mut events = flicker::engine::Recorder::default();
    let report = scene.run(&Limits::default(), &mut events).unwrap();
    let file = flicker::scene::Registry::builtin()
        .load(Path::new(&automaton("bouncing_ball.json")))
        .unwrap();
    let mut expected = flicker::engine::Recorder::default();
    let from_file = file.run(&Limits::default(), &mut expected).unwrap();
    assert_eq!(events.events, expected.events);
    assert_eq!(report.outcome.final_state, from_file.outcome.final_state);
    // The first bounce of a ball dropped from 1 m under 9.81.
    assert!((events.events[0].t - (2.0 / 9.81_f64).sqrt()).abs() < 1e-15);
    let error = AutomatonBuilder::new()
        .state("y", 1.0)
        .mode("flight", [("y", "vv")], [])
        .build()
        .unwrap_err();
    assert_eq!(error.field.as_deref(), Some("modes.flight.flow.y"));
    assert!(error.reason.contains("`vv`"), "{}", error.reason);
}

/// `flicker events --csv` of an automaton's log: each state before and
/// after each event, so that the bounces read off as the reset says, the
/// height kept and the speed turned up by `e = 0.8`.
#[test]
fn the_event_table_of_an_automaton_has_its_states_before_and_after() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let run = flicker(&[
        "run",
        &automaton("bouncing_ball.json"),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(run.status.code(), Some(0));
    let table = flicker(&[
        "events",
        out.join("events.jsonl").to_str().unwrap(),
        "--csv",
    ]);
    assert_eq!(table.status.code(), Some(0));
    let mut reader = csv::Reader::from_reader(table.stdout.as_slice());
    let header: Vec<String> = reader.headers().unwrap().iter().map(String::from).collect();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (y0, v0, y1, v1) = (
        col("before.y"),
        col("before.v"),
        col("after.y"),
        col("after.v"),
    );
    let mut rows = 0;
    for record in reader.records() {
        let r = record.unwrap();
        let x = |i: usize| r[i].parse::<f64>().unwrap();
        assert_eq!(&r[col("mode_before")], "flight");
        assert_eq!(x(y1), x(y0));
        assert_eq!(x(v1), -0.8 * x(v0));
        rows += 1;
    }
    assert!(rows > 30, "{rows} bounces");
}

/// Only a transition that resets nothing and stays in its mode marks a
/// passage (its saltation the identity, see `HybridModel::marks_only`): a
/// reset, even of one state to itself, or a change of mode, does not.
#[test]
fn only_a_transition_that_changes_nothing_marks_a_passage() {
    use flicker::engine::HybridModel;
    use flicker::models::automaton::{AutomatonBuilder, TransitionBuilder};
    let model = AutomatonBuilder::new()
        .state("x", 1.0)
        .state("v", 0.0)
        .mode(
            "a",
            [("x", "v"), ("v", "-x")],
            [
                TransitionBuilder::new("section", "x").rising(),
                TransitionBuilder::new("kept", "x").reset("v", "v"),
                TransitionBuilder::new("away", "v").to("b"),
                TransitionBuilder::new("bounce", "x")
                    .falling()
                    .barrier()
                    .reset("v", "-v"),
            ],
        )
        .mode(
            "b",
            [("x", "v"), ("v", "-x")],
            [TransitionBuilder::new("back", "v").to("a")],
        )
        .initial_mode("a")
        .build()
        .expect("the model compiles");
    let marks: Vec<bool> = (0..4).map(|g| model.marks_only(0, g)).collect();
    assert_eq!(marks, [true, false, false, false]);
    assert!(!model.marks_only(1, 0));
}
