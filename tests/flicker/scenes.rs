//! Every scene shipped in `models/` loads and runs to the outcome its
//! description promises, checked against the closed form (written out in
//! [`crate::oscillator`]) where one exists.

use std::path::Path;

use flicker::engine::Limits;
use flicker::engine::Status;
use flicker::models::mechanism::Mechanism;
use flicker::models::{self as scene, ChainScene, ContinuumScene, Formulation, MechanismScene};
use flicker::runner::Report;
use flicker::scene::Scene;

use crate::oscillator::Unit;

/// What each shipped scene must do.
const EXPECTED: &[(&str, Status)] = &[
    ("chain_cradle.json", Status::Completed),
    ("chain_release_classical.json", Status::Completed),
    ("chain_release_free_end.json", Status::Completed),
    ("chain_release_paper.json", Status::Completed),
    ("continuum_homogenized_free_end.json", Status::Completed),
    ("continuum_homogenized_paper.json", Status::Completed),
    ("continuum_release_classical.json", Status::Completed),
    ("continuum_release_free_end.json", Status::Completed),
    ("continuum_release_paper.json", Status::Completed),
    ("mechanism_angle.json", Status::Completed),
    ("mechanism_angle_plain.json", Status::Failed),
    ("mechanism_chattering.json", Status::Zeno),
    ("mechanism_critical.json", Status::Completed),
    ("mechanism_impacting.json", Status::Completed),
    ("mechanism_loose.json", Status::Completed),
    ("mechanism_near_grazing.json", Status::Completed),
    ("mechanism_resting.json", Status::Zeno),
    ("mechanism_separatrix.json", Status::Completed),
    ("mechanism_subcritical.json", Status::Completed),
];

fn run_file(path: &Path) -> (Scene, Report) {
    let scene = scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let report = scene.run(&Limits::default(), &mut ()).unwrap();
    (scene, report)
}

#[test]
fn every_shipped_scene_runs_to_its_expected_outcome() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".json"))
        .collect();
    files.sort();
    let listed: Vec<&str> = EXPECTED.iter().map(|(n, _)| *n).collect();
    assert_eq!(
        files, listed,
        "every scene in models/ needs an expected outcome here"
    );
    for (name, status) in EXPECTED {
        let (scene, report) = run_file(&dir.join(name));
        let o = &report.outcome;
        assert_eq!(o.status, *status, "{name}: {:?}", o.reason);
        let m = if let Some(m) = scene.downcast_ref::<MechanismScene>() {
            m.clone()
        } else if let Some(c) = scene.downcast_ref::<ChainScene>() {
            // Chains: exact flow, so energy and the momentum balance
            // hold to round-off whatever the (chaotic) details.
            assert_eq!(o.t_reached, c.t_end, "{name}");
            assert!(
                o.max_energy_error.unwrap() < 1e-12,
                "{name}: {:?}",
                o.max_energy_error
            );
            let chain = report.fields.as_ref().unwrap();
            assert!(chain.momentum_balance_error.unwrap() < 1e-12, "{name}");
            assert_eq!(chain.profiles.len(), c.snapshots.len(), "{name}");
            assert_eq!(chain.trace.len(), c.samples, "{name}");
            assert_eq!(
                o.events > 0,
                c.constraint,
                "{name}: impacts iff constrained"
            );
            continue;
        } else {
            let c = scene.downcast_ref::<ContinuumScene>().unwrap();
            // Exact front tracking: energy and momentum to round-off.
            assert_eq!(o.t_reached, c.t_end, "{name}");
            assert!(o.max_energy_error.unwrap() < 1e-12, "{name}");
            let fields = report.fields.as_ref().unwrap();
            assert!(fields.momentum_balance_error.unwrap() < 1e-12, "{name}");
            assert_eq!(fields.profiles.len(), c.snapshots.len(), "{name}");
            assert_eq!(fields.trace.len(), c.samples, "{name}");
            continue;
        };
        if o.status == Status::Failed {
            continue;
        }
        assert_eq!(o.t_reached, m.t_end, "{name}");
        // Exact impact counts and states against the closed form, written
        // out in crate::oscillator; the numerical angle formulation to its
        // integration tolerance.
        let exact = Unit {
            eta: m.mechanism.eta,
            omega: m.mechanism.omega,
        };
        if o.status == Status::Completed {
            let x0 = m.initial_strain;
            assert_eq!(o.events, exact.impacts_until(x0, m.t_end), "{name}");
            let (eps, rate) = exact.state_at(x0, m.t_end);
            let tol = if m.formulation == Formulation::Strain {
                1e-11
            } else {
                1e-7
            };
            let final_state = &report.final_state;
            assert!(
                (final_state[0].1 - eps).abs() < tol,
                "{name}: strain {} vs {eps}",
                final_state[0].1
            );
            assert!(
                (final_state[1].1 - rate).abs() < tol,
                "{name}: rate {} vs {rate}",
                final_state[1].1
            );
        }
        let max_error = o.max_energy_error.unwrap();
        assert!(
            max_error
                < if m.formulation == Formulation::Strain {
                    1e-14
                } else {
                    1e-8
                },
            "{name}: {max_error}"
        );
    }
}

#[test]
fn the_issue_example_scene_parses_as_written() {
    let text = r#"{"model": "mechanism", "formulation": "strain", "eta": 1.2, "omega": 1.0,
        "initial": {"strain": 0.05, "strain_rate": 0.0}, "t_end": 1000.0}"#;
    let scene = scene::parse(text).unwrap();
    let Some(m) = scene.downcast_ref::<MechanismScene>() else {
        panic!("a mechanism scene")
    };
    assert_eq!(
        m.mechanism,
        Mechanism {
            eta: 1.2,
            omega: 1.0
        }
    );
    assert_eq!(m.initial_strain, (0.05, 0.0));
}

#[test]
fn each_scene_offers_the_methods_its_model_can_take() {
    let methods = |name: &str| {
        let scene = scene::load(Path::new(&format!(
            "{}/models/{name}",
            env!("CARGO_MANIFEST_DIR")
        )))
        .unwrap();
        scene.methods()
    };
    // The strain formulation: a closed form, a linear flow x' = A x + b,
    // and q'' = a(q), so every method.
    let all = ["exact", "linear", "dopri5", "dop853", "verlet"];
    assert_eq!(methods("mechanism_impacting.json"), all);
    // The angle formulation: a nonlinear ODE whose acceleration depends on
    // the rate, so the embedded pairs only.
    assert_eq!(methods("mechanism_angle.json"), ["dopri5", "dop853"]);
    // A chain: its exact Taylor flow, and as a linear ODE every method.
    assert_eq!(methods("chain_cradle.json"), all);
    // The continuum runs by front tracking only.
    assert_eq!(methods("continuum_release_paper.json"), ["exact"]);
    // A chain too long for the ODE path keeps its exact flow alone.
    let long = r#"{"model": "chain", "units": 5000, "length": 2.0, "wave_speed": 1.0,
        "load": {"before": 1.1, "after": 0.0}, "t_end": 0.1}"#;
    assert_eq!(scene::parse(long).unwrap().methods(), ["exact"]);
}
