//! What a stepped run's error bound did between each of the last events
//! and the one before it, kept so that a jump over whole periods of a
//! periodic orbit (see [`periodic`](crate::engine::run::periodic)) carries the
//! bound over them as firing each event would have.
//!
//! A run whose steps depend only on the state they start from (the linear
//! propagator, Taylor's method) repeats its last period from a repeated
//! state: the same steps, the same tangent maps, the same saltations. What
//! changes from one period to the next is the set of errors they carry,
//! and with it the checks that stop a run (a graze within the errors, an
//! event time uncertain by half the time since the event before). So the
//! bound records each operation here: each step's tangent map and local
//! error, each graze check's gradient and margin, each event's saltation;
//! a jump replays the period's (the stretches between its events, in
//! order) period by period, checks included (`Bound::replay` in
//! `bound.rs`), and stops short of the first period whose checks would
//! fail (the run then fires it, and fails there itself).
//!
//! A step's scan proves a guard clear only of the uncertainty it was given
//! (its coefficients stay above it): a recording run scans with
//! [`HEADROOM`] times the uncertainty, so a replayed check holds until the
//! errors have grown that much. Scanning with more changes no crossing and
//! no margin that the run compares, only which shortcut a scan takes.

use std::collections::VecDeque;

/// The most events one period may hold: a state after an event is
/// compared with the states after this many events before it.
pub const MAX_CYCLE: usize = 8;

/// The most periods one jump replays: a replay costs each period's maps,
/// and the run loop reads the wall clock and looks for an interrupt between
/// its turns, so a long run of jumps must come back to it (about 1 ms of
/// replay on the mechanism).
pub const REPLAYED_AT_ONCE: u64 = 1024;

/// How many times the uncertainty a recording run's scans prove a guard
/// clear of: a jump may go on until the errors have grown this much.
pub const HEADROOM: f64 = 16.0;

/// One operation of the bound, as stored: its vectors and matrices are in
/// the period's numbers from `at`.
#[derive(Debug, Clone, Copy)]
enum Stored {
    Step { at: usize, local: f64 },
    Margin { at: usize, local: f64, limit: f64 },
    Event { at: usize, facts: EventFacts },
}

/// An event's numbers besides its vectors: the errors along its guard's
/// gradient move it in time (closing at `closing`, its dip `depth` deep,
/// `since` after the event before it); `widen` is added after its
/// saltation. A `timed` event (not an internal switch) has its time
/// bounded.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EventFacts {
    pub closing: f64,
    pub depth: f64,
    pub widen: f64,
    pub since: f64,
    pub timed: bool,
}

/// One operation of the bound over a period, as a replay reads it.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Op<'a> {
    /// A step: the errors go through the tangent map `matrix` (`n x n`,
    /// row by row), and the step's `local` error is added.
    Step { matrix: &'a [f64], local: f64 },
    /// A graze check: the errors along the guard's `gradient`, plus the
    /// step's `local` error along it, must stay below `limit`, the least
    /// margin the step's scan showed.
    Margin {
        gradient: &'a [f64],
        local: f64,
        limit: f64,
    },
    /// The event: the errors along its guard's `gradient` move it in time,
    /// and go through the `saltation` matrix (see [`EventFacts`]).
    Event {
        gradient: &'a [f64],
        saltation: &'a [f64],
        facts: EventFacts,
    },
}

/// A period's operations, in order.
#[derive(Debug, Clone, Default)]
struct Period {
    ops: Vec<Stored>,
    numbers: Vec<f64>,
    /// Whether it holds every operation since the event before (none that
    /// cannot be replayed, none missed before the recording began).
    whole: bool,
}

impl Period {
    fn restart(&mut self, whole: bool) {
        self.ops.clear();
        self.numbers.clear();
        self.whole = whole;
    }

    fn push(&mut self, numbers: &[&[f64]], op: impl FnOnce(usize) -> Stored) {
        let at = self.numbers.len();
        numbers
            .iter()
            .for_each(|x| self.numbers.extend_from_slice(x));
        self.ops.push(op(at));
    }
}

/// The operations since the last event, and those between each of the
/// last [`MAX_CYCLE`] events and the one before it, oldest first, of a run
/// of dimension `n`.
#[derive(Debug, Clone, Default)]
pub(crate) struct PeriodRecord {
    n: usize,
    on: bool,
    current: Period,
    last: VecDeque<Period>,
}

impl PeriodRecord {
    /// Whether operations are being recorded.
    pub fn on(&self) -> bool {
        self.on
    }

    /// Record the operations of a run of dimension `n` from now on. What
    /// has happened since the last event was not recorded, so the period
    /// under way is not whole.
    pub fn start(&mut self, n: usize) {
        if !self.on {
            (self.on, self.n) = (true, n);
            self.current.restart(false);
        }
    }

    /// Something no replay can repeat happened in the period under way
    /// (or, after a jump, it no longer starts from the errors it was
    /// checked against).
    pub fn broken(&mut self) {
        self.current.whole = false;
    }

    /// A step's tangent map `matrix` and local error.
    pub fn step(&mut self, matrix: &[f64], local: f64) {
        if self.on {
            self.current
                .push(&[matrix], |at| Stored::Step { at, local });
        }
    }

    /// A graze check along `gradient` with a step's `local` error; its
    /// limit follows from the scan ([`PeriodRecord::margin_limit`]).
    pub fn margin(&mut self, gradient: &[f64], local: f64) {
        if self.on {
            self.current.push(&[gradient], |at| Stored::Margin {
                at,
                local,
                limit: f64::NAN,
            });
        }
    }

    /// The least margin the scan of the last recorded graze check showed.
    pub fn margin_limit(&mut self, limit: f64) {
        if !self.on {
            return;
        }
        match self.current.ops.last_mut() {
            Some(Stored::Margin { limit: l, .. }) if l.is_nan() => *l = limit,
            _ => self.current.whole = false,
        }
    }

    /// The event that ends the period (see [`Op::Event`]). The period
    /// becomes the last one, and the next begins.
    pub fn event(&mut self, (gradient, saltation): (&[f64], &[f64]), facts: EventFacts) {
        if !self.on {
            return;
        }
        self.current
            .push(&[gradient, saltation], |at| Stored::Event { at, facts });
        let mut next = if self.last.len() == MAX_CYCLE {
            self.last.pop_front().unwrap_or_default()
        } else {
            Period::default()
        };
        next.restart(true);
        self.last
            .push_back(std::mem::replace(&mut self.current, next));
    }

    /// The operations between the last `events` events and the one before
    /// each, in order, where each stretch was recorded whole.
    pub fn last(&self, events: usize) -> Option<impl Iterator<Item = Op<'_>>> {
        let n = self.n;
        let from = self.last.len().checked_sub(events)?;
        let stretches = self.last.range(from..);
        (self.on && events > 0 && stretches.clone().all(|p| p.whole)).then(|| {
            stretches.flat_map(move |period| {
                let x = &period.numbers;
                period.ops.iter().map(move |op| match *op {
                    Stored::Step { at, local } => Op::Step {
                        matrix: &x[at..at + n * n],
                        local,
                    },
                    Stored::Margin { at, local, limit } => Op::Margin {
                        gradient: &x[at..at + n],
                        local,
                        limit,
                    },
                    Stored::Event { at, facts } => Op::Event {
                        gradient: &x[at..at + n],
                        saltation: &x[at + n..at + n + n * n],
                        facts,
                    },
                })
            })
        })
    }
}
