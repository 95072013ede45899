//! Discontinuous flows (`sign()` in a flow) as Filippov defined them,
//! against closed forms written here, to 1e-12 in time and state by the
//! methods exact to round-off (the linear propagator where every region is
//! affine, Taylor's method), and within their own stated bounds by the
//! others:
//!
//! - dry friction on a spring, `x'' + x = -sign(x')` from `x = 12`, `x' =
//!   6`: turning points at `atan(6/13) + k pi`, sticking at `atan(6/13) + 7
//!   pi` with `x = 15 - sqrt(205)`, and resting there;
//! - relay feedback `x'' + 2 zeta x' + x = -sign(x')`: each half swing about
//!   `c = -sign(x')` takes `x` to `c - (x - c) q`, `q = exp(-zeta pi /
//!   sqrt(1 - zeta^2))`, until a turning point falls within `[-1, 1]`;
//! - a forced relay `x' = -sign(x) + A sin t`, `A = 2`: it slides on `x = 0`
//!   from its first arrival and leaves where `A sin t` reaches 1;
//!
//! and what has no answer says so: a repelling surface, two surfaces at
//! once, a surface that is not finite.

use serde_json::{Value, json};

use crate::automata::{automaton, f, run, run_value};

/// Each method's arguments: the exact ones (to 1e-12), then the others
/// (within their stated bounds).
pub const EXACT: [&[&str]; 2] = [&[], &["--method", "taylor"]];
pub const OTHERS: [&[&str]; 2] = [
    &["--method", "dop853", "--rtol", "1e-13", "--atol", "1e-13"],
    &["--method", "dopri5", "--rtol", "1e-12", "--atol", "1e-12"],
];

/// What a run by `args` is held to against a closed form, `(event time,
/// state)`: 1e-12 for the exact methods (the propagator, Taylor's at
/// machine precision), the run's own stated bounds for the others.
pub fn allowance(args: &[&str], summary: &Value) -> (f64, f64) {
    if EXACT.contains(&args) {
        (1e-12, 1e-12)
    } else {
        (f(&summary["event_time_bound"]), f(&summary["error_bound"]))
    }
}

/// Events `(t, guard, mode after)` of a run against the closed form's,
/// each time within `tolerance`.
pub fn events_match(events: &[Value], want: &[(f64, &str, &str)], tolerance: f64, what: &str) {
    let got: Vec<(f64, &str, &str)> = events
        .iter()
        .map(|e| {
            (
                f(&e["t"]),
                e["guard"].as_str().unwrap(),
                e["mode_after"].as_str().unwrap(),
            )
        })
        .collect();
    assert_eq!(got.len(), want.len(), "{what}: {got:?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!((g.1, g.2), (w.1, w.2), "{what}: {got:?}");
        assert!(
            (g.0 - w.0).abs() <= tolerance,
            "{what}: {g:?} against {w:?}"
        );
    }
}

/// How many times the error a stated bound may be (see
/// `tests/flicker/conformance.rs`): the Runge-Kutta pairs' bounds carry
/// their embedded estimates, today up to some 1e4 times the error.
const LOOSENESS: f64 = 3e4;

/// A run by a method that states its bounds (one of [`OTHERS`]) is held
/// to them the other way too: each bound within [`LOOSENESS`] of the
/// error it bounds (event times against `want`, the final state against
/// `fin`), or of 16 ulps where the error is smaller.
pub fn tight(
    args: &[&str],
    summary: &Value,
    events: &[Value],
    want: &[(f64, &str, &str)],
    fin: &[(&str, f64)],
) {
    if EXACT.contains(&args) {
        return;
    }
    let (time, state) = allowance(args, summary);
    let t_end = f(&summary["t_reached"]).abs().max(1.0);
    let time_error = (events.iter().zip(want))
        .map(|(e, w)| (f(&e["t"]) - w.0).abs())
        .fold(16.0 * f64::EPSILON * t_end, f64::max);
    let state_error = (fin.iter())
        .map(|(name, value)| (f(&summary["final_state"][name]) - value).abs())
        .fold(16.0 * f64::EPSILON, f64::max);
    assert!(
        time <= LOOSENESS * time_error,
        "{args:?}: event times {time_error:.2e} off, their bound {time:.2e}"
    );
    assert!(
        state <= LOOSENESS * state_error,
        "{args:?}: final state {state_error:.2e} off, its bound {state:.2e}"
    );
}

