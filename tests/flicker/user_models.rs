//! Models a new user writes from docs/automata.md alone, the ones that once
//! went quietly wrong, each run from its file through the command line by
//! every method that applies and checked against an answer computed outside
//! flicker:
//!
//! - a pendulum's Poincare section (`th` rising, no reset): one event per
//!   swing, at the complete elliptic integral's period;
//! - Henon-Heiles's section `x = 0`: 326 crossings to `t = 2000`, against
//!   heyoka in 128-bit arithmetic (tests/fixtures/henon_heiles_section.json);
//! - a forced oscillator's passages (`cos(w t)` in the flow), rising and
//!   either way, against its closed form in double-double arithmetic; every
//!   event's clock is its `t`, and the final clock `t_reached`, bit for bit;
//! - a relay written as two modes, which sticks: the run stops, naming the
//!   sliding surface and both modes;
//! - a kick every time unit up to `t_end`, whose last kick lands on `t_end`
//!   by construction: applied, not refused;
//! - a circular billiard to `t = 2e5` by the exact propagator: it completes,
//!   within its bound.

use serde_json::{Value, json};
use twofloat::TwoFloat as D;

use crate::automata::{f, run_value};

/// Each method's arguments.
fn methods(names: &[&str]) -> Vec<Vec<&'static str>> {
    names
        .iter()
        .map(|name| match *name {
            "dopri5" => vec!["--method", "dopri5", "--rtol", "1e-10", "--atol", "1e-10"],
            "dop853" => vec!["--method", "dop853", "--rtol", "1e-12", "--atol", "1e-12"],
            "taylor" => vec!["--method", "taylor"],
            "linear" => vec!["--method", "linear"],
            other => panic!("{other}"),
        })
        .collect()
}

/// A completed run's event times against `exact`, each within its stated
/// event-time bound (plus `slack`, the reference's own error).
fn times_within_bound(summary: &Value, events: &[Value], exact: &[f64], slack: f64, what: &str) {
    assert_eq!(summary["status"], "completed", "{what}: {summary}");
    assert_eq!(events.len(), exact.len(), "{what}: event count");
    let bound = f(&summary["event_time_bound"]) + slack;
    let mut largest = 16.0 * f64::EPSILON * f(&summary["t_reached"]).abs().max(1.0);
    for (k, (e, want)) in events.iter().zip(exact).enumerate() {
        let t = f(&e["t"]);
        assert!(
            (t - want).abs() <= bound,
            "{what}: event {k} at {t}, exact {want}, off by {:.2e}, bound {bound:.2e}",
            (t - want).abs()
        );
        largest = largest.max((t - want).abs());
    }
    // And not far above the error (or 16 ulps of the time): the
    // Runge-Kutta pairs' bounds are today up to some 1e4 times it (see
    // tests/flicker/conformance.rs).
    assert!(
        bound <= LOOSENESS * largest,
        "{what}: event times {largest:.2e} off, their bound {bound:.2e}"
    );
}

/// How many times the error a stated bound may be.
const LOOSENESS: f64 = 3e4;

