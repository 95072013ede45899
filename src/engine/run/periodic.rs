//! Exactly periodic orbits, jumped over whole periods at a time.
//!
//! On an autonomous flow the state after an event decides everything after
//! it, for an exact flow and for steps that depend only on the state they
//! start from (the linear propagator, Taylor's method; see
//! [`Integrator::memoryless`](crate::engine::step::integrator::Integrator::memoryless)).
//! When the state after an event is, to round-off, the state after one of
//! the last [`MAX_CYCLE`] events, left by the same guard into the same
//! mode with nothing between that this module was not shown, the run is on
//! a periodic orbit: the events since then repeat, in order (a ball
//! between two walls: two impacts; the mechanism's angle on two charts:
//! six events, two of them chart switches). A run whose observer does not
//! look at events (no event log) then jumps over whole periods at once and
//! counts their events, instead of firing each: a chattering mechanism's
//! 2.5e8 impacts take microseconds ("model no more than a scene needs").
//!
//! An exact flow jumps with nothing to carry. A stepped run's bound carries
//! errors, and checks them at every step and event: it replays its last
//! period's operations over each period jumped, checks included, and the
//! jump stops short of the first period whose checks would fail (see
//! [`crate::engine::bound::period_record`]). Its stated bounds are those firing
//! each event would state, to round-off. A period with a step that the
//! run's end cut short (a flow whose series ends, which Taylor's method
//! steps to the end at once) depends on more than its start, and is not
//! jumped.
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

use std::collections::VecDeque;

use crate::engine::bound::period_record::MAX_CYCLE;
use crate::engine::model::Mode;
use crate::engine::model::names::Name;
use crate::time::{Span, Time};

/// How far the state after an event may lie from the state after the
/// previous one, in ulps of the state's largest component, for the orbit
/// to count as having returned.
pub const RETURN_ULPS: f64 = 8.0;

/// Whole periods a run keeps firing event by event before its limit (the
/// end, the next sample): the count at the limit is then the event loop's
/// own, whatever the rounding of the jump.
const MARGIN_PERIODS: f64 = 2.0;

/// One event the run went through: guard `slot` of `mode` fired at `t`
/// (counted as `named` where its reset names it) and left the run in
/// `after` at `state`.
#[derive(Debug, Clone, Default)]
struct Visit {
    mode: Mode,
    slot: usize,
    named: Option<Name>,
    after: Mode,
    t: Time,
    state: Vec<f64>,
}

/// The last [`MAX_CYCLE`] events with nothing between them (and the one
/// before them, which the last may have returned to), to tell whether
/// the next one returns to where one of them left the run. Their buffers
/// are kept across [`Returns::forget`]: no allocation per event.
#[derive(Debug, Clone, Default)]
pub(crate) struct Returns {
    /// Oldest first; `known` of them describe the events since the run
    /// last forgot.
    visits: VecDeque<Visit>,
    known: usize,
    /// How many events back the last one returned to, if it did.
    cycle: Option<usize>,
}

/// An event of a period, as counted: guard `slot` of `mode`, or the name
/// its reset gives it.
pub(crate) type Counted<'a> = (Mode, usize, Option<&'a Name>);

impl Returns {
    /// Forget the events so far: what follows is not a repeat of them (a
    /// step of a numerical method that depends on more than its start, a
    /// settling, a flow that is not exact).
    pub fn forget(&mut self) {
        self.known = 0;
        self.cycle = None;
    }

    /// Guard `slot` of `mode` fired at `t` (counted as `named`) and left the
    /// run in `after` at `state`: note whether that is where an event at
    /// most [`MAX_CYCLE`] before it left the run, the same guard's, and
    /// which one: the nearest.
    pub fn visit(
        &mut self,
        (mode, slot, named): (Mode, usize, Option<Name>),
        after: Mode,
        t: Time,
        state: &[f64],
    ) {
        let from = self.visits.len() - self.known;
        self.cycle = (1..=self.known.min(MAX_CYCLE)).find(|&k| {
            let v = &self.visits[from + self.known - k];
            v.mode == mode && v.slot == slot && v.after == after && v.t < t && same(&v.state, state)
        });
        // The one returned to stays, [`MAX_CYCLE`] back at most.
        let mut visit = if self.visits.len() > MAX_CYCLE {
            self.visits.pop_front().unwrap_or_default()
        } else {
            Visit::default()
        };
        visit.state.clear();
        visit.state.extend_from_slice(state);
        (visit.mode, visit.slot, visit.named, visit.after, visit.t) = (mode, slot, named, after, t);
        self.visits.push_back(visit);
        self.known = (self.known + 1).min(MAX_CYCLE + 1);
    }

