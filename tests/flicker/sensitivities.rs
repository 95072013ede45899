//! Sensitivities through flows and resets (`--sensitivities`): against
//! central finite differences of plain runs (1e-6 relative), and against
//! closed forms: the mechanism's `dT_imp / d eta`, the bouncing ball's
//! bounce times and Zeno point with respect to its restitution.

use serde_json::{Value, json};

use flicker::engine::Limits;
use flicker::engine::Recorder;
use flicker::runner::Report;
use flicker::scene::Registry;
use flicker::session::RunRequest;

use crate::automata::automaton;

fn read(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(automaton(name)).unwrap()).unwrap()
}

/// Run `scene` (with the derivatives along `directions`, if any).
fn run(scene: &Value, directions: &[&str]) -> (Report, Recorder) {
    let scene = Registry::builtin().from_value(scene).unwrap();
    let request = RunRequest {
        sensitivities: (!directions.is_empty())
            .then(|| directions.iter().map(|s| s.to_string()).collect()),
        ..RunRequest::default()
    };
    let run = request.prepare(scene).unwrap();
    let mut events = Recorder::default();
    let (report, _) = run.run(&Limits::default(), &mut events).unwrap();
    assert_eq!(
        report.outcome.status.as_str(),
        "completed",
        "{:?}",
        report.outcome.reason
    );
    (report, events)
}

fn final_state(report: &Report, name: &str) -> f64 {
    report
        .final_state
        .iter()
        .find(|(n, _)| *n == name)
        .unwrap()
        .1
}

/// `scene` with the number at `path` (`parameters.eta`, `initial.x`)
/// moved by `by`.
fn moved(scene: &Value, path: &str, by: f64) -> Value {
    let mut scene = scene.clone();
    let (group, key) = path.split_once('.').unwrap();
    let x = scene[group][key].as_f64().unwrap();
    scene[group][key] = json!(x + by);
    scene
}

/// Every final-state sensitivity of `scene` along `directions` against a
/// central difference of two plain runs with the same method, step `h`
/// relative to the value (or absolute where it is zero).
fn against_differences(scene: &Value, directions: &[&str], states: &[&str], h: f64, tol: f64) {
    let (report, _) = run(scene, directions);
    let s = report.sensitivities.as_ref().unwrap();
    for direction in directions {
        let path = if direction.starts_with("initial.") {
            direction.to_string()
        } else {
            format!("parameters.{direction}")
        };
        let (group, key) = path.split_once('.').unwrap();
        let x = scene[group][key].as_f64().unwrap();
        let step = h * x.abs().max(1.0);
        let (up, _) = run(&moved(scene, &path, step), &[]);
        let (down, _) = run(&moved(scene, &path, -step), &[]);
        for state in states {
            let fd = (final_state(&up, state) - final_state(&down, state)) / (2.0 * step);
            let ours = s[direction]["final_state"][state].as_f64().unwrap();
            assert!(
                (ours - fd).abs() <= tol * fd.abs().max(1.0),
                "d{state}/d{direction}: {ours} against {fd} by differences"
            );
        }
    }
}

/// The mechanism (strain form) to t = 100 by its default, the exact
/// propagator (its derivatives stay affine): along eta, omega and both
/// initial values.
#[test]
fn mechanism_sensitivities_equal_central_differences() {
    let mut scene = read("mechanism.json");
    scene["t_end"] = json!(100.0);
    against_differences(
        &scene,
        &["eta", "omega", "initial.strain", "initial.strain_rate"],
        &["strain", "strain_rate"],
        1e-6,
        1e-6,
    );
}

/// The forced impact oscillator (nonlinear in time, a restitution), by
/// DOP853 at 1e-13 both ways: along the restitution, the damping, the
/// forcing frequency and the initial position.
#[test]
fn forced_oscillator_sensitivities_equal_central_differences() {
    let mut scene = read("impact_oscillator.json");
    scene["t_end"] = json!(40.0);
    scene["solver"] = json!({"method": "dop853", "rtol": 1e-13, "atol": 1e-13});
    against_differences(
        &scene,
        &["r", "zeta", "w", "initial.x"],
        &["x", "v"],
        1e-5,
        1e-6,
    );
}

/// Starting at an impact (`eps = 0`, `eps' = sqrt(2 H0)`, so `H0` does not
/// move with eta), the impacts come every `T = (2 / omega) atan2(sqrt(2
/// H0), 1 - eta)`: each impact time's derivative grows by `dT/d eta = (2 /
/// omega) sqrt(2 H0) / (2 H0 + (1 - eta)^2)` per impact, which the log's
/// `dt/deta` shows to 1e-11 (the automaton's Jacobians are exact; the
/// derivatives grow as `k dT/d eta`, and their rounding with them).
#[test]
fn impact_times_move_with_eta_as_the_closed_form_period_does() {
    let (eta, omega, h0) = (1.2_f64, 1.0_f64, 0.025_f64);
    let mut scene = read("mechanism.json");
    scene["initial"] = json!({"strain": 0.0, "strain_rate": (2.0 * h0).sqrt()});
    scene["t_end"] = json!(200.0);
    let (_, events) = run(&scene, &["eta"]);
    let s = (2.0 * h0).sqrt();
    let slope = 2.0 / omega * s / (s * s + (1.0 - eta).powi(2));
    let dt: Vec<f64> = events
        .events
        .iter()
        .map(|e| *e.after.last().unwrap())
        .collect();
    assert!(dt.len() > 40);
    for (k, pair) in dt.windows(2).enumerate() {
        let step = pair[1] - pair[0];
        assert!(
            (step - slope).abs() < 1e-8 * slope,
            "impact {k}: {step} against {slope}"
        );
    }
    // And the first impact, one period from the start at an impact.
    assert!((dt[0] - slope).abs() < 1e-8 * slope);
}