/// `K(m)`, the complete elliptic integral of the first kind, by the
/// arithmetic-geometric mean.
fn elliptic_k(m: f64) -> f64 {
    let (mut a, mut b) = (1.0_f64, (1.0 - m).sqrt());
    while (a - b).abs() > 1e-16 * a {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    std::f64::consts::PI / (2.0 * a)
}

#[test]
fn a_pendulums_section_fires_once_per_swing() {
    // From th = 0 at w = 1: amplitude pi/3, k = 1/2, period 4 K(1/4);
    // the start on the section, moving up, is its first crossing.
    let scene = json!({"model": "automaton",
        "states": ["th", "w"], "initial": {"th": 0.0, "w": 1.0},
        "modes": {"swing": {"flow": {"th": "w", "w": "-sin(th)"},
            "transitions": [{"name": "section", "guard": "th", "direction": "rising"}]}},
        "t_end": 60.0});
    let period = 4.0 * elliptic_k(0.25);
    let exact: Vec<f64> = (0..)
        .map(|k| k as f64 * period)
        .take_while(|t| *t <= 60.0)
        .collect();
    assert_eq!(exact.len(), 9);
    for args in methods(&["taylor", "dop853", "dopri5"]) {
        let (summary, events) = run_value(&scene, &args);
        times_within_bound(&summary, &events, &exact, 1e-14, &format!("{args:?}"));
    }
}

#[test]
fn henon_heiles_crosses_its_section_as_heyoka_at_128_bits_does() {
    let fixture = crate::support::fixture("henon_heiles_section.json");
    let number = crate::support::digits;
    let exact: Vec<f64> = fixture["crossings"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    let last: Vec<f64> = fixture["final_state"]
        .as_array()
        .unwrap()
        .iter()
        .map(number)
        .collect();
    let x0 = &fixture["x0"];
    let scene = json!({"model": "automaton",
        "states": ["x", "y", "px", "py"],
        "initial": {"x": x0[0], "y": x0[1], "px": x0[2], "py": x0[3]},
        "modes": {"m": {"flow": {"x": "px", "y": "py", "px": "-x - 2 * x * y", "py": "-y - x^2 + y^2"},
            "transitions": [{"name": "section", "guard": "x", "direction": "rising"}]}},
        "energy": "(px^2 + py^2) / 2 + (x^2 + y^2) / 2 + x^2 * y - y^3 / 3",
        "t_end": fixture["t_end"]});
    assert_eq!(exact.len(), 326);
    // The final state's bound within `looseness` of its error: 3e4 for
    // the pairs (2.6e3 measured) and for Taylor's method where its
    // truncation dominates (rtol 1e-10: 3.3e3; the 4-D quasi-periodic flow
    // re-wraps the carried set at each of 12,000 steps, see
    // `src/engine/error_set`); 1e5 at machine precision (3.9e4), where its
    // errors are round-off: the bound sums 10,800 steps' allowances (4
    // ulps), where the roundings made (about half an ulp) walk at random
    // and mostly cancel, about sqrt(10800) = 100 apart.
    let mut runs: Vec<(Vec<&str>, f64)> = [("taylor", 1e5), ("dop853", 3e4), ("dopri5", 3e4)]
        .into_iter()
        .map(|(method, looseness)| (methods(&[method]).remove(0), looseness))
        .collect();
    runs.push((
        vec!["--method", "taylor", "--rtol", "1e-10", "--atol", "1e-10"],
        3e4,
    ));
    for (args, looseness) in runs {
        let (summary, events) = run_value(&scene, &args);
        let what = format!("{args:?}");
        times_within_bound(&summary, &events, &exact, 1e-15, &what);
        let state = &summary["final_state"];
        let bound = f(&summary["error_bound"]);
        let mut largest = 16.0 * f64::EPSILON;
        for (name, want) in ["x", "y", "px", "py"].iter().zip(&last) {
            let off = (f(&state[name]) - want).abs();
            assert!(off <= bound, "{what}: {name} {off:.2e} off");
            largest = largest.max(off);
        }
        assert!(
            bound <= looseness * largest,
            "{what}: final state {largest:.2e} off, its bound {bound:.2e}"
        );
    }
}

/// `x'' + 2 zeta x' + x = A cos(w t)` from `(x0, v0)`, in double-double:
/// `(x, v)` at `t`.
fn forced(t: D) -> (D, D) {
    let (z, w, a) = (D::from(0.05), D::from(0.8), D::from(1.0));
    let one = D::from(1.0);
    let d = (one - w * w) * (one - w * w) + (D::from(2.0) * z * w) * (D::from(2.0) * z * w);
    let (px, py) = (a * (one - w * w) / d, a * D::from(2.0) * z * w / d);
    let wd = (one - z * z).sqrt();
    let c1 = D::from(0.5) - px;
    let c2 = (D::from(0.0) - w * py + z * c1) / wd;
    let (s, c) = ((w * t).sin(), (w * t).cos());
    let (sd, cd) = ((wd * t).sin(), (wd * t).cos());
    let decay = (-z * t).exp();
    let x = px * c + py * s + decay * (c1 * cd + c2 * sd);
    let v = w * (py * c - px * s) + decay * ((wd * c2 - z * c1) * cd - (wd * c1 + z * c2) * sd);
    (x, v)
}

/// The closed form's passages of `x = 0` in `(0, t_end]`, rising or both
/// ways, bracketed on a grid finer than a tenth of a period and bisected in
/// double-double.
fn passages(t_end: f64, either: bool) -> Vec<f64> {
    let x = |t: f64| forced(D::from(t)).0;
    let n = (t_end * 100.0) as usize;
    let mut out = Vec::new();
    for i in 0..n {
        let (mut a, mut b) = (
            t_end * i as f64 / n as f64,
            t_end * (i + 1) as f64 / n as f64,
        );
        let (xa, xb) = (x(a), x(b));
        let rising = xa < D::from(0.0) && xb >= D::from(0.0);
        let falling = xa > D::from(0.0) && xb <= D::from(0.0);
        if rising || (either && falling) {
            for _ in 0..80 {
                let m = 0.5 * (a + b);
                if (x(m) < D::from(0.0)) == (xa < D::from(0.0)) {
                    a = m;
                } else {
                    b = m;
                }
            }
            out.push(b);
        }
    }
    out
}

#[test]
fn a_forced_oscillators_passages_fire_once_and_its_clock_is_the_runs_time() {
    for (direction, t_end) in [("rising", 1e4), ("either", 200.0)] {
        let scene = json!({"model": "automaton",
            "parameters": {"zeta": 0.05, "w": 0.8, "A": 1.0},
            "states": ["x", "v"], "initial": {"x": 0.5, "v": 0.0},
            "modes": {"m": {"flow": {"x": "v", "v": "-2 * zeta * v - x + A * cos(w * t)"},
                "transitions": [{"name": "pass", "guard": "x", "direction": direction}]}},
            "t_end": t_end});
        let exact = passages(t_end, direction == "either");
        for args in methods(&["taylor", "dop853", "dopri5"]) {
            let what = format!("{direction} {args:?}");
            let (summary, events) = run_value(&scene, &args);
            times_within_bound(&summary, &events, &exact, 0.0, &what);
            for e in &events {
                assert_eq!(e["before"]["t"], e["t"], "{what}: the clock at an event");
                assert_eq!(e["after"]["t"], e["t"], "{what}: the clock after an event");
            }
            assert_eq!(summary["final_state"]["t"], summary["t_reached"], "{what}");
            let (x, v) = forced(D::from(t_end));
            let state = &summary["final_state"];
            let off = (D::from(f(&state["x"])) - x)
                .abs()
                .max((D::from(f(&state["v"])) - v).abs());
            assert!(
                off.hi() <= f(&summary["error_bound"]),
                "{what}: final state {:.2e} off, bound {}",
                off.hi(),
                summary["error_bound"]
            );
        }
    }
}

#[test]
fn a_relay_written_as_two_modes_stops_where_it_sticks() {
    // x'' + 2 zeta x' + x = -sign(x'): from x = 5 at rest the swings shrink
    // until x sits within (-1, 1) as v reaches 0, where both modes' flows
    // push v back through zero: the relay sticks.
    let scene = json!({"model": "automaton",
        "parameters": {"zeta": 0.05},
        "states": ["x", "v"], "initial": {"x": 5.0, "v": 0.0}, "initial_mode": "down",
        "modes": {
            "up": {"flow": {"x": "v", "v": "-2 * zeta * v - x - 1"},
                "transitions": [{"name": "turn", "guard": "v", "direction": "falling", "to": "down"}]},
            "down": {"flow": {"x": "v", "v": "-2 * zeta * v - x + 1"},
                "transitions": [{"name": "turn", "guard": "v", "direction": "rising", "to": "up"}]}},
        "t_end": 40.0});
    for args in methods(&["linear", "taylor", "dop853", "dopri5"]) {
        let (summary, events) = run_value(&scene, &args);
        let reason = summary["reason"].as_str().unwrap_or("");
        assert_eq!(summary["status"], "failed", "{args:?}: {summary}");
        assert!(
            reason.contains("sliding") && reason.contains("`up`") && reason.contains("`down`"),
            "{args:?}: {reason}"
        );
        // It stops at the first turn with |x| < 1, having turned where the
        // closed form of each half-swing says: each half-swing about +-1
        // keeps exp(-zeta pi / wd) of its amplitude.
        let last = events.last().unwrap();
        assert!(f(&last["before"]["x"]).abs() < 1.0, "{args:?}: {last}");
        assert!(
            events[..events.len() - 1]
                .iter()
                .all(|e| f(&e["before"]["x"]).abs() >= 1.0)
        );
    }
}

#[test]
fn a_kick_on_t_end_is_applied() {
    let scene = json!({"model": "automaton",
        "states": ["c", "k"], "initial": {"c": 0.0, "k": 0.0},
        "modes": {"m": {"flow": {"c": "1"},
            "transitions": [{"name": "tick", "guard": "c - 1", "direction": "rising",
                "reset": {"c": "0", "k": "k + 1"}}]}},
        "t_end": 200.0});
    for args in methods(&["linear", "taylor", "dop853", "dopri5"]) {
        let (summary, events) = run_value(&scene, &args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        assert_eq!(events.len(), 200, "{args:?}");
        let last = events.last().unwrap();
        assert!((f(&last["t"]) - 200.0).abs() <= 1e-12, "{args:?}: {last}");
        assert_eq!(summary["final_state"]["k"], 200.0, "{args:?}");
        assert!(f(&summary["final_state"]["c"]).abs() <= 1e-12, "{args:?}");
    }
}

#[test]
fn a_circular_billiard_runs_to_two_hundred_thousand_within_its_bound() {
    // |v| = 1 from (0.1, 0.2): chords of length 2 sqrt(1 - b^2), b the
    // impact parameter, the first after the closed-form chord from inside.
    let scene = json!({"model": "automaton",
        "states": ["x", "y", "vx", "vy"],
        "initial": {"x": 0.1, "y": 0.2, "vx": 0.6, "vy": 0.8},
        "modes": {"fly": {"flow": {"x": "vx", "y": "vy"},
            "transitions": [{"name": "wall", "guard": "1 - x^2 - y^2", "direction": "falling",
                "barrier": true,
                "reset": {"vx": "vx - 2 * (vx * x + vy * y) * x / (x^2 + y^2)",
                          "vy": "vy - 2 * (vx * x + vy * y) * y / (x^2 + y^2)"}}]}},
        "t_end": 2e5});
    let (x, y, u, w) = (D::from(0.1), D::from(0.2), D::from(0.6), D::from(0.8));
    let pv = x * u + y * w;
    let t1 = -pv + (pv * pv + D::from(1.0) - x * x - y * y).sqrt();
    let b = x * w - y * u;
    let chord = D::from(2.0) * (D::from(1.0) - b * b).sqrt();
    for args in methods(&["linear", "taylor"]) {
        let (summary, events) = run_value(&scene, &args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        let bound = f(&summary["event_time_bound"]);
        for (k, e) in events.iter().enumerate() {
            let exact = t1 + chord * D::from(k as f64);
            let off = (D::from(f(&e["t"])) - exact).abs().hi();
            assert!(
                off <= bound,
                "{args:?}: bounce {k} {off:.2e} off, bound {bound:.2e}"
            );
        }
        let n = events.len() as f64;
        let expected = ((D::from(2e5) - t1) / chord).hi().floor() + 1.0;
        assert_eq!(n, expected, "{args:?}");
    }
}
