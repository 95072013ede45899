//! The tools run on every model with a finite state, through its family
//! (`Family`), not on automata alone: the built-in mechanism's impacting
//! orbit and its sensitivities against the closed form, in both
//! formulations; a chain's sensitivities against central differences of
//! plain runs; the continuum refused in one line.

use serde_json::{Value, json};

use flicker::engine::Limits;
use flicker::engine::{Method, Options, simulate};
use flicker::models::mechanism::{ExactOrbit, Mechanism, Phase};
use flicker::scene::{Registry, Scene};
use flicker::session::RunRequest;

use crate::support::{flicker, models, read_json};

/// `flicker orbit SCENE --section impact`, its orbit.json.
fn orbit(scene: &str) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("orbit");
    let done = flicker(&[
        "orbit",
        &models(scene),
        "--section",
        "impact",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    read_json(&out.join("orbit.json"))
}

/// The bundled impacting mechanism (eta 1.2, H0 0.05 from the apex):
/// `T_imp = 2 atan2(sqrt(2 H0), 1 - eta) / omega`.
fn t_imp() -> f64 {
    Mechanism {
        eta: 1.2,
        omega: 1.0,
    }
    .impact_period(0.05)
}

/// The period is `T_imp` and both multipliers are 1 (the flow's
/// direction, and the family of orbits by energy: the mechanism is
/// integrable), in the strain formulation (exact propagator, to 1e-12)
/// and the angle formulation (DOP853 and its chart changes, to 1e-9),
/// where the section is `theta` crossing zero and the orbit returns on
/// the other side, in the same strain.
#[test]
fn the_mechanism_s_impacting_orbit_has_the_closed_form_period_in_both_formulations() {
    for (scene, tol) in [
        ("mechanism_impacting.json", 1e-12),
        ("mechanism_angle.json", 1e-9),
    ] {
        let o = orbit(scene);
        assert_eq!(o["converged"], true, "{scene}: {o}");
        let period = o["period"].as_f64().unwrap();
        assert!(
            (period - t_imp()).abs() < tol * t_imp(),
            "{scene}: period {period} against {}",
            t_imp()
        );
        let multipliers = o["multipliers"].as_array().unwrap();
        assert_eq!(multipliers.len(), 2, "{scene}: {o}");
        for z in multipliers {
            let (re, im) = (z[0].as_f64().unwrap(), z[1].as_f64().unwrap());
            assert!(
                (re - 1.0).abs() < 1e-8 && im.abs() < 1e-8,
                "{scene}: multiplier {re} + {im}i"
            );
        }
        assert_eq!(o["stable"], true, "{scene}: neutral, as conservative");
        // At the section the strain is zero and opening at the speed of H0.
        let rate = o["section_state"]["strain_rate"].as_f64().unwrap();
        assert!(o["section_state"]["strain"].as_f64().unwrap().abs() < 1e-12);
        assert!((rate - 0.1f64.sqrt()).abs() < 1e-9, "{scene}: {rate}");
    }
}

/// The run with derivatives along `directions`: its summary's
/// sensitivities.
fn sensitivities(scene: Scene, directions: &[&str]) -> Value {
    let request = RunRequest {
        sensitivities: Some(directions.iter().map(|s| s.to_string()).collect()),
        ..RunRequest::default()
    };
    let run = request.prepare(scene).unwrap();
    let (report, _) = run.run(&Limits::default(), &mut ()).unwrap();
    assert_eq!(report.outcome.status.as_str(), "completed");
    report.sensitivities.unwrap()
}

/// The built-in mechanism's final strain and rate after `t_end = 50` (11
/// impacts) along `eta` (which also moves the start: the scene gives an
/// energy at the apex) and `initial.strain`, against central differences
/// of the closed form (46) to 1e-6.
#[test]
fn the_mechanism_s_sensitivities_meet_differences_of_the_closed_form() {
    let mut text = read_json(std::path::Path::new(&models("mechanism_impacting.json")));
    text["t_end"] = json!(50.0);
    let scene = Registry::builtin().from_value(&text).unwrap();
    let s = sensitivities(scene, &["eta", "initial.strain"]);
    let at = |eta: f64, d_strain: f64| {
        let m = Mechanism { eta, omega: 1.0 };
        let (e, r) = m.state_with_energy(0.05, Phase::Apex).unwrap();
        let (e, r) = ExactOrbit::new(m, e + d_strain, r).state_at(50.0);
        [e, r]
    };
    let h = 1e-6;
    let by_eta = |k: usize| (at(1.2 + h, 0.0)[k] - at(1.2 - h, 0.0)[k]) / (2.0 * h);
    let by_strain = |k: usize| (at(1.2, h)[k] - at(1.2, -h)[k]) / (2.0 * h);
    for (k, name) in ["strain", "strain_rate"].into_iter().enumerate() {
        for (direction, expected) in [("eta", by_eta(k)), ("initial.strain", by_strain(k))] {
            let got = s[direction]["final_state"][name].as_f64().unwrap();
            assert!(
                (got - expected).abs() < 1e-6 * expected.abs().max(1.0),
                "d{name}/d{direction}: {got} against {expected}"
            );
        }
    }
}

/// A chain of 10 units that impacts: the final positions and velocities'
/// sensitivities along a node's initial position and along the end load
/// meet central differences of plain runs of the same chain (the exact
/// linear propagator) to 1e-6.
#[test]
fn a_chain_s_sensitivities_meet_differences_of_plain_runs() {
    let chain = |load: f64| {
        let mut chain = crate::support::ten_unit_chain(6.0);
        chain["load"]["after"] = json!(load);
        chain
    };
    let scene = Registry::builtin().from_value(&chain(1.3)).unwrap();
    let s = sensitivities(scene, &["initial.y_4", "load"]);
    let plain = |load: f64, dy4: f64| {
        let scene = Registry::builtin().from_value(&chain(load)).unwrap();
        let family = scene.family().unwrap();
        let (mode, mut x0) = family.start();
        x0[3] += dy4;
        let options = Options {
            method: Method::Linear,
            ..Options::until(6.0)
        };
        let out = simulate(family.model(), mode, &x0, &options, &mut ());
        assert_eq!(out.status.as_str(), "completed");
        assert!(out.events > 5, "the chain impacts ({} events)", out.events);
        out.final_state
    };
    let h = 1e-6;
    let (up_y, down_y) = (plain(1.3, h), plain(1.3, -h));
    let (up_l, down_l) = (plain(1.3 + h, 0.0), plain(1.3 - h, 0.0));
    let names: Vec<String> = (1..=10)
        .map(|n| format!("y_{n}"))
        .chain((1..=10).map(|n| format!("v_{n}")))
        .collect();
    for (k, name) in names.iter().enumerate() {
        for (direction, expected) in [
            ("initial.y_4", (up_y[k] - down_y[k]) / (2.0 * h)),
            ("load", (up_l[k] - down_l[k]) / (2.0 * h)),
        ] {
            let got = s[direction]["final_state"][name].as_f64().unwrap();
            assert!(
                (got - expected).abs() < 1e-6 * expected.abs().max(1.0),
                "d{name}/d{direction}: {got} against {expected}"
            );
        }
    }
}

/// The continuum has no finite state: `orbit` and `--sensitivities` say so
/// in one line and exit 2.
#[test]
fn the_continuum_refuses_the_tools_in_one_line() {
    let scene = models("continuum_release_paper.json");
    for args in [
        vec!["orbit", scene.as_str(), "--section", "impact"],
        vec![
            "continue",
            scene.as_str(),
            "--section",
            "impact",
            "--param",
            "load",
            "--to",
            "1",
        ],
        vec!["lyapunov", scene.as_str()],
        vec!["run", scene.as_str(), "--sensitivities", "load"],
    ] {
        let done = flicker(&args);
        assert_eq!(done.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&done.stderr);
        assert!(err.contains("no finite state"), "{err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}

/// The search the command line runs is the session's (`SearchRequest::on`
/// then `Prepared::orbit`), which Python runs too: the same orbit to the
/// bit, and the continuum refused naming the field `model`.
#[test]
fn the_session_s_search_is_the_one_the_command_line_runs() {
    use flicker::session::SearchRequest;
    let asked = SearchRequest {
        section: "impact".into(),
        events: 1,
        settle: 0.0,
        forcing_period: None,
        wall: 60.0,
    };
    let load = |name: &str| {
        Registry::builtin()
            .load(std::path::Path::new(&models(name)))
            .expect("the bundled scene loads")
    };
    let found = asked
        .on(&load("mechanism_impacting.json"), None)
        .expect("the mechanism has a family")
        .orbit(Default::default())
        .expect("a valid search");
    assert!(found.converged, "{}", found.status);
    let cli = orbit("mechanism_impacting.json");
    assert_eq!(found.period, cli["period"].as_f64().unwrap());
    assert!((found.period - t_imp()).abs() < 1e-12 * t_imp());
    let refused = asked
        .on(&load("continuum_release_paper.json"), None)
        .err()
        .expect("the continuum has no family");
    assert_eq!(
        refused.field.as_deref(),
        Some("model"),
        "{}",
        refused.reason
    );
}

/// A model that names no states (the chain) names none of their
/// derivatives in its log either: names and values are paired in order,
/// and a partial list would put `dt/dload` on a node's position.
#[test]
fn a_chain_s_log_with_sensitivities_mislabels_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = crate::support::ten_unit_chain(6.0);
    let path = dir.path().join("chain.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let out = dir.path().join("out");
    let done = flicker(&[
        "run",
        path.to_str().unwrap(),
        "--sensitivities",
        "load",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    assert!(log.lines().count() > 5);
    for line in log.lines() {
        let event: Value = serde_json::from_str(line).unwrap();
        assert_eq!(event["before"], json!({}), "{line}");
        assert_eq!(event["after"], json!({}), "{line}");
    }
}
