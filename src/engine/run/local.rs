//! Event-local models: models too large to copy at every event, whose
//! events each touch a few of their parts (a chain of thousands of units,
//! particles in a box).
//!
//! A [`LocalModel`] owns its state and its clocks; the engine never sees the
//! whole state. It asks the model for each guard's next crossing, fires the
//! earliest, and re-predicts only the guards the model says the reset
//! touched, so an event costs what the model's reset and its few
//! predictions cost, whatever the model's size. Order, samples, budgets,
//! Zeno, counts and the energy audit are the one run loop's
//! (`src/engine/run/run_loop.rs`), as for [`simulate`]; the energy, a sum over
//! the whole model, is audited at every sample time, at every logged event
//! and at the end, since a model this size cannot afford it at every event
//! of a run without a log.
//!
//! [`simulate`]: crate::engine::simulate

use std::ops::Range;

use crate::engine::bound::ErrorEstimate;
use crate::engine::model::Guard;
use crate::engine::model::labels::Labels;
use crate::engine::run::ledger::End;
use crate::engine::run::ledger::{Final, Ledger};
use crate::engine::run::observer::{EventRecord, Observer, SETTLE};
use crate::engine::run::queue::EventQueue;
use crate::engine::run::run_loop::{Segments, drive};
use crate::engine::run::{Options, Outcome};
use crate::time::Time;

/// A hybrid model with one mode that owns its (large) state.
pub trait LocalModel {
    /// Name of the model's mode, for logs and summaries.
    fn mode_name(&self) -> &'static str;

    /// The guards; guard indices are positions in this slice. Internal
    /// guards (see [`Guard::internal`]) let the model do its own
    /// bookkeeping at times it chooses.
    fn guards(&self) -> &[Guard];

    /// The time of the next crossing of `guard` at or after `now` (the time
    /// of the last event), or `None` if there is none the model can vouch
    /// for yet (it must then predict an internal guard no later than the
    /// time its vouching ends, and re-predict this one there).
    fn predict(&self, guard: usize, now: Time) -> Result<Option<Time>, String>;

    /// Whether the model knows, without predicting, that `guard` has no
    /// crossing it can vouch for now (as if [`predict`](Self::predict)
    /// returned `None`). A reset's affected guards that are quiet are
    /// dropped from the queue without a prediction: a model with many
    /// guards, most of them proven clear at once, spares a call per guard.
    fn quiet(&self, guard: usize) -> bool {
        let _ = guard;
        false
    }

    /// Apply the reset of `guard`, which fires at `t`.
    fn fire(&mut self, guard: usize, t: Time) -> Result<Fired, String>;

    /// The conserved energy at `t` (not before the last event), if any.
    fn energy(&self, t: Time) -> Option<f64> {
        let _ = t;
        None
    }

    /// Called when the events of `guard` accumulate at `t` faster than the
    /// run can resolve (a Zeno point). A model that knows the limit
    /// (resting contact) puts its state there and says what it changed;
    /// `None` ends the run.
    fn settle(&mut self, guard: usize, t: Time) -> Option<Fired> {
        let _ = (guard, t);
        None
    }

    /// The scale relative energy errors are measured against.
    fn energy_scale(&self, initial_energy: f64) -> f64 {
        initial_energy.abs().max(f64::MIN_POSITIVE)
    }

    /// Where the model's own error estimate first reached 1e-3 of its
    /// state (see [`horizon`](crate::engine::bound::horizon)), if it has: the
    /// events from it on are flagged `shadow`. An exact model decides
    /// every event, so it goes on past its horizon: what it computes
    /// there is a pseudo-orbit, whose coarse-grained fields may still be
    /// the scene's.
    fn horizon(&self) -> Option<Time> {
        None
    }

    /// What the model can say of its errors at the end of the run (by
    /// default nothing: no bound, no estimate).
    fn accuracy(&self) -> Accuracy {
        Accuracy::default()
    }
}

/// What an event-local model says of its own errors at the end of a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Accuracy {
    /// A bound on every component of its state, where it has one.
    pub bound: Option<f64>,
    /// Where it has none, an estimate and how it was made.
    pub estimate: Option<ErrorEstimate>,
}

/// What a reset did.
#[derive(Debug, Clone, PartialEq)]
pub struct Fired {
    /// The guards whose predictions the reset changed; the fired guard is
    /// re-predicted whether it is in the range or not.
    pub affects: Range<usize>,
    /// What the model labels the event with, for the log.
    pub labels: Labels,
}

/// Run `model` from `t = 0` to `options.t_end`, calling `on_sample` with the
/// model at each of `samples` (times in increasing order; a sample at the
/// time of an event sees the state before it).
pub fn simulate_local<M: LocalModel + ?Sized, O: Observer + ?Sized>(
    model: &mut M,
    options: &Options,
    samples: &[f64],
    on_sample: &mut dyn FnMut(&M, f64),
    observer: &mut O,
) -> Outcome {
    let energy_initial = model.energy(Time::new(0.0));
    let energy_scale = energy_initial.map_or(1.0, |e| model.energy_scale(e));
    let mut ledger = Ledger::new(options, energy_initial, energy_scale);
    let mut run = LocalRun {
        model,
        on_sample,
        queue: EventQueue::default(),
        now: Time::new(0.0),
        evaluations: 0,
    };
    let end = drive(&mut run, &mut ledger, samples, observer);
    let LocalRun {
        model,
        evaluations,
        now,
        ..
    } = run;
    let accuracy = model.accuracy();
    let last = Final {
        t_reached: now,
        mode: 0,
        mode_name: model.mode_name(),
        state_names: &[],
        state: Vec::new(),
        energy: model.energy(now),
        flow_evaluations: evaluations,
        error_bound: accuracy.bound,
        error_estimate: accuracy.estimate,
        event_time_bound: None,
        horizon: model.horizon().map(Time::value),
    };
    let guards = model.guards();
    ledger.outcome(end, last, |_, slot| guards[slot].name.clone())
}

