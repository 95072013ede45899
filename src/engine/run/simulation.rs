//! The whole-state source of segments: the engine holds the model's state
//! and advances it, for models small enough to copy at every event.
//!
//! It never asks which integrator a mode uses. A mode's flow gives a
//! *segment*: for an exact flow, the whole future (guards predicted by the
//! model's exact crossing times); for an ODE, one accepted step with dense
//! output (guards located on it, see [`locate`]). The queue holds one
//! prediction per guard; whichever comes first, the earliest prediction or
//! the end of the current step, happens next. Along the way it carries the
//! run's error bound ([`bound`]) and stops where an event cannot be decided
//! (a graze within the integration error, a non-finite state, a step size
//! collapse). Order, samples, budgets, Zeno, the energy audit and counts
//! are the one run loop's (`src/engine/run/run_loop.rs`).
//!
//! [`locate`]: crate::engine::step::locate
//! [`bound`]: crate::engine::bound

use crate::engine::bound::Bound;
use crate::engine::bound::period_record::REPLAYED_AT_ONCE;
use crate::engine::bound::tangent::guard_gradient;
use crate::engine::model::labels::Labels;
use crate::engine::model::{Affects, Direction, HybridModel, Jump, Mode};
use crate::engine::run::ledger::End;
use crate::engine::run::ledger::{Final, Ledger};
use crate::engine::run::observer::{EventRecord, Observer, SETTLE};
use crate::engine::run::periodic::Returns;
use crate::engine::run::queue::EventQueue;
use crate::engine::run::run_loop::{Segments, drive, end_window};
use crate::engine::run::{Options, Outcome, Status};
use crate::engine::step::adaptive::StepFailure;
use crate::engine::step::crossing::{Crossing, Sharpened};
use crate::engine::step::integrator::{Integrator, Motion, motion};
use crate::engine::step::locate::{Start, scan_step};
use crate::engine::step::method::Method;
use crate::numerics::central_difference::CBRT_EPSILON;
use crate::time::{Span, Time};

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
    /// The bound on every state component's error there: the bound the
    /// run carried to the start of the step the sample falls in, plus
    /// that step's own local error, or its dense output's error there
    /// where larger (a Runge-Kutta interpolant's, measured by re-taking
    /// the step to the sample); and, within an event's time error of it,
    /// that event's jump (the true state may be on the reset's other
    /// side).
    pub bound: f64,
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
    let energy_initial = model.energy(mode, &x0);
    let energy_scale = energy_initial.map_or(1.0, |e| model.energy_scale(e));
    let mut ledger = Ledger::new(options, energy_initial, energy_scale);
    if !model.resets_keep_energy() {
        ledger = ledger.rebase_at_resets();
    }
    let mut run = Run::new(model, mode, &x0, options, on_sample);
    run.sampled = !samples.is_empty();
    let end = match refused {
        Some(reason) => End::failed(reason),
        None => drive(&mut run, &mut ledger, samples, observer),
    };
    run.outcome(end, ledger)
}

/// An event, for the samples beside it: when it fired, how uncertain that
/// time is, and how far its reset moved the state.
#[derive(Debug, Clone, Copy)]
struct Beside {
    t: Time,
    time_error: f64,
    jump: f64,
}

struct Run<'m, 's, M: HybridModel + ?Sized> {
    model: &'m M,
    options: &'m Options,
    on_sample: &'s mut dyn FnMut(&Sample),
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
    /// How far into the current step the origin is: zero where a step
    /// starts, more after a marker that let the step go on (see
    /// [`Run::go_on`]).
    step_offset: f64,
    /// What the dense output errs by at an event it placed (sharpening
    /// declined), for the segment that closes there.
    dense_gap: f64,
    /// A copy of a Runge-Kutta integrator to re-take steps on (see
    /// [`Run::flow_bound`]), made when first needed.
    spare: Option<Box<Integrator>>,
    /// Whether the run reports samples: then the last logged event is
    /// kept for the samples beside it.
    sampled: bool,
    last_event: Option<Beside>,
    /// Whether the integrator's last step starts at the current origin.
    stepped: bool,
    /// How each guard of the current mode starts the first step from the
    /// origin (see [`Run::arm`]), set at `t = 0`, after each event and
    /// after settling; `fresh` until a step has used it (later steps start
    /// armed).
    starts: Vec<Start>,
    fresh: bool,
    /// The guards predicted at the instant of the event being fired (a
    /// scratch list: simultaneous events).
    simultaneous: Vec<usize>,
    /// Scratch for a guard's gradient.
    gradient: Vec<f64>,
    /// The current step's error from a forcing's rounding (see
    /// [`Run::forcing_rounding`]).
    forcing_error: f64,
    /// Scratch of the state's length: a shifted state, and two rates.
    probe: Vec<f64>,
    rates: (Vec<f64>, Vec<f64>),
    /// How deep the dip of each guard's predicted crossing in the current
    /// step is (infinite where it does not curve back): what its time
    /// error grows by.
    depths: Vec<f64>,
    before: Vec<f64>,
    after: Vec<f64>,
    /// The model's clock component and its value at `t = 0`: the clock
    /// reads the run's time from there.
    clock: Option<(usize, f64)>,
    /// The last events and the states they left, to prove the orbit
    /// periodic.
    returns: Returns,
    /// Events logged so far (the round-off allowance's count, for the
    /// horizon between events).
    logged: u64,
    /// The guard whose graze the bound could not decide, when a segment
    /// failed for it: a pile-up of its events is a Zeno point.
    undecided_graze: Option<usize>,
}

impl<M: HybridModel + ?Sized> Segments for Run<'_, '_, M> {
    fn origin(&self) -> Time {
        self.origin
    }

    fn begin(&mut self, _: &mut Ledger) -> Result<(), End> {
        if let Some(why) = self.model.stop_reason(self.mode) {
            return Err(End::failed(format!("at the start: {why}")));
        }
        self.arm(None);
        self.start_segment()
    }

    #[inline]
    fn next(&self) -> (Option<usize>, Time) {
        // An event at the very end of a step happens before the step ends.
        match (self.queue.peek(), self.step_end) {
            (Some((_, t)), Some(end)) if end < t => (None, end),
            (Some((slot, t)), _) => (Some(slot), t),
            (None, Some(end)) => (None, end),
            (None, None) => (None, Time::new(f64::INFINITY)),
        }
    }

