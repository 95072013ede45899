//! Messages that misled a new user, each mended and pinned by a test that
//! fails on the old text: a forced flow refused by Stormer-Verlet for its
//! velocity, a step collapse from the run's own settings blamed on the
//! flow's Jacobian, a graze dated at the start of the step that found it,
//! a constant `sign()` taken as a switching surface, and a transition that
//! can never fire passed in silence.

use std::process::Output;

use serde_json::{Value, json};

use crate::automata::automaton;
use crate::support::flicker;

/// `flicker` with `args`, the scene (a path, or a scene written to a file
/// of its own) first after the subcommand.
fn with_scene(command: &str, scene: &Value, args: &[&str]) -> Output {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let out = dir.path().join("out");
    let mut all = vec![
        command,
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    if command != "run" {
        all.truncate(2);
    }
    all.extend_from_slice(args);
    flicker(&all)
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn stormer_verlet_refuses_a_forced_flow_for_reading_the_time() {
    let forced = flicker(&[
        "run",
        &automaton("impact_oscillator.json"),
        "--method",
        "verlet",
        "--step",
        "0.01",
    ]);
    assert_eq!(forced.status.code(), Some(2));
    let said = stderr(&forced);
    assert!(said.contains("reads the time t"), "{said}");
    assert!(!said.contains("velocity"), "{said}");
    // A damped one is refused for its velocity.
    let damped = json!({"model": "automaton", "states": ["x", "v"], "initial": {"x": 1.0, "v": 0.0},
        "modes": {"m": {"flow": {"x": "v", "v": "-x - 0.1 * v"}}}, "t_end": 1.0});
    let refused = with_scene("run", &damped, &["--method", "verlet", "--step", "0.01"]);
    assert_eq!(refused.status.code(), Some(2));
    assert!(
        stderr(&refused).contains("independent of v"),
        "{}",
        stderr(&refused)
    );
}

#[test]
fn a_step_collapse_from_the_runs_settings_names_the_setting() {
    let oscillator = automaton("impact_oscillator.json");
    let far = flicker(&["run", &oscillator, "--quiet", "--t-end", "1e15"]);
    let said = stderr(&far);
    assert!(
        said.contains("t_end = 1e15 resolves times only to"),
        "{said}"
    );
    assert!(!said.contains("per unit of"), "{said}");
    for method in ["dopri5", "dop853"] {
        let tight = flicker(&[
            "run",
            &oscillator,
            "--quiet",
            "--method",
            method,
            "--rtol",
            "1e-30",
            "--atol",
            "1e-30",
        ]);
        let said = stderr(&tight);
        assert!(
            said.contains("ask for less error than a step's rounding"),
            "{method}: {said}"
        );
        assert!(!said.contains("per unit of"), "{method}: {said}");
    }
}

/// `x'' = -x` from `x = 1` comes within 1e-12 of the floor `x = -1` at
/// `t = pi`, closer than a method at rtol 1e-6 can tell: the run stops and
/// dates the graze there, not at the start of the step that found it.
#[test]
fn a_graze_is_dated_where_it_touches() {
    let scene = json!({"model": "automaton", "states": ["x", "v"], "initial": {"x": 1.0, "v": 0.0},
        "modes": {"m": {"flow": {"x": "v", "v": "-x"},
            "transitions": [{"name": "floor", "guard": "x + 1 + 1e-12", "direction": "falling",
                             "barrier": true, "reset": {"v": "-v"}}]}},
        "t_end": 5.0});
    for method in ["dopri5", "dop853", "taylor"] {
        let done = with_scene(
            "run",
            &scene,
            &[
                "--quiet", "--method", method, "--rtol", "1e-6", "--atol", "1e-6",
            ],
        );
        let said = stderr(&done);
        let at = said
            .split("grazes zero at t = ")
            .nth(1)
            .and_then(|rest| rest.split(':').next())
            .and_then(|t| t.parse::<f64>().ok())
            .unwrap_or_else(|| panic!("{method}: {said}"));
        assert!((at - std::f64::consts::PI).abs() < 1e-4, "{method}: {said}");
    }
}

#[test]
fn a_constant_sign_is_refused_as_a_constant_guard_is() {
    let scene = json!({"model": "automaton", "parameters": {"vb": 0.5}, "states": ["x"],
        "initial": {"x": 1.0}, "modes": {"m": {"flow": {"x": "-sign(vb)"}}}, "t_end": 1.0});
    let done = with_scene("check", &scene, &[]);
    assert_eq!(done.status.code(), Some(2));
    let said = stderr(&done);
    assert!(said.contains("modes.m.flow.x"), "{said}");
    assert!(
        said.contains("`sign(vb)` changes with neither the state nor the time"),
        "{said}"
    );
}

#[test]
fn a_transition_that_can_never_fire_is_refused() {
    let transition = |name: &str, add: &str| json!({"name": name, "guard": "x - 0.5", "reset": {"n": format!("n + {add}")}, "to": "b"});
    let scene = |first: Value, second: Value| {
        json!({"model": "automaton", "states": ["x", "n"], "initial": {"x": 0.0, "n": 0},
            "initial_mode": "a",
            "modes": {"a": {"flow": {"x": "1", "n": "0"}, "transitions": [first, second]},
                      "b": {"flow": {"x": "1", "n": "0"}}},
            "t_end": 2.0})
    };
    let copy = scene(transition("first", "1"), transition("second", "10"));
    let done = with_scene("check", &copy, &[]);
    assert_eq!(done.status.code(), Some(2));
    let said = stderr(&done);
    assert!(said.contains("modes.a.transitions"), "{said}");
    assert!(said.contains("`second` can never fire"), "{said}");
    // With a higher priority the second fires first, and the first never.
    let mut preferred = transition("second", "10");
    preferred["priority"] = json!(1);
    let done = with_scene("check", &scene(transition("first", "1"), preferred), &[]);
    assert!(
        stderr(&done).contains("`first` can never fire"),
        "{}",
        stderr(&done)
    );
    // A rising copy of an either-way guard is covered too; one the other
    // way of a one-way guard is not.
    let mut rising = transition("first", "1");
    rising["direction"] = json!("rising");
    let mut falling = transition("second", "10");
    falling["direction"] = json!("falling");
    let done = with_scene("check", &scene(rising, falling), &[]);
    assert_eq!(done.status.code(), Some(0), "{}", stderr(&done));
}
