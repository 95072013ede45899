//! Invariants of the mechanism under random parameters and initial states
//! (proptest): energy kept at every reset and along every flow, events in
//! time order, the impact count of the closed form, and an exact flow that
//! runs backwards to where it started.

use flicker::engine::{Options, Recorder, Status, simulate};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{Mechanism, StrainMechanism};
use proptest::prelude::*;

use crate::oscillator::Unit;

fn mechanism() -> impl Strategy<Value = (Mechanism, f64, f64)> {
    (0.3f64..2.0, 0.2f64..5.0, 0.0f64..1.0, -2.0f64..2.0)
        .prop_map(|(eta, omega, eps, rate)| (Mechanism { eta, omega }, eps, rate))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn energy_order_and_count_hold_for_random_mechanisms((m, eps, rate) in mechanism(), t_end in 1.0f64..300.0) {
        let model = StrainMechanism { mechanism: m };
        let mut log = Recorder::default();
        let outcome = simulate(&model, FLIGHT, &[eps, rate], &Options::until(t_end), &mut log);
        prop_assume!(outcome.status == Status::Completed);
        let h0 = m.energy(eps, rate);
        let scale = m.energy_scale(h0);
        // Each impact and each flight rounds the state by about an ulp, and
        // the energy's terms (up to eps^2 / 2 + eps |1 - eta| and A^2 / 2,
        // A the arc's amplitude) by an ulp of their size, which may exceed
        // the scale the error is measured against; these may add up: allow
        // four ulps of the larger per event (a fixed 1e-13 failed at 408
        // impacts, 1.28e-13: 1.4 ulps each, near eta = 1; four ulps of the
        // scale failed at eta 1.30, where the terms are four times H0).
        let unit = Unit { eta: m.eta, omega: m.omega };
        let amplitude = unit.amplitude(h0);
        let eps_max = (m.eta - 1.0) + amplitude;
        let terms = eps_max * (eps_max / 2.0 + (1.0 - m.eta).abs()) + amplitude * amplitude / 2.0;
        let allowed =
            4.0 * f64::EPSILON * (outcome.events as f64 + 1.0) * (terms / scale).max(1.0);
        prop_assert!(outcome.max_energy_error.unwrap() < allowed, "energy error {:?} over {} events", outcome.max_energy_error, outcome.events);
        let mut last = 0.0;
        for e in &log.events {
            prop_assert!(e.t >= last);
            last = e.t;
            prop_assert!((e.energy_after.unwrap() - e.energy_before.unwrap()).abs() <= 1e-14 * scale);
            prop_assert!(e.before[0].abs() < 1e-12 && e.after[0] == 0.0);
        }
        // The closed form written out in crate::oscillator, not the crate's.
        let exact = Unit { eta: m.eta, omega: m.omega };
        let expected = exact.impacts_until((eps, rate), t_end);
        // A t_end within rounding of an impact may count it either way.
        let last = exact.impacts_until((eps, rate), t_end + 1e-9);
        let near_impact = last > 0 && {
            let t1 = exact.first_closing((eps, rate)).unwrap();
            let time = t1 + (last - 1) as f64 * exact.period_atan2(exact.energy(eps, rate));
            (time - t_end).abs() < 1e-9
        };
        prop_assert!(outcome.events == expected || near_impact, "{} impacts, closed form {}", outcome.events, expected);
    }

    #[test]
    fn the_exact_flow_runs_backwards_to_its_start((m, eps, rate) in mechanism(), t_end in 1.0f64..100.0) {
        let model = StrainMechanism { mechanism: m };
        let forward = simulate(&model, FLIGHT, &[eps, rate], &Options::until(t_end), &mut ());
        prop_assume!(forward.status == Status::Completed);
        let (e1, r1) = (forward.final_state[0], forward.final_state[1]);
        // Reversing the rate reverses time; an impact exactly at the end
        // leaves the state on the guard, closing, where it would fire again.
        prop_assume!(e1 > 1e-9);
        let backward = simulate(&model, FLIGHT, &[e1, -r1], &Options::until(t_end), &mut ());
        prop_assert_eq!(backward.events, forward.events);
        let scale = 1.0 + eps.abs() + (rate / m.omega).abs();
        prop_assert!((backward.final_state[0] - eps).abs() < 1e-9 * scale, "eps {} vs {}", backward.final_state[0], eps);
        prop_assert!((backward.final_state[1] + rate).abs() < 1e-9 * scale * m.omega, "rate {} vs {}", backward.final_state[1], -rate);
    }
}
