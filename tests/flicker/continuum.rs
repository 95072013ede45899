//! The continuum by front tracking: the classical string against an
//! independent characteristic lattice, the paper's release against its
//! d'Alembert solution worked out by hand, energy and momentum to
//! round-off, and compression the paper's continuum cannot carry refused.

use flicker::engine::{LocalModel, Options, Recorder, Status, simulate_local};
use flicker::models::continuum::{Continuum, FrontTracking, Piece, StringModel};
use flicker::models::{self as scene, ContinuumScene};
use flicker::time::Time;

use crate::support::{flicker, models, read_json};

fn string(load: f64, constraint: bool, wave_speed: f64) -> Continuum {
    Continuum {
        length: 2.0,
        wave_speed,
        load,
        constraint,
    }
}

/// The classical string on `cells` equal cells, by shifting the Riemann
/// invariants one cell per `h / c` (exact for cell-wise constant data):
/// `v - c eps` moves right and reflects at the wall as `-(v + c eps)`;
/// `v + c eps` moves left and reflects at the end as `(v - c eps) + 2 c eps_end`.
struct Lattice {
    right: Vec<f64>,
    left: Vec<f64>,
    c: f64,
    end_strain: f64,
}

impl Lattice {
    fn new(cells: &[Piece], c: f64, end_strain: f64) -> Self {
        Lattice {
            right: cells.iter().map(|p| p.velocity - c * p.strain).collect(),
            left: cells.iter().map(|p| p.velocity + c * p.strain).collect(),
            c,
            end_strain,
        }
    }

    fn step(&mut self) {
        let m = self.right.len();
        let into_end = self.right[m - 1];
        let into_wall = self.left[0];
        self.right.rotate_right(1);
        self.right[0] = -into_wall;
        self.left.rotate_left(1);
        self.left[m - 1] = into_end + 2.0 * self.c * self.end_strain;
    }

    fn piece(&self, i: usize) -> Piece {
        Piece {
            strain: (self.left[i] - self.right[i]) / (2.0 * self.c),
            velocity: 0.5 * (self.left[i] + self.right[i]),
        }
    }
}

/// Cell-wise constant data that looks random but is fixed.
fn cells(m: usize) -> Vec<Piece> {
    (0..m)
        .map(|i| {
            let s = (i as f64 * 1.7 + 0.3).sin();
            let v = (i as f64 * 2.3 + 1.1).cos();
            Piece {
                strain: 0.1 + 0.05 * s,
                velocity: 0.08 * v,
            }
        })
        .collect()
}

#[test]
fn the_classical_string_agrees_with_the_characteristic_lattice() {
    let (m, c) = (7, 1.3);
    let s = string(0.7, false, c);
    let data = cells(m);
    let mut model = FrontTracking::new(s.clone(), &data).unwrap();
    let h = s.length / m as f64;
    let steps = 40; // about 2.9 round trips of the string
    let times: Vec<f64> = (0..=steps).map(|k| k as f64 * h / c).collect();
    let mut lattice = Lattice::new(&data, c, s.end_strain());
    let mut worst: f64 = 0.0;
    let mut energies = Vec::new();
    let outcome = simulate_local(
        &mut model,
        &Options::until(times[steps]),
        &times,
        &mut |model: &FrontTracking, t| {
            let at = Time::new(t);
            for i in 0..m {
                let x = s.wall() + (i as f64 + 0.5) * h;
                let (a, b) = (model.piece_at(x, at), lattice.piece(i));
                worst = worst
                    .max((a.strain - b.strain).abs())
                    .max((a.velocity - b.velocity).abs());
            }
            let end: f64 = (0..m).map(|i| lattice.piece(i).strain * h).sum();
            worst = worst.max((model.right_end(at) - end).abs());
            // The one-pass profile says what the point-by-point answers do.
            let points: Vec<f64> = (0..3 * m)
                .map(|k| s.wall() + (k as f64 + 0.25) * h / 3.0)
                .collect();
            for (&x, (p, y)) in points.iter().zip(model.profile(&points, at)) {
                assert_eq!(p, model.piece_at(x, at));
                let by_point = model.displacement_at(x, at);
                assert!((y - by_point).abs() < 1e-14, "{y} against {by_point}");
            }
            energies.push(model.energy(at).unwrap());
            lattice.step();
        },
        &mut (),
    );
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert_eq!(energies.len(), steps + 1);
    assert!(
        worst < 1e-13,
        "largest difference from the lattice {worst:e}"
    );
    // Energy is a sum over pieces of exact states: round-off only.
    let e0 = energies[0];
    let drift = energies.iter().map(|e| (e - e0).abs()).fold(0.0, f64::max);
    assert!(drift < 1e-14 * e0.abs(), "energy drift {drift:e} of {e0}");
    assert!(outcome.max_energy_error.unwrap() < 1e-13);
    let t = Time::new(outcome.t_reached);
    assert!((model.momentum(t) - model.momentum_by_impulses(t)).abs() < 1e-14);
    // Every crossing, reflection at the wall and at the end is an event;
    // 2m fronts cross or reflect about m times per time h/c each.
    assert!(outcome.events > (m * steps) as u64, "{}", outcome.events);
}

