//! A flow affine in the state and driven by sines of the clock runs on the
//! exact linear propagator, its sines carried as two more components (see
//! `src/engine/model/affine_flow.rs`): checked against closed forms over long
//! runs, where the forcing's phase `w t` is large.

use serde_json::{Value, json};

use crate::automata::{f, run_value};

/// `x' = cos(w t)` from 0: `x = sin(w t) / w`, rising through `0.5 / w`
/// at `w t = pi / 6 + 2 pi k`.
fn integrator_of_a_cosine(t_end: f64) -> Value {
    json!({
        "model": "automaton",
        "parameters": {"w": 1.3},
        "states": ["x"],
        "initial": {"x": 0.0},
        "modes": {"m": {
            "flow": {"x": "cos(w * t)"},
            "transitions": [{"name": "half", "guard": "x - 0.5 / w", "direction": "rising"}]
        }},
        "t_end": t_end
    })
}

/// To t = 1e4 (2069 passages): the default is the linear propagator;
/// every passage is at its closed-form time within the stated event-time
/// bound (the closed form's own rounding, a few ulps of t, beside it), and
/// the final state is within 1e-14 of `sin(w t) / w` at the double `w`
/// (mpmath at 40 digits: 0.06883046814286983). Rounding the product `w t`
/// to double before its sine, as a plain evaluation does, lands 3.4e-13
/// off; the propagator takes each step's `cos(w t)` from the exact
/// product.
#[test]
fn a_sine_driven_flow_is_propagated_exactly_over_a_long_run() {
    let w = 1.3_f64;
    let (summary, events) = run_value(&integrator_of_a_cosine(1e4), &[]);
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["method"], "linear", "{summary}");
    let tau = std::f64::consts::TAU;
    let expected: Vec<f64> = (0..)
        .map(|k| (tau / 12.0 + tau * k as f64) / w)
        .take_while(|t| *t <= 1e4)
        .collect();
    assert_eq!(events.len(), expected.len(), "{summary}");
    assert_eq!(events.len(), 2069);
    let time_bound = f(&summary["event_time_bound"]);
    let mut largest = 16.0 * f64::EPSILON * 1e4;
    for (event, want) in events.iter().zip(&expected) {
        let t = f(&event["t"]);
        assert!(
            (t - want).abs() <= time_bound + 8.0 * f64::EPSILON * want,
            "{t} vs {want} (bound {time_bound:e})"
        );
        largest = largest.max((t - want).abs());
    }
    // Round-off alone errs: the bound, 16 ulps of the time and the
    // crossings' rounding over their speed, within 1e3 of the error or of
    // 16 ulps of t_end.
    assert!(
        time_bound <= 1e3 * largest,
        "{largest:.2e} off, bound {time_bound:.2e}"
    );
    let x = f(&summary["final_state"]["x"]);
    let exact = 0.06883046814286983;
    assert!((x - exact).abs() < 1e-14, "{x} vs {exact}");
    assert!((x - exact).abs() <= f(&summary["error_bound"]), "{summary}");
    assert!(
        ((w * 1e4).sin() / w - exact).abs() > 3e-13,
        "the plain product's rounding shows at this t"
    );
}

/// `scene` by its default method (the linear propagator) and by Taylor's
/// method at machine precision: both complete, with the same events, each
/// pair within the sum of the two stated event-time bounds, and final
/// states (`x` and `v`) within the sum of the two error bounds. Returns
/// the events.
fn agrees_with_taylor_within_both_bounds(scene: &Value, case: &str) -> Vec<Value> {
    let (linear, a) = run_value(scene, &[]);
    let (taylor, b) = run_value(scene, &["--method", "taylor"]);
    assert_eq!(linear["method"], "linear", "{case}: {linear}");
    for s in [&linear, &taylor] {
        assert_eq!(s["status"], "completed", "{case}: {s}");
    }
    assert_eq!(a.len(), b.len(), "{case}");
    let times = f(&linear["event_time_bound"]) + f(&taylor["event_time_bound"]);
    for (p, q) in a.iter().zip(&b) {
        assert_eq!(p["guard"], q["guard"], "{case}");
        assert!(
            (f(&p["t"]) - f(&q["t"])).abs() <= times,
            "{case}: {p} vs {q}"
        );
    }
    let states = f(&linear["error_bound"]) + f(&taylor["error_bound"]);
    for key in ["x", "v"] {
        let (p, q) = (
            f(&linear["final_state"][key]),
            f(&taylor["final_state"][key]),
        );
        assert!((p - q).abs() <= states, "{case} {key}: {p} vs {q}");
    }
    a
}

