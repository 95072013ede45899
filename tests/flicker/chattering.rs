//! A ball that chatters down onto its table says so in the same words by
//! every method and every tool, and names the cure; given a resting mode,
//! every method settles into it.
//!
//! The bundled table ball at restitution 0.5 and `Gamma = A w^2 / g = 0.5`
//! (the table never pulls away faster than gravity), dropped from 0.1:
//! its bounces shrink by half each time and pile up at t = 0.4728. The
//! exact propagator and Taylor's method lose the bounces to their error
//! bound (their order can no longer be told) before the Zeno watch's
//! resolution, Runge-Kutta to the watch or to a graze it cannot decide:
//! each once said something else (`cannot be trusted ... use an exact
//! one`, of an exact method; `zeno`; `the transient failed`).

use serde_json::{Value, json};

use crate::automata::{automaton, f, run_value};
use crate::support::{flicker, read_json};

/// The table ball that sticks; with `rest`, a resting mode in which it
/// moves with the table (which it never leaves: the table's acceleration
/// stays below g).
fn sticking(rest: bool) -> Value {
    let text = std::fs::read_to_string(automaton("vibrating_table.json")).unwrap();
    let mut scene: Value = serde_json::from_str(&text).unwrap();
    let p = &mut scene["parameters"];
    p["r"] = json!(0.5);
    p["A"] = json!(0.5 * f(&p["g"]) / (f(&p["w"]) * f(&p["w"])));
    scene["initial"] = json!({"y": 0.1, "v": 0.0});
    scene["t_end"] = json!(2.0);
    if rest {
        scene["initial_mode"] = json!("flight");
        scene["modes"]["flight"]["rest"] =
            json!({"to": "stuck", "reset": {"y": "A * sin(w * t)", "v": "A * w * cos(w * t)"}});
        scene["modes"]["stuck"] =
            json!({"flow": {"y": "A * w * cos(w * t)", "v": "-A * w^2 * sin(w * t)"}});
    }
    scene
}

const METHODS: [&[&str]; 5] = [
    &["--method", "linear"],
    &["--method", "taylor"],
    &["--method", "dop853"],
    &["--method", "dop853", "--rtol", "1e-13", "--atol", "1e-13"],
    &["--method", "dopri5"],
];

/// The words every stop at a pile-up says: what happens, and the cure.
fn names_the_chattering(reason: &str, what: &str) {
    for words in [
        "events of guard `impact` accumulate at t = ",
        "faster than the run can resolve",
        "the events pile up at the guard (an orbit chattering down onto it",
        "names one with `rest`",
    ] {
        assert!(reason.contains(words), "{what}: {words:?} not in {reason}");
    }
}

#[test]
fn a_chattering_ball_is_named_so_by_every_method() {
    let scene = sticking(false);
    let mut ends = Vec::new();
    for args in METHODS {
        let (summary, _) = run_value(&scene, args);
        let what = format!("{args:?}");
        assert_eq!(summary["status"], "zeno", "{what}: {summary}");
        names_the_chattering(summary["reason"].as_str().unwrap(), &what);
        ends.push(f(&summary["t_reached"]));
    }
    // All stop at the pile-up (closed form: about 0.4728), whichever
    // noticed it.
    for t in &ends {
        assert!((t - 0.4728).abs() < 2e-3, "{ends:?}");
    }
}

#[test]
fn lyapunov_names_the_same_cause() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("table.json");
    std::fs::write(&path, sticking(false).to_string()).unwrap();
    for transient in ["1", "0"] {
        let out = dir.path().join(format!("lyapunov-{transient}"));
        let result = flicker(&[
            "lyapunov",
            path.to_str().unwrap(),
            "--transient",
            transient,
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ]);
        assert!(!result.status.success());
        let spectrum = read_json(&out.join("lyapunov.json"));
        names_the_chattering(
            spectrum["status"].as_str().unwrap(),
            &format!("transient {transient}"),
        );
    }
}

#[test]
fn given_a_resting_mode_every_method_settles_into_it() {
    let scene = sticking(true);
    let (a, w) = (0.5 * 9.81 / 100.0, 10.0_f64);
    for args in METHODS {
        let (summary, events) = run_value(&scene, args);
        let what = format!("{args:?}");
        assert_eq!(summary["status"], "zeno", "{what}: {summary}");
        assert_eq!(f(&summary["t_reached"]), 2.0, "{what}");
        assert!(
            summary["reason"]
                .as_str()
                .unwrap()
                .ends_with("settled into `stuck`"),
            "{what}"
        );
        assert_eq!(events.last().unwrap()["guard"], "settle", "{what}");
        // On the table at the end, within the bound (the settling's jump
        // carried in it).
        let y = f(&summary["final_state"]["y"]);
        let bound = f(&summary["error_bound"]);
        assert!(
            (y - a * (2.0 * w).sin()).abs() <= bound,
            "{what}: y {y}, bound {bound}"
        );
    }
}
