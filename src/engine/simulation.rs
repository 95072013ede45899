//! The event-driven loop: predict, pop the earliest event, advance, reset,
//! re-predict, record.
//!
//! The loop never asks which integrator a mode uses. A mode's flow gives a
//! *segment*: for an exact flow, the whole future (guards predicted by the
//! model's exact crossing times); for an ODE, one accepted step with dense
//! output (guards located on it, see [`locate`]). The queue holds one
//! prediction per guard; whichever comes first, the earliest prediction or
//! the end of the current step, happens next.
//!
//! How a run can end, in [`Status`]: it reaches `t_end`; events of one guard
//! accumulate faster than the run can resolve (Zeno), and the model either
//! settles into a resting mode or the run stops there; a method fails (step
//! size collapse, non-finite state, event budget spent, the log could not be
//! written); or it is interrupted. The run never spins.
//!
//! [`locate`]: crate::engine::locate

use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use crate::engine::adaptive::{StepFailure, Tolerances};
use crate::engine::bound::Bound;
use crate::engine::integrator::{Crossing, Integrator, Method, Motion, motion};
use crate::engine::labels::Labels;
use crate::engine::locate::scan_step;
use crate::engine::model::{Affects, Direction, HybridModel, Mode};
use crate::engine::observer::{EventRecord, Observer, SETTLE};
use crate::engine::queue::EventQueue;
use crate::engine::zeno::ZenoWatch;
use crate::time::Time;

/// How to run a model.
#[derive(Debug, Clone)]
pub struct Options {
    /// Simulated time to stop at (the run starts at 0).
    pub t_end: f64,
    /// Stop with `failed` after this many events (guards against runs that
    /// would take forever without being Zeno).
    pub max_events: u64,
    /// How to advance the flows ([`Method::Auto`]: each mode's cheapest
    /// exact description).
    pub method: Method,
    /// Tolerances of Dormand-Prince where [`Method::Auto`] needs it (modes
    /// whose only flow is an ODE).
    pub tolerances: Tolerances,
    /// Set from outside (a signal handler) to stop the run cleanly.
    pub stop: Option<Arc<AtomicBool>>,
    /// Stop with `failed` after this much wall time (seconds), if set.
    pub max_wall_seconds: Option<f64>,
}

impl Options {
    /// Run to `t_end` with a budget of 10^9 events and default tolerances.
    pub fn until(t_end: f64) -> Self {
        Options {
            t_end,
            max_events: 1_000_000_000,
            method: Method::Auto,
            tolerances: Tolerances::default(),
            stop: None,
            max_wall_seconds: None,
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Reached `t_end`.
    Completed,
    /// A Zeno accumulation was recognised (see [`Outcome::reason`]); the run
    /// either settled into resting contact and went on, or stopped there.
    Zeno,
    /// A method failed; the result cannot be trusted past `t_reached`.
    Failed,
    /// Stopped from outside.
    Interrupted,
}

impl Status {
    /// The status as the summary writes it: `completed`, `zeno`, `failed` or
    /// `interrupted`.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Completed => "completed",
            Status::Zeno => "zeno",
            Status::Failed => "failed",
            Status::Interrupted => "interrupted",
        }
    }
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// How the run ended.
    pub status: Status,
    /// Why the run is not plainly `completed`.
    pub reason: Option<String>,
    /// The simulated time the run was asked to reach.
    pub t_end: f64,
    /// The simulated time it reached: `t_end` unless it stopped early.
    pub t_reached: f64,
    /// Non-internal events (impacts and other resets).
    pub events: u64,
    /// Events per guard name; Zeno settlings under [`SETTLE`].
    pub events_by_guard: BTreeMap<&'static str, u64>,
    /// Whether a Zeno accumulation was recognised, whether the run then
    /// settled and went on or stopped there.
    pub zeno: bool,
    /// The model's energy at the start, if it has one.
    pub energy_initial: Option<f64>,
    /// The model's energy at the end, if it has one.
    pub energy_final: Option<f64>,
    /// Largest `|E - E(0)| / scale` seen at any event and at the end.
    pub max_energy_error: Option<f64>,
    /// The mode the run ended in.
    pub final_mode: Mode,
    /// That mode's name.
    pub final_mode_name: &'static str,
    /// Names of the components of `final_state`.
    pub final_state_names: Vec<&'static str>,
    /// The state at `t_reached`.
    pub final_state: Vec<f64>,
    /// Evaluations of the flow: right-hand sides and propagators of
    /// numerical methods, flow maps and crossing times of exact ones.
    pub flow_evaluations: u64,
    /// The largest error any state component may carry at the end: the
    /// numerical steps' local errors carried through the flow and across
    /// every event (see [`bound`](crate::engine::bound)), plus a round-off allowance of
    /// [`ROUNDOFF_ULPS`](crate::engine::bound::ROUNDOFF_ULPS) ulps of the state's size per event. Above
    /// [`TRACKED`](crate::engine::error_set::TRACKED) state components,
    /// the plain sum of the local errors instead.
    pub error_bound: f64,
    /// The largest error any event time may carry: each event's share of
    /// the state error divided by its closing speed, plus a round-off
    /// allowance of [`ROUNDOFF_ULPS`](crate::engine::bound::ROUNDOFF_ULPS) ulps of the time reached; `None`
    /// where the errors are not tracked.
    pub event_time_bound: Option<f64>,
    /// Wall time the run took, in seconds.
    pub wall_seconds: f64,
}