    /// Reset, record, watch for Zeno, re-predict.
    fn fire<O: Observer + ?Sized>(
        &mut self,
        slot: usize,
        t: Time,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End> {
        // Most events are the queue's head (one due at t_end after a step
        // may not be queued at all).
        if self.queue.peek().is_some_and(|(head, _)| head == slot) {
            self.queue.pop();
        } else {
            self.queue.cancel(slot);
        }
        let (model, mode) = (self.model, self.mode);
        let guard = &model.guards(mode)[slot];
        let mut before = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut before);
        let t = self.sharpen(slot, t, &mut before);
        self.set_clock(t, &mut before);
        // How far into the current step the event is.
        let into_step = self.step_offset + t.since(self.origin);
        self.close_segment(t.since(self.origin));
        self.after.copy_from_slice(&before);
        let jump = model.reset(mode, slot, &mut self.after);
        let mut after = std::mem::take(&mut self.after);
        self.set_clock(t, &mut after);
        self.after = after;
        // A pile-up of this guard's events that the bound can no longer
        // order is a Zeno point (the same words as the Zeno watch's): the
        // event fires, and the run settles or stops after it.
        let mut piled_up = None;
        let recorded = if !all_finite(&before) || !all_finite(&self.after) {
            let why = model
                .diagnose_guard(mode, slot, &before, true)
                .map_or_else(String::new, |why| format!(": {why}"));
            Err(End::failed(format!(
                "non-finite state at the `{}` event at t = {} in mode `{}`: before {:?}, after {:?}{why}",
                guard.name,
                t.value(),
                model.mode_name(mode),
                before,
                self.after
            )))
        } else if let Err(why) = self.carry_errors(slot, t, &before, jump.mode)
            && (guard.internal || {
                piled_up = ledger.chatters(mode, slot, &guard.name, t);
                piled_up.is_none()
            })
        {
            Err(End::failed(why))
        } else if guard.internal {
            Ok(())
        } else {
            if self.sampled {
                let time_error = self.bound.last_time_bound();
                let after = std::mem::take(&mut self.after);
                self.last_event = Some(Beside {
                    t,
                    time_error,
                    jump: self.other_side((mode, &before), (jump.mode, &after), time_error),
                });
                self.after = after;
            }
            self.bound.watch(t, &self.after, self.logged + 1);
            match &jump.event {
                Some(name) => ledger.count_named(name),
                None => ledger.count(mode, slot),
            }
            let labels = model.labels(mode, slot, &before);
            ledger
                .log(
                    self.event(
                        jump.event.as_deref().unwrap_or(&guard.name),
                        t,
                        jump.mode,
                        &before,
                        &labels,
                    ),
                    observer,
                )
                .inspect(|()| self.logged = ledger.events())
        };
        if recorded.is_err() && all_finite(&before) {
            // The run fails at the event: it reached its time, with the
            // state just before it (a failure was reported at the last
            // step's start, before the event it named).
            self.origin = t;
            self.state.copy_from_slice(&before);
        }
        self.before = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.origin = t;
        self.mode = jump.mode;
        if model.terminal(mode, slot) {
            return Err(End {
                status: Status::Completed,
                reason: Some(format!(
                    "the terminal transition `{}` fired at t = {}",
                    guard.name,
                    t.value()
                )),
            });
        }
        if let Some(why) = model.stop_reason(jump.mode) {
            return Err(End::failed(format!("at t = {}: {why}", t.value())));
        }
        if jump.mode != mode && !guard.barrier && !guard.internal {
            self.slides(mode, slot, t).map_err(End::failed)?;
        }
        // Internal switches are watched too: a chart that flickers at one
        // instant must not spin either.
        let zeno = ledger.zeno(mode, slot, &guard.name, t);
        if let Some(what) = piled_up.or(zeno) {
            return self.settle(what, t, ledger, observer);
        }
        let predicted = match (self.motion, jump.affects) {
            (Motion::Exact, Affects::Range { first, count }) if jump.mode == mode => {
                let guards = model.guards(mode).len();
                if first.saturating_add(count) > guards {
                    return Err(End::failed(format!(
                        "the `{}` reset re-predicts guards {first}..{} of a mode with {guards}",
                        guard.name,
                        first.saturating_add(count)
                    )));
                }
                // The guard that fired left the queue: it is always predicted
                // anew, a marker past the crossing it sits on; so is any
                // other marker on the same surface, crossed with it, unless
                // it was due at this instant too (simultaneous events).
                if !guard.barrier {
                    let instant = t.after(end_window(t.value()));
                    self.queue.due_by(instant, &mut self.simultaneous);
                    self.predict_past(slot)?;
                } else if !(first..first + count).contains(&slot) {
                    self.predict_exact(slot)?;
                }
                (first..first + count)
                    .filter(|&g| guard.barrier || g != slot)
                    .try_for_each(|g| {
                        let value = model.guard(mode, g, &self.state);
                        if !guard.barrier
                            && !model.guards(mode)[g].barrier
                            && !self.simultaneous.contains(&g)
                            && self.on_surface(g, value)
                            && self.same_surface((mode, slot), g)
                        {
                            self.predict_past(g)
                        } else {
                            self.predict_exact(g)
                        }
                    })
            }
            // Only where no period is looked for (a run that logs its
            // events, or a forced one): a step that goes on past a marker
            // is not the same from the same state.
            _ if (observer.wants_details() || self.clock.is_some())
                && self.go_on(mode, slot, &jump, t, into_step)? =>
            {
                Ok(())
            }
            _ => {
                self.integrator.restart();
                // An exact flow's guards start as its model predicts them:
                // only a marker's, spent, needs the engine's word (the
                // built-in impacts are all barriers, at millions a second).
                let exact = if jump.mode == mode {
                    self.motion == Motion::Exact
                } else {
                    self.motion_of(jump.mode)? == Motion::Exact
                };
                if exact && model.guards(jump.mode).iter().all(|g| g.barrier) {
                    self.fresh = false;
                } else {
                    let instant = t.after(end_window(t.value()));
                    self.queue.due_by(instant, &mut self.simultaneous);
                    self.arm(Some((mode, slot)));
                    if let Some(g) = jump.leaves.filter(|&g| g < self.starts.len()) {
                        self.starts[g] = Start::Spent;
                    }
                }
                self.start_segment()
            }
        };
        // A graze the bound cannot decide on a guard whose events pile up
        // is the same Zeno point (the ball chatters down onto the table).
        if predicted.is_err()
            && let Some(g) = self.undecided_graze.take()
            && let Some(what) = ledger.chatters(self.mode, g, &model.guards(self.mode)[g].name, t)
        {
            return self.settle(what, t, ledger, observer);
        }
        predicted?;
        // An autonomous flow repeats from a repeated state (see
        // `periodic`): an exact one with nothing to carry, or steps that
        // depend on nothing else, whose bound replays its last period. Only
        // a run whose observer looks at no event may jump, so only such a
        // run keeps the state.
        let repeats = match self.motion {
            Motion::Exact => self.bound.idle(),
            // A step that went on past a marker depends on where it
            // started, not on the state the marker left.
            Motion::Stepped => self.integrator.memoryless() && self.step_offset == 0.0,
            Motion::Frozen => false,
        };
        if !observer.wants_details() && !guard.internal && repeats && self.clock.is_none() {
            self.returns
                .visit((mode, slot, jump.event), jump.mode, t, &self.state);
            // Record the stepped bound's periods once the orbit has
            // returned: a run that never does pays nothing for it.
            if !self.bound.idle() && self.returns.cycle().is_some() && !self.bound.record_periods()
            {
                self.returns.forget();
            }
        } else {
            self.returns.forget();
        }
        Ok(())
    }

