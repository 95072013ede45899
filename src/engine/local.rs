//! Event-local models: models too large to copy at every event, whose
//! events each touch a few of their parts (a chain of thousands of units,
//! particles in a box).
//!
//! A [`LocalModel`] owns its state and its clocks; the engine never sees the
//! whole state. It asks the model for each guard's next crossing, fires the
//! earliest, and re-predicts only the guards the model says the reset
//! touched, so an event costs what the model's reset and its few
//! predictions cost, whatever the model's size. The rest is the engine's as
//! in [`simulate`]: the queue and strict time order (ties by guard index),
//! the Zeno watch, the event and wall-time budgets, interruption, the
//! observer, and the energy audit (at every sample time, at every logged
//! event, and at the end, since a model this size cannot afford it at
//! every event of a run without a log).
//!
//! [`simulate`]: crate::engine::simulate

use std::collections::BTreeMap;
use std::ops::Range;
use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::engine::labels::Labels;
use crate::engine::model::Guard;
use crate::engine::observer::{EventRecord, Observer, SETTLE};
use crate::engine::queue::EventQueue;
use crate::engine::simulation::{Options, Outcome, Status};
use crate::engine::zeno::ZenoWatch;
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
    let started = Instant::now();
    let energy_initial = model.energy(Time::new(0.0));
    let mut run = LocalRun {
        options,
        queue: EventQueue::default(),
        zeno: ZenoWatch::new(options.t_end),
        now: Time::new(0.0),
        events: 0,
        counts: vec![0; model.guards().len()],
        energy_initial,
        energy_scale: energy_initial.map_or(1.0, |e| model.energy_scale(e)),
        max_energy_error: energy_initial.map(|_| 0.0),
        evaluations: 0,
        settles: 0,
        zeno_reason: None,
    };
    let (status, reason) = match run.event_loop(model, samples, on_sample, observer, started) {
        // A run that settled a Zeno point and went on says so.
        Ok(()) => match run.zeno_reason.take() {
            Some(reason) => (Status::Zeno, Some(reason)),
            None => (Status::Completed, None),
        },
        Err((status, reason)) => (status, Some(reason)),
    };
    let energy_final = model.energy(run.now);
    run.audit(energy_final);
    let guards = model.guards();
    let mut events_by_guard = BTreeMap::new();
    for (slot, &n) in run.counts.iter().enumerate() {
        if n > 0 {
            *events_by_guard.entry(guards[slot].name).or_insert(0) += n;
        }
    }
    if run.settles > 0 {
        events_by_guard.insert(SETTLE, run.settles);
    }
    Outcome {
        zeno: status == Status::Zeno,
        status,
        reason,
        t_end: options.t_end,
        t_reached: run.now.value(),
        events: run.events,
        events_by_guard,
        energy_initial,
        energy_final,
        max_energy_error: run.max_energy_error,
        final_mode: 0,
        final_mode_name: model.mode_name(),
        final_state_names: Vec::new(),
        final_state: Vec::new(),
        flow_evaluations: run.evaluations,
        error_bound: 0.0,
        event_time_bound: None,
        wall_seconds: started.elapsed().as_secs_f64(),
    }
}

type Stop = (Status, String);

struct LocalRun<'o> {
    options: &'o Options,
    queue: EventQueue,
    zeno: ZenoWatch,
    /// Time of the last event.
    now: Time,
    events: u64,
    counts: Vec<u64>,
    energy_initial: Option<f64>,
    energy_scale: f64,
    max_energy_error: Option<f64>,
    /// Predictions asked of the model.
    evaluations: u64,
    /// Zeno accumulations the model settled, and what the last one was.
    settles: u64,
    zeno_reason: Option<String>,
}

