//! A switch that a Taylor series cannot see coming: `x' = -tanh(x / eps)`
//! from `x = 1` with `eps = 0.01`. At `x / eps = 100` the tanh is 1 to
//! every digit and all its derivatives underflow, so the flow's series is
//! exactly `1 - t`, with an infinite radius; yet the flow turns off where
//! `x` reaches `eps`, and `x` then decays as `exp(-t / eps)`. The closed
//! form: `sinh(x / eps) = sinh(x0 / eps) exp(-t / eps)`. Every method must
//! end within its bounds of it, and find the marker at `x = 1/2` within
//! its event time bound.

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
