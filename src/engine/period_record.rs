//! What a stepped run's error bound did over the last period between two
//! events, kept so that a jump over whole periods of a periodic orbit (see
//! [`periodic`](crate::engine::periodic)) carries the bound over them as
//! firing each would have.
//!
//! A run whose steps depend only on the state they start from (the linear
//! propagator, Taylor's method) repeats its last period from a repeated
//! state: the same steps, the same tangent maps, the same saltation. What
//! changes from one period to the next is the set of errors they carry,
//! and with it the checks that stop a run (a graze within the errors, an
//! event time uncertain by half a period). So the bound records each
//! operation of a period here: each step's tangent map and local error,
//! each graze check's gradient and margin, the event's saltation; a jump
//! replays them period by period, checks included (`Bound::replay` in
//! `bound.rs`), and stops
//! short of the first period whose checks would fail (the run then fires
//! it, and fails there itself).
//!
//! A step's scan proves a guard clear only of the uncertainty it was given
//! (its coefficients stay above it): a recording run scans with
//! [`HEADROOM`] times the uncertainty, so a replayed check holds until the
//! errors have grown that much. Scanning with more changes no crossing and
//! no margin that the run compares, only which shortcut a scan takes.

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
    Step {
        at: usize,
        local: f64,
    },
    Margin {
        at: usize,
        local: f64,
        limit: f64,
    },
    Event {
        at: usize,
        closing: f64,
        depth: f64,
        widen: f64,
        timed: bool,
    },
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
    /// The event: the errors along its guard's `gradient` move it in time
    /// (closing at `closing`, its dip `depth` deep); they go through the
    /// `saltation` matrix, and `widen` is added. A `timed` event (not an
    /// internal switch) has its time bounded.
    Event {
        gradient: &'a [f64],
        saltation: &'a [f64],
        closing: f64,
        depth: f64,
        widen: f64,
        timed: bool,
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

/// The operations since the last event, and the last whole period's, of a
/// run of dimension `n`.
#[derive(Debug, Clone, Default)]
pub(crate) struct PeriodRecord {
    n: usize,
    on: bool,
    current: Period,
    last: Period,
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
    pub fn event(
        &mut self,
        (gradient, saltation): (&[f64], &[f64]),
        (closing, depth, widen): (f64, f64, f64),
        timed: bool,
    ) {
        if !self.on {
            return;
        }
        self.current
            .push(&[gradient, saltation], |at| Stored::Event {
                at,
                closing,
                depth,
                widen,
                timed,
            });
        std::mem::swap(&mut self.current, &mut self.last);
        self.current.restart(true);
    }

    /// The last period's operations, where it was recorded whole.
    pub fn last(&self) -> Option<impl Iterator<Item = Op<'_>>> {
        let (n, period) = (self.n, &self.last);
        let x = &period.numbers;
        (self.on && period.whole).then(|| {
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
                Stored::Event {
                    at,
                    closing,
                    depth,
                    widen,
                    timed,
                } => Op::Event {
                    gradient: &x[at..at + n],
                    saltation: &x[at + n..at + n + n * n],
                    closing,
                    depth,
                    widen,
                    timed,
                },
            })
        })
    }
}