impl LocalRun<'_> {
    fn event_loop<M: LocalModel + ?Sized, O: Observer + ?Sized>(
        &mut self,
        model: &mut M,
        samples: &[f64],
        on_sample: &mut dyn FnMut(&M, f64),
        observer: &mut O,
        started: Instant,
    ) -> Result<(), Stop> {
        let t_end = self.options.t_end;
        for g in 0..model.guards().len() {
            self.predict(model, g)?;
        }
        let mut samples = samples.iter().copied().filter(|&s| s <= t_end).peekable();
        let mut turn: u64 = 0;
        let mut reported = 0.0;
        loop {
            turn = turn.wrapping_add(1);
            // Often enough for a model whose events are heavy (a step of a
            // whole string), rarely enough not to show in a light one's.
            if turn.is_multiple_of(CHECK_EVERY) {
                self.check_outside(started)?;
                let elapsed = started.elapsed().as_secs_f64();
                if elapsed - reported >= PROGRESS_SECONDS {
                    observer.on_progress(self.now.value(), self.events);
                    reported = elapsed;
                }
            }
            let next = self.queue.peek().filter(|(_, t)| t.value() <= t_end);
            if let Some(&s) = samples.peek()
                && next.is_none_or(|(_, t)| s <= t.value())
            {
                samples.next();
                let at = Time::new(s.max(self.now.value()));
                self.audit(model.energy(at));
                on_sample(model, at.value());
                continue;
            }
            let Some((slot, t)) = next else {
                let end = Time::new(t_end);
                if end > self.now {
                    self.now = end;
                }
                return Ok(());
            };
            self.queue.pop();
            self.fire(model, slot, t, observer)?;
        }
    }

    /// Interruption and the wall-time budget.
    fn check_outside(&self, started: Instant) -> Result<(), Stop> {
        if self
            .options
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            return Err((Status::Interrupted, "stopped by a signal".into()));
        }
        if let Some(limit) = self.options.max_wall_seconds
            && started.elapsed().as_secs_f64() > limit
        {
            return Err((
                Status::Failed,
                format!(
                    "wall-time budget of {limit} s spent at t = {:e} after {} events",
                    self.now.value(),
                    self.events
                ),
            ));
        }
        Ok(())
    }

    fn fire<M: LocalModel + ?Sized, O: Observer + ?Sized>(
        &mut self,
        model: &mut M,
        slot: usize,
        t: Time,
        observer: &mut O,
    ) -> Result<(), Stop> {
        let guard = model.guards()[slot];
        let logged = !guard.internal && observer.wants_details();
        let energy_before = if logged { model.energy(t) } else { None };
        let fired = model.fire(slot, t).map_err(|why| {
            failed(format!(
                "the `{}` reset at t = {}: {why}",
                guard.name,
                t.value()
            ))
        })?;
        self.now = t;
        let guards = model.guards().len();
        if fired.affects.end > guards {
            return Err(failed(format!(
                "the `{}` reset re-predicts guards up to {} of {guards}",
                guard.name, fired.affects.end
            )));
        }
        if !guard.internal {
            self.events += 1;
            self.counts[slot] += 1;
            let energy_after = if logged { model.energy(t) } else { None };
            self.audit(energy_before);
            self.audit(energy_after);
            let event = EventRecord {
                seq: self.events,
                t: t.value(),
                guard: guard.name,
                mode_before: model.mode_name(),
                mode_after: model.mode_name(),
                energy_before,
                energy_after,
                names_before: &[],
                before: &[],
                names_after: &[],
                after: &[],
                labels: &fired.labels,
            };
            observer
                .on_event(&event)
                .map_err(|e| failed(format!("could not write the event log: {e}")))?;
            if self.events > self.options.max_events {
                return Err(failed(format!(
                    "event budget: more than max_events = {} events by t = {:e}; raise max_events or shorten t_end",
                    self.options.max_events,
                    t.value()
                )));
            }
        }
        // Internal guards are the model's bookkeeping at times it chooses
        // (a window every so often), not events that could accumulate.
        let mut fired = fired;
        if !guard.internal && self.zeno.observe(0, slot, t) {
            let what = format!(
                "events of guard `{}` accumulate at t = {:e} faster than the run can resolve ({})",
                guard.name,
                t.value(),
                self.zeno.describe()
            );
            let Some(settled) = model.settle(slot, t) else {
                return Err((
                    Status::Zeno,
                    format!("{what}; the model has no resting mode, so the run stops here"),
                ));
            };
            self.settles += 1;
            self.events += 1;
            let event = EventRecord {
                seq: self.events,
                t: t.value(),
                guard: SETTLE,
                mode_before: model.mode_name(),
                mode_after: model.mode_name(),
                energy_before: None,
                energy_after: None,
                names_before: &[],
                before: &[],
                names_after: &[],
                after: &[],
                labels: &settled.labels,
            };
            observer
                .on_event(&event)
                .map_err(|e| failed(format!("could not write the event log: {e}")))?;
            self.zeno_reason = Some(format!("{what}; settled into resting contact"));
            fired = Fired {
                affects: fired.affects.start.min(settled.affects.start)
                    ..fired.affects.end.max(settled.affects.end),
                ..settled
            };
        }
        if !fired.affects.contains(&slot) {
            self.predict(model, slot)?;
        }
        for g in fired.affects {
            if model.quiet(g) {
                self.queue.cancel(g);
            } else {
                self.predict(model, g)?;
            }
        }
        Ok(())
    }

    fn predict<M: LocalModel + ?Sized>(&mut self, model: &M, g: usize) -> Result<(), Stop> {
        self.evaluations += 1;
        match model.predict(g, self.now) {
            Ok(None) => {
                self.queue.cancel(g);
                Ok(())
            }
            Ok(Some(t)) if t >= self.now && self.queue.schedule(g, t) => Ok(()),
            Ok(Some(t)) => Err(failed(format!(
                "the model predicted guard `{}` at t = {}, before the last event at {}",
                model.guards()[g].name,
                t.value(),
                self.now.value()
            ))),
            Err(why) => Err(failed(format!(
                "predicting guard `{}` at t = {}: {why}",
                model.guards()[g].name,
                self.now.value()
            ))),
        }
    }

    fn audit(&mut self, energy: Option<f64>) {
        if let (Some(e), Some(e0), Some(max)) =
            (energy, self.energy_initial, self.max_energy_error.as_mut())
        {
            *max = max.max((e - e0).abs() / self.energy_scale);
        }
    }
}

fn failed(reason: String) -> Stop {
    (Status::Failed, reason)
}

/// Turns of the loop between two looks outside (a signal, the wall-time
/// budget, the progress display).
const CHECK_EVERY: u64 = 16;

/// Wall time between two progress reports.
const PROGRESS_SECONDS: f64 = 0.2;