struct LocalRun<'m, M: LocalModel + ?Sized> {
    model: &'m mut M,
    on_sample: &'m mut dyn FnMut(&M, f64),
    queue: EventQueue,
    /// Time of the last event.
    now: Time,
    /// Predictions asked of the model.
    evaluations: u64,
}

impl<M: LocalModel + ?Sized> Segments for LocalRun<'_, M> {
    fn origin(&self) -> Time {
        self.now
    }

    fn begin(&mut self, _: &mut Ledger) -> Result<(), End> {
        (0..self.model.guards().len()).try_for_each(|g| self.predict(g))
    }

    fn next(&self) -> (Option<usize>, Time) {
        match self.queue.peek() {
            Some((slot, t)) => (Some(slot), t),
            None => (None, Time::new(f64::INFINITY)),
        }
    }

    fn fire<O: Observer + ?Sized>(
        &mut self,
        slot: usize,
        t: Time,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End> {
        self.queue.pop();
        // A local model's guards are literals: a copy, not a count.
        let guard = self.model.guards()[slot].clone();
        let logged = !guard.internal && observer.wants_details();
        let energy_before = if logged { self.model.energy(t) } else { None };
        let fired = self.model.fire(slot, t).map_err(|why| {
            End::failed(format!(
                "the `{}` reset at t = {}: {why}",
                guard.name,
                t.value()
            ))
        })?;
        self.now = t;
        let guards = self.model.guards().len();
        if fired.affects.end > guards {
            return Err(End::failed(format!(
                "the `{}` reset re-predicts guards up to {} of {guards}",
                guard.name, fired.affects.end
            )));
        }
        // Internal guards are the model's bookkeeping at times it chooses
        // (a window every so often), not events to log or watch.
        if guard.internal {
            return self.repredict(slot, fired.affects);
        }
        ledger.count(0, slot);
        let energy_after = if logged { self.model.energy(t) } else { None };
        let event = self.event(&guard.name, t, energy_before, energy_after, &fired.labels);
        ledger.log(event, observer)?;
        let Some(what) = ledger.zeno(0, slot, &guard.name, t) else {
            return self.repredict(slot, fired.affects);
        };
        let Some(settled) = self.model.settle(slot, t) else {
            return Err(Ledger::unsettled(&what));
        };
        let event = self.event(SETTLE, t, None, None, &settled.labels);
        ledger.settled(what, "resting contact", event, observer)?;
        let affects = fired.affects.start.min(settled.affects.start)
            ..fired.affects.end.max(settled.affects.end);
        self.repredict(slot, affects)
    }

    fn renew(&mut self, _: Time) -> Result<(), End> {
        unreachable!("an event-local run has no segment ends")
    }

    fn sample(&mut self, s: f64, ledger: &mut Ledger) {
        let at = Time::new(s.max(self.now.value()));
        ledger.audit(self.model.energy(at));
        (self.on_sample)(self.model, at.value());
    }

    /// An event due at `t_end` may have fired a rounding past it: the run
    /// ends at `t_end` all the same.
    fn finish(&mut self, t_end: Time) -> Result<(), End> {
        self.now = t_end;
        Ok(())
    }
}

impl<M: LocalModel + ?Sized> LocalRun<'_, M> {
    /// An event of the model's (its state is its own, not the log's).
    fn event<'a>(
        &self,
        name: &'a str,
        t: Time,
        energy_before: Option<f64>,
        energy_after: Option<f64>,
        labels: &'a Labels,
    ) -> EventRecord<'a> {
        let mode = self.model.mode_name();
        EventRecord {
            seq: 0,
            t: t.value(),
            guard: name,
            mode_before: mode,
            mode_after: mode,
            from: 0,
            to: 0,
            energy_before,
            energy_after,
            names_before: &[],
            before: &[],
            names_after: &[],
            after: &[],
            labels,
            shadow: self.model.horizon().is_some_and(|h| t >= h),
        }
    }

    /// Predict the guards a reset of `slot` affected, and `slot` itself.
    fn repredict(&mut self, slot: usize, affects: Range<usize>) -> Result<(), End> {
        if !affects.contains(&slot) {
            self.predict(slot)?;
        }
        for g in affects {
            if self.model.quiet(g) {
                self.queue.cancel(g);
            } else {
                self.predict(g)?;
            }
        }
        Ok(())
    }

    fn predict(&mut self, g: usize) -> Result<(), End> {
        self.evaluations += 1;
        match self.model.predict(g, self.now) {
            Ok(None) => {
                self.queue.cancel(g);
                Ok(())
            }
            Ok(Some(t)) if t >= self.now && self.queue.schedule(g, t) => Ok(()),
            Ok(Some(t)) => Err(End::failed(format!(
                "the model predicted guard `{}` at t = {}, before the last event at {}",
                self.model.guards()[g].name,
                t.value(),
                self.now.value()
            ))),
            Err(why) => Err(End::failed(format!(
                "predicting guard `{}` at t = {}: {why}",
                self.model.guards()[g].name,
                self.now.value()
            ))),
        }
    }
}