    /// How many events the period holds, where the last event returned the
    /// state to where one before it left it.
    pub fn cycle(&self) -> Option<usize> {
        self.cycle
    }

    /// The time from the event the last returned to, to the last: the
    /// period, to double-double.
    pub fn period(&self) -> Span {
        let k = self.cycle.unwrap_or(1);
        let last = self.visits.len() - 1;
        match (
            self.visits.get(last),
            last.checked_sub(k).and_then(|i| self.visits.get(i)),
        ) {
            (Some(now), Some(then)) => now.t.span_since(then.t),
            _ => Span::from(f64::NAN),
        }
    }

    /// The run jumped over `periods` periods of `tau`: the events seen
    /// move with it.
    pub fn postpone(&mut self, periods: u64, tau: Span) {
        for v in &mut self.visits {
            v.t = v.t.after_multiple(periods, tau);
        }
    }

    /// The guard the last event fired.
    pub fn last_slot(&self) -> Option<usize> {
        self.visits.back().map(|v| v.slot)
    }

    /// The events of the period, in order.
    pub fn events(&self) -> impl Iterator<Item = Counted<'_>> {
        let k = self.cycle.unwrap_or(0);
        self.visits
            .iter()
            .skip(self.visits.len() - k)
            .map(|v| (v.mode, v.slot, v.named.as_ref()))
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
        let at = |t: f64| Time::new(t);
        r.visit((0, 0, None), 0, at(1.0), &[0.0, 1.0]);
        assert_eq!(r.cycle(), None, "the first event returns to nothing");
        r.visit((0, 0, None), 0, at(2.5), &[0.0, 1.0 + 2.0 * f64::EPSILON]);
        assert_eq!(r.cycle(), Some(1));
        assert_eq!(r.period().value(), 1.5);
        r.visit((0, 1, None), 0, at(3.0), &[0.0, 1.0]);
        assert_eq!(r.cycle(), None, "another guard");
        r.visit((0, 1, None), 0, at(4.0), &[0.0, 1.0 + 1e-12]);
        assert_eq!(r.cycle(), None, "a state that moved");
        r.visit((1, 1, None), 0, at(5.0), &[0.0, 1.0 + 1e-12]);
        assert_eq!(r.cycle(), None, "another mode");
        r.visit((1, 1, None), 1, at(5.5), &[0.0, 1.0 + 1e-12]);
        assert_eq!(r.cycle(), None, "another mode after");
        r.forget();
        r.visit((1, 1, None), 1, at(6.0), &[0.0, 1.0 + 1e-12]);
        assert_eq!(r.cycle(), None, "forgotten");
    }

    #[test]
    fn a_period_of_several_events_counts_them_in_order() {
        // Two walls, hit in turn: the state after each returns two events
        // later. Events older than MAX_CYCLE are not looked at.
        let mut r = Returns::default();
        let wall = |r: &mut Returns, slot: usize, t: f64| {
            let v = if slot == 0 { 1.0 } else { -1.0 };
            r.visit((0, slot, None), 0, Time::new(t), &[slot as f64, v]);
        };
        wall(&mut r, 0, 1.0);
        wall(&mut r, 1, 2.0);
        assert_eq!(r.cycle(), None);
        wall(&mut r, 0, 3.0);
        assert_eq!(r.cycle(), Some(2));
        assert_eq!(r.period().value(), 2.0);
        let counted: Vec<usize> = r.events().map(|(_, slot, _)| slot).collect();
        assert_eq!(counted, [1, 0]);
        let mut r = Returns::default();
        for (i, slot) in (0..MAX_CYCLE).chain([0]).enumerate() {
            r.visit((0, slot, None), 0, Time::new(i as f64), &[slot as f64]);
        }
        assert_eq!(r.cycle(), Some(MAX_CYCLE), "the longest period");
        assert_eq!(r.period().value(), MAX_CYCLE as f64);
        assert_eq!(r.events().count(), MAX_CYCLE);
        let mut r = Returns::default();
        for (i, slot) in (0..MAX_CYCLE + 1).chain([0]).enumerate() {
            r.visit((0, slot, None), 0, Time::new(i as f64), &[slot as f64]);
        }
        assert_eq!(
            r.cycle(),
            None,
            "the same state {} events back",
            MAX_CYCLE + 1
        );
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