#[test]
fn the_friction_oscillator_turns_and_sticks_where_its_closed_form_does() {
    let first = (6.0f64 / 13.0).atan();
    let pi = std::f64::consts::PI;
    let mut want: Vec<(f64, &str, &str)> = (0..7)
        .map(|k| {
            let into = if k % 2 == 0 {
                "block[v<0]"
            } else {
                "block[v>0]"
            };
            (first + k as f64 * pi, "cross:v", into)
        })
        .collect();
    want.push((first + 7.0 * pi, "slide:v", "block[v=0]"));
    let rest = 15.0 - 205f64.sqrt();
    for args in EXACT.iter().chain(&OTHERS) {
        let (summary, events) = run(&automaton("friction_oscillator.json"), args);
        let what = format!("{args:?}");
        let (time, state) = allowance(args, &summary);
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        events_match(&events, &want, time, &what);
        // It rests there, exactly on the surface.
        assert!(
            (f(&summary["final_state"]["x"]) - rest).abs() <= state,
            "{what}: {summary}"
        );
        assert_eq!(f(&summary["final_state"]["v"]), 0.0, "{what}");
        assert_eq!(summary["final_mode"], "block[v=0]");
        tight(args, &summary, &events, &want, &[("x", rest)]);
        assert_eq!(summary["events_by_guard"]["slide:v"], 1);
    }
}

#[test]
fn relay_feedback_sticks_at_the_amplitude_its_half_swings_give() {
    let zeta = 0.05f64;
    let damped = (1.0 - zeta * zeta).sqrt();
    let (q, half) = (
        (-zeta * std::f64::consts::PI / damped).exp(),
        std::f64::consts::PI / damped,
    );
    // Turning points from x = 5 at rest: about c = +1 going down, -1 up.
    let (mut x, mut want, mut k) = (5.0f64, Vec::new(), 0);
    while x.abs() > 1.0 {
        let c = x.signum();
        x = c - (x - c) * q;
        k += 1;
        let t = k as f64 * half;
        if x.abs() > 1.0 {
            let into = if x > 0.0 { "relay[v<0]" } else { "relay[v>0]" };
            want.push((t, "cross:v", into));
        } else {
            want.push((t, "slide:v", "relay[v=0]"));
        }
    }
    for args in EXACT.iter().chain(&OTHERS) {
        let (summary, events) = run(&automaton("relay_feedback.json"), args);
        let what = format!("{args:?}");
        let (time, state) = allowance(args, &summary);
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        events_match(&events, &want, time, &what);
        assert!(
            (f(&summary["final_state"]["x"]) - x).abs() <= state,
            "{what}"
        );
        assert_eq!(f(&summary["final_state"]["v"]), 0.0, "{what}");
        tight(args, &summary, &events, &want, &[("x", x)]);
    }
}

/// The forced relay's events by its closed form: in each region `x` is
/// `x0 - s (t - t0) + A (cos t0 - cos t)`, its next zero found on a fine
/// grid and bisected; on `x = 0` it slides while `|A sin t| < 1`, and
/// leaves where `A sin t` reaches 1 (upwards) or -1 (downwards).
pub fn forced_relay(a: f64, x0: f64, t_end: f64) -> (Vec<(f64, &'static str, &'static str)>, f64) {
    let (mut t0, mut x, mut s) = (0.0f64, x0, x0.signum());
    let mut want = Vec::new();
    let zero_after = |t0: f64, x0: f64, s: f64| -> Option<f64> {
        let g = |t: f64| x0 - s * (t - t0) + a * (t0.cos() - t.cos());
        let grid = 1e-3;
        let mut lo = t0;
        while lo < t_end {
            let hi = lo + grid;
            if g(hi) * s <= 0.0 {
                let (mut l, mut h) = (lo, hi);
                for _ in 0..200 {
                    let m = 0.5 * (l + h);
                    if g(m) * s > 0.0 { l = m } else { h = m }
                }
                return Some(h);
            }
            lo = hi;
        }
        None
    };
    loop {
        let Some(t) = zero_after(t0, x, s) else {
            let xe = x - s * (t_end - t0) + a * (t0.cos() - t_end.cos());
            return (want, xe);
        };
        if t > t_end {
            let xe = x - s * (t_end - t0) + a * (t0.cos() - t_end.cos());
            return (want, xe);
        }
        let forcing = a * t.sin();
        if forcing.abs() < 1.0 {
            want.push((t, "slide:x", "relay[x=0]"));
            // Leaves where a sin t reaches +-1: the next such time.
            let leave = (0..)
                .map(|k| k as f64 * std::f64::consts::PI)
                .flat_map(|base| {
                    let r = (1.0 / a).asin();
                    [base + r, base + std::f64::consts::PI - r]
                })
                .find(|&l| l > t)
                .unwrap();
            if leave > t_end {
                return (want, 0.0);
            }
            let up = a * leave.sin() > 0.0;
            want.push((
                leave,
                "leave:x",
                if up { "relay[x>0]" } else { "relay[x<0]" },
            ));
            (t0, x, s) = (leave, 0.0, if up { 1.0 } else { -1.0 });
        } else {
            s = -s;
            want.push((
                t,
                "cross:x",
                if s > 0.0 { "relay[x>0]" } else { "relay[x<0]" },
            ));
            (t0, x) = (t, 0.0);
        }
    }
}