    fn period(&self) -> Option<(Span, u64)> {
        let events = self.returns.cycle()?;
        match self.motion {
            // The next event, predicted, is the same guard's again.
            Motion::Exact if events == 1 => {
                let (next, at) = self.queue.peek()?;
                (Some(next) == self.returns.last_slot()).then(|| (at.span_since(self.origin), 1))
            }
            // The events repeat the last period's, and so do the steps.
            Motion::Exact | Motion::Stepped => Some((self.returns.period(), events as u64)),
            Motion::Frozen => None,
        }
    }

    fn jump(&mut self, periods: u64, tau: Span, ledger: &mut Ledger) {
        // A bound that carries errors goes over the periods as firing each
        // event would have, as far as its checks allow.
        let periods = if self.bound.idle() {
            periods
        } else {
            let events = self.returns.cycle().unwrap_or(0);
            self.bound.replay(periods.min(REPLAYED_AT_ONCE), events)
        };
        if periods == 0 {
            return;
        }
        let from = self.origin;
        self.origin = from.after_multiple(periods, tau);
        self.queue.postpone(periods, tau);
        self.bound.postpone(periods, tau);
        // The step under way started at the event: it moves with it.
        if self.step_end.is_some() {
            self.step_end = Some(self.origin.after(self.integrator.h()));
        }
        self.returns.postpone(periods, tau);
        ledger.jumped(
            self.returns.events(),
            periods,
            tau.value(),
            (from, self.origin),
        );
        // To the jump: the periods replayed grew the bound as firing
        // each event would have.
        self.logged = ledger.events();
        self.bound.watch(self.origin, &self.state, self.logged);
    }

    fn renew(&mut self, t: Time) -> Result<(), End> {
        self.close_segment(t.since(self.origin));
        self.integrator.end(&mut self.state);
        self.bound.watch(t, &self.state, self.logged);
        self.origin = t;
        self.start_segment()
    }

    /// The state at time `s` (not before the current origin).
    fn sample(&mut self, s: f64, ledger: &mut Ledger) {
        let mut x = std::mem::take(&mut self.before);
        self.state_at(Time::new(s).since(self.origin).max(0.0), &mut x);
        self.set_clock(Time::new(s), &mut x);
        let bound = self.sample_bound(
            Time::new(s).since(self.origin).max(0.0),
            &x,
            ledger.events(),
        );
        (self.on_sample)(&Sample {
            t: s,
            mode: self.mode,
            state: &x,
            events: ledger.events(),
            bound,
        });
        self.before = x;
    }

    /// A step stops at `t_end` and looks no further: a crossing just past
    /// it, within the rounding window, is found from each guard's value and
    /// rate there (see [`Run::crossing_after`]).
    fn due_at_end(&mut self, t_end: Time, window: f64) -> Option<usize> {
        self.crossing_after(t_end)
            .filter(|(_, tau, _)| tau.abs() <= window)
            .map(|(g, _, _)| g)
    }

    fn finish(&mut self, t: Time) -> Result<(), End> {
        // An event due at t_end may have fired a rounding past it.
        let tau = t.since(self.origin).max(0.0);
        self.close_segment(tau);
        // What comes next, and how uncertain its time is: a predicted event
        // carries the last event's time error; a crossing just past the
        // last step, its guard's error over its rate.
        let next = match self.queue.peek() {
            Some((_, next)) => Some((next, self.bound.last_time_bound())),
            None => self.crossing_after(t).map(|(g, tau, rate)| {
                let local = self.local_error();
                let (model, mode) = (self.model, self.mode);
                let uncertainty = self
                    .bound
                    .guard_uncertainty(model, mode, g, &self.before, local);
                (t.after(tau.max(0.0)), uncertainty / rate.abs())
            }),
        };
        self.bound
            .at_end(t, next, end_window(t.value()))
            .map_err(End::failed)?;
        let mut x = std::mem::take(&mut self.before);
        self.state_at(tau, &mut x);
        self.set_clock(t, &mut x);
        self.state.copy_from_slice(&x);
        self.before = x;
        self.bound.watch(t, &self.state, self.logged);
        self.origin = t;
        self.check_guards()
    }
}

impl<'m, 's, M: HybridModel + ?Sized> Run<'m, 's, M> {
    fn new(
        model: &'m M,
        mode: Mode,
        x0: &[f64],
        options: &'m Options,
        on_sample: &'s mut dyn FnMut(&Sample),
    ) -> Self {
        let n = model.dimension();
        Run {
            model,
            options,
            on_sample,
            mode,
            origin: Time::new(0.0),
            state: x0.to_vec(),
            queue: EventQueue::default(),
            integrator: {
                let mut integrator = Integrator::for_method(options.method, n, options.tolerances);
                integrator.bound_first(model.bounded_dimension());
                integrator
            },
            motion: Motion::Frozen,
            motions: Vec::new(),
            exact_evaluations: 0,
            bound: Bound::new(
                (n, model.bounded_dimension()),
                x0,
                model.clock(),
                // Only the closed forms round about their own scale.
                match options.method {
                    Method::Auto | Method::Exact => model.exact_flow_scale(),
                    _ => 0.0,
                },
                options.past_horizon,
            ),
            logged: 0,
            undecided_graze: None,
            stepped: false,
            step_end: None,
            step_offset: 0.0,
            dense_gap: 0.0,
            spare: None,
            sampled: false,
            last_event: None,
            starts: Vec::new(),
            fresh: false,
            simultaneous: Vec::new(),
            gradient: vec![0.0; n],
            depths: Vec::new(),
            forcing_error: 0.0,
            probe: vec![0.0; n],
            rates: (vec![0.0; n], vec![0.0; n]),
            before: vec![0.0; n],
            after: vec![0.0; n],
            clock: model.clock().map(|c| (c, x0[c])),
            returns: Returns::default(),
        }
    }

