//! The run as the one loop drives it ([`Segments`]): where it starts,
//! the next event or step end, firing an event (its reset, its record, what
//! is predicted after it), a jump over whole periods, samples and the end.

use super::{Beside, Run, Sample, all_finite};
use crate::engine::bound::period_record::REPLAYED_AT_ONCE;
use crate::engine::model::{Affects, HybridModel, Jump, Mode};
use crate::engine::run::Status;
use crate::engine::run::ledger::End;
use crate::engine::run::ledger::Ledger;
use crate::engine::run::observer::Observer;
use crate::engine::run::run_loop::{Segments, end_window};
use crate::engine::step::integrator::Motion;
use crate::engine::step::locate::Start;
use crate::time::{Span, Time};

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
        let (model, mode) = (self.model, self.mode);
        let guard = &model.guards(mode)[slot];
        let (t, before, jump, into_step) = self.take_event(slot, t);
        // A pile-up of this guard's events that the bound can no longer
        // order is a Zeno point (the same words as the Zeno watch's): the
        // event fires, and the run settles or stops after it.
        let mut piled_up = None;
        let recorded = self.record(slot, t, &before, &jump, &mut piled_up, ledger, observer);
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
        let predicted = self.predict_after((mode, slot), &jump, t, into_step, observer);
        // A graze the bound cannot decide on a guard whose events pile up
        // is the same Zeno point (the ball chatters down onto the table).
        if predicted.is_err()
            && let Some(g) = self.undecided_graze.take()
            && let Some(what) = ledger.chatters(self.mode, g, &model.guards(self.mode)[g].name, t)
        {
            return self.settle(what, t, ledger, observer);
        }
        predicted?;
        self.watch_returns((mode, slot), jump, t, observer);
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

impl<M: HybridModel + ?Sized> Run<'_, '_, M> {
    /// Take guard `slot`'s event at `t` off the queue, place it (sharpened
    /// where the integrator can), close the segment there and apply the
    /// reset into `self.after`: the event's time, the state before it, the
    /// jump, and how far into the current step it is.
    #[inline(always)]
    fn take_event(&mut self, slot: usize, t: Time) -> (Time, Vec<f64>, Jump, f64) {
        // Most events are the queue's head (one due at t_end after a step
        // may not be queued at all).
        if self.queue.peek().is_some_and(|(head, _)| head == slot) {
            self.queue.pop();
        } else {
            self.queue.cancel(slot);
        }
        let (model, mode) = (self.model, self.mode);
        let mut before = std::mem::take(&mut self.before);
        self.state_at(t.since(self.origin), &mut before);
        let t = self.sharpen(slot, t, &mut before);
        self.set_clock(t, &mut before);
        let into_step = self.step_offset + t.since(self.origin);
        self.close_segment(t.since(self.origin));
        self.after.copy_from_slice(&before);
        let jump = model.reset(mode, slot, &mut self.after);
        let mut after = std::mem::take(&mut self.after);
        self.set_clock(t, &mut after);
        self.after = after;
        (t, before, jump, into_step)
    }

    /// Carry the errors across the event and log it (an internal switch
    /// is carried, not logged); why the run cannot go on, if it cannot. A
    /// pile-up the bound can no longer order is left in `piled_up`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn record<O: Observer + ?Sized>(
        &mut self,
        slot: usize,
        t: Time,
        before: &[f64],
        jump: &Jump,
        piled_up: &mut Option<String>,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        let guard = &model.guards(mode)[slot];
        if !all_finite(before) || !all_finite(&self.after) {
            let why = model
                .diagnose_guard(mode, slot, before, true)
                .map_or_else(String::new, |why| format!(": {why}"));
            Err(End::failed(format!(
                "non-finite state at the `{}` event at t = {} in mode `{}`: before {:?}, after {:?}{why}",
                guard.name,
                t.value(),
                model.mode_name(mode),
                before,
                self.after
            )))
        } else if let Err(why) = self.carry_errors(slot, t, before, jump.mode)
            && (guard.internal || {
                *piled_up = ledger.chatters(mode, slot, &guard.name, t);
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
                    jump: self.other_side((mode, before), (jump.mode, &after), time_error),
                });
                self.after = after;
            }
            self.bound.watch(t, &self.after, self.logged + 1);
            match &jump.event {
                Some(name) => ledger.count_named(name),
                None => ledger.count(mode, slot),
            }
            let labels = model.labels(mode, slot, before);
            ledger
                .log(
                    self.event(
                        jump.event.as_deref().unwrap_or(&guard.name),
                        t,
                        jump.mode,
                        before,
                        &labels,
                    ),
                    observer,
                )
                .inspect(|()| self.logged = ledger.events())
        }
    }

    /// Predict the guards' next crossings after the event of `(mode, slot)`
    /// at `t` (`into_step` into the current step): an exact flow's from
    /// the guards the reset spoiled, a marker that lets the step go on, or
    /// a new segment from the state after the reset.
    #[inline(always)]
    fn predict_after<O: Observer + ?Sized>(
        &mut self,
        (mode, slot): (Mode, usize),
        jump: &Jump,
        t: Time,
        into_step: f64,
        observer: &mut O,
    ) -> Result<(), End> {
        let model = self.model;
        let guard = &model.guards(mode)[slot];
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
                && self.go_on(mode, slot, jump, t, into_step)? =>
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
        }
    }

    /// Show the event to the watch for a periodic orbit where the run may
    /// jump over whole periods, or forget what it saw where it may not.
    #[inline(always)]
    fn watch_returns<O: Observer + ?Sized>(
        &mut self,
        (mode, slot): (Mode, usize),
        jump: Jump,
        t: Time,
        observer: &mut O,
    ) {
        let internal = self.model.guards(mode)[slot].internal;
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
        if !observer.wants_details() && !internal && repeats && self.clock.is_none() {
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
    }
}
