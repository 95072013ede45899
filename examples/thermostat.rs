//! A new hybrid model from scratch: a thermostat. Heating drives the
//! temperature towards 30, cooling towards 10; the heater switches off at 22
//! and on at 18. The flow is an ODE the engine integrates; the guards only
//! mark passages (`as_crossing`), and each switch changes the mode.
//! Run: `cargo run --release --example thermostat`
use flicker::engine::Name;
use flicker::engine::{
    Direction, Flow, Guard, HybridModel, Jump, Mode, Options, Recorder, simulate,
};
use flicker::names;

const HEATING: Mode = 0;
const RATE: f64 = 0.5;
const TARGET: [f64; 2] = [30.0, 10.0];
const SWITCH_AT: [f64; 2] = [22.0, 18.0];
const OFF: &[Guard] = &[Guard::affine("heater_off", Direction::Rising).as_crossing()];
const ON: &[Guard] = &[Guard::affine("heater_on", Direction::Falling).as_crossing()];

pub struct Thermostat;

// One line per method: the whole model at a glance.
#[rustfmt::skip]
impl HybridModel for Thermostat {
    fn dimension(&self) -> usize { 1 }
    fn state_names(&self, _: Mode) -> &[Name] { names!["temperature"] }
    fn mode_name(&self, mode: Mode) -> &str { ["heating", "cooling"][mode] }
    fn guards(&self, mode: Mode) -> &[Guard] { if mode == HEATING { OFF } else { ON } }
    fn guard(&self, mode: Mode, _: usize, x: &[f64]) -> f64 { x[0] - SWITCH_AT[mode] }
    fn flow(&self, _: Mode) -> Flow { Flow::Ode }
    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) { dx[0] = RATE * (TARGET[mode] - x[0]) }
    fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump { Jump::to(1 - mode) }
}

/// The switching times over `t_end`, from 18 degrees, heating.
pub fn switches(t_end: f64) -> Vec<f64> {
    let mut log = Recorder::default();
    simulate(
        &Thermostat,
        HEATING,
        &[18.0],
        &Options::until(t_end),
        &mut log,
    );
    log.events.iter().map(|e| e.t).collect()
}

/// The closed form: each phase relaxes exponentially between the thresholds.
pub fn period() -> f64 {
    let phase = |target: f64, from: f64, to: f64| ((target - from) / (target - to)).ln() / RATE;
    phase(TARGET[0], SWITCH_AT[1], SWITCH_AT[0]) + phase(TARGET[1], SWITCH_AT[0], SWITCH_AT[1])
}

fn main() {
    let times = switches(40.0);
    let cycle = times[2] - times[0];
    println!(
        "{} switches; the heater cycles every {cycle:.6} (closed form {:.6})",
        times.len(),
        period()
    );
}
