//! The states a run passes through a section in: an observer that keeps
//! the mode and state just after each event of one guard (from a time
//! on), and stops the run once it has as many as it wants, or once an
//! outer stop flag (Ctrl-C) is set. What diagrams and basins read; and
//! the check, shared with the orbit tools, that a section names a guard.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::engine::{EventRecord, HybridModel, Mode, Observer};
use crate::scene::SceneError;

/// Refuse, as field `section`, a `section` that names no guard of
/// `model`'s modes `0..modes`, listing those it has.
pub fn check_section(
    model: &dyn HybridModel,
    modes: usize,
    section: &str,
) -> Result<(), SceneError> {
    let mut known: Vec<&str> = Vec::new();
    for m in 0..modes {
        for g in model.guards(m) {
            if !known.contains(&&*g.name) {
                known.push(&g.name);
            }
        }
    }
    if known.contains(&section) {
        return Ok(());
    }
    Err(SceneError::field(
        "section",
        format!(
            "no transition is called `{section}` (transitions: {})",
            known.join(", ")
        ),
    ))
}

/// One section event: its time, and the mode and state just after it.
#[derive(Debug, Clone, PartialEq)]
pub struct Crossing {
    /// The event's time.
    pub t: f64,
    /// The mode after the reset.
    pub mode: Mode,
    /// The state after the reset.
    pub state: Vec<f64>,
}

/// Keeps up to `wanted` section events from time `from` on.
pub struct SectionRecords<'a> {
    section: &'a str,
    from: f64,
    wanted: usize,
    own_stop: &'a AtomicBool,
    outer_stop: Option<&'a AtomicBool>,
    /// The events kept.
    pub kept: Vec<Crossing>,
}

impl<'a> SectionRecords<'a> {
    /// Keep `wanted` events of `section` from `from` on, then set
    /// `own_stop` (the run's own stop flag), as it does once `outer_stop`
    /// is set.
    pub fn new(
        section: &'a str,
        (from, wanted): (f64, usize),
        own_stop: &'a AtomicBool,
        outer_stop: Option<&'a AtomicBool>,
    ) -> Self {
        SectionRecords {
            section,
            from,
            wanted,
            own_stop,
            outer_stop,
            kept: Vec::with_capacity(wanted.min(1024)),
        }
    }

    /// Whether it has all it wanted.
    pub fn full(&self) -> bool {
        self.kept.len() >= self.wanted
    }
}

impl Observer for SectionRecords<'_> {
    fn on_event(&mut self, event: &EventRecord) -> std::io::Result<()> {
        if event.guard == self.section && event.t >= self.from && !self.full() {
            self.kept.push(Crossing {
                t: event.t,
                mode: event.to,
                state: event.after.to_vec(),
            });
            if self.full() {
                self.own_stop.store(true, Ordering::Relaxed);
            }
        }
        if self.outer_stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            self.own_stop.store(true, Ordering::Relaxed);
        }
        Ok(())
    }

    fn wants_details(&self) -> bool {
        true
    }
}
