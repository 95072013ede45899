//! Lyapunov spectra through impacts (`flicker lyapunov`), against answers
//! that do not come from flicker: what the dynamics fixes of the sum of
//! the exponents, a map whose exponent is known in closed form, and an
//! integrable system's zeros.

use serde_json::{Value, json};

use crate::support::{flicker, models, read_json};

/// `flicker lyapunov SCENE ARGS...` on a scene file: its exit code and
/// lyapunov.json (if written).
fn lyapunov(scene: &Value, args: &[&str]) -> (Option<i32>, Option<Value>, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let out = dir.path().join("out");
    let mut all = vec![
        "lyapunov",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ];
    all.extend_from_slice(args);
    let done = flicker(&all);
    let json = out.join("lyapunov.json");
    (
        done.status.code(),
        json.exists().then(|| read_json(&json)),
        String::from_utf8_lossy(&done.stderr).into_owned(),
    )
}

fn exponents(found: &Value) -> Vec<f64> {
    found["exponents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// A ball on a table moving as `A sin(w t)`, restitution `r` (Holmes):
/// the flight keeps phase volume and each impact's saltation matrix has
/// determinant `r^2`, so the exponents (the clock's 0 among them) sum to
/// `2 ln(r)` times the impacts per unit time, to 1e-6.
#[test]
fn the_table_ball_s_exponents_sum_to_its_restitution_s_volume_loss() {
    let scene = read_json(std::path::Path::new(&models(
        "automata/vibrating_table.json",
    )));
    let (code, found, err) = lyapunov(&scene, &["--t-end", "200", "--transient", "2"]);
    assert_eq!(code, Some(0), "{err}");
    let found = found.unwrap();
    let l = exponents(&found);
    assert_eq!(l.len(), 3, "y, v and the clock");
    let rate = found["events"].as_f64().unwrap() / found["t_span"].as_f64().unwrap();
    assert!(rate > 1.0, "the ball impacts ({rate} per unit time)");
    let expected = 2.0 * 0.5f64.ln() * rate;
    let sum: f64 = l.iter().sum();
    assert!(
        (sum - expected).abs() < 1e-6,
        "sum {sum} against {expected}"
    );
    assert!(l.iter().any(|x| x.abs() < 1e-9), "the clock's 0: {l:?}");
}

/// Henon-Heiles in its chaotic sea (E = 0.16, from x = 0, y = -0.2): a
/// Hamiltonian flow, so the exponents sum to 0 and come in pairs
/// `(l, -l)`, the flow's direction and the energy's giving the pair that
/// tends to 0 (as ln(t)/t); the largest is clearly positive.
#[test]
fn henon_heiles_s_exponents_come_in_pairs_that_sum_to_zero() {
    let (e, y) = (0.16_f64, -0.2_f64);
    let px = (2.0 * (e - (y * y / 2.0 - y.powi(3) / 3.0))).sqrt();
    let scene = json!({"model": "automaton",
        "states": ["x", "y", "px", "py"],
        "initial": {"x": 0.0, "y": y, "px": px, "py": 0.0},
        "modes": {"m": {"flow": {"x": "px", "y": "py", "px": "-x - 2 * x * y", "py": "-y - x^2 + y^2"},
            "transitions": [{"name": "section", "guard": "x", "direction": "rising"}]}},
        "t_end": 3000.0});
    let (code, found, err) = lyapunov(&scene, &[]);
    assert_eq!(code, Some(0), "{err}");
    let l = exponents(&found.unwrap());
    assert!(l.iter().sum::<f64>().abs() < 1e-9, "{l:?}");
    assert!(l[0] > 0.05, "chaotic: {l:?}");
    assert!((l[0] + l[3]).abs() < 1e-3 * l[0], "{l:?}");
    let zero = 2.0 * 3000f64.ln() / 3000.0;
    assert!(l[1].abs() < zero && l[2].abs() < zero, "{l:?}");
}

/// The paper's mechanism is integrable: neighbouring orbits part only by
/// the shear of their periods, linearly in time, so both exponents tend to
/// 0 as ln(t)/t: they are within 2 ln(t)/t of 0, the larger above a fifth
/// of it (the shear is there), in both formulations (the strain's to
/// t = 10^4; the angle's, integrated numerically, to 10^3).
#[test]
fn the_mechanism_s_exponents_tend_to_zero_as_log_t_over_t() {
    for (name, t) in [
        ("mechanism_impacting.json", 10000.0_f64),
        ("mechanism_angle.json", 1000.0),
    ] {
        let scene = read_json(std::path::Path::new(&models(name)));
        let (code, found, err) = lyapunov(&scene, &["--t-end", &t.to_string()]);
        assert_eq!(code, Some(0), "{name}: {err}");
        let l = exponents(&found.unwrap());
        let scale = t.ln() / t;
        assert!(l.iter().all(|x| x.abs() < 2.0 * scale), "{name}: {l:?}");
        assert!(l[0] > 0.2 * scale, "{name}: {l:?}");
    }
}

/// A hybrid system whose return map is the tent map `x -> mu min(x, 1 -
/// x)`, one iterate per unit time: its exponent is `ln(mu)` (the map's
/// slope is `mu` everywhere), the clock-like `s` gives 0.
#[test]
fn a_tent_map_in_resets_has_exponent_log_mu() {
    let scene = json!({"model": "automaton", "parameters": {"mu": 1.99},
        "states": ["x", "s"], "initial": {"x": 0.3141592653589793, "s": 0},
        "modes": {"m": {"flow": {"x": "0", "s": "1"},
            "transitions": [{"name": "iterate", "guard": "s - 1", "direction": "rising",
                "reset": {"x": "mu * min(x, 1 - x)", "s": "0"}}]}},
        "t_end": 2000.0});
    let (code, found, err) = lyapunov(&scene, &["--interval", "10"]);
    assert_eq!(code, Some(0), "{err}");
    let l = exponents(&found.unwrap());
    assert!((l[0] - 1.99f64.ln()).abs() < 1e-3, "{l:?}");
    assert!(l[1].abs() < 1e-9, "{l:?}");
}

/// A hybrid flow in two dimensions whose single exponents its period map
/// gives in closed form: `x' = x`, `y' = -0.3 y`, and where `x` reaches 2
/// the reset `x -> 1`, `y -> y / 2 + 1` (a period of `T = ln 2`). Over one
/// period the flow's tangent is `diag(2, 2^-0.3)` and the saltation
/// matrix `[[1/2, 0], [-0.15, 1/2]]` (the reset's Jacobian `diag(0, 1/2)`
/// corrected by the jump in the flow, `(f+ - DR f-) e_x / 2`), so the map
/// is `[[1, 0], [-0.3, 2^-1.3]]`: exponents 0 (the flow's own direction)
/// and `log2(2^-1.3) = -1.3` per unit time. The reset's Jacobian alone
/// would give minus infinity for the first.
#[test]
fn a_hybrid_linear_flow_has_the_exponents_its_saltation_gives() {
    let scene = json!({"model": "automaton", "states": ["x", "y"], "initial": {"x": 1.0, "y": 0.0},
        "modes": {"m": {"flow": {"x": "x", "y": "-0.3 * y"},
            "transitions": [{"name": "kick", "guard": "x - 2", "direction": "rising",
                "reset": {"x": "1", "y": "0.5 * y + 1"}}]}},
        "t_end": 2000.0});
    let (code, found, err) = lyapunov(&scene, &["--interval", "10"]);
    assert_eq!(code, Some(0), "{err}");
    let l = exponents(&found.unwrap());
    assert_eq!(l.len(), 2, "{l:?}");
    assert!(l[0].abs() < 1e-3, "{l:?}");
    assert!((l[1] + 1.3).abs() < 1e-3, "{l:?}");
}

/// Bad requests are refused before anything runs (exit 2, naming the
/// flag); the continuum has no finite state; a spectrum past its wall
/// budget stops, says so and exits 3, keeping what it measured.
#[test]
fn bad_requests_are_refused_and_a_spent_budget_stops_the_spectrum() {
    let scene = read_json(std::path::Path::new(&models("mechanism_impacting.json")));
    for (args, says) in [
        (vec!["--exponents", "3"], "--exponents"),
        (vec!["--interval", "0"], "--interval"),
        (vec!["--t-end", "-1"], "--t-end"),
        (vec!["--interval", "2000"], "--interval"),
    ] {
        let (code, found, err) = lyapunov(&scene, &args);
        assert_eq!(code, Some(2), "{args:?}: {err}");
        assert!(err.contains(says) && found.is_none(), "{args:?}: {err}");
    }
    let continuum = read_json(std::path::Path::new(&models(
        "continuum_release_paper.json",
    )));
    let (code, _, err) = lyapunov(&continuum, &[]);
    assert_eq!(code, Some(2));
    assert!(err.contains("no finite state"), "{err}");
    let (code, found, err) = lyapunov(&scene, &["--t-end", "1e9", "--wall", "0.3"]);
    assert_eq!(code, Some(3), "{err}");
    assert!(err.contains("wall-clock budget"), "{err}");
    let found = found.unwrap();
    assert!(found["t_span"].as_f64().unwrap() > 0.0);
    assert!(!found["history"].as_array().unwrap().is_empty());
}

/// The largest exponent predicts the chain's reproducibility horizon
/// (`flicker run --ensemble`): copies perturbed by `delta` part by 1e-3 at
/// about `ln(1e-3 / delta) / l1`, so a thousandfold smaller perturbation
/// buys `ln(1000) / l1` more time. A 10-unit chain: the horizons at 1e-12
/// and 1e-9 differ by that to within 25% (the growth is exponential only
/// on average, impact by impact).
#[test]
fn the_largest_exponent_predicts_the_chain_s_horizon() {
    let mut chain = crate::support::ten_unit_chain(600.0);
    chain["samples"] = json!(6001);
    let (code, found, err) = lyapunov(&chain, &["--exponents", "1"]);
    assert_eq!(code, Some(0), "{err}");
    let l1 = exponents(&found.unwrap())[0];
    assert!(l1 > 0.01, "the chain is chaotic: {l1}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chain.json");
    std::fs::write(&path, chain.to_string()).unwrap();
    let horizon = |perturb: &str| {
        let out = dir.path().join(perturb);
        let done = flicker(&[
            "run",
            path.to_str().unwrap(),
            "--ensemble",
            "8",
            "--perturb",
            perturb,
            "--no-events",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            done.status.success(),
            "{}",
            String::from_utf8_lossy(&done.stderr)
        );
        read_json(&out.join("summary.json"))["ensemble"]["horizon"]
            .as_f64()
            .unwrap()
    };
    let gained = horizon("1e-12") - horizon("1e-9");
    let predicted = 1000f64.ln() / l1;
    assert!(
        (gained / predicted - 1.0).abs() < 0.25,
        "the horizon moved by {gained}, ln(1000) / l1 = {predicted}"
    );
}

/// The spectrum's settings resolved once for the command line and Python
/// (`flicker::session::SpectrumRequest`): unset, they follow the scene (all
/// exponents of the state, averaged to its `t_end`, re-orthonormalised
/// every quarter of its time scale); a wrong one is refused naming its
/// field before anything runs.
#[test]
fn a_spectrum_request_follows_the_scene_where_unset_and_names_a_bad_field() {
    use flicker::scene::Registry;
    use flicker::session::SpectrumRequest;
    let scene = Registry::builtin()
        .load(std::path::Path::new(&models(
            "automata/impact_oscillator.json",
        )))
        .expect("the bundled scene loads");
    let family = scene.family().expect("an automaton has a family");
    let asked = SpectrumRequest {
        exponents: None,
        transient: 0.0,
        t_end: None,
        interval: None,
        wall: 60.0,
    };
    let request = asked.resolve(&scene, &*family, None).expect("resolves");
    assert_eq!(request.exponents, family.model().dimension());
    assert_eq!(request.span, scene.t_end());
    assert_eq!(
        request.interval,
        (scene.time_scale() / 4.0).min(scene.t_end())
    );
    assert!(request.deadline.is_some());
    for (bad, field) in [
        (
            SpectrumRequest {
                exponents: Some(0),
                ..asked.clone()
            },
            "exponents",
        ),
        (
            SpectrumRequest {
                wall: -1.0,
                ..asked.clone()
            },
            "wall",
        ),
    ] {
        let refused = bad.resolve(&scene, &*family, None).expect_err("refused");
        assert_eq!(refused.field.as_deref(), Some(field), "{}", refused.reason);
    }
}
