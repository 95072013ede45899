//! Exactly periodic orbits, jumped over whole periods at a time.
//!
//! On an autonomous flow the state after an event decides everything after
//! it, for an exact flow and for steps that depend only on the state they
//! start from (the linear propagator, Taylor's method; see
//! [`Integrator::memoryless`](crate::engine::integrator::Integrator::memoryless)).
//! When the state after an event is the state after the previous event, to
//! round-off, with the same guard fired in the same mode and nothing
//! between, the run is on a periodic orbit of one event per period: the
//! next stretch repeats the last. A run whose observer does not look at
//! events (no event log) then jumps over whole periods at once and counts
//! their events, instead of firing each: a chattering mechanism's 2.5e8
//! impacts take microseconds ("model no more than a scene needs").
//!
//! An exact flow jumps with nothing to carry. A stepped run's bound carries
//! errors, and checks them at every step and event: it replays its last
//! period's operations over each period jumped, checks included, and the
//! jump stops short of the first period whose checks would fail (see
//! [`crate::engine::period_record`]). Its stated bounds are those firing
//! each event would state, to round-off.
//!
//! What it costs in accuracy: the run stays on the state it returned to,
//! where firing each event would have walked away from it by round-off,
//! at most [`RETURN_ULPS`] ulps of the state per period (else the return is
//! not accepted). The run's stated bound already allows
//! [`ROUNDOFF_ULPS`](crate::engine::bound::ROUNDOFF_ULPS) per event, more
//! than that (and more than a stepped period that differs from the last by
//! a step at its end, whose replay misses that step's rounding). The clock
//! jumps by `k` periods as one exact product, where `k` additions round
//! `k` times.

use crate::engine::model::Mode;
use crate::time::Time;

/// How far the state after an event may lie from the state after the
/// previous one, in ulps of the state's largest component, for the orbit
/// to count as having returned.
pub const RETURN_ULPS: f64 = 8.0;

/// Whole periods a run keeps firing event by event before its limit (the
/// end, the next sample): the count at the limit is then the event loop's
/// own, whatever the rounding of the jump.
const MARGIN_PERIODS: f64 = 2.0;

/// The state after the last event, to tell whether the next one returns
/// to it. Its buffer is kept across [`Returns::forget`]: no allocation per
/// event.
#[derive(Debug, Clone, Default)]
pub(crate) struct Returns {
    /// Whether the fields below describe the last event.
    known: bool,
    mode: Mode,
    slot: usize,
    t: Time,
    state: Vec<f64>,
    /// Whether the last event returned to the one before it, and how long
    /// after it.
    returned: bool,
    period: f64,
}

impl Returns {
    /// Forget the last event: what follows is not a repeat of it (a step
    /// of a numerical method, a settling, a flow that is not exact).
    pub fn forget(&mut self) {
        self.known = false;
        self.returned = false;
    }

    /// Guard `slot` of `mode` fired at `t` and left the run in `mode` at
    /// `state`: note whether that is where the previous event left it.
    pub fn visit(&mut self, mode: Mode, slot: usize, t: Time, state: &[f64]) {
        self.period = t.since(self.t);
        self.returned = self.known
            && self.mode == mode
            && self.slot == slot
            && self.t < t
            && same(&self.state, state);
        (self.known, self.mode, self.slot, self.t) = (true, mode, slot, t);
        self.state.clear();
        self.state.extend_from_slice(state);
    }

    /// Whether the last event returned the state to where the event
    /// before it left it.
    pub fn returned(&self) -> bool {
        self.returned
    }

    /// The time from the event before the last to the last: the period,
    /// where the last returned.
    pub fn period(&self) -> f64 {
        self.period
    }
}

/// Whether two states agree to [`RETURN_ULPS`] ulps of their size.
fn same(a: &[f64], b: &[f64]) -> bool {
    let size = a.iter().chain(b).fold(0.0_f64, |m, x| m.max(x.abs()));
    let within = RETURN_ULPS * f64::EPSILON * size;
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= within)
}

/// How many whole periods of `tau` a run at `origin` (just after an event,
/// the next `tau` ahead) may jump over without passing `limit`; the last
/// [`MARGIN_PERIODS`] before the limit are left to fire one by one.
pub(crate) fn periods_to_skip(origin: Time, tau: f64, limit: f64) -> u64 {
    if tau.is_nan() || tau <= 0.0 {
        return 0;
    }
    let whole = (Time::new(limit).since(origin) / tau - MARGIN_PERIODS).floor();
    if whole < 1.0 {
        return 0;
    }
    // Below 2^53 the period count and the clock's product stay exact.
    whole.min(9.0e15) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_return_needs_the_same_guard_mode_and_state() {
        let mut r = Returns::default();
        r.visit(0, 0, Time::new(1.0), &[0.0, 1.0]);
        assert!(!r.returned(), "the first event returns to nothing");
        r.visit(0, 0, Time::new(2.5), &[0.0, 1.0 + 2.0 * f64::EPSILON]);
        assert!(r.returned());
        assert_eq!(r.period(), 1.5);
        r.visit(0, 1, Time::new(3.0), &[0.0, 1.0]);
        assert!(!r.returned(), "another guard");
        r.visit(0, 1, Time::new(4.0), &[0.0, 1.0 + 1e-12]);
        assert!(!r.returned(), "a state that moved");
        r.visit(1, 1, Time::new(5.0), &[0.0, 1.0 + 1e-12]);
        assert!(!r.returned(), "another mode");
        r.forget();
        r.visit(1, 1, Time::new(6.0), &[0.0, 1.0 + 1e-12]);
        assert!(!r.returned(), "forgotten");
    }

    #[test]
    fn skips_stop_short_of_the_limit() {
        let origin = Time::new(0.5);
        // 99.5 ahead, periods of 1: events at 1.5, ..., 99.5 = 99 of them;
        // two are left to fire.
        assert_eq!(periods_to_skip(origin, 1.0, 100.0), 97);
        assert_eq!(periods_to_skip(origin, 1.0, 2.0), 0);
        assert_eq!(periods_to_skip(origin, 0.0, 100.0), 0);
        assert_eq!(periods_to_skip(origin, f64::NAN, 100.0), 0);
    }
}
