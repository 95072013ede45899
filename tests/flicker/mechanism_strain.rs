//! The strain formulation against references written out here and in
//! [`crate::oscillator`] (docs/physics.md s.2), not against the crate's own
//! closed form, which its model shares: impact times against
//! `t1 + (n - 1) T_imp` with `T_imp` in its atan2 and arccos forms, states
//! against the cosine arc, both against a tight RK4 integration of
//! `eps'' = -omega^2 (eps - (eta - 1))` with the reset, below, at and above
//! the critical load and near grazing; 10^7 impacts in release builds; and
//! every regime ending cleanly: loose, impacting, grazing, chattering,
//! resting.

use flicker::engine::{EventRecord, Observer, Options, Recorder, Status, simulate};
use flicker::models::mechanism::strain::{FLIGHT, RESTING};
use flicker::models::mechanism::{Mechanism, StrainMechanism};

use crate::oscillator::{Unit, rk4, rk4_phase_error};

const EPS: f64 = f64::EPSILON;

fn mechanism(u: Unit) -> Mechanism {
    Mechanism {
        eta: u.eta,
        omega: u.omega,
    }
}

fn run_observed<O: Observer>(
    u: Unit,
    x0: (f64, f64),
    t_end: f64,
    log: &mut O,
) -> flicker::engine::Outcome {
    simulate(
        &StrainMechanism {
            mechanism: mechanism(u),
        },
        FLIGHT,
        &[x0.0, x0.1],
        &Options::until(t_end),
        log,
    )
}

fn run(u: Unit, x0: (f64, f64), t_end: f64) -> flicker::engine::Outcome {
    run_observed(u, x0, t_end, &mut ())
}

/// A `t_end` a generic fraction (0.37) of a period after the `n`-th impact.
fn t_end_after_impacts(u: Unit, x0: (f64, f64), n: u64) -> f64 {
    let first = u.first_closing(x0).unwrap();
    first + (n as f64 - 0.63) * u.period_atan2(u.energy(x0.0, x0.1))
}

/// Impact count and final state after `impacts` impacts against the
/// written-out hybrid state (the arc from the last impact at
/// `t1 + (n - 1) T`).
fn check_against_the_arc(u: Unit, x0: (f64, f64), impacts: u64, state_tol: f64) {
    let t_end = t_end_after_impacts(u, x0, impacts);
    let outcome = run(u, x0, t_end);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert_eq!(u.impacts_until(x0, t_end), impacts);
    assert_eq!(outcome.events, impacts);
    let (eps, rate) = u.state_at(x0, t_end);
    let err = (outcome.final_state[0] - eps)
        .abs()
        .max((outcome.final_state[1] - rate).abs());
    assert!(
        err < state_tol,
        "state error {err:e} after {impacts} impacts"
    );
}