#[test]
fn the_paper_release_is_a_front_at_the_wave_speed_then_one_impact_at_the_wall() {
    // docs/physics.md s.6, eta -> 1: eps = 0.1 at rest ahead of a front at
    // x = 1 - t, eps = 0 and v = -0.1 behind it; at t = 2 the whole shut
    // string strikes the wall and bounces (v -> +0.1, (A.12)), and a front
    // leaves the wall restoring eps = 0.1 at rest.
    let s = string(1.0, true, 1.0);
    let mut model = FrontTracking::new(
        s.clone(),
        &[Piece {
            strain: 0.1,
            velocity: 0.0,
        }],
    )
    .unwrap();
    let times = [0.5, 1.0, 1.5, 1.999, 2.5, 2.9];
    let mut worst: f64 = 0.0;
    let mut log = Recorder::default();
    let outcome = simulate_local(
        &mut model,
        &Options::until(3.0),
        &times,
        &mut |model: &FrontTracking, t| {
            let at = Time::new(t);
            for k in 0..200 {
                let x = -0.995 + 0.01 * k as f64;
                let (strain, velocity) = if t < 2.0 {
                    if x < 1.0 - t { (0.1, 0.0) } else { (0.0, -0.1) }
                } else if x < -1.0 + (t - 2.0) {
                    (0.1, 0.0)
                } else {
                    (0.0, 0.1)
                };
                let p = model.piece_at(x, at);
                worst = worst
                    .max((p.strain - strain).abs())
                    .max((p.velocity - velocity).abs());
                // No overshoot: the strain stays within [0, 0.1].
                assert!(
                    (0.0..=0.1).contains(&p.strain),
                    "{} at x {x}, t {t}",
                    p.strain
                );
            }
            let end = if t < 2.0 {
                0.2 - 0.1 * t
            } else {
                0.1 * (t - 2.0)
            };
            worst = worst.max((model.right_end(at) - end).abs());
        },
        &mut log,
    );
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert!(worst < 1e-15, "{worst:e}");
    let guards: Vec<&str> = log.events.iter().map(|e| e.guard.as_str()).collect();
    assert_eq!(guards, ["wall", "impact"]);
    let impact = &log.events[1];
    assert_eq!((impact.t, impact.labels.number("x")), (2.0, Some(-1.0)));
    assert!((impact.labels.number("rel_velocity").unwrap() - 0.1).abs() < 1e-15);
    // Energy 0.21 - F_cr y_end(0) = 0.01, kept through the impact.
    assert!((outcome.energy_initial.unwrap() - 0.01).abs() < 1e-15);
    assert!(outcome.max_energy_error.unwrap() < 1e-12);
    // Momentum: -0.2 before the impact, +0.2 after, then the wall's pull
    // F_cr (1 + 0.1) against the end's F_cr: 0.2 - 0.1 (t - 2) at t = 3.
    let end = Time::new(3.0);
    assert!((model.momentum(end) - 0.1).abs() < 1e-15);
    assert!((model.momentum(end) - model.momentum_by_impulses(end)).abs() < 1e-15);
}

