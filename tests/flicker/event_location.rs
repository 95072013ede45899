//! Event location on numerical flows must not miss a crossing, even one that
//! enters and leaves inside a single step.

use flicker::engine::{
    Direction, Flow, Guard, HybridModel, Jump, Mode, Options, Recorder, Status, Tolerances,
    simulate,
};

/// A harmonic oscillator `x'' = -x` whose guard `x = level` is reached only
/// briefly near each crest: with a loose tolerance the integrator takes a
/// few steps per period, so both ends of the step that holds a crest sit
/// below the level. A sign check at step ends misses every crossing.
struct Crest {
    level: f64,
}

const CREST_GUARDS: [Guard; 1] = [Guard::affine("crest", Direction::Rising).as_crossing()];

impl HybridModel for Crest {
    fn dimension(&self) -> usize {
        2
    }
    fn state_names(&self, _: Mode) -> &[&'static str] {
        &["x", "v"]
    }
    fn mode_name(&self, _: Mode) -> &'static str {
        "free"
    }
    fn guards(&self, _: Mode) -> &[Guard] {
        &CREST_GUARDS
    }
    fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
        x[0] - self.level
    }
    fn flow(&self, _: Mode) -> Flow {
        Flow::Ode
    }
    fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -x[0];
    }
    fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump {
        Jump::to(mode)
    }
}

#[test]
fn a_crossing_in_and_out_within_one_step_is_found() {
    let model = Crest { level: 0.999 };
    let mut options = Options::until(20.0 * std::f64::consts::TAU);
    options.tolerances = Tolerances {
        rtol: 1e-5,
        atol: 1e-5,
    };
    let mut log = Recorder::default();
    let outcome = simulate(&model, 0, &[1.0, 0.0], &options, &mut log);
    assert_eq!(outcome.status, Status::Completed);
    // Rising crossings of x = 0.999 happen just before each crest at t = 2 pi k.
    assert_eq!(
        log.events.len(),
        20,
        "times {:?}",
        log.events.iter().map(|e| e.t).collect::<Vec<_>>()
    );
    let dip = (0.999f64).acos();
    for (k, e) in log.events.iter().enumerate() {
        let exact = (k + 1) as f64 * std::f64::consts::TAU - dip;
        // At rtol 1e-5 the amplitude drifts by ~1e-4 over these periods; the
        // guard's slope at the crossing is sqrt(1 - 0.999^2) = 0.045, so the
        // time may move by ~2e-3.
        assert!(
            (e.t - exact).abs() < 1e-2,
            "event {k} at {} not {exact}",
            e.t
        );
    }
    // The test is only meaningful if steps really straddle the crests: the
    // time above the level, 2 acos(0.999) = 0.09 per period, must be far
    // shorter than a typical step.
    let steps_per_period = outcome.flow_evaluations as f64 / 6.0 / 20.0;
    assert!(
        steps_per_period < 20.0,
        "{steps_per_period} steps per period"
    );
}