/// The state at one of the sample times a run was asked for.
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    /// The sample time.
    pub t: f64,
    /// The mode then.
    pub mode: Mode,
    /// The state then (before an event at the same time).
    pub state: &'a [f64],
    /// Events logged before it.
    pub events: u64,
}

/// Run `model` from state `x0` in `mode` at `t = 0`, reporting events to
/// `observer`.
pub fn simulate<M: HybridModel + ?Sized, O: Observer + ?Sized>(
    model: &M,
    mode: Mode,
    x0: &[f64],
    options: &Options,
    observer: &mut O,
) -> Outcome {
    simulate_sampled(model, mode, x0, options, &[], &mut |_| {}, observer)
}

/// [`simulate`], also calling `on_sample` with the state at each of
/// `samples` (times in increasing order, up to `t_end`), taken from the
/// flow as it goes: the run is not restarted there, so sampling changes
/// neither its steps nor its events.
pub fn simulate_sampled<M: HybridModel + ?Sized, O: Observer + ?Sized>(
    model: &M,
    mode: Mode,
    x0: &[f64],
    options: &Options,
    samples: &[f64],
    on_sample: &mut dyn FnMut(&Sample),
    observer: &mut O,
) -> Outcome {
    // The model is asked nothing about a state it cannot hold.
    let refused = if x0.len() != model.dimension() {
        Some(format!(
            "the initial state has {} components, the model {}",
            x0.len(),
            model.dimension()
        ))
    } else if !all_finite(x0) {
        Some(format!("the initial state {x0:?} is not finite"))
    } else {
        None
    };
    let x0 = if refused.is_some() {
        vec![0.0; model.dimension()]
    } else {
        x0.to_vec()
    };
    let mut run = Run::new(model, mode, &x0, options);
    let end = match refused {
        Some(reason) => End::failed(reason),
        None => run.event_loop(observer, samples, on_sample),
    };
    run.outcome(end)
}

/// Why the loop stopped, with a reason for anything but completion.
struct End {
    status: Status,
    reason: Option<String>,
}

impl End {
    fn failed(reason: String) -> Self {
        End {
            status: Status::Failed,
            reason: Some(reason),
        }
    }
}

struct Run<'m, M: HybridModel + ?Sized> {
    model: &'m M,
    options: &'m Options,
    started: Instant,
    mode: Mode,
    /// Time of the last event (or step end); `state` is the state then.
    origin: Time,
    state: Vec<f64>,
    queue: EventQueue,
    integrator: Integrator,
    /// How the current mode moves under the run's method.
    motion: Motion,
    /// The same for every mode met so far.
    motions: Vec<Option<Motion>>,
    /// Flow maps and crossing times asked of exact flows.
    exact_evaluations: u64,
    /// The errors so far, and the bounds the run will state.
    bound: Bound,
    /// When the integrator's current step ends, for stepped modes.
    step_end: Option<Time>,
    /// Whether the integrator's last step starts at the current origin.
    stepped: bool,
    /// Set at `t = 0` and after each reset: guards exactly on zero are
    /// checked for firing at once, and so is the barrier guard that just
    /// fired (`Some(slot)`, within the same mode).
    fresh: Option<Option<usize>>,
    zeno: ZenoWatch,
    /// Set once the run has settled a Zeno accumulation and gone on.
    zeno_reason: Option<String>,
    settles: u64,
    /// The event count at which to check the budget next, and the count
    /// and time at the previous check.
    budget_check: (u64, u64, Time),
    before: Vec<f64>,
    after: Vec<f64>,
    events: u64,
    /// Event counts per mode and guard slot.
    counts: Vec<Vec<u64>>,
    energy_initial: Option<f64>,
    energy_scale: f64,
    max_energy_error: Option<f64>,
}

