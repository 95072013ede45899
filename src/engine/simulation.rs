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
//! are the one run loop's (`src/engine/run_loop.rs`).
//!
//! [`locate`]: crate::engine::locate
//! [`bound`]: crate::engine::bound

use crate::engine::adaptive::StepFailure;
use crate::engine::bound::Bound;
use crate::engine::integrator::{Crossing, Integrator, Motion, motion};
use crate::engine::labels::Labels;
use crate::engine::ledger::{Final, Ledger};
use crate::engine::locate::scan_step;
use crate::engine::model::{Affects, Direction, HybridModel, Mode};
use crate::engine::observer::{EventRecord, Observer, SETTLE};
use crate::engine::queue::EventQueue;
use crate::engine::run::{Options, Outcome, Status};
use crate::engine::run_loop::{End, Segments, drive};
use crate::time::Time;

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
    let energy_initial = model.energy(mode, &x0);
    let energy_scale = energy_initial.map_or(1.0, |e| model.energy_scale(e));
    let mut ledger = Ledger::new(options, energy_initial, energy_scale);
    if !model.resets_keep_energy() {
        ledger = ledger.rebase_at_resets();
    }
    let mut run = Run::new(model, mode, &x0, options, on_sample);
    let end = match refused {
        Some(reason) => End::failed(reason),
        None => drive(&mut run, &mut ledger, samples, observer),
    };
    run.outcome(end, ledger)
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
    /// Whether the integrator's last step starts at the current origin.
    stepped: bool,
    /// Set at `t = 0` and after each reset: guards exactly on zero are
    /// checked for firing at once, and so is the barrier guard that just
    /// fired (`Some(slot)`, within the same mode).
    fresh: Option<Option<usize>>,
    before: Vec<f64>,
    after: Vec<f64>,
}

impl<M: HybridModel + ?Sized> Segments for Run<'_, '_, M> {
    fn origin(&self) -> Time {
        self.origin
    }

    fn begin(&mut self, _: &mut Ledger) -> Result<(), End> {
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
        self.queue.pop();
        let (model, mode) = (self.model, self.mode);
        let guard = model.guards(mode)[slot];
        let mut before = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut before);
        let t = self.sharpen(slot, t, &mut before);
        self.close_segment(t.since(self.origin));
        self.after.copy_from_slice(&before);
        let jump = model.reset(mode, slot, &mut self.after);
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
        } else if let Err(why) = self.carry_errors(slot, t, &before, jump.mode) {
            Err(End::failed(why))
        } else if guard.internal {
            Ok(())
        } else {
            ledger.count(mode, slot);
            let labels = model.labels(mode, slot, &before);
            ledger.log(
                self.event(guard.name, t, jump.mode, &before, &labels),
                observer,
            )
        };
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
        // Internal switches are watched too: a chart that flickers at one
        // instant must not spin either.
        if let Some(what) = ledger.zeno(mode, slot, guard.name, t) {
            return self.settle(what, t, ledger, observer);
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

    fn renew(&mut self, t: Time) -> Result<(), End> {
        self.close_segment(t.since(self.origin));
        self.integrator.end(&mut self.state);
        self.origin = t;
        self.start_segment()
    }

    /// The state at time `s` (not before the current origin).
    fn sample(&mut self, s: f64, ledger: &mut Ledger) {
        let mut x = std::mem::take(&mut self.before);
        self.state_at(Time::new(s).since(self.origin).max(0.0), &mut x);
        (self.on_sample)(&Sample {
            t: s,
            mode: self.mode,
            state: &x,
            events: ledger.events(),
        });
        self.before = x;
    }

    fn finish(&mut self, t: Time) -> Result<(), End> {
        self.close_segment(t.since(self.origin));
        self.bound
            .at_end(t, self.queue.peek().map(|(_, next)| next))
            .map_err(End::failed)?;
        let mut x = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut x);
        self.state.copy_from_slice(&x);
        self.before = x;
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
            bound: Bound::new(n, x0),
            stepped: false,
            step_end: None,
            fresh: Some(None),
            before: vec![0.0; n],
            after: vec![0.0; n],
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

    /// The event of guard `name` at `t`, from `before` in the current mode
    /// to `self.after` in `mode_after`, with the model's energies.
    fn event<'a>(
        &'a self,
        name: &'static str,
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
            energy_before: model.energy(mode, before),
            energy_after: model.energy(mode_after, &self.after),
            names_before: model.state_names(mode),
            before,
            names_after: model.state_names(mode_after),
            after: &self.after,
            labels,
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
        self.state = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.mode = rest;
        self.integrator.restart();
        self.fresh = Some(None);
        self.start_segment()
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
        self.check_guards()?;
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
                    let scan =
                        match self
                            .integrator
                            .locate(model, mode, g, check_start, uncertainty)
                        {
                            Some(Ok(scan)) => scan,
                            Some(Err(why)) => {
                                return Err(End::failed(format!(
                                    "{} at t = {}: {why}",
                                    self.integrator.name(),
                                    self.origin.value()
                                )));
                            }
                            None => {
                                let (step, x) = (&self.integrator, &mut self.before[..n]);
                                scan_step(guard, check_start, interpolant, uncertainty, |s| {
                                    step.eval(s * h, x);
                                    model.guard(mode, g, x)
                                })
                            }
                        };
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
                "the step size of {} collapsed to {h:.3e} at t = {t} in mode `{}` (state {:?})",
                self.integrator.name(),
                self.model.mode_name(self.mode),
                self.state
            ),
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
            event_time_bound: self.bound.event_time_bound(self.origin),
            state: self.state,
        };
        ledger.outcome(end, last, |mode, slot| model.guards(mode)[slot].name)
    }
}

fn all_finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}