#[test]
fn a_forced_relay_slides_and_leaves_where_its_forcing_reaches_the_relay() {
    let (want, xe) = forced_relay(2.0, 0.1, 20.0);
    assert_eq!(want[0].1, "slide:x");
    assert!((want[1].0 - std::f64::consts::FRAC_PI_6).abs() < 1e-15);
    for args in [&["--method", "taylor"][..]].iter().chain(&OTHERS) {
        let (summary, events) = run(&automaton("forced_relay.json"), args);
        let what = format!("{args:?}");
        let (time, state) = allowance(args, &summary);
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        events_match(&events, &want, time, &what);
        assert!(
            (f(&summary["final_state"]["x"]) - xe).abs() <= state.max(1e-12),
            "{what}"
        );
        tight(args, &summary, &events, &want, &[("x", xe)]);
    }
}

/// Sliding on surfaces that are no state, where Filippov's weight `a =
/// L- / (L- - L+)` alone keeps the state on the surface (nothing holds a
/// component there), against closed forms:
///
/// - `x' = 0.5 - sign(x + y)`, `y' = 0.1 - 0.5 sign(x + y)` from `(1, 0.5)`:
///   the surface `x + y = 0` is met at `t = 1.5 / 0.9`, at `(1/6, -1/6)`;
///   there `L+ = -0.9`, `L- = 2.1`, `a = 0.7`, and the state slides at
///   `(0.1, -0.1)`, to `(0.4, -0.4)` at `t = 4`;
/// - `x' = 1`, `y' = -sign(y - x^2)` from `(-1, 1.5)`, a surface whose
///   gradient `(-2 x, 1)` moves with the state: met where `t^2 - t - 1/2 =
///   0`, `t = (1 + sqrt 3) / 2`; it slides on the parabola (`a = (1 - 2x) /
///   2`, `y' = 2 x`) until `L- = 1 - 2 x` falls through zero at `x = 1/2`,
///   `t = 3/2`, and leaves below, to `(1, 3/4)` at `t = 2`.
#[test]
fn sliding_on_surfaces_that_are_no_state_follows_filippovs_weight() {
    let diagonal = json!({"model": "automaton", "states": ["x", "y"], "initial": {"x": 1.0, "y": 0.5},
        "modes": {"m": {"flow": {"x": "-sign(x + y) + 0.5", "y": "-0.5 * sign(x + y) + 0.1"}}},
        "t_end": 4.0});
    let parabola = json!({"model": "automaton", "states": ["x", "y"], "initial": {"x": -1.0, "y": 1.5},
        "modes": {"m": {"flow": {"x": "1", "y": "-sign(y - x^2)"}}}, "t_end": 2.0});
    let cases = [
        (
            &diagonal,
            vec![(1.5 / 0.9, "slide:x + y", "m[x + y=0]")],
            (0.4, -0.4),
        ),
        (
            &parabola,
            vec![
                (
                    (1.0 + 3f64.sqrt()) / 2.0,
                    "slide:y - x ^ 2",
                    "m[y - x ^ 2=0]",
                ),
                (1.5, "leave:y - x ^ 2", "m[y - x ^ 2<0]"),
            ],
            (1.0, 0.75),
        ),
    ];
    for (scene, want, (x, y)) in cases {
        for args in EXACT.iter().chain(&OTHERS) {
            let (summary, events) = run_value(scene, args);
            let what = format!("{args:?}");
            assert_eq!(summary["status"], "completed", "{what}: {summary}");
            let (time, state) = allowance(args, &summary);
            events_match(&events, &want, time, &what);
            let fin = &summary["final_state"];
            for (name, value) in [("x", x), ("y", y)] {
                let error = (f(&fin[name]) - value).abs();
                assert!(error <= state.max(1e-12), "{what}: {name} {fin}");
            }
            tight(args, &summary, &events, &want, &[("x", x), ("y", y)]);
        }
    }
}