impl<'m, M: HybridModel + ?Sized> Run<'m, M> {
    fn new(model: &'m M, mode: Mode, x0: &[f64], options: &'m Options) -> Self {
        let n = model.dimension();
        let energy_initial = model.energy(mode, x0);
        Run {
            model,
            options,
            started: Instant::now(),
            mode,
            origin: Time::new(0.0),
            state: x0.to_vec(),
            queue: EventQueue::default(),
            integrator: Integrator::for_method(options.method, n, options.tolerances),
            motion: Motion::Frozen,
            motions: Vec::new(),
            exact_evaluations: 0,
            bound: Bound::new(n, x0),
            stepped: false,
            step_end: None,
            fresh: Some(None),
            zeno: ZenoWatch::new(options.t_end),
            zeno_reason: None,
            settles: 0,
            budget_check: (BUDGET_CHECK, 0, Time::new(0.0)),
            before: vec![0.0; n],
            after: vec![0.0; n],
            events: 0,
            counts: Vec::new(),
            energy_initial,
            energy_scale: energy_initial.map_or(1.0, |e| model.energy_scale(e)),
            max_energy_error: energy_initial.map(|_| 0.0),
        }
    }

    fn event_loop<O: Observer + ?Sized>(
        &mut self,
        observer: &mut O,
        samples: &[f64],
        on_sample: &mut dyn FnMut(&Sample),
    ) -> End {
        let t_end = self.options.t_end;
        let mut sampled = 0;
        if let Err(end) = self.start_segment() {
            return end;
        }
        let mut turn: u64 = 0;
        loop {
            turn = turn.wrapping_add(1);
            if self
                .options
                .stop
                .as_ref()
                .is_some_and(|s| s.load(Ordering::Relaxed))
            {
                return End {
                    status: Status::Interrupted,
                    reason: Some("stopped by a signal".into()),
                };
            }
            if turn.is_multiple_of(PROGRESS_EVERY) {
                observer.on_progress(self.origin.value(), self.events);
            }
            if turn.is_multiple_of(1024)
                && let Some(limit) = self.options.max_wall_seconds
                && self.started.elapsed().as_secs_f64() > limit
            {
                return End::failed(format!(
                    "wall-time budget of {limit} s spent at t = {:e} after {} events",
                    self.origin.value(),
                    self.events
                ));
            }
            // An event at the very end of a step happens before the step ends.
            let next = match (self.queue.peek(), self.step_end) {
                (Some((_, t)), Some(end)) if end < t => (None, end),
                (Some((slot, t)), _) => (Some(slot), t),
                (None, Some(end)) => (None, end),
                (None, None) => (None, Time::new(f64::INFINITY)),
            };
            // Samples due before what happens next see the flow as it is.
            let due = next.1.value().min(t_end);
            while let Some(&s) = samples.get(sampled)
                && s <= due
            {
                self.sample_at(s, on_sample);
                sampled += 1;
            }
            let result = match next {
                (_, t) if t.value() > t_end => return self.finish_at(Time::new(t_end)),
                (Some(slot), t) => {
                    self.queue.pop();
                    self.fire(slot, t, observer)
                }
                (None, t) => {
                    self.close_segment(t.since(self.origin));
                    self.integrator.end(&mut self.state);
                    self.origin = t;
                    self.start_segment()
                }
            };
            if let Err(end) = result {
                return end;
            }
            if self.events > self.options.max_events {
                return End::failed(format!(
                    "event budget: more than max_events = {} events by t = {:e}; raise max_events or shorten t_end",
                    self.options.max_events,
                    self.origin.value()
                ));
            }
            if self.events >= self.budget_check.0
                && let Err(end) = self.check_budget(self.origin)
            {
                return end;
            }
        }
    }

