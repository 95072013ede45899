//! The strain formulation against the closed form of docs/physics.md s.2:
//! impact counts exact, states to 1e-9 (1e-8 after 10^7 impacts), energy
//! to 1e-12, and every regime ending cleanly: loose, impacting, grazing,
//! chattering, resting.

use flicker::engine::{Options, Recorder, Status, simulate};
use flicker::models::mechanism::strain::{FLIGHT, RESTING};
use flicker::models::mechanism::{ExactOrbit, Mechanism, Phase, StrainMechanism};

fn run(m: Mechanism, x0: (f64, f64), t_end: f64) -> flicker::engine::Outcome {
    simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &Options::until(t_end),
        &mut (),
    )
}

/// A `t_end` a generic fraction (0.37) of a period after the `n`-th impact.
fn t_end_after_impacts(m: Mechanism, x0: (f64, f64), n: u64) -> f64 {
    let first = m.time_to_closing(x0.0, x0.1).unwrap();
    first + (n as f64 - 0.63) * m.impact_period(m.energy(x0.0, x0.1))
}

fn check_against_closed_form(m: Mechanism, x0: (f64, f64), impacts: u64, state_tol: f64) {
    let t_end = t_end_after_impacts(m, x0, impacts);
    let outcome = run(m, x0, t_end);
    let exact = ExactOrbit::new(m, x0.0, x0.1);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert_eq!(exact.impacts_until(t_end), impacts);
    assert_eq!(outcome.events, impacts);
    let (eps, rate) = exact.state_at(t_end);
    let err = (outcome.final_state[0] - eps)
        .abs()
        .max((outcome.final_state[1] - rate).abs());
    assert!(
        err < state_tol,
        "state error {err:e} after {impacts} impacts"
    );
}

#[test]
fn ten_thousand_impacts_match_the_closed_form_to_1e9() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    check_against_closed_form(m, (0.5, 0.1), 10_000, 1e-9);
    let below = Mechanism {
        eta: 0.7,
        omega: 2.5,
    };
    check_against_closed_form(below, (0.05, -0.3), 10_000, 1e-9);
}

#[test]
fn ten_million_impacts_match_the_closed_form_to_1e8() {
    // The clock reaches ~3e7: accumulating it in plain f64 would drift by
    // microseconds; the engine's compensated clock must not.
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    check_against_closed_form(m, (0.5, 0.0), 10_000_000, 1e-8);
}

#[test]
fn energy_is_kept_to_1e12_over_a_million_impacts() {
    let m = Mechanism {
        eta: 0.9,
        omega: 1.3,
    };
    let x0 = m.state_with_energy(0.37, Phase::Apex).unwrap();
    let outcome = run(m, x0, t_end_after_impacts(m, x0, 1_000_000));
    assert_eq!(outcome.events, 1_000_000);
    let err = outcome.max_energy_error.unwrap();
    assert!(err < 1e-12, "relative energy error {err:e}");
}

#[test]
fn every_event_flips_the_strain_rate_at_zero_strain() {
    let m = Mechanism {
        eta: 1.5,
        omega: 0.7,
    };
    let mut log = Recorder::default();
    let model = StrainMechanism { mechanism: m };
    simulate(
        &model,
        FLIGHT,
        &[0.0, 0.4],
        &Options::until(200.0),
        &mut log,
    );
    let period = m.impact_period(m.energy(0.0, 0.4));
    assert_eq!(log.events.len() as f64, (200.0 / period).floor());
    for (k, e) in log.events.iter().enumerate() {
        assert!(e.before[0].abs() < 1e-15 && e.after[0] == 0.0);
        assert_eq!(e.after[1], -e.before[1]);
        assert!(e.before[1] < 0.0);
        assert!((e.t - (k + 1) as f64 * period).abs() < 1e-12);
    }
}

#[test]
fn loose_orbits_never_impact() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(-0.015, Phase::Apex).unwrap();
    let outcome = run(m, x0, 1e5);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(outcome.events, 0);
    let (eps, rate) = m.flow(x0.0, x0.1, 1e5);
    assert!(
        (outcome.final_state[0] - eps).abs() < 1e-12
            && (outcome.final_state[1] - rate).abs() < 1e-12
    );
}

