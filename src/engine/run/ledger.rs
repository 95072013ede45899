//! A run's books, kept the same way whichever source of segments drives it:
//! the events logged and counted per guard, the energy audit, the Zeno
//! watch and what was settled, the budgets and the stop flag, and the
//! [`Outcome`] they add up to. The rules are the loop's, in
//! [`run_loop`](crate::engine::run::run_loop).

use std::collections::BTreeMap;
use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::engine::bound::ErrorEstimate;
use crate::engine::bound::zeno::ZenoWatch;
use crate::engine::model::Mode;
use crate::engine::model::names::Name;
use crate::engine::run::observer::{EventRecord, Observer, SETTLE};
use crate::engine::run::periodic::Counted;
use crate::engine::run::{FastForward, Options, Outcome, Status};
use crate::time::Time;

/// Turns of the loop between two readings of the wall clock.
pub const CLOCK_EVERY: u64 = 64;

/// Wall time between two progress reports, in seconds.
pub const PROGRESS_SECONDS: f64 = 0.2;

/// Events between two projections of the event budget.
pub const BUDGET_CHECK: u64 = 1 << 20;

/// Why the loop stopped, with a reason for anything but completion.
#[derive(Debug, Clone)]
pub(crate) struct End {
    pub status: Status,
    pub reason: Option<String>,
}

impl End {
    /// A run that cannot be trusted past this point, and why.
    pub fn failed(reason: String) -> Self {
        End {
            status: Status::Failed,
            reason: Some(reason),
        }
    }

    /// A Zeno accumulation the run stopped at.
    pub fn zeno(reason: String) -> Self {
        End {
            status: Status::Zeno,
            reason: Some(reason),
        }
    }
}

/// What only the source knows at the end of a run.
pub(crate) struct Final<'a> {
    pub t_reached: Time,
    pub mode: Mode,
    pub mode_name: &'a str,
    pub state_names: &'a [Name],
    pub state: Vec<f64>,
    pub energy: Option<f64>,
    pub flow_evaluations: u64,
    pub error_bound: Option<f64>,
    pub error_estimate: Option<ErrorEstimate>,
    pub event_time_bound: Option<f64>,
    pub horizon: Option<f64>,
}

pub(crate) struct Ledger<'o> {
    options: &'o Options,
    started: Instant,
    turn: u64,
    /// Wall time of the last progress report.
    reported: f64,
    /// The event count at which to project the budget next, and the count
    /// and time at the previous projection.
    budget_check: (u64, u64, Time),
    events: u64,
    /// Event counts per mode and guard.
    counts: Vec<Vec<u64>>,
    /// Counts of the events a reset named (see `Jump::event`).
    named: BTreeMap<Name, u64>,
    zeno: ZenoWatch,
    settles: u64,
    /// Events logged past the horizon (flagged `shadow`).
    shadow_events: u64,
    /// Set once the run has settled a Zeno accumulation and gone on.
    zeno_reason: Option<String>,
    energy_initial: Option<f64>,
    /// What the energy should be now: the initial energy, moved by each
    /// reset's change where resets may change it.
    energy_reference: Option<f64>,
    /// Whether a reset's change of energy moves the reference.
    rebase_at_resets: bool,
    energy_scale: f64,
    /// The largest distance of the energy from its reference so far: the
    /// error, before it is made relative at the end.
    max_energy_error: Option<f64>,
    /// The largest energy met, the scale where the initial energy is zero
    /// (a forced system started at rest): relative to zero, any change
    /// would be infinite.
    energy_peak: f64,
    /// The periods jumped over so far.
    fast_forward: Option<FastForward>,
}

impl<'o> Ledger<'o> {
    /// Books for a run under `options` whose initial energy is
    /// `energy_initial`, errors measured against `energy_scale`.
    pub fn new(options: &'o Options, energy_initial: Option<f64>, energy_scale: f64) -> Self {
        Ledger {
            options,
            started: Instant::now(),
            turn: 0,
            reported: 0.0,
            budget_check: (BUDGET_CHECK, 0, Time::new(0.0)),
            events: 0,
            counts: Vec::new(),
            named: BTreeMap::new(),
            zeno: ZenoWatch::new(options.t_end),
            settles: 0,
            shadow_events: 0,
            zeno_reason: None,
            energy_initial,
            energy_reference: energy_initial,
            rebase_at_resets: false,
            energy_scale,
            max_energy_error: energy_initial.map(|_| 0.0),
            energy_peak: energy_initial.map_or(0.0, f64::abs),
            fast_forward: None,
        }
    }