    /// Write the clock's reading at time `t` into `x`, where the model has
    /// a clock: its initial value plus `t`, rounded once from the run's
    /// double-double time.
    #[inline]
    fn set_clock(&self, t: Time, x: &mut [f64]) {
        if let Some((c, c0)) = self.clock {
            x[c] = t.after(c0).value();
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
        // An event due at t_end is fired there (see run_loop.rs).
        if !(self.motion == Motion::Stepped && self.stepped)
            || tau == 0.0
            || t.value() >= self.options.t_end
        {
            return t;
        }
        let (model, mode) = (self.model, self.mode);
        let h = self.integrator.h();
        let next = self
            .queue
            .peek()
            .map_or(h - self.step_offset, |(_, later)| later.since(self.origin));
        let reach = (1e-3 * h).min(next - tau);
        let guard = |y: &[f64]| model.guard(mode, slot, y);
        let direction = model.guards(mode)[slot].direction;
        // For a guard of either direction, the side it came from: a little
        // before the crossing on the dense output.
        let before = if direction == Direction::Either {
            let mut y = std::mem::take(&mut self.after);
            self.integrator
                .eval(self.step_offset + (tau - 1e-4 * h).max(0.0), &mut y);
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
            tau: self.step_offset + tau,
            reach,
            room: next - tau,
            guard: &guard,
            crossed: &crossed,
            slot,
        };
        let correction = self
            .integrator
            .sharpen(model, mode, &self.state, &crossing, &mut sharp);
        let t = match correction {
            Sharpened::Moved(s) => {
                x.copy_from_slice(&sharp);
                t.after(s)
            }
            // A re-step that blew up where the accepted step did not says
            // nothing of the dense output.
            Sharpened::Kept(off) => {
                self.dense_gap = if off.is_finite() { off } else { 0.0 };
                t
            }
        };
        self.after = sharp;
        t
    }

    /// The event of guard `name` at `t`, from `before` in the current mode
    /// to `self.after` in `mode_after`, with the model's energies.
    fn event<'a>(
        &'a self,
        name: &'a str,
        t: Time,
        mode_after: Mode,
        before: &'a [f64],
        labels: &'a Labels,
    ) -> EventRecord<'a> {
        let (model, mode) = (self.model, self.mode);
        EventRecord {
            seq: 0,
            t: t.value(),
            guard: name,
            mode_before: model.mode_name(mode),
            mode_after: model.mode_name(mode_after),
            from: mode,
            to: mode_after,
            energy_before: model.energy(mode, before),
            energy_after: model.energy(mode_after, &self.after),
            names_before: model.state_names(mode),
            before,
            names_after: model.state_names(mode_after),
            after: &self.after,
            labels,
            shadow: self.bound.past_horizon(),
        }
    }

    /// Events came faster than the run can resolve (`what`): let the model
    /// settle into resting contact, or stop.
    fn settle<O: Observer + ?Sized>(
        &mut self,
        what: String,
        t: Time,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End> {
        self.after.copy_from_slice(&self.state);
        self.returns.forget();
        let Some(rest) = self.model.settle(self.mode, &mut self.after) else {
            return Err(Ledger::unsettled(&what));
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
        let into = format!("`{}`", self.model.mode_name(rest));
        let event = self.event(SETTLE, t, rest, &before, &Labels::NONE);
        let recorded = ledger.settled(what, &into, event, observer);
        self.logged = ledger.events();
        self.state = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.mode = rest;
        self.integrator.restart();
        self.arm(None);
        self.start_segment()
    }

    /// After guard `slot` of mode `from` took the run across its surface
    /// into the current mode at `t` (the state before in `self.before`,
    /// after in `self.state`): why the run cannot go on if the new mode's
    /// flow points straight back through that surface and one of its own
    /// guards, on the surface, fires at once. Both sides then point into
    /// the surface: the solution slides along it (Filippov), which no
    /// sequence of mode changes follows; going on would chatter between
    /// the modes or, where the located crossings leave the state a
    /// rounding to the other side, drift off the surface quietly. (Modes
    /// of a hysteresis, whose guards lie apart, are not caught: the new
    /// mode's guards are off the surface.)
    fn slides(&mut self, from: Mode, slot: usize, t: Time) -> Result<(), String> {
        let (model, to) = (self.model, self.mode);
        if !(model.has_rhs(from) && model.has_rhs(to)) {
            return Ok(());
        }
        let clock = self.clock.map(|(c, _)| c);
        let (mut f_from, mut f_to) = std::mem::take(&mut self.rates);
        let mut probe = std::mem::take(&mut self.probe);
        model.rhs(from, &self.before, &mut f_from);
        model.rhs(to, &self.state, &mut f_to);
        let surface = |x: &[f64]| model.guard(from, slot, x);
        let came = guard_rate(surface, &self.before, &f_from, clock, &mut probe);
        let back = guard_rate(surface, &self.state, &f_to, clock, &mut probe);
        let size = size_of(&self.state, clock);
        let at_once = (came * back < 0.0 && back.abs() > 1e-8 * came.abs())
            .then(|| {
                model.guards(to).iter().enumerate().find(|(h, guard)| {
                    let value = model.guard(to, *h, &self.state);
                    let rate = guard_rate(
                        |x| model.guard(to, *h, x),
                        &self.state,
                        &f_to,
                        clock,
                        &mut probe,
                    );
                    // On the surface: as near zero as the crossing was
                    // located, or within rounding of the state (a guard
                    // scaled otherwise).
                    let near =
                        value.abs() <= surface(&self.before).abs().max(64.0 * f64::EPSILON * size);
                    near && match guard.direction {
                        Direction::Falling => rate < 0.0,
                        Direction::Rising => rate > 0.0,
                        Direction::Either => rate != 0.0,
                    }
                })
            })
            .flatten();
        self.rates = (f_from, f_to);
        self.probe = probe;
        match at_once {
            None => Ok(()),
            Some((_, guard)) => Err(format!(
                "sliding at t = {}: the `{}` event took mode `{}` into `{}`, whose flow points straight \
                 back through the same surface, where its guard `{}` fires at once: both sides point \
                 into the surface, so the solution slides along it (Filippov) and no sequence of mode \
                 changes follows it. Model the sliding: a mode whose flow keeps the surface (the \
                 convex combination of the two flows tangent to it), left where one side's flow turns \
                 away",
                t.value(),
                model.guards(from)[slot].name,
                model.mode_name(from),
                model.mode_name(to),
                guard.name
            )),
        }
    }

    /// After marker `slot` fired at `t`, `into_step` into the current step,
    /// let the step go on instead of starting a new one, where that changes
    /// nothing but the cost: a marker of a stepped flow that left the state
    /// and mode as they were, with no other guard due at its instant, well
    /// inside the step, on a method that can search the rest of the step
    /// (Taylor's: the guard's series re-expanded there). The other guards'
    /// predictions on the step stand; the marker's own is searched anew
    /// from where it fired. Whether it went on; where its search comes
    /// within the errors of a graze, it does not (a new step decides).
    fn go_on(
        &mut self,
        mode: Mode,
        slot: usize,
        jump: &Jump,
        t: Time,
        into_step: f64,
    ) -> Result<bool, End> {
        let model = self.model;
        let guard = &model.guards(mode)[slot];
        let h = self.integrator.h();
        let unchanged =
            (self.state.iter().zip(&self.before)).all(|(a, b)| a.to_bits() == b.to_bits());
        let inside = self.step_end.is_some_and(|end| t < end)
            && h - into_step > 64.0 * f64::EPSILON * t.value().abs().max(h)
            && t.value() < self.options.t_end;
        if !(self.motion == Motion::Stepped
            && self.stepped
            && self.integrator.locates_inside()
            && jump.mode == mode
            && jump.leaves.is_none()
            && !guard.barrier
            && !guard.internal
            && unchanged
            && inside)
        {
            return Ok(false);
        }
        let instant = t.after(end_window(t.value()));
        self.queue.due_by(instant, &mut self.simultaneous);
        if !self.simultaneous.is_empty() {
            return Ok(false);
        }
        let local = self.local_error();
        let uncertainty = self
            .bound
            .guard_uncertainty(model, mode, slot, &self.state, local);
        let scan =
            match self
                .integrator
                .locate(model, mode, slot, Start::Spent, uncertainty, into_step)
            {
                Some(Ok(scan)) if scan.margin > uncertainty => scan,
                _ => return Ok(false),
            };
        self.step_offset = into_step;
        if let Some(s) = scan.crossing {
            self.queue.schedule(slot, t.after(s * (h - into_step)));
            if let Some(depth) = self.depths.get_mut(slot) {
                *depth = scan.margin;
            }
        }
        Ok(true)
    }

    /// Decide how every guard of the current mode starts from the origin
    /// (see [`Start`]), after the event of guard `slot` of mode `from`
    /// (`fired`; `None` at `t = 0` and after settling). A crossing fires
    /// once, and whatever is due at this instant fires now:
    /// - the guard that fired, staying in its mode: a barrier is checked
    ///   for firing at once (a reset that did not turn the motion round is
    ///   resting contact); a marker the reset left on the surface is spent;
    /// - the other guards of that mode predicted at the same instant
    ///   (simultaneous events) fire at once if they move their way;
    /// - any other guard on its surface (within rounding of zero): at the
    ///   start, or a barrier, it fires at once if it moves its way; a
    ///   marker after an event is spent (the surface it sits on is the one
    ///   just crossed: a copy of the same guard in the new mode does not
    ///   count the crossing twice);
    /// - the rest start armed, as their values say.
    fn arm(&mut self, fired: Option<(Mode, usize)>) {
        let (model, mode) = (self.model, self.mode);
        let mut starts = std::mem::take(&mut self.starts);
        starts.clear();
        let same = fired.filter(|(from, _)| *from == mode).map(|(_, s)| s);
        for (g, guard) in model.guards(mode).iter().enumerate() {
            if same == Some(g) && guard.barrier {
                starts.push(Start::OnZero);
                continue;
            }
            let value = model.guard(mode, g, &self.state);
            let start = if same == Some(g) {
                let located = model.guard(mode, g, &self.before).abs();
                if value.abs() <= located || self.on_surface(g, value) {
                    Start::Spent
                } else {
                    Start::Armed
                }
            } else if same.is_some() && self.simultaneous.contains(&g) {
                Start::OnZero
            } else if !self.on_surface(g, value) {
                Start::Armed
            } else if fired.is_none()
                || guard.barrier
                || fired.is_some_and(|fired| !self.same_surface(fired, g))
            {
                Start::OnZero
            } else {
                Start::Spent
            };
            starts.push(start);
        }
        self.starts = starts;
        self.fresh = true;
    }

    /// Whether guard `g` of the current mode, on its surface, lies along
    /// the surface of guard `slot` of mode `from` just crossed (their
    /// gradients parallel, at the states after and before the event): a
    /// copy of the same transition, not another surface through the same
    /// point (a corner), which fires on its own.
    fn same_surface(&mut self, (from, slot): (Mode, usize), g: usize) -> bool {
        let model = self.model;
        let (mut a, mut b) = std::mem::take(&mut self.rates);
        let mut probe = std::mem::take(&mut self.probe);
        guard_gradient(model, from, slot, &self.before, &mut a, &mut probe);
        guard_gradient(model, self.mode, g, &self.state, &mut b, &mut probe);
        let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        let norms = a.iter().map(|x| x * x).sum::<f64>() * b.iter().map(|y| y * y).sum::<f64>();
        (self.rates, self.probe) = ((a, b), probe);
        dot * dot >= (1.0 - 1e-6) * norms && norms > 0.0
    }

    /// Whether guard `g` of the current mode, `value` at the state, is on
    /// its surface to rounding: within 64 ulps of the sizes of the terms
    /// its gradient sums (`sum |dg/dx_i x_i|`), and as far as its rate
    /// moves it over the rounding of the time (an event due at `t_end` is
    /// fired there, up to that much before its crossing).
    fn on_surface(&mut self, g: usize, value: f64) -> bool {
        if value == 0.0 {
            return true;
        }
        let (model, mode) = (self.model, self.mode);
        let clock = self.clock.map(|(c, _)| c);
        let x = &self.state;
        // Most guards are far from zero after an event: within a millionth
        // of the state's size they are worth a closer look, beyond it not.
        if value.abs() > 1e-6 * size_of(x, clock) {
            return false;
        }
        let mut probe = std::mem::take(&mut self.probe);
        let drift = if model.has_rhs(mode) {
            let mut rate = std::mem::take(&mut self.rates.0);
            model.rhs(mode, x, &mut rate);
            let drift = guard_rate(|y| model.guard(mode, g, y), x, &rate, clock, &mut probe).abs()
                * end_window(self.origin.value());
            self.rates.0 = rate;
            drift
        } else {
            0.0
        };
        let mut gradient = std::mem::take(&mut self.gradient);
        guard_gradient(model, mode, g, x, &mut gradient, &mut probe);
        self.probe = probe;
        let scale: f64 = gradient.iter().zip(x).map(|(d, v)| (d * v).abs()).sum();
        self.gradient = gradient;
        value.abs() <= 64.0 * f64::EPSILON * scale + drift
    }

    /// Where guards may be undefined, stop at one that is not finite at
    /// `(origin, state)`: a crossing cannot be looked for in it.
    fn check_guards(&self) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        if !model.may_be_undefined() {
            return Ok(());
        }
        for (g, guard) in model.guards(mode).iter().enumerate() {
            let value = model.guard(mode, g, &self.state);
            if !value.is_finite() {
                let why = model
                    .diagnose_guard(mode, g, &self.state, false)
                    .map_or_else(String::new, |why| format!(": {why}"));
                return Err(End::failed(format!(
                    "guard `{}` is {value} at t = {} in mode `{}` (state {:?}){why}",
                    guard.name,
                    self.origin.value(),
                    model.mode_name(mode),
                    self.state
                )));
            }
        }
        Ok(())
    }

    /// Predict every guard of the current mode from `(origin, state)`; for an
    /// ODE mode this takes the next integration step.
    fn start_segment(&mut self) -> Result<(), End> {
        let mut state = std::mem::take(&mut self.state);
        self.set_clock(self.origin, &mut state);
        self.state = state;
        self.depths.clear();
        self.check_guards()?;
        self.queue.clear();
        self.step_end = None;
        self.step_offset = 0.0;
        let (model, mode) = (self.model, self.mode);
        let guards = model.guards(mode);
        self.motion = self.motion_of(mode)?;
        match self.motion {
            Motion::Frozen => Ok(()),
            Motion::Exact => {
                let fresh = std::mem::replace(&mut self.fresh, false);
                (0..guards.len()).try_for_each(|g| {
                    if fresh && self.starts[g] == Start::Spent {
                        self.predict_past(g)
                    } else {
                        self.predict_exact(g)
                    }
                })
            }
            Motion::Stepped => {
                let t_end = self.options.t_end;
                let remaining = self.origin.until(t_end);
                let h_min = self.min_step();
                // What is left of the run is below what a step can resolve
                // (the guards keep how they start, for `due_at_end`).
                self.stepped = remaining > h_min;
                if !self.stepped {
                    return Ok(());
                }
                let fresh = std::mem::replace(&mut self.fresh, false);
                let mut graze: Option<(usize, f64, f64, f64)> = None;
                let mut earliest = f64::INFINITY;
                self.depths.resize(guards.len(), f64::INFINITY);
                if let Some((c, c0)) = self.clock {
                    self.integrator
                        .clock_at(c, self.origin.after(c0).rounding());
                }
                if let Err(failure) =
                    self.integrator
                        .step(model, mode, &self.state, remaining, h_min)
                {
                    return Err(self.step_failed(failure));
                }
                let h = self.integrator.h();
                // A step the run's end cut short depends on more than its
                // start: its period does not repeat.
                if h >= remaining {
                    self.bound.unrepeatable();
                }
                self.forcing_error = self.forcing_rounding(h);
                let local = self.local_error();
                let interpolant = self.integrator.interpolant();
                let n = self.state.len();
                for (g, guard) in guards.iter().enumerate() {
                    let start = if fresh { self.starts[g] } else { Start::Armed };
                    // What the errors so far, and this step's, may shift the
                    // guard by.
                    let uncertainty = if guard.internal {
                        0.0
                    } else {
                        self.bound
                            .guard_uncertainty(model, mode, g, &self.state, local)
                    };
                    // A recording run proves guards clear of more (see
                    // `period_record`).
                    let searched = self.bound.scan_uncertainty(uncertainty);
                    let scan = match self.integrator.locate(model, mode, g, start, searched, 0.0) {
                        Some(Ok(scan)) => {
                            if !guard.internal {
                                let proven = scan.margin.is_finite() || searched > uncertainty;
                                self.bound
                                    .margin_found(proven.then(|| scan.margin.min(searched)));
                            }
                            scan
                        }
                        Some(Err(why)) => {
                            return Err(End::failed(format!(
                                "{} at t = {}: {why}",
                                self.integrator.name(),
                                self.origin.value()
                            )));
                        }
                        None => {
                            self.bound.margin_found(None);
                            let (step, x) = (&self.integrator, &mut self.before[..n]);
                            scan_step(guard, start, interpolant, uncertainty, |s| {
                                step.eval(s * h, x);
                                model.guard(mode, g, x)
                            })
                        }
                    };
                    if scan.margin <= uncertainty
                        && graze.is_none_or(|(_, _, _, at)| scan.margin_at < at)
                    {
                        graze = Some((g, scan.margin, uncertainty, scan.margin_at));
                    }
                    if let Some(s) = scan.crossing {
                        self.queue.schedule(g, self.origin.after(s * h));
                        self.depths[g] = scan.margin;
                        earliest = earliest.min(s);
                    }
                }
                // A graze the errors cannot decide stops the run, unless an
                // event comes first: the step is taken again after it.
                if let Some((g, margin, uncertainty, at)) =
                    graze.filter(|&(_, _, _, at)| at <= earliest)
                {
                    let why = self.undecidable(g, self.origin.after(at * h), margin, uncertainty);
                    if let Err(why) = self.bound.undecided(self.origin, why) {
                        self.undecided_graze = Some(g);
                        return Err(End::failed(why));
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
                let local =
                    self.local_error() * (tau / h).min(1.0) + std::mem::take(&mut self.dense_gap);
                let (step, offset) = (&self.integrator, self.step_offset);
                let rates = step.rates(offset, tau);
                self.bound.after_step(
                    model,
                    mode,
                    (tau, local),
                    |s, x| step.sample(offset + s, x),
                    rates,
                );
            }
            Motion::Exact => self.bound.after_exact(model, mode, &self.state, tau),
            _ => {}
        }
    }

    /// The earliest guard that a stepped flow would cross just after
    /// `t_end` (which its last step does not look past), by each guard's
    /// value and rate there: `(guard, time after t_end, rate)`, the time
    /// negative for one a few ulps before it, where no step was taken. The
    /// state it was judged from is left in `self.before`. A guard that
    /// fired at the origin counts as its start says: a spent marker is not
    /// due again.
    fn crossing_after(&mut self, t_end: Time) -> Option<(usize, f64, f64)> {
        let (model, mode) = (self.model, self.mode);
        if self.motion != Motion::Stepped || !model.has_rhs(mode) {
            return None;
        }
        // The state at t_end, from the last step; or, where no step was
        // taken (what was left of the run was below a step), at the
        // origin, a few ulps before t_end, which the extrapolation covers.
        let (reach, from) = if self.stepped {
            (t_end.since(self.origin).max(0.0), t_end)
        } else {
            (0.0, self.origin)
        };
        let gap = t_end.since(from);
        let clock = self.clock.map(|(c, _)| c);
        let mut x = std::mem::take(&mut self.before);
        let mut rate = std::mem::take(&mut self.rates.0);
        let mut probe = std::mem::take(&mut self.probe);
        self.state_at(reach, &mut x);
        self.set_clock(from, &mut x);
        model.rhs(mode, &x, &mut rate);
        let fresh = !self.stepped && self.fresh;
        let mut first: Option<(usize, f64, f64)> = None;
        for (g, guard) in model.guards(mode).iter().enumerate() {
            if fresh && self.starts[g] != Start::Armed {
                continue;
            }
            let value = model.guard(mode, g, &x);
            let slope = guard_rate(|y| model.guard(mode, g, y), &x, &rate, clock, &mut probe);
            let tau = -value / slope - gap;
            if value != 0.0
                && -value / slope > 0.0
                && guard.direction.accepts(value, -value)
                && first.is_none_or(|(_, earliest, _)| tau < earliest)
            {
                first = Some((g, tau, slope));
            }
        }
        (self.before, self.rates.0, self.probe) = (x, rate, probe);
        first
    }

    /// The bound on the state `tau` past the origin (`x`), after
    /// `events` events, NaN where none is carried.
    fn sample_bound(&mut self, tau: f64, x: &[f64], events: u64) -> f64 {
        self.flow_bound(tau, events) + self.beside_events(self.origin.after(tau), x)
    }

    /// Where a sample at `t` (state `x`) lies within an event's time error
    /// of it, the true state may be on the reset's other side: the reset's
    /// jump. For the last event, where the true one may be later; for the
    /// next, where it may be earlier (its jump from `x`, its time error
    /// from the errors so far along its guard).
    fn beside_events(&mut self, t: Time, x: &[f64]) -> f64 {
        let last = self
            .last_event
            .filter(|last| t.since(last.t) <= last.time_error)
            .map_or(0.0, |last| last.jump);
        let Some((slot, next)) = self.queue.peek() else {
            return last;
        };
        let (model, mode) = (self.model, self.mode);
        let local = if self.motion == Motion::Stepped {
            self.local_error()
        } else {
            0.0
        };
        let time_error = self.bound.crossing_uncertainty(model, mode, slot, x, local);
        if next.since(t) > time_error {
            return last;
        }
        let mut after = std::mem::take(&mut self.probe);
        after.copy_from_slice(x);
        let to = model.reset(mode, slot, &mut after).mode;
        let jump = self.other_side((mode, x), (to, &after), time_error);
        self.probe = after;
        last + jump
    }

    /// How far the state on one side of a reset, from `before` in one mode
    /// to `after` in another, may be from the other side's within
    /// `time_error` of it: the jump, and how far either flow moves in that
    /// time (the jump itself moves with the state it is taken at; largest
    /// bounded component, the clock's aside).
    fn other_side(
        &mut self,
        before: (Mode, &[f64]),
        after: (Mode, &[f64]),
        time_error: f64,
    ) -> f64 {
        let model = self.model;
        let bounded = model.bounded_dimension().min(before.1.len());
        let clock = self.clock.map(|(c, _)| c);
        let mut rates = std::mem::take(&mut self.rates);
        let parting = if model.has_rhs(before.0) && model.has_rhs(after.0) {
            model.rhs(before.0, before.1, &mut rates.0);
            model.rhs(after.0, after.1, &mut rates.1);
            time_error
        } else {
            rates.0.fill(0.0);
            rates.1.fill(0.0);
            0.0
        };
        let side = (0..bounded)
            .filter(|&i| Some(i) != clock)
            .map(|i| {
                (after.1[i] - before.1[i]).abs() + parting * (rates.1[i].abs() + rates.0[i].abs())
            })
            .fold(0.0, f64::max);
        self.rates = rates;
        side
    }

    /// [`Run::sample_bound`] without the events beside it: the errors
    /// carried to the origin, and a stepped flow's local error, or its
    /// dense output's where that is larger (see
    /// [`Integrator::dense_error`]). Both are errors over the whole step:
    /// the carried errors' growth over part of it is within them.
    fn flow_bound(&mut self, tau: f64, events: u64) -> f64 {
        let Some(carried) = self.bound.state_bound(events) else {
            return f64::NAN;
        };
        if self.motion != Motion::Stepped {
            return carried;
        }
        let mut local = self.local_error();
        if self.stepped && tau > 0.0 {
            let (model, mode) = (self.model, self.mode);
            let mut x = std::mem::take(&mut self.after);
            let at = (self.state.as_slice(), self.step_offset + tau);
            let spare = &mut self.spare;
            if let Some(dense) = self.integrator.dense_error(spare, model, mode, at, &mut x) {
                local = local.max(dense + self.forcing_error);
            }
            self.after = x;
        }
        carried + local
    }

    /// The last step's local error: the method's estimate, and never less
    /// than the step's rounding ([`STEP_ROUNDING_ULPS`] ulps of the state),
    /// which a step exact in its arithmetic (a Taylor series that ends, on
    /// a polynomial flow; Stormer-Verlet under a constant force) still
    /// makes, and which a chaotic run amplifies like any other error; plus
    /// the rounding of a forcing (see [`Run::forcing_rounding`]).
    fn local_error(&self) -> f64 {
        let bounded = self.model.bounded_dimension().min(self.state.len());
        let clock = self.clock.map(|(c, _)| c);
        let size = self.state[..bounded]
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != clock)
            .fold(0.0_f64, |m, (_, x)| m.max(x.abs()));
        self.integrator
            .local_error()
            .max(STEP_ROUNDING_ULPS * f64::EPSILON * size)
            + self.forcing_error
    }

    /// What a forced flow's step of length `h` from the origin errs by
    /// because it reads the clock: `sin(w t)` at `t = 1e4` is computed from
    /// a product rounded by an ulp of `w t`, a shift of the time by `eps
    /// |t|`, so the rate errs by `|df/dt| eps |t|` and the step by `h` times
    /// that (`df/dt` by a central difference of the right-hand side).
    fn forcing_rounding(&mut self, h: f64) -> f64 {
        let (model, mode) = (self.model, self.mode);
        let Some((c, _)) = self.clock.filter(|_| model.has_rhs(mode)) else {
            return 0.0;
        };
        // The linear propagator steps from the exact time.
        if let Some(error) = self.integrator.exact_clock_error(h) {
            return error;
        }
        let t = self.state[c];
        // A difference over a small part of the step (which resolves the
        // forcing), and far above the ulps of t.
        let dt = (CBRT_EPSILON * h).max(1e3 * f64::EPSILON * t.abs());
        let (mut up, mut down) = std::mem::take(&mut self.rates);
        let mut x = std::mem::take(&mut self.probe);
        x.copy_from_slice(&self.state);
        x[c] = t + dt;
        model.rhs(mode, &x, &mut up);
        x[c] = t - dt;
        model.rhs(mode, &x, &mut down);
        let bounded = model.bounded_dimension().min(x.len());
        let slope = up[..bounded]
            .iter()
            .zip(&down[..bounded])
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs() / (2.0 * dt)));
        (self.rates, self.probe) = ((up, down), x);
        h * slope * f64::EPSILON * t.abs()
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
            self.bound
                .note_crossing(self.model, self.mode, slot, before);
            return Ok(());
        }
        let depth = match self.motion {
            Motion::Stepped => self.depths.get(slot).copied().unwrap_or(f64::INFINITY),
            _ => f64::INFINITY,
        };
        self.bound.across(
            self.model,
            self.mode,
            slot,
            t,
            (before, &self.after),
            mode_after,
            (self.options.t_end, depth),
            self.integrator.name(),
        )
    }

    /// A graze or near miss at `t` closer than the integration error can
    /// resolve, in words (the run stops where the step that finds it
    /// starts).
    fn undecidable(&self, g: usize, t: Time, margin: f64, uncertainty: f64) -> String {
        format!(
            "guard `{}` grazes zero at t = {:e}: its dip or near miss is {margin:.2e} deep, within the \
             integration error so far ({uncertainty:.2e}), so {} cannot tell whether it fires; \
             tighten the method or use an exact one",
            self.model.guards(self.mode)[g].name,
            t.value(),
            self.integrator.name()
        )
    }

    fn predict_exact(&mut self, g: usize) -> Result<(), End> {
        self.exact_evaluations += 1;
        match self.model.next_crossing(self.mode, g, &self.state) {
            None => {
                self.queue.cancel(g);
                Ok(())
            }
            Some(tau) => self.schedule_exact(g, tau),
        }
    }

    /// Predict spent guard `g` (a marker the state has just passed) on an
    /// exact flow: the model, asked from a state on the surface, names the
    /// crossing just passed (at zero); the next is asked from a little
    /// further along, far enough that the guard has visibly left.
    fn predict_past(&mut self, g: usize) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        self.exact_evaluations += 1;
        match model.next_crossing(mode, g, &self.state) {
            Some(tau) if tau > end_window(self.origin.value().abs().max(1.0)) => {
                return self.schedule_exact(g, tau);
            }
            None => {
                self.queue.cancel(g);
                return Ok(());
            }
            Some(_) => {}
        }
        let mut ahead = std::mem::take(&mut self.probe);
        let mut skip = 1e-12 * self.origin.value().abs().max(1.0);
        let mut predicted = None;
        for _ in 0..40 {
            model.advance(mode, &self.state, skip, &mut ahead);
            self.exact_evaluations += 2;
            match model.next_crossing(mode, g, &ahead) {
                Some(tau) if tau > 0.0 => {
                    predicted = Some(Some(skip + tau));
                    break;
                }
                Some(_) => skip *= 4.0,
                None => {
                    predicted = Some(None);
                    break;
                }
            }
        }
        self.probe = ahead;
        match predicted {
            Some(Some(tau)) => self.schedule_exact(g, tau),
            Some(None) => {
                self.queue.cancel(g);
                Ok(())
            }
            None => Err(End::failed(format!(
                "guard `{}` stays on zero at t = {}: the model predicts its crossing at once from \
                 every state up to {skip:.1e} further along the flow, so the next crossing cannot \
                 be told from the one just fired",
                model.guards(mode)[g].name,
                self.origin.value()
            ))),
        }
    }

    /// Queue guard `g` `tau` after the origin, as an exact flow predicted it.
    fn schedule_exact(&mut self, g: usize, tau: f64) -> Result<(), End> {
        if tau >= 0.0 && self.queue.schedule(g, self.origin.after(tau)) {
            return Ok(());
        }
        Err(End::failed(format!(
            "the model predicted guard `{}` at an invalid elapsed time {tau} from state {:?} at t = {}",
            self.model.guards(self.mode)[g].name,
            self.state,
            self.origin.value()
        )))
    }

    fn step_failed(&self, failure: StepFailure) -> End {
        let t = self.origin.value();
        let what = match failure {
            StepFailure::Collapsed { h } => {
                let what = format!(
                    "the step size of {} collapsed to {h:.3e} at t = {t} in mode `{}` (state {:?})",
                    self.integrator.name(),
                    self.model.mode_name(self.mode),
                    self.state
                );
                // Neither cause below is the flow's: no diagnosis of it.
                if let Some(why) = self.collapse_not_the_flows(h) {
                    return End::failed(format!("{what}: {why}"));
                }
                what
            }
            StepFailure::GuardCollapsed { h, guard } => {
                let why = self
                    .model
                    .diagnose_guard(self.mode, guard, &self.state, false)
                    .map_or_else(String::new, |why| format!(": {why}"));
                return End::failed(format!(
                    "the step size of {} collapsed to {h:.3e} at t = {t} in mode `{}` (state {:?}): \
                     guard `{}` turns steep there{why}",
                    self.integrator.name(),
                    self.model.mode_name(self.mode),
                    self.state,
                    self.model.guards(self.mode)[guard].name
                ));
            }
            StepFailure::NotApplicable(why) => {
                format!(
                    "method `{}` cannot run this model: {why}",
                    self.options.method.name()
                )
            }
            StepFailure::NonFinite => {
                format!(
                    "the right-hand side is not finite at t = {t} in mode `{}` (state {:?})",
                    self.model.mode_name(self.mode),
                    self.state
                )
            }
        };
        match self.model.diagnose(self.mode, &self.state) {
            Some(why) => End::failed(format!("{what}: {why}")),
            None => End::failed(what),
        }
    }

    /// The shortest step the run takes: 64 ulps of the latest time it
    /// reaches, below which a step's end cannot be told from its start.
    fn min_step(&self) -> f64 {
        64.0 * f64::EPSILON * self.origin.value().abs().max(self.options.t_end)
    }

    /// Where a step collapsed to `h` for a reason of the run's settings
    /// rather than its flow, that reason: tolerances below the rounding of
    /// a step, or a `t_end` so far that times are resolved more coarsely
    /// than the flow needs.
    fn collapse_not_the_flows(&self, h: f64) -> Option<String> {
        // Taylor's method runs to machine precision (its default); a
        // Runge-Kutta pair's estimate drowns in rounding well above it.
        let (tolerances, floor) = match self.options.method {
            Method::Taylor(tol) => (Some(tol), f64::EPSILON),
            Method::Dopri5(tol) | Method::Dop853(tol) => (Some(tol), 100.0 * f64::EPSILON),
            _ => (None, 0.0),
        };
        let size = self.state.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        if let Some(tol) = tolerances
            && tol.rtol < floor
            && tol.atol < floor * size.max(1.0)
        {
            return Some(format!(
                "rtol = {:e} and atol = {:e} ask for less error than a step's rounding leaves (about \
                 {:.1e} of the state): loosen them to 1e-14 or more",
                tol.rtol,
                tol.atol,
                f64::EPSILON,
            ));
        }
        // A step far longer than the time's own rounding here (a collapse
        // into a singularity shrinks to that) was cut by t_end's.
        let h_min = self.min_step();
        let resolved = 64.0 * f64::EPSILON * self.origin.value().abs().max(1.0);
        (h >= 1e6 * resolved && h_min > h).then(|| {
            format!(
                "t_end = {:e} resolves times only to {h_min:.3e} (a step is at least 64 ulps of it), \
                 coarser than the {h:.3e} this flow needs: shorten t_end, or rescale time",
                self.options.t_end
            )
        })
    }

    /// The state `tau` after `origin`, by the current segment's flow.
    fn state_at(&mut self, tau: f64, x: &mut [f64]) {
        match self.motion {
            Motion::Exact => {
                self.exact_evaluations += 1;
                self.model.advance(self.mode, &self.state, tau, x)
            }
            Motion::Stepped if self.stepped => self.integrator.eval(self.step_offset + tau, x),
            Motion::Stepped | Motion::Frozen => x.copy_from_slice(&self.state),
        }
    }

    fn outcome(self, end: End, ledger: Ledger) -> Outcome {
        let model = self.model;
        let last = Final {
            t_reached: self.origin,
            mode: self.mode,
            mode_name: model.mode_name(self.mode),
            state_names: model.state_names(self.mode),
            energy: model.energy(self.mode, &self.state),
            flow_evaluations: self.integrator.evaluations() + self.exact_evaluations,
            error_bound: self.bound.state_bound(ledger.events()),
            error_estimate: self.bound.uncarried_estimate(ledger.events()),
            event_time_bound: self.bound.event_time_bound(self.origin),
            horizon: self.bound.horizon(),
            state: self.state,
        };
        ledger.outcome(end, last, |mode, slot| {
            model.guards(mode)[slot].name.clone()
        })
    }
}

