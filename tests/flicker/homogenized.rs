//! The homogenized string: its finite volumes keep mass, momentum and
//! energy to round-off, reproduce the exact shock of their own equations
//! at the traction-free end (the Hugoniot, solved apart), and carry an
//! elastic release at the wave speed.

use flicker::engine::{LocalModel, Options, Status, simulate_local};
use flicker::models as scene;
use flicker::models::continuum::hugoniot;
use flicker::models::continuum::{Continuum, Homogenized, StringModel, Variant};
use flicker::time::Time;

fn string(load: f64) -> Continuum {
    Continuum {
        length: 2.0,
        wave_speed: 1.0,
        load,
        constraint: true,
    }
}

/// The end's flux takes its state from the same Hugoniot, so this checks
/// that the interior carries the shock the end emits (its speed, and the
/// plateau at a distance from the end); the chain comparison below is the
/// independent check.
#[test]
fn the_traction_free_release_is_the_shock_its_conservation_laws_give() {
    // Ahead: eps 0.1 at rest, force 1.1 F_cr, energy 0.105 per length.
    let shock = hugoniot::from_end([0.1, 0.0, 0.105], 1.1, 0.0).unwrap();
    let [strain, velocity, _] = shock.behind;
    let t = 0.25;
    let mut model = Homogenized::new(string(0.0), 0.1, 400, &[t]).unwrap();
    let mut seen = None;
    let outcome = simulate_local(
        &mut model,
        &Options::until(t),
        &[t],
        &mut |m: &Homogenized, s| {
            let at = Time::new(s);
            // Mid-plateau, halfway between the end and the front.
            let x = 1.0 + 0.5 * shock.speed * t;
            let p = m.piece_at(x, at);
            let points = [-0.9, x, 0.99];
            for (&x, (q, y)) in points.iter().zip(m.profile(&points, at)) {
                assert_eq!(q, m.piece_at(x, at));
                assert!((y - m.displacement_at(x, at)).abs() < 1e-15);
            }
            seen = Some((p, m.energy(at).unwrap(), m.momentum(at), m.right_end(at)));
        },
        &mut (),
    );
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    let (p, energy, momentum, end) = seen.unwrap();
    assert!(
        (p.strain - strain).abs() < 0.01 * strain,
        "{} against {strain}",
        p.strain
    );
    assert!(
        (p.velocity - velocity).abs() < 0.01 * velocity.abs(),
        "{} against {velocity}",
        p.velocity
    );
    // The end moves at the plateau's velocity: y = 0.2 + v t (to the
    // first cells' start-up, a few cell widths of 0.005 times the strain).
    assert!((end - (0.2 + velocity * t)).abs() < 2e-3, "{end}");
    // Conserved to round-off: energy (no load), momentum -1.1 t (the
    // wall's pull alone, the front not there yet).
    assert!((energy - 0.21).abs() < 1e-14, "{energy}");
    assert!((momentum + 1.1 * t).abs() < 1e-13, "{momentum}");
    assert!((model.momentum_by_impulses(Time::new(t)) - momentum).abs() < 1e-14);
}

#[test]
fn an_elastic_release_moves_at_the_wave_speed_without_rattling() {
    // Load 1.1 -> 1.05: the string stays stretched (eps 0.05 behind a
    // front at c_b, v = -0.05); no unit reaches zero, nothing rattles.
    let t = 1.0;
    let mut model = Homogenized::new(string(1.05), 0.1, 200, &[t]).unwrap();
    let mut seen = None;
    simulate_local(
        &mut model,
        &Options::until(t),
        &[t],
        &mut |m: &Homogenized, s| {
            let at = Time::new(s);
            let coarse = m.coarse(&[-0.5, 0.5], at);
            seen = Some((coarse, m.right_end(at)));
        },
        &mut (),
    );
    let (coarse, end) = seen.unwrap();
    // Ahead of the front (x = 0 at t = 1) and behind it.
    assert!((coarse.strain[0] - 0.1).abs() < 1e-9, "{:?}", coarse.strain);
    assert!(
        (coarse.strain[1] - 0.05).abs() < 1e-6,
        "{:?}",
        coarse.strain
    );
    assert!((coarse.velocity[1] + 0.05).abs() < 1e-6);
    // The scheme's diffusion at the passing front leaves a trace of
    // internal energy (numerical heating, first order in the cell width),
    // far below the e^2 / 2 = 1.25e-3 the law would read as rattling: the
    // force stays elastic, as the strain and velocity above show.
    assert!(
        coarse.hidden_energy[1].abs() < 1e-4,
        "{:?}",
        coarse.hidden_energy
    );
    assert!((end - (0.2 - 0.05 * t)).abs() < 1e-9, "{end}");
}

#[test]
fn a_homogenized_scene_runs_and_says_what_it_used() {
    let text = r#"{"model": "continuum", "variant": "homogenized", "length": 2.0,
        "wave_speed": 1.0, "load": {"before": 1.1, "after": 0.0}, "t_end": 0.2,
        "snapshots": [0.1], "samples": 5, "resolution": 100}"#;
    let scene = scene::parse(text).unwrap();
    let report = scene.run(&Default::default(), &mut ()).unwrap();
    assert_eq!(report.method, flicker::engine::Method::FiniteVolume);
    assert!(
        report.description.contains("100 cells"),
        "{}",
        report.description
    );
    let fields = report.fields.unwrap();
    assert!(fields.momentum_balance_error.unwrap() < 1e-13);
    assert!(report.outcome.max_energy_error.unwrap() < 1e-13);
    assert_eq!(fields.trace.len(), 5);
    let e =
        scene::parse(&text.replace("\"t_end\"", "\"constraint\": false, \"t_end\"")).unwrap_err();
    assert_eq!(e.field.as_deref(), Some("constraint"));
}

#[test]
fn against_the_traction_free_chain_it_meets_the_figures_the_issue_sets() {
    // Chain N = 200 (its own plateau within 0.2% of N = 1600's) and the
    // homogenized string on 100 cells, to just past the wave's return.
    use flicker::analysis::release_convergence::{Model, distance, release, run_all};
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models/continuum_release_free_end.json");
    let mut release = release(&scene::load(&path).unwrap()).unwrap().string;
    release.t_end = 0.7;
    release.snapshots = vec![0.3];
    release.samples = 57;
    release.resolution = 100;
    let models = [Model::Chain(200), Model::Continuum(Variant::Homogenized)];
    let tracks = run_all(&release, &models, &Default::default()).unwrap();
    let d = distance(&tracks[1], &tracks[0]);
    let (ours, chain) = (
        d.front_speed.unwrap(),
        distance(&tracks[0], &tracks[0]).front_speed.unwrap(),
    );
    assert!(
        (ours - chain).abs() < 0.01 * chain,
        "front {ours} against {chain}"
    );
    assert!(d.plateau_strain.unwrap() < 0.02, "{:?}", d);
    assert!(d.plateau_velocity.unwrap() < 0.02, "{:?}", d);
    assert!(d.returned.is_some_and(|t| t > 0.5), "{:?}", d.returned);
    assert!(d.right_end_before_return < 0.01, "{:?}", d);
}