    /// Audit the energy along the flows only: each logged reset's change of
    /// energy moves the reference (for a model whose resets may change the
    /// energy, [`HybridModel::resets_keep_energy`]).
    ///
    /// [`HybridModel::resets_keep_energy`]: crate::engine::HybridModel::resets_keep_energy
    pub fn rebase_at_resets(mut self) -> Self {
        self.rebase_at_resets = true;
        self
    }

    pub fn t_end(&self) -> f64 {
        self.options.t_end
    }

    /// Events logged so far, settlings included.
    pub fn events(&self) -> u64 {
        self.events
    }

    /// The stop flag at every turn; the wall-time budget and progress every
    /// [`CLOCK_EVERY`] turns.
    #[inline]
    pub fn look_outside<O: Observer + ?Sized>(
        &mut self,
        now: Time,
        observer: &mut O,
    ) -> Result<(), End> {
        if self
            .options
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            return Err(End {
                status: Status::Interrupted,
                reason: Some("stopped by a signal".into()),
            });
        }
        self.turn = self.turn.wrapping_add(1);
        if self.turn.is_multiple_of(CLOCK_EVERY) {
            self.read_clock(now, observer)?;
        }
        Ok(())
    }

    #[inline(never)]
    fn read_clock<O: Observer + ?Sized>(&mut self, now: Time, observer: &mut O) -> Result<(), End> {
        let elapsed = self.started.elapsed().as_secs_f64();
        if let Some(limit) = self.options.max_wall_seconds
            && elapsed > limit
        {
            return Err(End::failed(format!(
                "wall-time budget of {limit} s spent at t = {:e} after {} events",
                now.value(),
                self.events
            )));
        }
        if elapsed - self.reported >= PROGRESS_SECONDS {
            observer.on_progress(now.value(), self.events);
            self.reported = elapsed;
        }
        Ok(())
    }

    /// The event budget after a turn that reached `now`.
    #[inline]
    pub fn check_events(&mut self, now: Time) -> Result<(), End> {
        if self.events > self.options.max_events {
            return Err(End::failed(format!(
                "event budget: more than max_events = {} events by t = {:e}; raise max_events or shorten t_end",
                self.options.max_events,
                now.value()
            )));
        }
        if self.events >= self.budget_check.0 {
            return self.project_budget(now);
        }
        Ok(())
    }

    /// Project the events still needed to reach `t_end` at the recent rate,
    /// so that a run that cannot finish within `max_events` says so early
    /// instead of grinding to the limit.
    #[inline(never)]
    fn project_budget(&mut self, t: Time) -> Result<(), End> {
        let (_, events_then, t_then) = self.budget_check;
        let max = self.options.max_events;
        let rate = (self.events - events_then) as f64 / t.since(t_then);
        let needed = self.events as f64 + rate * Time::new(self.options.t_end).since(t);
        if needed > max as f64 {
            return Err(End::failed(format!(
                "event budget: {} events by t = {:e}, and at the recent rate ({rate:.3e} events per unit time) \
                 reaching t_end = {} needs about {needed:.3e}, more than max_events = {max}; \
                 raise max_events or shorten t_end",
                self.events,
                t.value(),
                self.options.t_end
            )));
        }
        self.budget_check = (self.events + BUDGET_CHECK, self.events, t);
        Ok(())
    }

    /// Count an event the model named otherwise than its guard.
    pub fn count_named(&mut self, name: &Name) {
        self.count_named_many(name, 1);
    }

    fn count_named_many(&mut self, name: &Name, n: u64) {
        match self.named.get_mut(name) {
            Some(count) => *count += n,
            None => {
                self.named.insert(name.clone(), n);
            }
        }
    }

    /// Periods of `tau`, with `events` events each, that a jump from `now`
    /// may count, so that the budget's rules hold as if each event fired:
    /// never past the budget (the event past it fails the run), and not
    /// past the budget's next projection where that projection (at the
    /// orbit's rate) would fail the run there.
    pub fn jump_allowance(&self, (tau, events): (f64, u64), now: Time) -> u64 {
        let max = self.options.max_events;
        let left = max.saturating_sub(self.events);
        let to_projection = self.budget_check.0.saturating_sub(self.events);
        let needed =
            self.events as f64 + Time::new(self.options.t_end).since(now) / tau * events as f64;
        let allowed = if left > to_projection && needed > max as f64 {
            to_projection
        } else {
            left
        };
        allowed / events.max(1)
    }

    /// A jump over `periods` periods of `tau`, from `from` to `to`, each
    /// with one event of each of `cycle` (a guard of a mode, or the name
    /// its reset gives): count them as fired.
    pub fn jumped<'a>(
        &mut self,
        cycle: impl Iterator<Item = Counted<'a>>,
        periods: u64,
        tau: f64,
        (from, to): (Time, Time),
    ) {
        let mut events = 0;
        for (mode, slot, named) in cycle {
            match named {
                Some(name) => self.count_named_many(name, periods),
                None => self.count_many(mode, slot, periods),
            }
            events += 1;
        }
        self.events += periods * events;
        if self.events > self.budget_check.0 {
            // The projections jumped over passed (see `jump_allowance`);
            // one the jump stops at is the loop's to make.
            self.budget_check = (self.events + BUDGET_CHECK, self.events, to);
        }
        let jump = self.fast_forward.get_or_insert(FastForward {
            periods: 0,
            events_per_period: events,
            period: tau,
            from: from.value(),
            to: to.value(),
        });
        jump.periods += periods;
        (jump.events_per_period, jump.period, jump.to) = (events, tau, to.value());
    }

    /// Count a non-internal event of guard `slot` in `mode`.
    #[inline]
    pub fn count(&mut self, mode: Mode, slot: usize) {
        self.count_many(mode, slot, 1);
    }

    /// Count `n` non-internal events of guard `slot` in `mode`.
    #[inline]
    fn count_many(&mut self, mode: Mode, slot: usize, n: u64) {
        if self.counts.len() <= mode {
            self.counts.resize(mode + 1, Vec::new());
        }
        let counts = &mut self.counts[mode];
        if counts.len() <= slot {
            counts.resize(slot + 1, 0);
        }
        counts[slot] += n;
    }

    /// Log `event` (its `seq` is the ledger's to number), auditing the
    /// energies it carries.
    #[inline]
    pub fn log<O: Observer + ?Sized>(
        &mut self,
        mut event: EventRecord,
        observer: &mut O,
    ) -> Result<(), End> {
        self.events += 1;
        event.seq = self.events;
        self.audit(event.energy_before);
        // A change within the energies' own rounding is no change: summed
        // over millions of resets it would be a drift of the books alone.
        if self.rebase_at_resets
            && let (Some(before), Some(after), Some(reference)) = (
                event.energy_before,
                event.energy_after,
                self.energy_reference.as_mut(),
            )
            && (after - before).abs() > 8.0 * f64::EPSILON * before.abs().max(after.abs())
        {
            *reference += after - before;
        }
        self.audit(event.energy_after);
        self.shadow_events += u64::from(event.shadow);
        observer
            .on_event(&event)
            .map_err(|e| End::failed(format!("could not write the event log: {e}")))?;
        match observer.stop() {
            Some(why) => Err(End {
                status: Status::Interrupted,
                reason: Some(format!("stopped by its observer: {why}")),
            }),
            None => Ok(()),
        }
    }

    /// Audit one value of the energy.
    #[inline]
    pub fn audit(&mut self, energy: Option<f64>) {
        if let (Some(e), Some(e0), Some(max)) = (
            energy,
            self.energy_reference,
            self.max_energy_error.as_mut(),
        ) {
            *max = max.max((e - e0).abs());
            self.energy_peak = self.energy_peak.max(e.abs());
        }
    }

    /// What the energy error is relative to: the model's scale for the
    /// initial energy, or, where that is zero, the largest energy met.
    fn relative_to(&self) -> f64 {
        if self.energy_scale > f64::MIN_POSITIVE {
            self.energy_scale
        } else {
            self.energy_peak.max(f64::MIN_POSITIVE)
        }
    }

    /// Show the watch that guard `slot` (named `name`) of `mode` fired at
    /// `t`; if its events are now Zeno, what was seen, for the reason.
    #[inline]
    pub fn zeno(&mut self, mode: Mode, slot: usize, name: &str, t: Time) -> Option<String> {
        self.zeno.observe(mode, slot, t).then(|| {
            format!(
                "events of guard `{name}` accumulate at t = {:e} faster than the run can resolve ({})",
                t.value(),
                self.zeno.describe()
            )
        })
    }

    /// Where the run's bound cannot order an event of guard `slot` of
    /// `mode` (named `name`) at `t`: whether it is one of a pile-up of
    /// that guard's events (see [`ZenoWatch::chattering`]), and if so
    /// what was seen, in the Zeno watch's words (and the pile-up is
    /// spent: a later one must shrink anew).
    pub fn chatters(&mut self, mode: Mode, slot: usize, name: &str, t: Time) -> Option<String> {
        let seen = self.zeno.describe_chattering(mode, slot)?;
        self.zeno.forget_chattering(mode, slot);
        Some(format!(
            "events of guard `{name}` accumulate at t = {:e} faster than the run can resolve ({seen})",
            t.value()
        ))
    }

    /// The Zeno accumulation `what` has no resting mode: the run stops.
    pub fn unsettled(what: &str) -> End {
        End::zeno(format!(
            "{what}: the events pile up at the guard (an orbit chattering down onto it would come \
             to rest there), and the model has no resting mode to go on in, so the run stops here; \
             an automaton's mode names one with `rest` (docs/automata.md, \"Resting modes\")"
        ))
    }

    /// Log the settling of the Zeno accumulation `what` into `rest` and go
    /// on; the run will end `zeno`.
    pub fn settled<O: Observer + ?Sized>(
        &mut self,
        what: String,
        rest: &str,
        event: EventRecord,
        observer: &mut O,
    ) -> Result<(), End> {
        self.settles += 1;
        self.zeno_reason = Some(format!("{what}; settled into {rest}"));
        self.log(event, observer)
    }

    /// How a run that reached `t_end` ended.
    pub fn completed(&self) -> End {
        match &self.zeno_reason {
            Some(reason) => End::zeno(reason.clone()),
            None => End {
                status: Status::Completed,
                reason: None,
            },
        }
    }

    /// The outcome of a run that ended as `end`, `guard_name` naming the
    /// guards counted.
    pub fn outcome(
        mut self,
        end: End,
        last: Final,
        guard_name: impl Fn(Mode, usize) -> Name,
    ) -> Outcome {
        self.audit(last.energy);
        let mut events_by_guard = BTreeMap::new();
        for (mode, counts) in self.counts.iter().enumerate() {
            for (slot, &n) in counts.iter().enumerate() {
                if n > 0 {
                    *events_by_guard.entry(guard_name(mode, slot)).or_insert(0) += n;
                }
            }
        }
        for (name, n) in std::mem::take(&mut self.named) {
            *events_by_guard.entry(name).or_insert(0) += n;
        }
        if self.settles > 0 {
            events_by_guard.insert(Name::new(SETTLE), self.settles);
        }
        Outcome {
            zeno: end.status == Status::Zeno || self.zeno_reason.is_some(),
            status: end.status,
            reason: end.reason,
            t_end: self.options.t_end,
            t_reached: last.t_reached.value(),
            events: self.events,
            events_by_guard,
            energy_initial: self.energy_initial,
            energy_final: last.energy,
            max_energy_error: self
                .max_energy_error
                .map(|error| error / self.relative_to()),
            final_mode: last.mode,
            final_mode_name: Name::from(last.mode_name),
            final_state_names: last.state_names.to_vec(),
            final_state: last.state,
            flow_evaluations: last.flow_evaluations,
            error_bound: last.error_bound,
            error_estimate: last.error_estimate,
            horizon: last.horizon,
            shadow_events: self.shadow_events,
            event_time_bound: last.event_time_bound,
            fast_forward: self.fast_forward,
            wall_seconds: self.started.elapsed().as_secs_f64(),
        }
    }
}