/// Two blocks on springs, coupled by a spring `c`, each with dry friction
/// `mu` on the ground: block 2 sticks at `x2 = 0.1` (its spring force
/// `|-x2 + c (x1 - x2)| <= mu` while `|x1| <= 0.9`) while block 1 swings
/// about `e = (c x2 -+ mu) / (1 + c)` at `w = sqrt(1 + c)`, reversing where
/// its speed passes zero: a state on both surfaces, whose continuation is
/// unique (every flow around carries `v1` through zero the same way), not
/// the codimension-two slide it was once refused as. From rest on both.
/// Likewise a state sliding on `x = 0` whose `y` passes through zero.
#[test]
fn a_block_that_reverses_while_another_sticks_goes_on() {
    let through = json!({"model": "automaton", "states": ["x", "y"], "initial": {"x": 0.5, "y": 1.0},
        "modes": {"m": {"flow": {"x": "-sign(x)", "y": "-1 + 0 * sign(y)"}}}, "t_end": 2.0});
    let (summary, events) = run_value(&through, &[]);
    assert_eq!(summary["status"], "completed", "{summary}");
    events_match(
        &events,
        &[
            (0.5, "slide:x", "m[x=0, y>0]"),
            (1.0, "cross:y", "m[x=0, y<0]"),
        ],
        1e-12,
        "through",
    );
    assert_eq!(summary["final_state"]["x"], 0.0);
    assert!((f(&summary["final_state"]["y"]) + 1.0).abs() < 1e-12);
    let (mu, c, x2) = (0.3_f64, 0.2_f64, 0.1_f64);
    let scene = json!({"model": "automaton", "parameters": {"mu": mu, "c": c},
        "states": ["x1", "v1", "x2", "v2"],
        "initial": {"x1": 1.0, "v1": 0.0, "x2": x2, "v2": 0.0},
        "modes": {"m": {"flow": {"x1": "v1", "v1": "-x1 + c * (x2 - x1) - mu * sign(v1)",
                                 "x2": "v2", "v2": "-x2 + c * (x1 - x2) - mu * sign(v2)"}}},
        "t_end": 5.5});
    let w = (1.0 + c).sqrt();
    let (back, forth) = ((c * x2 + mu) / (1.0 + c), (c * x2 - mu) / (1.0 + c));
    let turn = std::f64::consts::PI / w;
    // Back from 1 about `back` to 2 back - 1, then forth about `forth`.
    let x_turn = 2.0 * back - 1.0;
    let tau = 5.5 - turn;
    let (x1, v1) = (
        forth + (x_turn - forth) * (w * tau).cos(),
        -(x_turn - forth) * w * (w * tau).sin(),
    );
    let want = [
        (0.0, "cross:v1", "m[v1<0, v2=0]"),
        (turn, "cross:v1", "m[v1>0, v2=0]"),
    ];
    for args in EXACT.iter().chain(&OTHERS) {
        let (summary, events) = run_value(&scene, args);
        let what = format!("{args:?}");
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        let (time, state) = allowance(args, &summary);
        events_match(&events, &want, time, &what);
        let fin = &summary["final_state"];
        for (name, value) in [("x1", x1), ("v1", v1), ("x2", x2), ("v2", 0.0)] {
            assert!(
                (f(&fin[name]) - value).abs() <= state.max(1e-12),
                "{what}: {name} {fin}"
            );
        }
        tight(args, &summary, &events, &want, &[("x1", x1), ("v1", v1)]);
    }
}