#[test]
fn compression_inside_the_string_stops_the_run_with_its_place_and_time() {
    // Three stretches: the outer two move towards the middle one. The waves
    // from the two jumps meet at x = 0, t = h / 2c, in compression.
    let s = string(1.0, true, 1.0);
    let cells = [
        Piece {
            strain: 0.1,
            velocity: 0.15,
        },
        Piece {
            strain: 0.1,
            velocity: 0.0,
        },
        Piece {
            strain: 0.1,
            velocity: -0.15,
        },
    ];
    let mut model = FrontTracking::new(s, &cells).unwrap();
    let outcome = simulate_local(
        &mut model,
        &Options::until(3.0),
        &[],
        &mut |_, _| {},
        &mut (),
    );
    assert_eq!(outcome.status, Status::Failed);
    let reason = outcome.reason.unwrap();
    assert!(
        reason.contains("compression at x = ") && reason.contains("0.000000000, t = 0.333"),
        "{reason}"
    );
    assert!(
        (outcome.t_reached - 1.0 / 3.0).abs() < 1e-15,
        "{}",
        outcome.t_reached
    );
    // The classical string carries the same data through.
    let mut classical = FrontTracking::new(string(1.0, false, 1.0), &cells).unwrap();
    let outcome = simulate_local(
        &mut classical,
        &Options::until(3.0),
        &[],
        &mut |_, _| {},
        &mut (),
    );
    assert_eq!(outcome.status, Status::Completed);
}

#[test]
fn bad_continuum_scenes_are_refused_by_field() {
    let good = r#"{"model": "continuum", "length": 2.0, "wave_speed": 1.0,
        "load": {"before": 1.1, "after": 1.0}, "t_end": 3.0}"#;
    assert!(
        scene::parse(good)
            .unwrap()
            .downcast_ref::<ContinuumScene>()
            .is_some()
    );
    for (bad, field, words) in [
        (
            good.replace("\"t_end\"", "\"variant\": \"fluid\", \"t_end\""),
            "variant",
            "unknown variant",
        ),
        (good.replace("1.1", "0.9"), "load.before", "below zero"),
        (
            good.replace("\"t_end\"", "\"units\": 4, \"t_end\""),
            "units",
            "not a known key",
        ),
        (
            good.replace("\"t_end\"", "\"resolution\": 0, \"t_end\""),
            "resolution",
            "positive",
        ),
        (
            good.replace(
                "\"t_end\"",
                "\"initial\": {\"strain\": [0.1, 0.2], \"velocity\": [0]}, \"t_end\"",
            ),
            "initial.velocity",
            "one entry per cell (2)",
        ),
        (
            good.replace("\"t_end\"", "\"initial\": {\"strain\": []}, \"t_end\""),
            "initial",
            "from 1",
        ),
    ] {
        let e = scene::parse(&bad).expect_err(&bad);
        assert_eq!(e.field.as_deref(), Some(field), "{e}");
        assert!(e.to_string().contains(words), "{e}");
    }
    let mut scene = scene::parse(good).unwrap();
    let numerical = flicker::scene::solver::SolverSpec {
        method: Some("dopri5".into()),
        ..Default::default()
    };
    let e = scene.override_solver(&numerical).unwrap_err();
    assert!(e.reason.contains("its own method only"), "{e}");
}

#[test]
fn a_release_run_writes_its_files_and_the_classical_string_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("paper");
    let o = flicker(&[
        "run",
        &models("continuum_release_paper.json"),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
        "--plot",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["model"], "continuum");
    assert_eq!(summary["events_by_guard"]["impact"], 1);
    assert!(summary["max_energy_error"].as_f64().unwrap() < 1e-12);
    assert!(summary["momentum_balance_error"].as_f64().unwrap() < 1e-12);
    let profiles = read_json(&out.join("profiles.json"));
    let snapshots = profiles["snapshots"].as_array().unwrap();
    assert_eq!(snapshots.len(), 4);
    // 400 points at cell centres over [-1, 1].
    let x = snapshots[1]["x"].as_array().unwrap();
    assert_eq!(x.len(), 400);
    assert!((x[0].as_f64().unwrap() + 0.9975).abs() < 1e-12);
    // The classical string at the same times, its trace with its energy.
    let classical = &profiles["classical"];
    assert_eq!(classical["snapshots"].as_array().unwrap().len(), 4);
    let trace = classical["trace"].as_array().unwrap();
    assert_eq!(trace.len(), 300);
    assert!(
        trace
            .iter()
            .all(|r| (r["energy"].as_f64().unwrap() - 0.01).abs() < 1e-15)
    );
    // Figs. 12-14, drawn by the same command: profiles beside the
    // classical string and H(t) / H(0).
    for name in [
        "snapshots",
        "displacement",
        "end_displacement",
        "energy_ratio",
    ] {
        let svg = std::fs::read_to_string(out.join(format!("{name}.svg"))).unwrap();
        assert!(svg.contains("<svg"), "{name}");
    }
}