#[test]
fn the_two_period_forms_agree_to_their_conditioning() {
    // Near grazing (eta > 1, H0 -> 0) the arccos argument -(eta - 1) / A
    // tends to -1, where arccos' slope A / sqrt(2 H0) multiplies its few
    // ulps of rounding; atan2 keeps full precision. At eta = 1 both give
    // a half cosine, pi / omega.
    let half = Unit {
        eta: 1.0,
        omega: 1.7,
    };
    for h0 in [1e-12, 0.3, 40.0] {
        assert_eq!(half.period_atan2(h0), std::f64::consts::PI / 1.7);
        assert!((half.period_arccos(h0) - std::f64::consts::PI / 1.7).abs() < 4.0 * EPS);
    }
    for (eta, omega) in [(0.7, 2.5), (1.3, 0.7), (1.2, 1.0)] {
        let u = Unit { eta, omega };
        for h0 in [1e-12, 1e-6, 0.01, 0.2, 5.0] {
            let (a, b) = (u.period_arccos(h0), u.period_atan2(h0));
            let conditioning = 4.0 * EPS * (eta - 1.0).abs() / (omega * (2.0 * h0).sqrt());
            assert!(
                (a - b).abs() <= conditioning + 4.0 * EPS * b,
                "eta {eta}, H0 {h0}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn impacts_and_states_match_the_written_out_arc_and_rk4_in_every_regime() {
    // Below, at and above the critical load, and near grazing (H0 = 1e-6
    // with eta > 1: the orbit dips to zero at speed 1.4e-3).
    let cases = [
        (
            "below",
            Unit {
                eta: 0.7,
                omega: 2.5,
            },
            (0.05, -0.3),
        ),
        (
            "critical",
            Unit {
                eta: 1.0,
                omega: 1.0,
            },
            (0.3, 0.2),
        ),
        (
            "above",
            Unit {
                eta: 1.3,
                omega: 0.7,
            },
            (1.0, 0.0),
        ),
        (
            "near grazing",
            Unit {
                eta: 1.2,
                omega: 1.0,
            },
            Unit {
                eta: 1.2,
                omega: 1.0,
            }
            .apex(1e-6),
        ),
    ];
    for (name, u, x0) in cases {
        let h0 = u.energy(x0.0, x0.1);
        let period = u.period_atan2(h0);
        let t1 = u.first_closing(x0).unwrap();
        // About 25 turns of the oscillator, at omega h = 1e-3 for RK4.
        let t_end = 150.0 / u.omega;
        let h = 1e-3 / u.omega;
        let mut log = Recorder::default();
        let outcome = run_observed(u, x0, t_end, &mut log);
        assert_eq!(
            outcome.status,
            Status::Completed,
            "{name}: {:?}",
            outcome.reason
        );
        let n = u.impacts_until(x0, t_end);
        assert!(n > 20, "{name}: {n} impacts");
        assert_eq!(outcome.events, n, "{name}");

        // Against t1 + k T: the engine computes each flight's time to a few
        // ulps and adds them with a compensated clock, so impact k is off
        // by at most a few ulps of T per flight: 8 ulps of the time itself.
        for (k, e) in log.events.iter().enumerate() {
            let expected = t1 + k as f64 * period;
            assert!(
                (e.t - expected).abs() <= 8.0 * EPS * expected,
                "{name}: impact {k} at {} not {expected}",
                e.t
            );
            assert!(e.before[0].abs() < 1e-15 && e.after[0] == 0.0, "{name}");
            assert_eq!(e.after[1], -e.before[1], "{name}");
            let speed = u.impact_speed(h0);
            assert!(
                (e.before[1] + speed).abs() < 1e-14 * speed.max(1.0),
                "{name}"
            );
        }

        // Against RK4: its phase error bound (see rk4_phase_error) moves an
        // impact by phase / omega; its amplitude error, of the same
        // relative size, moves the crossing by A phase / impact speed,
        // which dominates near grazing.
        let reference = rk4(u, x0, t_end, h);
        assert_eq!(reference.impacts.len() as u64, n, "{name}: RK4 impacts");
        let phase = rk4_phase_error(u.omega, h, t_end, reference.steps);
        let a = u.amplitude(h0);
        let time_tol = phase / u.omega + a * phase / u.impact_speed(h0);
        for (k, (e, r)) in log.events.iter().zip(&reference.impacts).enumerate() {
            assert!(
                (e.t - r).abs() < time_tol,
                "{name}: impact {k} at {} vs RK4 {r} (tolerance {time_tol:e})",
                e.t
            );
        }
        let state_tol = a * phase * (1.0 + u.omega) + u.impact_speed(h0) * time_tol;
        let (eps, rate) = (outcome.final_state[0], outcome.final_state[1]);
        assert!(
            (eps - reference.state.0).abs() < state_tol
                && (rate - reference.state.1).abs() < state_tol,
            "{name}: final ({eps}, {rate}) vs RK4 {:?}",
            reference.state
        );

        // Against the cosine arc from the last impact, at times through the
        // run (each its own run): the arc's own rounding is a few ulps of
        // A omega t; 1e-12 leaves room for the engine's.
        for j in 1..=20 {
            let t = t_end * j as f64 / 20.0 - 0.1234;
            let o = run(u, x0, t);
            let (eps, rate) = u.state_at(x0, t);
            assert!(
                (o.final_state[0] - eps).abs() < 1e-12 && (o.final_state[1] - rate).abs() < 1e-12,
                "{name}: at t = {t}: {:?} vs ({eps}, {rate})",
                o.final_state
            );
        }
    }
}

#[test]
fn near_grazing_impacts_keep_the_atan2_period_up_to_the_drift_of_round_off() {
    // H0 = 1e-12 at eta = 1.2: the orbit dips to zero at speed 1.4e-6,
    // where the arccos form of the period has lost about half its digits
    // and the atan2 form none.
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = (0.0, u.impact_speed(1e-12));
    let h0 = u.energy(x0.0, x0.1);
    let (c, a, s) = (u.eta - 1.0, u.amplitude(h0), (2.0 * h0).sqrt());
    let mut log = Recorder::default();
    let t_end = 1000.0;
    let outcome = run_observed(u, x0, t_end, &mut log);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(outcome.events, u.impacts_until(x0, t_end));
    assert!(outcome.events > 150);
    // Round-off drifts here. Each flight ends with a rate rounded to some
    // ulps of the arc's scale A omega, not of the impact speed: 8 ulps
    // move H0 = (eps'/omega)^2 / 2 by up to dH = 8 eps A s (s = sqrt(2 H0))
    // per impact, and identical flights round alike, so these add up. The
    // period's slope dT/dH0 = -2 c / (omega A^2 s) turns each into
    // dT = 16 eps c / (omega A) on every later flight: impact k is off by
    // up to dT k (k + 1) / 2, besides the clock's 8 ulps of t.
    let dh = 8.0 * EPS * a * s;
    let dt = 2.0 * c / (u.omega * a * a * s) * dh;
    let period = u.period_atan2(h0);
    for (k, e) in log.events.iter().enumerate() {
        let expected = (k + 1) as f64 * period;
        let drift = dt * (k * (k + 1)) as f64 / 2.0;
        assert!(
            (e.t - expected).abs() <= drift + 8.0 * EPS * expected,
            "impact {k} at {} not {expected} (drift allowed {drift:e})",
            e.t
        );
        let after = u.energy(e.after[0], e.after[1]);
        assert!(
            (after - h0).abs() <= dh * (k + 1) as f64,
            "impact {k}: H0 {after:e} vs {h0:e}"
        );
    }
    // The measured period agrees with the arccos form only to that form's
    // conditioning (the_two_period_forms_agree_to_their_conditioning).
    let n = log.events.len();
    let measured = (log.events[n - 1].t - log.events[0].t) / (n - 1) as f64;
    let conditioning = 4.0 * EPS * c / s;
    assert!((measured - u.period_arccos(h0)).abs() < conditioning + dt * n as f64);
}

#[test]
fn ten_thousand_impacts_match_the_arc_to_1e9() {
    check_against_the_arc(
        Unit {
            eta: 1.2,
            omega: 1.0,
        },
        (0.5, 0.1),
        10_000,
        1e-9,
    );
    check_against_the_arc(
        Unit {
            eta: 0.7,
            omega: 2.5,
        },
        (0.05, -0.3),
        10_000,
        1e-9,
    );
}

/// Checks each impact against `t1 + (n - 1) T` as it comes, keeping the
/// worst error relative to `n` ulps of `T`.
struct AgainstThePeriod {
    t1: f64,
    period: f64,
    seen: u64,
    worst: f64,
}

impl Observer for AgainstThePeriod {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        let expected = self.t1 + self.seen as f64 * self.period;
        self.seen += 1;
        let ulps = (e.t - expected).abs() / (EPS * self.period * self.seen as f64);
        self.worst = self.worst.max(ulps);
        Ok(())
    }
}

#[test]
#[cfg_attr(debug_assertions, ignore = "10^7 impacts: release builds only")]
fn ten_million_impacts_fall_on_t1_plus_n_periods() {
    // The clock reaches ~4.6e7: accumulating it in plain f64 would drift by
    // microseconds; the engine's compensated clock must not.
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = (0.5, 0.0);
    let h0 = u.energy(x0.0, x0.1);
    let mut check = AgainstThePeriod {
        t1: u.first_closing(x0).unwrap(),
        period: u.period_atan2(h0),
        seen: 0,
        worst: 0.0,
    };
    let n = 10_000_000;
    let t_end = t_end_after_impacts(u, x0, n);
    let outcome = run_observed(u, x0, t_end, &mut check);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!((outcome.events, check.seen), (n, n));
    // Per flight, both the engine's time and the reference T are within a
    // couple of ulps of T, errors that may all have one sign: 4 ulps per
    // impact, which is 4.6e7 * 4 ulps ~ 4e-8 at the end.
    assert!(check.worst < 4.0, "{} ulps of T per impact", check.worst);
    let (eps, rate) = u.state_at(x0, t_end);
    assert!(
        (outcome.final_state[0] - eps).abs() < 1e-7 && (outcome.final_state[1] - rate).abs() < 1e-7,
        "{:?} vs ({eps}, {rate})",
        outcome.final_state
    );
}

/// The largest relative deviation of the written-out energy at every event
/// (both sides of the reset) from the initial energy.
struct EnergyAtEvents {
    unit: Unit,
    h0: f64,
    worst: f64,
}

impl Observer for EnergyAtEvents {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        for x in [e.before, e.after] {
            let drift = (self.unit.energy(x[0], x[1]) - self.h0).abs() / self.h0.abs();
            self.worst = self.worst.max(drift);
        }
        Ok(())
    }
}

#[test]
fn energy_is_kept_to_1e12_over_a_million_impacts() {
    let u = Unit {
        eta: 0.9,
        omega: 1.3,
    };
    let x0 = u.apex(0.37);
    let h0 = u.energy(x0.0, x0.1);
    let mut energy = EnergyAtEvents {
        unit: u,
        h0,
        worst: 0.0,
    };
    let outcome = run_observed(u, x0, t_end_after_impacts(u, x0, 1_000_000), &mut energy);
    assert_eq!(outcome.events, 1_000_000);
    // 1e-12 is ~4500 ulps: rounding at each of 10^6 flights and resets, if
    // it did not average out, would show as a drift well beyond it.
    assert!(
        energy.worst < 1e-12,
        "relative energy error {:e}",
        energy.worst
    );
    let last = (outcome.final_state[0], outcome.final_state[1]);
    assert!((u.energy(last.0, last.1) - h0).abs() < 1e-12 * h0);
}

#[test]
fn every_event_flips_the_strain_rate_at_zero_strain() {
    let u = Unit {
        eta: 1.5,
        omega: 0.7,
    };
    let mut log = Recorder::default();
    run_observed(u, (0.0, 0.4), 200.0, &mut log);
    // From eps = 0 opening, impacts come at whole periods.
    let period = u.period_atan2(u.energy(0.0, 0.4));
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
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let x0 = u.apex(-0.015);
    let outcome = run(u, x0, 1e5);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(outcome.events, 0);
    // omega t = 1e5: the arc's phase is rounded to ~1e-11 there.
    let (eps, rate) = u.arc(x0, 1e5);
    assert!(
        (outcome.final_state[0] - eps).abs() < 1e-10
            && (outcome.final_state[1] - rate).abs() < 1e-10,
        "{:?} vs ({eps}, {rate})",
        outcome.final_state
    );
}

#[test]
fn the_grazing_separatrix_touches_without_impacts() {
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    // H0 = 0: from the apex 2 (eta - 1), and from eps = 0 at rest.
    for x0 in [(2.0 * (u.eta - 1.0), 0.0), (0.0, 0.0)] {
        assert_eq!(u.energy(x0.0, x0.1), 0.0);
        let outcome = run(u, x0, 1000.0);
        assert_eq!(outcome.status, Status::Completed);
        assert_eq!(
            outcome.events, 0,
            "spurious impacts on the separatrix from {x0:?}"
        );
        assert!(outcome.final_state[0] >= -1e-15);
        // Energy scale (eta - 1)^2 / 2 = 0.02; 1e-14 of it is ~45 ulps.
        let last = (outcome.final_state[0], outcome.final_state[1]);
        assert!(u.energy(last.0, last.1).abs() < 0.02 * 1e-14);
    }
}

#[test]
fn resolvable_chattering_is_run_out_exactly() {
    // H0 = 1e-12 below critical load: impacts every ~1.4e-5, resolvable.
    let u = Unit {
        eta: 0.8,
        omega: 1.0,
    };
    let x0 = (0.0, u.impact_speed(1e-12));
    let outcome = run(u, x0, 10.0);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(outcome.events, u.impacts_until(x0, 10.0));
    assert!(outcome.events > 500_000);
}

#[test]
fn chattering_below_critical_load_settles_into_resting_contact() {
    let u = Unit {
        eta: 0.8,
        omega: 1.0,
    };
    let x0 = (0.0, u.impact_speed(1e-40));
    let outcome = run(u, x0, 100.0);
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
    let u = Unit {
        eta: 0.5,
        omega: 1.0,
    };
    let outcome = run(u, (0.0, 0.0), 10.0);
    assert_eq!(outcome.status, Status::Zeno);
    assert_eq!(outcome.final_mode, RESTING);
    assert_eq!(outcome.t_reached, 10.0);
    assert!(outcome.max_energy_error.unwrap() == 0.0);
}

#[test]
fn a_run_that_cannot_finish_within_its_event_budget_says_so_early() {
    // Chattering just below critical load: resolvable impacts ~3e-6 apart,
    // ~3e11 of them to t_end. The projection must stop it long before.
    let u = Unit {
        eta: 0.999_999_999,
        omega: 1.0,
    };
    let m = mechanism(u);
    let x0 = u.apex(1e-30);
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
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let m = mechanism(u);
    let x0 = (0.5, 0.0);
    let t_end = t_end_after_impacts(u, x0, 50);
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
