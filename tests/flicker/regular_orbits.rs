//! On a regular orbit (a periodic one, or one on a torus) the tangent map
//! over a period is a shear: the phase error grows with the energy error,
//! polynomially in time. The stated bound must grow so too: a tangent off
//! by 1e-4 (the midpoint's exponential over long Taylor steps) or even
//! 1e-7 splits the shear's double eigenvalue 1, and the bound then grows by
//! a factor per period, or swings across the enclosure's frame (see
//! `src/engine/bound/tangent.rs`).

use crate::automata::{f, run_value};
use serde_json::{Value, json};

fn henon_heiles(t_end: f64) -> Value {
    json!({
        "model": "automaton",
        "states": ["x", "y", "px", "py"],
        "initial": {"x": 0.05, "y": 0.3, "px": 0.3521363372331802, "py": 0.0},
        "modes": {"m": {
            "flow": {"x": "px", "y": "py", "px": "-x - 2 * x * y", "py": "-y - x^2 + y^2"},
            "transitions": []
        }},
        "t_end": t_end
    })
}

/// Henon-Heiles at energy 0.1 (a regular orbit) by Taylor's method: from
/// t = 2000 to 20,000 the bound grows about t^3 (measured 8.9e-10 to
/// 8.9e-7), where the midpoint's tangent grew it 4e11 times (to 391), and
/// it holds against a run of order 25 (tolerance 1e-20).
#[test]
fn a_regular_orbits_bound_grows_polynomially() {
    let (early, _) = run_value(&henon_heiles(2000.0), &[]);
    let (late, _) = run_value(&henon_heiles(20000.0), &[]);
    let (fine, _) = run_value(
        &henon_heiles(20000.0),
        &["--rtol", "1e-20", "--atol", "1e-20"],
    );
    for s in [&early, &late, &fine] {
        assert_eq!(s["status"], "completed", "{s}");
    }
    let (a, b) = (f(&early["error_bound"]), f(&late["error_bound"]));
    assert!(b < 1e-5, "bound {b:e} at t = 20000");
    assert!(b < 1e4 * a, "bound {a:e} at t = 2000, {b:e} at t = 20000");
    let allowed = b + f(&fine["error_bound"]);
    for key in ["x", "y", "px", "py"] {
        let (x, y) = (f(&late["final_state"][key]), f(&fine["final_state"][key]));
        assert!(
            (x - y).abs() <= allowed,
            "{key}: {x} against {y}, bounds {allowed:e}"
        );
    }
}

/// A pendulum against a wall (elastic, `theta'' = -sin theta`, from the
/// wall at speed 1, amplitude pi/3) by Taylor's method to t = 35,000:
/// 10,381 impacts, every one at `j T`, `T = 2 K(1/2) = pi / AGM(1,
/// sqrt(3) / 2)`, within the stated event-time bound, which stays below
/// 1e-6 (the exact tangent's worst case, measured 3.6e-7: the phase error
/// grows as t^2). A tangent that left the period's shear a slow rotation
/// (off by 4e-7) let the bound swing across the parallelepiped's frame and
/// grow to 1.6e-5.
#[test]
fn a_periodic_orbits_bound_holds_and_stays_below_its_shear() {
    let scene = json!({
        "model": "automaton",
        "states": ["theta", "omega"],
        "initial": {"theta": 0.0, "omega": 1.0},
        "modes": {"swing": {
            "flow": {"theta": "omega", "omega": "-sin(theta)"},
            "transitions": [{"name": "impact", "guard": "theta", "direction": "falling",
                             "barrier": true, "reset": {"theta": "0", "omega": "-omega"}}]
        }},
        "t_end": 35000.0
    });
    let (summary, events) = run_value(&scene, &["--method", "taylor"]);
    assert_eq!(summary["status"], "completed", "{summary}");
    let (mut a, mut g) = (1.0f64, 0.75f64.sqrt());
    for _ in 0..10 {
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    let period = std::f64::consts::PI / a;
    assert_eq!(events.len(), (35000.0 / period) as usize);
    let time_bound = f(&summary["event_time_bound"]);
    assert!(time_bound < 1e-6, "event-time bound {time_bound:e}");
    for (j, ev) in events.iter().enumerate() {
        let (t, exact) = (f(&ev["t"]), (j + 1) as f64 * period);
        assert!(
            (t - exact).abs() <= time_bound,
            "impact {}: {t} against {exact}",
            j + 1
        );
    }
    let bound = f(&summary["error_bound"]);
    assert!(bound < 1e-6, "state bound {bound:e}");
}
