//! The engine's own rules, on a model made for them: a reset re-predicts
//! only the guards it says it affects, and events at the same instant come
//! out in a fixed order (guard order), so logs are reproducible.

use std::cell::Cell;

use flicker::engine::{
    Affects, Direction, Flow, Guard, HybridModel, Jump, Mode, Options, Recorder, Status, simulate,
};

/// Two independent ramps `x' = 1`, `y' = 4`, each wrapped to zero at one.
struct TwoRamps {
    predictions: Cell<u64>,
}

const RATES: [f64; 2] = [1.0, 4.0];
const WRAPS: [Guard; 2] = [
    Guard::affine("wrap_x", Direction::Rising),
    Guard::affine("wrap_y", Direction::Rising),
];

impl HybridModel for TwoRamps {
    fn dimension(&self) -> usize {
        2
    }
    fn state_names(&self, _: Mode) -> &[&'static str] {
        &["x", "y"]
    }
    fn mode_name(&self, _: Mode) -> &'static str {
        "ramps"
    }
    fn guards(&self, _: Mode) -> &[Guard] {
        &WRAPS
    }
    fn guard(&self, _: Mode, g: usize, x: &[f64]) -> f64 {
        x[g] - 1.0
    }
    fn flow(&self, _: Mode) -> Flow {
        Flow::Exact
    }
    fn advance(&self, _: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        for i in 0..2 {
            x[i] = x0[i] + RATES[i] * tau;
        }
    }
    fn next_crossing(&self, _: Mode, g: usize, x0: &[f64]) -> Option<f64> {
        self.predictions.set(self.predictions.get() + 1);
        Some(((1.0 - x0[g]) / RATES[g]).max(0.0))
    }
    fn reset(&self, mode: Mode, g: usize, x: &mut [f64]) -> Jump {
        x[g] = 0.0;
        Jump {
            mode,
            affects: Affects::Range { first: g, count: 1 },
        }
    }
}

#[test]
fn a_reset_re_predicts_only_the_guards_it_affects() {
    let model = TwoRamps {
        predictions: Cell::new(0),
    };
    let mut log = Recorder::default();
    let outcome = simulate(&model, 0, &[0.0, 0.0], &Options::until(10.5), &mut log);
    assert_eq!(outcome.status, Status::Completed);
    assert_eq!(outcome.events_by_guard["wrap_x"], 10);
    assert_eq!(outcome.events_by_guard["wrap_y"], 42);
    // Two predictions at the start, then one per event: the other ramp's
    // prediction stays queued untouched.
    assert_eq!(model.predictions.get(), 2 + outcome.events);
    // Each ramp keeps its own clock across the other's resets.
    assert!((outcome.final_state[0] - 0.5).abs() < 1e-12);
    assert!(
        (outcome.final_state[1] - 0.0).abs() < 1e-12
            || (outcome.final_state[1] - 1.0).abs() < 1e-12
    );
}

#[test]
fn simultaneous_events_come_out_in_guard_order() {
    let model = TwoRamps {
        predictions: Cell::new(0),
    };
    let mut log = Recorder::default();
    simulate(&model, 0, &[0.0, 0.0], &Options::until(3.1), &mut log);
    let at_one: Vec<&str> = log
        .events
        .iter()
        .filter(|e| e.t == 1.0)
        .map(|e| e.guard)
        .collect();
    assert_eq!(at_one, vec!["wrap_x", "wrap_y"]);
    let times: Vec<f64> = log.events.iter().map(|e| e.t).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]));
    for e in log.events.iter().filter(|e| e.guard == "wrap_y") {
        assert_eq!((e.t * 4.0).fract(), 0.0, "y wraps every quarter: {}", e.t);
    }
}