/// A damped oscillator driven at two frequencies with a phase,
/// `x'' + 0.1 x' + x = cos(0.8 t + 0.3) - 0.5 sin(2 t)`, by the linear
/// propagator and by Taylor's method at machine precision: the same
/// passages, each pair within the two stated event-time bounds, and final
/// states within the two error bounds of each other.
#[test]
fn two_frequencies_and_a_phase_agree_with_taylors_method_within_both_bounds() {
    let scene = json!({
        "model": "automaton",
        "states": ["x", "v"],
        "initial": {"x": 0.5, "v": 0.0},
        "modes": {"m": {
            "flow": {"x": "v", "v": "-0.1 * v - x + cos(0.8 * t + 0.3) - 0.5 * sin(2 * t)"},
            "transitions": [{"name": "up", "guard": "x", "direction": "rising"}]
        }},
        "t_end": 2000.0
    });
    let passages = agrees_with_taylor_within_both_bounds(&scene, "two frequencies");
    assert!(passages.len() > 200, "{} passages", passages.len());
}

/// The same flow where every step is cut short: a guard with a fast sine
/// of the clock (`40 t`) makes the propagator halve its steps until the
/// guard's series converges, so no step is a whole one and none carries
/// its end's rounding to the next. Each still starts from the exact time
/// (the engine's), and the final state is within 1e-14 of `sin(w t) / w`;
/// a step that read the clock's rounded value instead would shift the
/// forcing by up to half an ulp of `t` each time, about 1e-10 by the end.
#[test]
fn steps_cut_short_start_from_the_exact_time_too() {
    let mut scene = integrator_of_a_cosine(1e4);
    scene["modes"]["m"]["transitions"][0]["guard"] = json!("x - 0.5 / w + 0.001 * sin(40 * t)");
    let (summary, _) = run_value(&scene, &["--no-events"]);
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["method"], "linear", "{summary}");
    let x = f(&summary["final_state"]["x"]);
    let exact = 0.06883046814286983;
    assert!((x - exact).abs() < 1e-14, "{x} vs {exact}");
    assert!((x - exact).abs() <= f(&summary["error_bound"]), "{summary}");
}

/// Twenty driven oscillators drawn at random (a fixed seed): two modes,
/// one driven by a cosine with a phase, the other by a sine of a negative
/// frequency and a cosine of another (augmented states of 5 and 7
/// components), switched at each passage of `x` through zero. By the
/// linear propagator (the default) and by Taylor's method: the same
/// events, each pair within the sum of the two stated event-time bounds,
/// and final states within the sum of the two error bounds.
#[test]
fn random_driven_modes_agree_with_taylors_method_within_both_bounds() {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut draw = |lo: f64, hi: f64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        lo + (hi - lo) * (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..20 {
        let (k1, k2, c) = (draw(0.5, 3.0), draw(0.5, 3.0), draw(0.0, 0.3));
        let (w1, w2, w3, phase) = (
            draw(0.2, 3.0),
            draw(0.2, 3.0),
            draw(0.2, 3.0),
            draw(-3.0, 3.0),
        );
        let (a1, a2, a3) = (draw(-2.0, 2.0), draw(-2.0, 2.0), draw(-2.0, 2.0));
        let scene = json!({
            "model": "automaton",
            "states": ["x", "v"],
            "initial": {"x": draw(-1.0, 1.0), "v": draw(-1.0, 1.0)},
            "initial_mode": "a",
            "modes": {
                "a": {"flow": {"x": "v", "v": format!("-{k1} * x - {c} * v + {a1} * cos({w1} * t + {phase})")},
                      "transitions": [{"name": "up", "guard": "x", "direction": "rising", "to": "b"}]},
                "b": {"flow": {"x": "v", "v": format!("-{k2} * x - {c} * v + {a2} * sin(-{w2} * t) + {a3} * cos(t * {w3})")},
                      "transitions": [{"name": "down", "guard": "x", "direction": "falling", "to": "a"}]}
            },
            "t_end": 50.0
        });
        let events = agrees_with_taylor_within_both_bounds(&scene, &format!("case {case}"));
        assert!(events.len() >= 10, "case {case}: {} events", events.len());
    }
}
