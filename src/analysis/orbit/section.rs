//! The Poincare map of a model at the events of one guard, with its
//! Jacobian: from a state just after a section event, the state just after
//! the `K`-th next one, how long that took, and the derivatives of both
//! with respect to every component of the starting state.
//!
//! The run carries its derivatives ([`Variational`], every component a
//! direction), so at the `K`-th event it holds `S`, the monodromy matrix:
//! the derivative of the state just after that event at a fixed time,
//! saltation matrices included, and `dtau`, the derivative of the event's
//! time. The map's Jacobian is then `M + f+ dtau^T` (`f+` the rate just
//! after): a start moved along the flow arrives earlier by as much, at the
//! same place.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::DMatrix;

use crate::engine::bound::variational::Variational;
use crate::engine::step::method::tightest;
use crate::engine::{
    EventRecord, Family, Flow, HybridModel, Method, Mode, Observer, Options, Status, Tolerances,
    simulate,
};

/// Tolerance of the section map's runs (DOP853) where the modes are not
/// all linear.
const TOLERANCE: f64 = 1e-13;

/// The events of one guard of a model, `K` of them per return.
pub struct Section<'a> {
    /// The model's family: its modes, and which of them move alike.
    pub family: &'a dyn Family,
    /// The model run: the family's, or the same with parameters held as
    /// states.
    pub model: &'a (dyn HybridModel + Sync),
    /// The guard's name.
    pub guard: &'a str,
    /// Section events per return of the map.
    pub events: usize,
    /// The longest a return may take.
    pub t_max: f64,
    /// Set from outside (Ctrl-C) to end the search: the run under way
    /// ends at its next event, and the next map refuses.
    pub stop: Option<&'a Arc<AtomicBool>>,
    /// When the work must end (`--wall`): runs get what is left of it.
    pub deadline: Option<Instant>,
}

/// One return of the map.
#[derive(Debug, Clone)]
pub struct Return {
    /// Time from the start to the `K`-th event.
    pub elapsed: f64,
    /// The mode just after it.
    pub mode: Mode,
    /// The state just after it.
    pub state: Vec<f64>,
    /// The monodromy matrix: `d state / d start` at a fixed time, saltation
    /// matrices included.
    pub monodromy: DMatrix<f64>,
    /// The Poincare map's Jacobian, `monodromy + f+ dtau^T`.
    pub jacobian: DMatrix<f64>,
    /// `d elapsed / d start`.
    pub dtau: Vec<f64>,
}

/// Keeps the `K`-th event of the section guard and stops the run there.
/// Counts the section's events and ends the run at the `wanted`-th.
struct Counter<'a> {
    guard: &'a str,
    wanted: usize,
    seen: usize,
    hit: Option<(f64, Mode, Vec<f64>)>,
}

impl Observer for Counter<'_> {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        if e.guard == self.guard && self.hit.is_none() {
            self.seen += 1;
            if self.seen == self.wanted {
                self.hit = Some((e.t, e.to, e.after.to_vec()));
            }
        }
        Ok(())
    }

    fn stop(&self) -> Option<String> {
        self.hit
            .as_ref()
            .map(|(t, _, _)| format!("the section's event {} at t = {t}", self.wanted))
    }
}

impl std::fmt::Debug for Section<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Section")
            .field("guard", &self.guard)
            .field("events", &self.events)
            .field("t_max", &self.t_max)
            .finish()
    }
}

impl Section<'_> {
    /// The method `model`'s runs take (the section's, its transient):
    /// [`tightest`] at 1e-13.
    pub fn method<M: HybridModel + ?Sized>(&self, model: &M) -> Method {
        tightest(model, self.family.modes(), TOLERANCE)
    }

    /// Run `model` from `x0` in `mode` to the `K`-th section event: its
    /// time, the mode and the state just after it.
    fn run<M: HybridModel + ?Sized>(
        &self,
        model: &M,
        mode: Mode,
        x0: &[f64],
    ) -> Result<(f64, Mode, Vec<f64>), String> {
        if let Some(why) = self.spent() {
            return Err(why);
        }
        let options = Options {
            t_end: self.t_max,
            max_events: 100_000_000,
            method: self.method(model),
            tolerances: Tolerances::default(),
            stop: self.stop.cloned(),
            max_wall_seconds: self
                .deadline
                .map(|d| d.saturating_duration_since(Instant::now()).as_secs_f64()),
            past_horizon: false,
        };
        let mut counter = Counter {
            guard: self.guard,
            wanted: self.events,
            seen: 0,
            hit: None,
        };
        let outcome = simulate(model, mode, x0, &options, &mut counter);
        match counter.hit {
            Some(hit) => Ok(hit),
            None if self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) => {
                Err("interrupted: the stop flag was set".into())
            }
            None => Err(match outcome.status {
                Status::Completed | Status::Interrupted => format!(
                    "only {} of {} `{}` events before t = {} (no return to the section)",
                    counter.seen, self.events, self.guard, self.t_max
                ),
                _ => format!(
                    "the run stopped at t = {} before the section: {}",
                    outcome.t_reached,
                    outcome.reason.unwrap_or_default()
                ),
            }),
        }
    }

    /// Why no more runs may begin, if none may: interrupted, or past the
    /// deadline.
    pub fn spent(&self) -> Option<String> {
        if self.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            Some("interrupted: the stop flag was set".into())
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Some("stopped: past the wall-clock budget (--wall)".into())
        } else {
            None
        }
    }

    /// The state just after the `K`-th section event from `x0` in `mode`,
    /// and how long it took (no derivatives).
    pub fn plain(&self, mode: Mode, x0: &[f64]) -> Result<(f64, Mode, Vec<f64>), String> {
        self.run(self.model, mode, x0)
    }

    /// One return of the map from `x0` in `mode`, with its derivatives.
    pub fn map(&self, mode: Mode, x0: &[f64]) -> Result<Return, String> {
        let n = self.model.dimension();
        let directions: Vec<String> = (0..n).map(|k| format!("x{k}")).collect();
        let variational = Variational::new(self.model, self.family.modes(), &directions);
        let identity: Vec<Vec<f64>> = (0..n)
            .map(|j| (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect())
            .collect();
        let start = variational.initial(x0, &identity);
        let (elapsed, mode_after, after) = self.run(&variational, mode, &start)?;
        let monodromy = DMatrix::from_fn(n, n, |i, j| variational.sensitivity(&after, j)[i]);
        let dtau: Vec<f64> = (0..n)
            .map(|j| variational.event_time_sensitivity(&after, j))
            .collect();
        let state = after[..n].to_vec();
        let mut rate = vec![0.0; n];
        if self.model.flow(mode_after) != Flow::Frozen {
            self.model.rhs(mode_after, &state, &mut rate);
        }
        let jacobian = DMatrix::from_fn(n, n, |i, j| monodromy[(i, j)] + rate[i] * dtau[j]);
        Ok(Return {
            elapsed,
            mode: mode_after,
            state,
            monodromy,
            jacobian,
            dtau,
        })
    }
}