/// The bouncing ball: bounce k at `t_k = t1 (1 + 2 (e - e^k) / (1 - e))`,
/// so `dt_k/de = 2 t1 (1 - k e^(k-1) + (k - 1) e^k) / (1 - e)^2`, and the
/// Zeno point `t* = t1 (1 + e) / (1 - e)` moves by `2 t1 / (1 - e)^2`. The
/// log's `dt/de` meets the first to 1e-9 over the first 30 bounces, and the
/// last of them is within `e^30` of the second; `dt/dinitial.y` is
/// `t_k / (2 h)` (every time scales as `sqrt(h)`).
#[test]
fn bounce_times_and_the_zeno_point_move_with_the_restitution_as_the_closed_form() {
    let (g, e, h) = (9.81_f64, 0.8_f64, 1.0_f64);
    let t1 = (2.0 * h / g).sqrt();
    let mut scene = read("bouncing_ball.json");
    scene["t_end"] = json!(4.06);
    let registry_scene = Registry::builtin().from_value(&scene).unwrap();
    let request = RunRequest {
        sensitivities: Some(vec!["e".to_string(), "initial.y".to_string()]),
        ..RunRequest::default()
    };
    let mut events = Recorder::default();
    request
        .prepare(registry_scene)
        .unwrap()
        .run(&Limits::default(), &mut events)
        .unwrap();
    let n = events.events[0].after.len();
    let (de, dy) = (n - 2, n - 1);
    for (k, ev) in events.events.iter().take(30).enumerate() {
        let k = (k + 1) as f64;
        let t = t1 * (1.0 + 2.0 * (e - e.powf(k)) / (1.0 - e));
        let dt_de =
            2.0 * t1 * (1.0 - k * e.powf(k - 1.0) + (k - 1.0) * e.powf(k)) / (1.0 - e).powi(2);
        assert!((ev.t - t).abs() < 1e-13, "bounce {k}");
        assert!(
            (ev.after[de] - dt_de).abs() < 1e-9 * dt_de.abs().max(1.0),
            "bounce {k}: dt/de {} against {dt_de}",
            ev.after[de]
        );
        assert!(
            (ev.after[dy] - t / (2.0 * h)).abs() < 1e-9,
            "bounce {k}: dt/dy"
        );
    }
    let zeno = 2.0 * t1 / (1.0 - e).powi(2);
    let last = events.events[29].after[de];
    assert!(
        (last - zeno).abs() < e.powi(28) * 30.0 * zeno,
        "{last} against {zeno}"
    );
}

/// A direction that is neither a parameter nor an initial value, or a
/// model without a finite state, is refused with the names it knows.
#[test]
fn unknown_directions_are_refused() {
    let scene = Registry::builtin()
        .from_value(&read("mechanism.json"))
        .unwrap();
    let check = |scene: &flicker::scene::Scene, name: &str| {
        flicker::analysis::sensitivities::check(scene, &[name.to_string()]).unwrap_err()
    };
    let err = check(&scene, "etta");
    assert!(err.reason.contains("no parameter is called `etta`") && err.reason.contains("eta"));
    let err = check(&scene, "initial.speed");
    assert!(err.reason.contains("strain, strain_rate"));
    let builtin = Registry::builtin()
        .load(std::path::Path::new(&crate::support::models(
            "mechanism_impacting.json",
        )))
        .unwrap();
    let err = check(&builtin, "etta");
    assert!(
        err.reason.contains("(parameters: eta, omega;"),
        "{}",
        err.reason
    );
    let continuum = Registry::builtin()
        .load(std::path::Path::new(&crate::support::models(
            "continuum_release_paper.json",
        )))
        .unwrap();
    let err = check(&continuum, "load");
    assert!(err.reason.contains("no finite state"), "{}", err.reason);
}

/// The exact linear propagator asked for where a direction makes a flow
/// non-affine (`omega^2 strain` with `omega` carried as a state) is
/// refused with the methods that do run (exit 2), before the output
/// folder's event log from an earlier run is touched.
#[test]
fn the_linear_propagator_is_refused_where_the_derivatives_are_not_affine() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("events.jsonl");
    std::fs::write(&log, "an earlier run's events\n").unwrap();
    let done = crate::support::flicker(&[
        "run",
        &automaton("mechanism.json"),
        "--sensitivities",
        "omega",
        "--method",
        "linear",
        "--quiet",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(done.status.code(), Some(2));
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(
        said.contains("linear propagator") && said.contains("dop853"),
        "{said}"
    );
    assert_eq!(
        std::fs::read_to_string(&log).unwrap(),
        "an earlier run's events\n"
    );
}