/// Rounding a step makes, in ulps of the state's size: a few roundings of
/// each stage's or term's sum.
pub const STEP_ROUNDING_ULPS: f64 = 4.0;

/// The largest component of `x` but the clock, and at least one: the
/// scale differences and rounding are measured against.
fn size_of(x: &[f64], clock: Option<usize>) -> f64 {
    x.iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != clock)
        .fold(1.0_f64, |m, (_, v)| m.max(v.abs()))
}

/// The rate of `guard` along the flow `rate` at `x`, by a central
/// difference along the flow (errors about 1e-10 relative), its step a
/// cube root of eps of the state's size (the clock's aside) over the
/// speed; `probe` is scratch of the state's length.
fn guard_rate(
    guard: impl Fn(&[f64]) -> f64,
    x: &[f64],
    rate: &[f64],
    clock: Option<usize>,
    probe: &mut [f64],
) -> f64 {
    let speed = rate.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if speed == 0.0 || !speed.is_finite() {
        return 0.0;
    }
    let h = CBRT_EPSILON * size_of(x, clock) / speed;
    let mut at = |sign: f64| {
        for ((p, a), r) in probe.iter_mut().zip(x).zip(rate) {
            *p = a + sign * h * r;
        }
        guard(probe)
    };
    (at(1.0) - at(-1.0)) / (2.0 * h)
}

fn all_finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}