#[test]
fn the_grazing_separatrix_touches_without_impacts() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    for phase in [Phase::Apex, Phase::Impact] {
        let x0 = m.state_with_energy(0.0, phase).unwrap();
        let outcome = run(m, x0, 1000.0);
        assert_eq!(outcome.status, Status::Completed);
        assert_eq!(
            outcome.events, 0,
            "spurious impacts on the separatrix from {phase:?}"
        );
        assert!(outcome.final_state[0] >= -1e-15);
        assert!(outcome.max_energy_error.unwrap() < 1e-14);
    }
}

#[test]
fn near_grazing_orbits_impact_once_per_period() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(1e-12, Phase::Impact).unwrap();
    let t_end = 1000.0;
    let outcome = run(m, x0, t_end);
    assert_eq!(
        outcome.events,
        ExactOrbit::new(m, x0.0, x0.1).impacts_until(t_end)
    );
    assert!(outcome.events > 150);
}

#[test]
fn chattering_below_critical_load_settles_into_resting_contact() {
    let m = Mechanism {
        eta: 0.8,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(1e-40, Phase::Impact).unwrap();
    let outcome = run(m, x0, 100.0);
    assert_eq!(outcome.status, Status::Zeno);
    assert!(outcome.zeno);
    assert!(
        outcome.reason.as_deref().unwrap().contains("resting"),
        "{:?}",
        outcome.reason
    );
    assert_eq!(outcome.final_mode, RESTING);
    assert_eq!(outcome.t_reached, 100.0);
    assert_eq!(outcome.final_state, vec![0.0, 0.0]);
    assert!(outcome.events < 100);
}

#[test]
fn resting_contact_at_zero_energy_is_recognised_at_once() {
    let m = Mechanism {
        eta: 0.5,
        omega: 1.0,
    };
    let outcome = run(m, (0.0, 0.0), 10.0);
    assert_eq!(outcome.status, Status::Zeno);
    assert_eq!(outcome.final_mode, RESTING);
    assert_eq!(outcome.t_reached, 10.0);
    assert!(outcome.max_energy_error.unwrap() == 0.0);
}

#[test]
fn resolvable_chattering_is_run_out_exactly() {
    // H0 = 1e-12 below critical load: impacts every ~1.4e-5, resolvable.
    let m = Mechanism {
        eta: 0.8,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(1e-12, Phase::Impact).unwrap();
    let outcome = run(m, x0, 10.0);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(
        outcome.events,
        ExactOrbit::new(m, x0.0, x0.1).impacts_until(10.0)
    );
    assert!(outcome.events > 500_000);
}

#[test]
fn a_run_that_cannot_finish_within_its_event_budget_says_so_early() {
    // Chattering just below critical load: resolvable impacts ~3e-6 apart,
    // ~3e11 of them to t_end. The projection must stop it long before.
    let m = Mechanism {
        eta: 0.999_999_999,
        omega: 1.0,
    };
    let x0 = m.state_with_energy(1e-30, Phase::Apex).unwrap();
    let mut options = Options::until(1e6);
    options.max_events = 100_000_000;
    let outcome = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &options,
        &mut (),
    );
    assert_eq!(outcome.status, Status::Failed);
    assert!(
        outcome.reason.as_deref().unwrap().contains("max_events"),
        "{:?}",
        outcome.reason
    );
    assert!(
        outcome.events <= 1 << 21,
        "stopped only after {} events",
        outcome.events
    );
    // A small budget is a hard limit too: the event past it fails the run.
    options.max_events = 1000;
    let outcome = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &options,
        &mut (),
    );
    assert_eq!((outcome.status, outcome.events), (Status::Failed, 1001));
}

#[test]
fn a_run_needing_exactly_its_event_budget_completes() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = (0.5, 0.0);
    let t_end = t_end_after_impacts(m, x0, 50);
    let mut options = Options::until(t_end);
    options.max_events = 50;
    let outcome = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &options,
        &mut (),
    );
    assert_eq!((outcome.status, outcome.events), (Status::Completed, 50));
    options.max_events = 49;
    let outcome = simulate(
        &StrainMechanism { mechanism: m },
        FLIGHT,
        &[x0.0, x0.1],
        &options,
        &mut (),
    );
    assert_eq!((outcome.status, outcome.events), (Status::Failed, 50));
}
