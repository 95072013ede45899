//! Rough edges a new user met, each pinned by a test that failed on the
//! old behaviour: help that lists every method, an energy audit that
//! starts from zero energy, a reference run that fails (a run that cannot
//! be trusted, exit 3, not bad input), an initial value that names a state,
//! and `plot phase --t-end`.

use serde_json::json;

use std::process::Output;

use serde_json::Value;

use crate::automata::{f, run_value};
use crate::support::flicker;

/// `flicker check` of `scene`, written to a file of its own.
fn check(scene: &Value) -> Output {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    flicker(&["check", path.to_str().unwrap()])
}

/// `flicker run --help` names every method a scene's `solver` takes, and
/// an unknown one is refused with the list.
#[test]
fn run_help_lists_every_method() {
    let help = flicker(&["run", "--help"]);
    let text = String::from_utf8_lossy(&help.stdout);
    for method in flicker::engine::step::method::NAMES {
        assert!(text.contains(method), "{method} missing from:\n{text}");
    }
    let bad = flicker(&["run", "scene.json", "--method", "rk4"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("taylor"));
}

/// A forced oscillator from rest, `x'' + x = sin(2 t)`, energy `(x'^2 +
/// x^2) / 2`: it starts at zero, so its error is measured against the
/// largest energy the run meets, and the forcing's whole work is an error
/// of exactly 1 of it (it was 1.6e308, relative to zero).
#[test]
fn an_energy_that_starts_at_zero_is_measured_against_its_largest() {
    let scene = json!({
        "model": "automaton",
        "states": ["x", "v"],
        "initial": {"x": 0.0, "v": 0.0},
        "modes": {"m": {"flow": {"x": "v", "v": "-x + sin(2 * t)"}}},
        "energy": "0.5 * v^2 + 0.5 * x^2",
        "t_end": 6.0
    });
    let (summary, _) = run_value(&scene, &[]);
    assert_eq!(summary["status"], "completed", "{summary}");
    let error = f(&summary["max_energy_error"]);
    assert!((error - 1.0).abs() <= 1e-12, "{summary}");
}

/// `flicker compare` on a scene whose reference run fails (`x' = x^2`
/// from 1 blows up at t = 1) exits 3, saying so.
#[test]
fn a_failed_reference_is_an_untrusted_run_not_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blow_up.json");
    let scene = json!({
        "model": "automaton",
        "states": ["x"],
        "initial": {"x": 1.0},
        "modes": {"m": {"flow": {"x": "x^2"}}},
        "t_end": 2.0
    });
    std::fs::write(&path, scene.to_string()).unwrap();
    let out = dir.path().join("o");
    let done = flicker(&[
        "compare",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&done.stderr);
    assert_eq!(done.status.code(), Some(3), "{said}");
    assert!(said.contains("the reference run"), "{said}");
}

/// An initial value that reads a state says so, and suggests no
/// parameter with a name one letter away (`w` for `x`).
#[test]
fn an_initial_value_naming_a_state_is_told_so_without_a_near_miss() {
    let scene = json!({
        "model": "automaton",
        "parameters": {"w": 2.0},
        "states": ["x", "v"],
        "initial": {"x": 1.0, "v": "w * x"},
        "modes": {"m": {"flow": {"x": "v", "v": "-w^2 * x"}}},
        "t_end": 1.0
    });
    let done = check(&scene);
    let said = String::from_utf8_lossy(&done.stderr);
    assert_eq!(done.status.code(), Some(2), "{said}");
    assert!(said.contains("initial.v"), "{said}");
    assert!(
        said.contains("`x` is a state: an initial value may use parameters only"),
        "{said}"
    );
    assert!(!said.contains("did you mean"), "{said}");
}

/// `plot phase SCENE --t-end T` draws the run to T, not to the scene's end.
#[test]
fn plot_phase_takes_t_end() {
    let dir = tempfile::tempdir().unwrap();
    let picture = dir.path().join("p.svg");
    let scene = crate::automata::automaton("bouncing_ball.json");
    let done = flicker(&[
        "plot",
        "phase",
        &scene,
        "--x",
        "y",
        "--y",
        "v",
        "--t-end",
        "0.25",
        "--out",
        picture.to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&done.stdout);
    assert_eq!(done.status.code(), Some(0), "{said}");
    assert!(said.contains("at t = 0.25 with 0 events"), "{said}");
    let bad = flicker(&[
        "plot",
        "phase",
        &scene,
        "--x",
        "y",
        "--y",
        "v",
        "--t-end",
        "-1",
        "--out",
        picture.to_str().unwrap(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("--t-end"));
}

/// `check` names the guard that reads `min` (in another mode than the
/// non-affine flow), not "a mode's flow".
#[test]
fn check_names_the_expression_that_has_no_taylor_series() {
    let scene = json!({
        "model": "automaton",
        "states": ["x", "v"],
        "initial": {"x": 1.0, "v": 0.0},
        "initial_mode": "a",
        "modes": {
            "a": {"flow": {"x": "v", "v": "-x^3"},
                  "transitions": [{"name": "switch", "guard": "x", "direction": "falling", "to": "b"}]},
            "b": {"flow": {"x": "v", "v": "-x"},
                  "transitions": [{"name": "corner", "guard": "min(x, v) + 2", "direction": "falling"}]}},
        "t_end": 1.0
    });
    let done = check(&scene);
    let said = String::from_utf8_lossy(&done.stdout);
    assert_eq!(done.status.code(), Some(0), "{said}");
    assert!(
        said.contains("the guard `corner` of mode `b` reads abs, min or max"),
        "{said}"
    );
}

/// A guard that does not change (`x - x`, a number), or whose form keeps
/// one sign (`x^2 + 1`), can never fire: it is refused, naming the field,
/// where it was accepted silently.
#[test]
fn a_guard_that_never_changes_is_refused() {
    for guard in [
        "x - x",
        "2",
        "k * (v - v) + 1",
        "x^2 + 1",
        "-(v^2) - exp(x)",
    ] {
        let scene = json!({
            "model": "automaton",
            "parameters": {"k": 3.0},
            "states": ["x", "v"],
            "initial": {"x": 1.0, "v": 0.0},
            "modes": {"m": {"flow": {"x": "v", "v": "-x"},
                "transitions": [{"name": "never", "guard": guard}]}},
            "t_end": 1.0
        });
        let done = check(&scene);
        let said = String::from_utf8_lossy(&done.stderr);
        assert_eq!(done.status.code(), Some(2), "{guard}: {said}");
        assert!(
            said.contains("modes.m.transitions[0].guard") && said.contains("never crosses zero"),
            "{guard}: {said}"
        );
    }
}

/// A ball written as an automaton whose mode names a `rest`: at its Zeno
/// point `t* = sqrt(2 h / g) (1 + e) / (1 - e)` it settles into the
/// resting mode with the state the rest gives, and rests to t_end. Without
/// one, the stop says how to name one. A `rest` where it cannot apply
/// (a mode switched by sign(), or into one) is refused, naming the field.
#[test]
fn an_automaton_names_its_resting_mode_with_rest() {
    let (g, e, h) = (9.81f64, 0.8, 1.0f64);
    let ball = |rest: Option<serde_json::Value>| {
        let mut flight = json!({
            "flow": {"y": "v", "v": "-g"},
            "transitions": [{"name": "bounce", "guard": "y", "direction": "falling",
                             "barrier": true, "reset": {"v": "-e * v"}}]});
        if let Some(rest) = rest {
            flight["rest"] = rest;
        }
        json!({
            "model": "automaton",
            "parameters": {"g": g, "e": e},
            "states": ["y", "v"],
            "initial": {"y": h, "v": 0.0},
            "initial_mode": "flight",
            "modes": {"flight": flight, "resting": {}},
            "t_end": 6.0
        })
    };
    let zeno = (2.0 * h / g).sqrt() * (1.0 + e) / (1.0 - e);
    let (summary, events) = run_value(
        &ball(Some(
            json!({"to": "resting", "reset": {"y": "0", "v": "0"}}),
        )),
        &[],
    );
    let settle = events.last().unwrap();
    assert_eq!(settle["guard"], "settle", "{settle}");
    assert_eq!(settle["mode_after"], "resting");
    assert!(
        (f(&settle["t"]) - zeno).abs() < 1e-9,
        "{settle} against {zeno}"
    );
    assert_eq!(summary["t_reached"], 6.0);
    assert_eq!(summary["final_mode"], "resting");
    assert_eq!(summary["final_state"], json!({"y": 0.0, "v": 0.0}));
    assert!(
        summary["reason"]
            .as_str()
            .unwrap()
            .contains("settled into `resting`")
    );
    let (stopped, _) = run_value(&ball(None), &[]);
    assert_eq!(stopped["status"], "zeno");
    assert!(
        stopped["reason"]
            .as_str()
            .unwrap()
            .contains("names one with `rest`"),
        "{stopped}"
    );
    let mut bad = ball(Some(json!({"to": "floor"})));
    let done = check(&bad);
    assert_eq!(done.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&done.stderr).contains("modes.flight.rest.to"));
    bad = ball(Some(json!({"to": "resting"})));
    bad["modes"]["flight"]["flow"]["v"] = json!("-g - 0.1 * sign(v)");
    let done = check(&bad);
    assert_eq!(done.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&done.stderr).contains("modes.flight.rest"));
}

/// A guard that turns steep and then NaN (`sqrt(x) - 2` as `x` falls
/// through zero) is named by every method that stops on it; the linear
/// propagator blamed "the rate of `x`", which is constant.
#[test]
fn a_guard_that_breaks_down_is_named_by_every_method() {
    let scene = json!({
        "model": "automaton",
        "states": ["x"],
        "initial": {"x": 1.0},
        "modes": {"m": {"flow": {"x": "-1"},
            "transitions": [{"name": "root", "guard": "sqrt(x) - 2", "direction": "falling"}]}},
        "t_end": 3.0
    });
    for args in [&[][..], &["--method", "taylor"], &["--method", "dop853"]] {
        let (summary, _) = run_value(&scene, args);
        assert_eq!(summary["status"], "failed", "{args:?}: {summary}");
        let reason = summary["reason"].as_str().unwrap();
        assert!(
            reason.contains("guard `root`") && reason.contains("sqrt(x) - 2"),
            "{args:?}: {reason}"
        );
    }
}

/// `check` names an automaton's regime, as it does the mechanism's: forced
/// or autonomous, its impacts and markers, switching surfaces, whether
/// every flow is affine.
#[test]
fn check_names_an_automatons_regime() {
    for (file, regime) in [
        (
            "bouncing_ball.json",
            "regime: autonomous, impacting (`bounce`), every flow affine",
        ),
        (
            "vibrating_table.json",
            "regime: forced (reads the clock t), impacting (`impact`), every flow affine",
        ),
        (
            "stick_slip_belt.json",
            "regime: autonomous, impacting (`wall`), discontinuous (sign() in 1 mode(s): \
             Filippov sliding), nonlinear",
        ),
    ] {
        let done = flicker(&["check", &crate::automata::automaton(file)]);
        let said = String::from_utf8_lossy(&done.stdout);
        assert!(said.contains(regime), "{file}: {said}");
    }
}

/// A run that fails at an event (a reset that turns the state NaN) says it
/// failed at that event's time, with the state just before it; it said
/// the time its last step started, earlier than the event it named.
#[test]
fn a_run_that_fails_at_an_event_reached_that_event() {
    let scene = json!({
        "model": "automaton",
        "states": ["y", "v"],
        "initial": {"y": 1.0, "v": 0.0},
        "modes": {"m": {"flow": {"y": "v", "v": "-9.81"},
            "transitions": [{"name": "bounce", "guard": "y", "direction": "falling",
                             "barrier": true, "reset": {"v": "sqrt(v)"}}]}},
        "t_end": 3.0
    });
    let fall = (2.0f64 / 9.81).sqrt();
    for args in [&[][..], &["--method", "taylor"], &["--method", "dop853"]] {
        let (summary, _) = run_value(&scene, args);
        assert_eq!(summary["status"], "failed", "{args:?}: {summary}");
        let reason = summary["reason"].as_str().unwrap();
        let at: f64 = reason
            .split("event at t = ")
            .nth(1)
            .and_then(|s| s.split(' ').next())
            .and_then(|s| s.parse().ok())
            .unwrap_or_else(|| panic!("{reason}"));
        assert_eq!(f(&summary["t_reached"]), at, "{args:?}: {summary}");
        assert!((at - fall).abs() < 1e-9, "{args:?}: {at}");
        let v = f(&summary["final_state"]["v"]);
        assert!((v + 9.81 * fall).abs() < 1e-8, "{args:?}: {summary}");
    }
}