#[test]
fn what_has_no_unique_answer_stops_and_says_why() {
    // Both sides flow away from x = 0, where it starts.
    let repelling = json!({"model": "automaton", "states": ["x"], "initial": {"x": 0.0},
        "modes": {"m": {"flow": {"x": "sign(x)"}}}, "t_end": 1.0});
    // Reached by a reset onto it.
    let landed = json!({"model": "automaton", "states": ["x"], "initial": {"x": 1.0},
        "initial_mode": "fall",
        "modes": {
            "fall": {"flow": {"x": "-1"},
                     "transitions": [{"name": "land", "guard": "x - 0.5", "direction": "falling",
                                      "reset": {"x": "0"}, "to": "away"}]},
            "away": {"flow": {"x": "sign(x)"}}},
        "t_end": 2.0});
    // Sliding on x = 0 when y reaches 0, which attracts from both sides
    // too: sliding on both (codimension two). (Where y passes through
    // zero, `y' = -1 + 0 sign(y)`, the run goes on: see below.)
    let corner = json!({"model": "automaton", "states": ["x", "y"], "initial": {"x": 0.5, "y": 1.0},
        "modes": {"m": {"flow": {"x": "-sign(x)", "y": "-sign(y)"}}}, "t_end": 2.0});
    // A surface that is not finite where the run goes.
    let undefined = json!({"model": "automaton", "states": ["x"], "initial": {"x": 2.0},
        "modes": {"m": {"flow": {"x": "-1 - sign(sqrt(x - 1))"}}}, "t_end": 2.0});
    for (scene, want) in [
        (&repelling, "point away"),
        (&landed, "point away"),
        (&corner, "two surfaces"),
        (&undefined, "not finite"),
    ] {
        for args in [&[][..], &["--method", "taylor"], &["--method", "dop853"]] {
            let (summary, _) = run_value(scene, args);
            let reason = summary["reason"].as_str().unwrap_or("");
            assert_eq!(summary["status"], "failed", "{want} {args:?}: {summary}");
            // A surface undefined where the run goes stops where a method
            // first meets it: a value that is not finite, or a step that
            // collapses where it turns steep.
            let undefined =
                want == "not finite" && (reason.contains("NaN") || reason.contains("steep"));
            assert!(
                reason.contains(want) || undefined,
                "{want} {args:?}: {reason}"
            );
        }
    }
}

#[test]
fn sign_belongs_in_flows_and_takes_one_argument() {
    let with = |flow: &str, guard: &str| {
        json!({"model": "automaton", "states": ["x"], "initial": {"x": 1.0},
               "modes": {"m": {"flow": {"x": flow},
                               "transitions": [{"name": "g", "guard": guard}]}}, "t_end": 1.0})
    };
    for (scene, field, want) in [
        (with("-1", "sign(x)"), "transitions", "in a guard"),
        (with("-sign(x, 1)", "x"), "flow.x", "1 argument"),
        (with("-sign(sign(x))", "x"), "flow.x", "inside the argument"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.json");
        std::fs::write(&path, scene.to_string()).unwrap();
        let out = crate::support::flicker(&["check", path.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(field) && err.contains(want), "{field}: {err}");
    }
}

/// Derivatives through crossings and the slide (the saltation matrix of
/// each, the general one: entering a sliding is a reset-free change of
/// flow) against the closed form: the block sticks at `x = 15 - A`, `A =
/// sqrt((x0 + 1)^2 + v0^2)`, at `t = atan(v0 / (x0 + 1)) + 7 pi`.
#[test]
fn sensitivities_through_the_slide_meet_the_closed_form() {
    let (summary, _) = run(
        &automaton("friction_oscillator.json"),
        &["--sensitivities", "initial.x,initial.v"],
    );
    assert_eq!(summary["status"], "completed", "{summary}");
    let (x0, v0) = (12.0f64, 6.0f64);
    let a2 = (x0 + 1.0).powi(2) + v0 * v0;
    let a = a2.sqrt();
    let s = &summary["sensitivities"];
    for (name, dx, dt) in [
        ("initial.x", -(x0 + 1.0) / a, -v0 / a2),
        ("initial.v", -v0 / a, (x0 + 1.0) / a2),
    ] {
        assert!(
            (f(&s[name]["final_state"]["x"]) - dx).abs() < 1e-12,
            "{name}: {s}"
        );
        assert_eq!(f(&s[name]["final_state"]["v"]), 0.0, "{name}: {s}");
        assert!(
            (f(&s[name]["last_event_time"]) - dt).abs() < 1e-12,
            "{name}: {s}"
        );
    }
}

/// `events --summary` reports the time spent sliding on each surface: the
/// forced relay's one interval, from its arrival to pi / 6.
#[test]
fn the_event_summary_reports_the_time_spent_sliding() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let scene = automaton("forced_relay.json");
    let done = crate::support::flicker(&["run", &scene, "--out", out, "--quiet"]);
    assert!(done.status.success());
    let log = dir.path().join("events.jsonl");
    let summary = crate::support::flicker(&["events", log.to_str().unwrap(), "--summary"]);
    let summary: Value = serde_json::from_slice(&summary.stdout).unwrap();
    let (want, _) = forced_relay(2.0, 0.1, 20.0);
    let sliding = &summary["sliding"]["x"];
    assert_eq!(sliding["intervals"], 1, "{summary}");
    assert!(
        (f(&sliding["time"]) - (want[1].0 - want[0].0)).abs() < 1e-12,
        "{summary}"
    );
    assert!(sliding["since"].is_null());
}
