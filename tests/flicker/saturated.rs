//! A switch that a Taylor series cannot see coming: `x' = -tanh(x / eps)`
//! from `x = 1` with `eps = 0.01`. At `x / eps = 100` the tanh is 1 to
//! every digit and all its derivatives underflow, so the flow's series is
//! exactly `1 - t`, with an infinite radius; yet the flow turns off where
//! `x` reaches `eps`, and `x` then decays as `exp(-t / eps)`. The closed
//! form: `sinh(x / eps) = sinh(x0 / eps) exp(-t / eps)`. Every method must
//! end within its bounds of it, and find the marker at `x = 1/2` within
//! its event time bound.
//!
//! A polynomial flow does it too: `x' = y^40`, `y' = 1` from `y = 0.01`.
//! The series of order 20 holds only `y0^21` and smaller, so the last two
//! coefficients put the radius far past where `y^40` wakes up. Without
//! the Taylor step's check of its series against the flow at its end, the
//! run ended at `x = 2e-29` against the true `5.3e5`, stating a bound of
//! 4e-17.

use serde_json::json;

use crate::automata::{f, run_value};

#[test]
fn a_switch_no_coefficient_shows_is_still_followed() {
    let (eps, x0, t_end) = (0.01f64, 1.0f64, 2.0f64);
    let scene = json!({
        "model": "automaton",
        "parameters": {"eps": eps},
        "states": ["x"],
        "initial": {"x": x0},
        "modes": {"m": {
            "flow": {"x": "-tanh(x / eps)"},
            "transitions": [{"name": "half", "guard": "x - 0.5", "direction": "falling"}]}},
        "t_end": t_end
    });
    let exact = |t: f64| eps * ((x0 / eps).sinh() * (-t / eps).exp()).asinh();
    let half = eps * ((x0 / eps).sinh() / (0.5 / eps).sinh()).ln();
    for args in [
        &["--method", "taylor"][..],
        &["--method", "taylor", "--rtol", "1e-8", "--atol", "1e-8"],
        &["--method", "dop853"],
        &["--method", "dopri5"],
    ] {
        let (summary, events) = run_value(&scene, args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        assert_eq!(events.len(), 1, "{args:?}: {events:?}");
        let (bound, time) = (f(&summary["error_bound"]), f(&summary["event_time_bound"]));
        let x = f(&summary["final_state"]["x"]);
        assert!(
            (x - exact(t_end)).abs() <= bound,
            "{args:?}: {x} against {}",
            exact(t_end)
        );
        let t = f(&events[0]["t"]);
        assert!(
            (t - half).abs() <= time,
            "{args:?}: {t} against {half}, bound {time}"
        );
    }
}

#[test]
fn a_polynomial_flow_flat_past_the_series_order_is_still_followed() {
    let (y0, t_end) = (0.01f64, 1.5f64);
    let scene = json!({
        "model": "automaton",
        "parameters": {},
        "states": ["x", "y"],
        "initial": {"x": 0.0, "y": y0},
        "modes": {"m": {"flow": {"x": "y^40", "y": "1"}, "transitions": []}},
        "t_end": t_end
    });
    // x(t) = ((y0 + t)^41 - y0^41) / 41.
    let exact = ((y0 + t_end).powi(41) - y0.powi(41)) / 41.0;
    for args in [
        &["--method", "taylor"][..],
        &["--method", "taylor", "--rtol", "1e-10", "--atol", "1e-10"],
        &["--method", "dop853"],
    ] {
        let (summary, _) = run_value(&scene, args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        let (x, bound) = (f(&summary["final_state"]["x"]), f(&summary["error_bound"]));
        assert!(
            (x - exact).abs() <= bound,
            "{args:?}: {x} against {exact}, bound {bound}"
        );
        // A bound that says something (the loose tolerances' steps each
        // allow rtol of x, about 1e-4 of it in all).
        assert!(bound < 1e-4 * exact, "{args:?}: bound {bound}");
    }
}
