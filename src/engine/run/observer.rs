//! Events as the engine reports them, and the observers that receive them.
//!
//! The engine pushes one [`EventRecord`] per fired (non-internal) guard to an
//! [`Observer`]. `()` ignores them (and lets a run jump over whole periods
//! of an exactly periodic orbit), [`EachEvent`] ignores them but has each
//! one fired, [`Recorder`] keeps them in memory, and the JSON Lines writer
//! in [`crate::log`] streams them to disk.

use crate::engine::model::Mode;
use crate::engine::model::labels::Labels;
use crate::engine::model::names::Name;

/// One event, borrowed from the engine for the duration of the call.
#[derive(Debug, Clone, Copy)]
pub struct EventRecord<'a> {
    /// 1-based position in the log.
    pub seq: u64,
    /// Time of the event.
    pub t: f64,
    /// Name of the guard that fired ([`SETTLE`] for a Zeno settling).
    pub guard: &'a str,
    /// Name of the mode before the reset.
    pub mode_before: &'a str,
    /// Name of the mode after the reset.
    pub mode_after: &'a str,
    /// The mode before the reset, by index (the model's `Mode`; its name is
    /// `mode_before`).
    pub from: Mode,
    /// The mode after the reset, by index.
    pub to: Mode,
    /// The model's energy just before the reset, if it has one.
    pub energy_before: Option<f64>,
    /// The model's energy just after the reset, if it has one.
    pub energy_after: Option<f64>,
    /// Names of the components of `before`.
    pub names_before: &'a [Name],
    /// The state just before the reset (empty for an event-local model).
    pub before: &'a [f64],
    /// Names of the components of `after`.
    pub names_after: &'a [Name],
    /// The state just after the reset (empty for an event-local model).
    pub after: &'a [f64],
    /// What the model labels the event with (a chain's unit and closing
    /// speed, a place along a continuum), passed on as it is.
    pub labels: &'a Labels,
    /// Whether the event comes past the run's horizon, in a run that goes
    /// on past it (asked to, `--past-horizon`, or an exact event-local
    /// model such as the chain, which always does): it is an event of a
    /// pseudo-orbit (see [`horizon`](crate::engine::bound::horizon)).
    pub shadow: bool,
}

/// Receives events as they happen. An error stops the run (status `failed`).
pub trait Observer {
    /// Receive one event. An error stops the run.
    fn on_event(&mut self, event: &EventRecord) -> std::io::Result<()>;

    /// Called now and then (every few thousand turns of the loop) with the
    /// simulated time reached and the events so far, for progress displays.
    fn on_progress(&mut self, t: f64, events: u64) {
        let _ = (t, events);
    }

    /// Why the run should end here, if the observer has seen what it came
    /// for (asked after each event it receives): the run then ends at that
    /// event, `interrupted` with this reason, its final state the one just
    /// before the event's reset (as a run that fails at an event).
    fn stop(&self) -> Option<String> {
        None
    }

    /// Whether the observer looks at events at all. An event-local model
    /// computes the energies of an event (a sum over the whole model) only
    /// for an observer that does, and a run jumps over whole periods of an
    /// exactly periodic orbit only for one that does not.
    fn wants_details(&self) -> bool {
        true
    }
}

impl Observer for () {
    fn on_event(&mut self, _: &EventRecord) -> std::io::Result<()> {
        Ok(())
    }

    fn wants_details(&self) -> bool {
        false
    }
}

/// Asks for every event and keeps none: a run under it fires each event,
/// even along an orbit it could jump over whole periods of (see
/// [`periodic`](crate::engine::run::periodic)). For measuring what each event
/// costs: benchmarks, soak runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct EachEvent;

impl Observer for EachEvent {
    fn on_event(&mut self, _: &EventRecord) -> std::io::Result<()> {
        Ok(())
    }
}

/// The name under which a Zeno settling appears in the log.
pub const SETTLE: &str = "settle";

/// Keeps the times of events, Zeno settles left out.
#[derive(Debug, Clone, Default)]
pub struct EventTimes(pub Vec<f64>);

impl Observer for EventTimes {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        if e.guard != SETTLE {
            self.0.push(e.t);
        }
        Ok(())
    }
}

/// An event copied out of the engine.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedEvent {
    /// Time of the event.
    pub t: f64,
    /// Name of the guard that fired.
    pub guard: Name,
    /// The mode before the reset, by index.
    pub from: Mode,
    /// The mode after the reset, by index.
    pub to: Mode,
    /// The model's energy just before the reset, if it has one.
    pub energy_before: Option<f64>,
    /// The model's energy just after the reset, if it has one.
    pub energy_after: Option<f64>,
    /// The state just before the reset.
    pub before: Vec<f64>,
    /// The state just after the reset.
    pub after: Vec<f64>,
    /// What the model labelled the event with.
    pub labels: Labels,
}

/// Keeps every event in memory.
#[derive(Debug, Clone, Default)]
pub struct Recorder {
    /// The events, in the order they happened.
    pub events: Vec<RecordedEvent>,
    /// Each guard name met, kept once: its events share it.
    guards: Vec<Name>,
}

impl Observer for Recorder {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        let guard = match self.guards.iter().find(|g| *g == e.guard) {
            Some(known) => known.clone(),
            None => {
                let new = Name::from(e.guard);
                self.guards.push(new.clone());
                new
            }
        };
        self.events.push(RecordedEvent {
            t: e.t,
            guard,
            from: e.from,
            to: e.to,
            energy_before: e.energy_before,
            energy_after: e.energy_after,
            before: e.before.to_vec(),
            after: e.after.to_vec(),
            labels: *e.labels,
        });
        Ok(())
    }
}
