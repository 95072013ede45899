//! The error bound a run states holds: over random mechanism orbits (near
//! grazing, near resting contact, loose and impacting) and every method,
//! a run either completes with the exact answer's impact count, its final
//! state within its `error_bound` and every impact time within its
//! `event_time_bound`, or fails and says why. Never a quiet wrong answer.

use std::cell::Cell;

use flicker::engine::{Method, Options, Recorder, Status, Tolerances, simulate};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{ExactOrbit, Mechanism, StrainMechanism};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};

/// A mechanism and a state on it: `eta`, `omega`, the energy `H0` (from
/// 1e-10, a near graze or near resting contact, to 1, and loose orbits
/// below zero for `eta > 1`), where on the orbit's arc above `eps = 0` the
/// state sits, and which way it moves.
fn orbit() -> impl Strategy<Value = (Mechanism, f64, f64)> {
    (
        0.5f64..1.8,
        0.5f64..3.0,
        -10.0f64..0.0,
        prop::bool::weighted(0.15),
        0.0f64..1.0,
        prop::bool::ANY,
    )
        .prop_map(|(eta, omega, log_h0, loose, along, closing)| {
            let m = Mechanism { eta, omega };
            let centre = eta - 1.0;
            // A loose orbit (H0 < 0) exists only above the critical load.
            let h0 = if loose && eta > 1.0 {
                -0.5 * centre * centre * along
            } else {
                10f64.powf(log_h0)
            };
            let amplitude = (2.0 * h0 + centre * centre).sqrt();
            let low = (centre - amplitude).max(0.0);
            let eps = low + along * (centre + amplitude - low);
            let rate2 = omega * omega * (2.0 * h0 - eps * (eps + 2.0 * (1.0 - eta)));
            let rate = rate2.max(0.0).sqrt() * if closing { -1.0 } else { 1.0 };
            (m, eps, rate)
        })
}

/// A numerical method and its setting: the embedded pairs at a tolerance
/// from 1e-12 to 1e-6, Stormer-Verlet at 50 to 1000 steps per natural
/// period, or the linear propagator.
fn method() -> impl Strategy<Value = (usize, f64)> {
    (0..4usize, 0.0f64..1.0)
}

fn setting(kind: usize, u: f64, omega: f64) -> Method {
    let tol = 10f64.powf(-12.0 + 6.0 * u);
    let tol = Tolerances {
        rtol: tol,
        atol: tol,
    };
    match kind {
        0 => Method::Dopri5(tol),
        1 => Method::Dop853(tol),
        2 => Method::Verlet {
            step: std::f64::consts::TAU / omega / 10f64.powf(1.7 + 1.3 * u),
        },
        _ => Method::Linear,
    }
}

#[test]
fn every_run_ends_within_its_stated_bounds_or_says_it_cannot() {
    let mut runner = TestRunner::new(Config {
        cases: 200,
        rng_seed: RngSeed::Fixed(20261125),
        failure_persistence: None,
        ..Config::default()
    });
    let (completed, failed) = (Cell::new(0u32), Cell::new(0u32));
    let strategy = (orbit(), method(), 1.0f64..30.0);
    runner
        .run(&strategy, |((m, eps, rate), (kind, u), t_end)| {
            let model = StrainMechanism { mechanism: m };
            let mut options = Options::until(t_end);
            options.method = setting(kind, u, m.omega);
            // Orbits near resting contact impact thousands of times per
            // unit time: a budget keeps the case quick, and a run that
            // spends it says so.
            options.max_events = 20_000;
            let mut log = Recorder::default();
            let outcome = simulate(&model, FLIGHT, &[eps, rate], &options, &mut log);
            let exact = ExactOrbit::new(m, eps, rate);
            let what = format!(
                "eta {} omega {} eps {eps} rate {rate} t_end {t_end} {:?}",
                m.eta, m.omega, options.method
            );
            match outcome.status {
                Status::Completed => {
                    completed.set(completed.get() + 1);
                    prop_assert_eq!(outcome.events, exact.impacts_until(t_end), "{}", what);
                    let (e, r) = exact.state_at(t_end);
                    let error = (outcome.final_state[0] - e)
                        .abs()
                        .max((outcome.final_state[1] - r).abs());
                    prop_assert!(
                        error <= outcome.error_bound.unwrap(),
                        "{what}: final error {error:.2e} above its bound {:.2e}",
                        outcome.error_bound.unwrap()
                    );
                    let bound = outcome.event_time_bound.unwrap();
                    for (k, event) in log.events.iter().enumerate() {
                        let off = (event.t - exact.impact_time(k as u64)).abs();
                        prop_assert!(
                            off <= bound,
                            "{what}: impact {k} {off:.2e} off, bound {bound:.2e}"
                        );
                    }
                }
                Status::Failed => {
                    failed.set(failed.get() + 1);
                    let reason = outcome.reason.as_deref().unwrap_or_default();
                    prop_assert!(
                        reason.contains("cannot") || reason.starts_with("event budget"),
                        "{what}: {reason}"
                    );
                }
                // Near resting contact below the critical load the run
                // settles; where it settles is judged by the stress suite.
                Status::Zeno => {}
                Status::Interrupted => prop_assert!(false, "{}: interrupted", what),
            }
            Ok(())
        })
        .unwrap();
    // The property is only tested if most runs complete: a method that
    // gave up on everything would pass it.
    let (completed, failed) = (completed.get(), failed.get());
    eprintln!("{completed} completed, {failed} failed");
    assert!(completed >= 100, "{completed} completed, {failed} failed");
}
