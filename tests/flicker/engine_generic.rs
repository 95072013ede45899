//! The engine's own rules, on models made for them: a reset re-predicts
//! only the guards it says it affects (and a local model's quiet guards not
//! at all), and events at the same instant come out in a fixed order (guard
//! order), so logs are reproducible.

use std::cell::Cell;

use flicker::engine::Name;
use flicker::engine::{
    Affects, Direction, Fired, Flow, Guard, HybridModel, Jump, Labels, LocalModel, Mode, Options,
    Recorder, Status, simulate, simulate_local,
};
use flicker::names;
use flicker::time::Time;

/// Two independent ramps `x' = 1`, `y' = 4`, each wrapped to zero at one.
struct TwoRamps {
    predictions: Cell<u64>,
}

const RATES: [f64; 2] = [1.0, 4.0];
const WRAPS: &[Guard] = &[
    Guard::affine("wrap_x", Direction::Rising),
    Guard::affine("wrap_y", Direction::Rising),
];

impl HybridModel for TwoRamps {
    fn dimension(&self) -> usize {
        2
    }
    fn state_names(&self, _: Mode) -> &[Name] {
        names!["x", "y"]
    }
    fn mode_name(&self, _: Mode) -> &str {
        "ramps"
    }
    fn guards(&self, _: Mode) -> &[Guard] {
        WRAPS
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
            event: None,
            leaves: None,
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
        .map(|e| e.guard.as_str())
        .collect();
    assert_eq!(at_one, vec!["wrap_x", "wrap_y"]);
    let times: Vec<f64> = log.events.iter().map(|e| e.t).collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]));
    for e in log.events.iter().filter(|e| e.guard == "wrap_y") {
        assert_eq!((e.t * 4.0).fract(), 0.0, "y wraps every quarter: {}", e.t);
    }
}

/// A local model with a clock ticking at whole times and an alarm set for
/// t = 2.5, which the first tick silences: from then on the model calls the
/// alarm quiet.
struct SilencedAlarm {
    silenced: bool,
    alarm_predictions: Cell<u64>,
}

const CLOCK: &[Guard] = &[
    Guard::affine("tick", Direction::Rising),
    Guard::affine("alarm", Direction::Rising),
];

impl LocalModel for SilencedAlarm {
    fn mode_name(&self) -> &'static str {
        "clock"
    }
    fn guards(&self) -> &[Guard] {
        CLOCK
    }
    fn predict(&self, guard: usize, now: Time) -> Result<Option<Time>, String> {
        if guard == 0 {
            return Ok(Some(Time::new(now.value().floor() + 1.0)));
        }
        self.alarm_predictions.set(self.alarm_predictions.get() + 1);
        Ok((!self.silenced).then_some(Time::new(2.5)))
    }
    fn quiet(&self, guard: usize) -> bool {
        guard == 1 && self.silenced
    }
    fn fire(&mut self, guard: usize, _: Time) -> Result<Fired, String> {
        self.silenced = true;
        Ok(Fired {
            affects: guard..2,
            labels: Labels::NONE,
        })
    }
}

#[test]
fn a_quiet_guard_is_dropped_from_the_queue_without_a_prediction() {
    let mut model = SilencedAlarm {
        silenced: false,
        alarm_predictions: Cell::new(0),
    };
    let mut log = Recorder::default();
    let outcome = simulate_local(
        &mut model,
        &Options::until(3.2),
        &[],
        &mut |_, _| {},
        &mut log,
    );
    assert_eq!(outcome.status, Status::Completed);
    // The alarm queued for 2.5 at the start is gone after the first tick,
    // and was never asked about again.
    assert_eq!(outcome.events_by_guard["tick"], 3);
    assert!(!outcome.events_by_guard.contains_key("alarm"));
    assert_eq!(model.alarm_predictions.get(), 1);
}

/// Samples are taken from the flow as the run goes: they change neither
/// its steps nor its events, they lie on the orbit, and one at an event's
/// time sees the state before the reset.
#[test]
fn sampling_a_run_changes_nothing_and_reads_the_flow() {
    use flicker::engine::{Method, Sample, Tolerances, simulate_sampled};
    use flicker::models::mechanism::strain::FLIGHT;
    use flicker::models::mechanism::{ExactOrbit, Mechanism, StrainMechanism};

    let m = Mechanism {
        eta: 0.8,
        omega: 1.0,
    };
    let model = StrainMechanism { mechanism: m };
    let x0 = [0.3, 0.0];
    let exact = ExactOrbit::new(m, x0[0], x0[1]);
    let first_impact = exact.impact_time(0);
    // Evenly spaced times, and one exactly at the first impact.
    let mut times: Vec<f64> = (1..=500).map(|k| k as f64 * 0.1).collect();
    times.push(first_impact);
    times.sort_by(f64::total_cmp);
    let tol = Tolerances {
        rtol: 1e-10,
        atol: 1e-10,
    };
    for method in [Method::Exact, Method::Dopri5(tol)] {
        let mut options = Options::until(50.0);
        options.method = method;
        let mut plain = Recorder::default();
        let alone = simulate(&model, FLIGHT, &x0, &options, &mut plain);
        let mut sampled = Recorder::default();
        let mut seen = Vec::new();
        let with = simulate_sampled(
            &model,
            FLIGHT,
            &x0,
            &options,
            &times,
            &mut |s: &Sample| seen.push((s.t, s.state.to_vec())),
            &mut sampled,
        );
        assert_eq!(alone.final_state, with.final_state, "{method:?}");
        assert_eq!(plain.events, sampled.events, "{method:?}");
        assert_eq!(seen.len(), times.len(), "{method:?}");
        for (t, x) in &seen {
            let (eps, rate) = exact.state_at(*t);
            // Exact: the closed form to round-off; Dormand-Prince: within
            // the error bound the run states.
            let allowed = with.error_bound.unwrap().max(1e-12);
            assert!((x[0] - eps).abs() <= allowed, "{method:?} t = {t}: {x:?}");
            // Within an impact's time error the rate may be either side of
            // its flip; the exact flow's sample at the impact itself sees
            // the state before the reset, still closing.
            let near = (0..exact.impacts_until(51.0)).any(|k| {
                (exact.impact_time(k) - t).abs() <= with.event_time_bound.unwrap().max(1e-12)
            });
            if method == Method::Exact && *t == first_impact {
                assert!(x[1] < 0.0, "{x:?}");
            } else if !near {
                assert!((x[1] - rate).abs() <= allowed, "{method:?} t = {t}: {x:?}");
            }
        }
    }
}