    /// Report the state at time `s` (not before the current origin).
    fn sample_at(&mut self, s: f64, on_sample: &mut dyn FnMut(&Sample)) {
        let mut x = std::mem::take(&mut self.before);
        self.state_at(Time::new(s).since(self.origin).max(0.0), &mut x);
        on_sample(&Sample {
            t: s,
            mode: self.mode,
            state: &x,
            events: self.events,
        });
        self.before = x;
    }

    /// Every [`BUDGET_CHECK`] events, project the events still needed to
    /// reach `t_end` at the recent rate, so that a run that cannot finish
    /// within `max_events` says so early instead of grinding to the limit
    /// (which fails the run when event `max_events + 1` fires).
    fn check_budget(&mut self, t: Time) -> Result<(), End> {
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

    /// Fire guard `slot` at time `t`: reset, record, watch for Zeno, re-predict.
    fn fire<O: Observer + ?Sized>(
        &mut self,
        slot: usize,
        t: Time,
        observer: &mut O,
    ) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        let guard = model.guards(mode)[slot];
        let mut before = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut before);
        let t = self.sharpen(slot, t, &mut before);
        self.close_segment(t.since(self.origin));
        self.after.copy_from_slice(&before);
        let jump = model.reset(mode, slot, &mut self.after);
        let recorded = if !all_finite(&before) || !all_finite(&self.after) {
            Err(End::failed(format!(
                "non-finite state at the `{}` event at t = {}: before {:?}, after {:?}",
                guard.name,
                t.value(),
                before,
                self.after
            )))
        } else if let Err(why) = self.carry_errors(slot, t, &before, jump.mode) {
            Err(End::failed(why))
        } else if guard.internal {
            Ok(())
        } else {
            self.count(mode, slot);
            let labels = model.labels(mode, slot, &before);
            self.record(guard.name, t, jump.mode, &before, &labels, observer)
        };
        self.before = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.origin = t;
        self.mode = jump.mode;
        // Internal switches are watched too: a chart that flickers at one
        // instant must not spin either.
        if self.zeno.observe(mode, slot, t) {
            return self.settle(guard.name, t, observer);
        }
        match (self.motion, jump.affects) {
            (Motion::Exact, Affects::Range { first, count }) if jump.mode == mode => {
                let guards = model.guards(mode).len();
                if first.saturating_add(count) > guards {
                    return Err(End::failed(format!(
                        "the `{}` reset re-predicts guards {first}..{} of a mode with {guards}",
                        guard.name,
                        first.saturating_add(count)
                    )));
                }
                // The guard that fired left the queue: it is always predicted anew.
                if !(first..first + count).contains(&slot) {
                    self.predict_exact(slot)?;
                }
                (first..first + count).try_for_each(|g| self.predict_exact(g))
            }
            _ => {
                self.integrator.restart();
                // A guard index names the same guard only within one mode.
                let fired = (jump.mode == mode).then_some(slot);
                self.fresh = Some(fired);
                self.start_segment()
            }
        }
    }

    /// The crossing of guard `slot` at `t` (state `x`, from the dense
    /// output) sharpened where the integrator can (see
    /// [`Integrator::sharpen`]); the correction stays within a thousandth of
    /// the step and before the next queued event, so the order of events
    /// is kept. A re-fire at the segment's start is left alone: its state
    /// is the segment's own.
    fn sharpen(&mut self, slot: usize, t: Time, x: &mut [f64]) -> Time {
        let tau = t.since(self.origin);
        if !(self.motion == Motion::Stepped && self.stepped) || tau == 0.0 {
            return t;
        }
        let (model, mode) = (self.model, self.mode);
        let h = self.integrator.h();
        let next = self
            .queue
            .peek()
            .map_or(h, |(_, later)| later.since(self.origin));
        let reach = (1e-3 * h).min(next - tau);
        let guard = |y: &[f64]| model.guard(mode, slot, y);
        let direction = model.guards(mode)[slot].direction;
        // For a guard of either direction, the side it came from: a little
        // before the crossing on the dense output.
        let before = if direction == Direction::Either {
            let mut y = std::mem::take(&mut self.after);
            self.integrator.eval((tau - 1e-4 * h).max(0.0), &mut y);
            let g = guard(&y);
            self.after = y;
            if g == 0.0 {
                return t;
            }
            g
        } else {
            0.0
        };
        let crossed = |v: f64| match direction {
            Direction::Falling => v <= 0.0,
            Direction::Rising => v >= 0.0,
            Direction::Either => v == 0.0 || v.signum() != before.signum(),
        };
        let mut sharp = std::mem::take(&mut self.after);
        let crossing = Crossing {
            tau,
            reach,
            guard: &guard,
            crossed: &crossed,
        };
        let correction = self
            .integrator
            .sharpen(model, mode, &self.state, &crossing, &mut sharp);
        let t = match correction {
            Some(s) => {
                x.copy_from_slice(&sharp);
                t.after(s)
            }
            None => t,
        };
        self.after = sharp;
        t
    }

    fn count(&mut self, mode: Mode, slot: usize) {
        if self.counts.len() <= mode {
            self.counts.resize(mode + 1, Vec::new());
        }
        let counts = &mut self.counts[mode];
        if counts.len() <= slot {
            counts.resize(slot + 1, 0);
        }
        counts[slot] += 1;
    }

    /// Send one event (from `before` in the current mode to `self.after` in
    /// `mode_after`) to the observer and keep the energy audit.
    fn record<O: Observer + ?Sized>(
        &mut self,
        name: &'static str,
        t: Time,
        mode_after: Mode,
        before: &[f64],
        labels: &Labels,
        observer: &mut O,
    ) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        self.events += 1;
        let energy_before = model.energy(mode, before);
        let energy_after = model.energy(mode_after, &self.after);
        self.audit_energy(energy_before);
        self.audit_energy(energy_after);
        let event = EventRecord {
            seq: self.events,
            t: t.value(),
            guard: name,
            mode_before: model.mode_name(mode),
            mode_after: model.mode_name(mode_after),
            energy_before,
            energy_after,
            names_before: model.state_names(mode),
            before,
            names_after: model.state_names(mode_after),
            after: &self.after,
            labels,
        };
        observer
            .on_event(&event)
            .map_err(|e| End::failed(format!("could not write the event log: {e}")))
    }

    /// Events of the guard `name` came faster than the run can resolve: let
    /// the model settle into resting contact, or stop.
    fn settle<O: Observer + ?Sized>(
        &mut self,
        name: &str,
        t: Time,
        observer: &mut O,
    ) -> Result<(), End> {
        let what = format!(
            "events of guard `{name}` accumulate at t = {:e} faster than the run can resolve ({})",
            t.value(),
            self.zeno.describe()
        );
        self.after.copy_from_slice(&self.state);
        let Some(rest) = self.model.settle(self.mode, &mut self.after) else {
            return Err(End {
                status: Status::Zeno,
                reason: Some(format!(
                    "{what}; the model has no resting mode, so the run stops here"
                )),
            });
        };
        let before = std::mem::take(&mut self.state);
        // The resting state stands in for an orbit it is not exactly on:
        // the jump to it is an error the run carries on.
        let jump = before
            .iter()
            .zip(&self.after)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        self.bound.widen(jump);
        self.settles += 1;
        let recorded = self.record(SETTLE, t, rest, &before, &Labels::NONE, observer);
        self.state = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.mode = rest;
        self.zeno_reason = Some(format!(
            "{what}; settled into `{}`",
            self.model.mode_name(rest)
        ));
        self.integrator.restart();
        self.fresh = Some(None);
        self.start_segment()
    }

    /// Predict every guard of the current mode from `(origin, state)`; for an
    /// ODE mode this takes the next integration step.
    fn start_segment(&mut self) -> Result<(), End> {
        self.queue.clear();
        self.step_end = None;
        let (model, mode) = (self.model, self.mode);
        let guards = model.guards(mode);
        self.motion = self.motion_of(mode)?;
        match self.motion {
            Motion::Frozen => Ok(()),
            Motion::Exact => (0..guards.len()).try_for_each(|g| self.predict_exact(g)),
            Motion::Stepped => {
                let t_end = self.options.t_end;
                let remaining = self.origin.until(t_end);
                let h_min = 64.0 * f64::EPSILON * self.origin.value().abs().max(t_end);
                let fresh = self.fresh.take();
                // What is left of the run is below what a step can resolve.
                self.stepped = remaining > h_min;
                if !self.stepped {
                    return Ok(());
                }
                if let Err(failure) =
                    self.integrator
                        .step(model, mode, &self.state, remaining, h_min)
                {
                    return Err(self.step_failed(failure));
                }
                let local = self.integrator.local_error();
                let h = self.integrator.h();
                let interpolant = self.integrator.interpolant();
                let n = self.state.len();
                for (g, guard) in guards.iter().enumerate() {
                    let check_start = fresh.is_some_and(|fired| {
                        if fired == Some(g) {
                            guard.barrier
                        } else {
                            model.guard(mode, g, &self.state) == 0.0
                        }
                    });
                    // What the errors so far, and this step's, may shift the
                    // guard by.
                    let uncertainty = if guard.internal {
                        0.0
                    } else {
                        self.bound
                            .guard_uncertainty(model, mode, g, &self.state, local)
                    };
                    let (step, x) = (&self.integrator, &mut self.before[..n]);
                    let scan = scan_step(guard, check_start, interpolant, uncertainty, |s| {
                        step.eval(s * h, x);
                        model.guard(mode, g, x)
                    });
                    if scan.margin <= uncertainty {
                        return Err(self.undecidable(g, scan.margin, uncertainty));
                    }
                    if let Some(s) = scan.crossing {
                        self.queue.schedule(g, self.origin.after(s * h));
                    }
                }
                self.step_end = Some(self.origin.after(h));
                Ok(())
            }
        }
    }

    /// How `mode` moves under the run's method, decided once per mode.
    fn motion_of(&mut self, mode: Mode) -> Result<Motion, End> {
        if let Some(Some(known)) = self.motions.get(mode) {
            return Ok(*known);
        }
        let decided = motion(self.model, mode, self.options.method).map_err(|why| {
            End::failed(format!(
                "method `{}` cannot run this model: {why}",
                self.options.method.name()
            ))
        })?;
        if self.motions.len() <= mode {
            self.motions.resize(mode + 1, None);
        }
        self.motions[mode] = Some(decided);
        Ok(decided)
    }

    /// Carry the state errors over the `tau` of the current segment that
    /// has passed: along the flow's tangent, with a numerical step's local
    /// error added. Nothing to do while the run has made no error.
    #[inline(always)]
    fn close_segment(&mut self, tau: f64) {
        if self.motion != Motion::Stepped && self.bound.idle() {
            return;
        }
        self.close_stretch(tau);
    }

    /// [`Run::close_segment`] once there is something to carry.
    #[inline(never)]
    fn close_stretch(&mut self, tau: f64) {
        let (model, mode) = (self.model, self.mode);
        match self.motion {
            Motion::Stepped if self.stepped => {
                // The part of the step passed leaves its share of the local
                // error (none for an event at the step's start).
                let h = self.integrator.h();
                let local = self.integrator.local_error() * (tau / h).min(1.0);
                let step = &self.integrator;
                self.bound
                    .after_step(model, mode, tau, local, |s, x| step.eval(s, x));
            }
            Motion::Exact => self.bound.after_exact(model, mode, &self.state, tau),
            _ => {}
        }
    }

    /// Carry the errors across the event of guard `slot` at `t` (state
    /// `before`, `self.after` after the reset, in `mode_after`): see
    /// [`Bound::across`]; why the run cannot go on, if it cannot.
    #[inline(always)]
    fn carry_errors(
        &mut self,
        slot: usize,
        t: Time,
        before: &[f64],
        mode_after: Mode,
    ) -> Result<(), String> {
        self.bound.note_state(before);
        if self.bound.idle() {
            return Ok(());
        }
        self.bound.across(
            self.model,
            self.mode,
            slot,
            t,
            (before, &self.after),
            mode_after,
            self.options.t_end,
            self.integrator.name(),
        )
    }

    /// A graze or near miss closer than the integration error can resolve.
    fn undecidable(&self, g: usize, margin: f64, uncertainty: f64) -> End {
        End::failed(format!(
            "guard `{}` grazes zero near t = {:e}: its dip or near miss is {margin:.2e} deep, within the \
             integration error so far ({uncertainty:.2e}), so {} cannot tell whether it fires; \
             tighten the method or use an exact one",
            self.model.guards(self.mode)[g].name,
            self.origin.value(),
            self.integrator.name()
        ))
    }

    fn predict_exact(&mut self, g: usize) -> Result<(), End> {
        self.exact_evaluations += 1;
        match self.model.next_crossing(self.mode, g, &self.state) {
            None => {
                self.queue.cancel(g);
                Ok(())
            }
            Some(tau) if tau >= 0.0 && self.queue.schedule(g, self.origin.after(tau)) => Ok(()),
            Some(tau) => Err(End::failed(format!(
                "the model predicted guard `{}` at an invalid elapsed time {tau} from state {:?} at t = {}",
                self.model.guards(self.mode)[g].name,
                self.state,
                self.origin.value()
            ))),
        }
    }

    fn step_failed(&self, failure: StepFailure) -> End {
        let t = self.origin.value();
        let what = match failure {
            StepFailure::Collapsed { h } => format!(
                "the {} step size collapsed to {h:.3e} at t = {t} (state {:?})",
                self.integrator.name(),
                self.state
            ),
            StepFailure::NotApplicable(why) => {
                format!(
                    "method `{}` cannot run this model: {why}",
                    self.options.method.name()
                )
            }
            StepFailure::NonFinite => {
                format!(
                    "the right-hand side is not finite at t = {t} (state {:?})",
                    self.state
                )
            }
        };
        match self.model.diagnose(self.mode, &self.state) {
            Some(why) => End::failed(format!("{what}: {why}")),
            None => End::failed(what),
        }
    }

    /// The state `tau` after `origin`, by the current segment's flow.
    fn state_at(&mut self, tau: f64, x: &mut [f64]) {
        match self.motion {
            Motion::Exact => {
                self.exact_evaluations += 1;
                self.model.advance(self.mode, &self.state, tau, x)
            }
            Motion::Stepped if self.stepped => self.integrator.eval(tau, x),
            Motion::Stepped | Motion::Frozen => x.copy_from_slice(&self.state),
        }
    }

    fn audit_energy(&mut self, energy: Option<f64>) {
        if let (Some(e), Some(e0), Some(max)) =
            (energy, self.energy_initial, self.max_energy_error.as_mut())
        {
            *max = max.max((e - e0).abs() / self.energy_scale);
        }
    }

    fn finish_at(&mut self, t: Time) -> End {
        self.close_segment(t.since(self.origin));
        if let Err(why) = self
            .bound
            .at_end(t, self.queue.peek().map(|(_, next)| next))
        {
            return End::failed(why);
        }
        let mut x = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut x);
        self.state.copy_from_slice(&x);
        self.before = x;
        self.origin = t;
        match self.zeno_reason.clone() {
            Some(reason) => End {
                status: Status::Zeno,
                reason: Some(reason),
            },
            None => End {
                status: Status::Completed,
                reason: None,
            },
        }
    }

    fn outcome(self, end: End) -> Outcome {
        let model = self.model;
        let energy_final = model.energy(self.mode, &self.state);
        let mut run = self;
        run.audit_energy(energy_final);
        let mut events_by_guard = BTreeMap::new();
        for (mode, counts) in run.counts.iter().enumerate() {
            for (slot, &n) in counts.iter().enumerate() {
                if n > 0 {
                    *events_by_guard
                        .entry(model.guards(mode)[slot].name)
                        .or_insert(0) += n;
                }
            }
        }
        if run.settles > 0 {
            events_by_guard.insert(SETTLE, run.settles);
        }
        let error_bound = run.bound.state_bound(run.events);
        let event_time_bound = run.bound.event_time_bound(run.origin);
        Outcome {
            zeno: end.status == Status::Zeno || run.zeno_reason.is_some(),
            status: end.status,
            reason: end.reason,
            t_end: run.options.t_end,
            t_reached: run.origin.value(),
            events: run.events,
            events_by_guard,
            energy_initial: run.energy_initial,
            energy_final,
            max_energy_error: run.max_energy_error,
            final_mode: run.mode,
            final_mode_name: model.mode_name(run.mode),
            final_state_names: model.state_names(run.mode).to_vec(),
            final_state: run.state,
            flow_evaluations: run.integrator.evaluations() + run.exact_evaluations,
            error_bound,
            event_time_bound,
            wall_seconds: run.started.elapsed().as_secs_f64(),
        }
    }
}

/// Turns of the loop between two progress reports.
const PROGRESS_EVERY: u64 = 1 << 14;

/// Events between two projections of the event budget.
const BUDGET_CHECK: u64 = 1 << 20;

fn all_finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}
