//! What an observer sees and may do: events name their modes by index as
//! well as by name, and an observer that has seen what it came for ends
//! the run at that event.

use flicker::engine::Name;
use flicker::engine::{
    Direction, EventRecord, Flow, Guard, HybridModel, Jump, Mode, Observer, Options, Status,
    simulate,
};
use flicker::names;

/// `x` climbs to 1 at rate 1 in mode `up`, falls to 0 at rate 2 in mode
/// `down`, and turns there: a triangle wave of period 1.5.
struct Triangle;

const RATE: [f64; 2] = [1.0, -2.0];
const TURNS: &[&[Guard]] = &[
    &[Guard::affine("top", Direction::Rising)],
    &[Guard::affine("bottom", Direction::Falling)],
];

impl HybridModel for Triangle {
    fn dimension(&self) -> usize {
        1
    }
    fn state_names(&self, _: Mode) -> &[Name] {
        names!["x"]
    }
    fn mode_name(&self, mode: Mode) -> &str {
        ["up", "down"][mode]
    }
    fn guards(&self, mode: Mode) -> &[Guard] {
        TURNS[mode]
    }
    fn guard(&self, mode: Mode, _: usize, x: &[f64]) -> f64 {
        if mode == 0 { x[0] - 1.0 } else { x[0] }
    }
    fn flow(&self, _: Mode) -> Flow {
        Flow::Exact
    }
    fn advance(&self, mode: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        x[0] = x0[0] + RATE[mode] * tau;
    }
    fn next_crossing(&self, mode: Mode, _: usize, x0: &[f64]) -> Option<f64> {
        let to = if mode == 0 { 1.0 } else { 0.0 };
        Some(((to - x0[0]) / RATE[mode]).max(0.0))
    }
    fn reset(&self, mode: Mode, _: usize, x: &mut [f64]) -> Jump {
        x[0] = if mode == 0 { 1.0 } else { 0.0 };
        Jump::to(1 - mode)
    }
}

/// Keeps each event's modes, and asks the run to end after `stop_after`.
struct Modes {
    seen: Vec<(Mode, Mode, String, String, f64)>,
    stop_after: usize,
}

impl Observer for Modes {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        self.seen
            .push((e.from, e.to, e.mode_before.into(), e.mode_after.into(), e.t));
        Ok(())
    }

    fn stop(&self) -> Option<String> {
        (self.seen.len() >= self.stop_after).then(|| format!("{} turns seen", self.seen.len()))
    }
}

#[test]
fn events_carry_their_modes_by_index_and_by_name() {
    let mut modes = Modes {
        seen: Vec::new(),
        stop_after: usize::MAX,
    };
    let outcome = simulate(&Triangle, 0, &[0.0], &Options::until(3.9), &mut modes);
    assert_eq!(outcome.status, Status::Completed);
    // Turns at 1, 1.5, 2.5, 3; the next top is at 4.
    let times: Vec<f64> = modes.seen.iter().map(|s| s.4).collect();
    assert_eq!(times, vec![1.0, 1.5, 2.5, 3.0]);
    for (i, (from, to, before, after, _)) in modes.seen.iter().enumerate() {
        assert_eq!(*from, i % 2);
        assert_eq!(*to, 1 - i % 2);
        assert_eq!(before, Triangle.mode_name(*from));
        assert_eq!(after, Triangle.mode_name(*to));
    }
}

#[test]
fn an_observer_that_has_seen_enough_ends_the_run_at_that_event() {
    let mut modes = Modes {
        seen: Vec::new(),
        stop_after: 3,
    };
    let outcome = simulate(&Triangle, 0, &[0.0], &Options::until(100.0), &mut modes);
    assert_eq!(outcome.status, Status::Interrupted);
    assert_eq!(modes.seen.len(), 3);
    assert_eq!(outcome.events, 3);
    assert_eq!(outcome.t_reached, 2.5);
    let reason = outcome.reason.unwrap_or_default();
    assert!(
        reason.contains("stopped by its observer: 3 turns seen"),
        "{reason}"
    );
    // Ended at the third event, before its reset: at the top, still rising.
    assert_eq!((outcome.final_mode, outcome.final_state[0]), (0, 1.0));
}
