//! A run's horizon: where what it computes stops being the answer to its
//! scene, and what a run asked to go past it does there.
//!
//! The horizon is the first time the run's own error (its bound, or its
//! estimate where no bound is carried) reaches [`FRACTION`] of the state's
//! scale, or its bound can no longer decide what happens (whether a graze
//! fires, the order of two events, whether an event comes before `t_end`),
//! whichever comes first. A chaotic run meets it as its errors grow with
//! the chaos, an exact one after about `10^11` events of round-off.
//!
//! Where the bound cannot decide, a run stops, saying why, and where it is.
//! A run asked to go past it (`--past-horizon`) goes on instead, as the
//! method computes, and stops carrying its bound: from there its state is
//! a pseudo-orbit, an orbit of the model to within the method's local
//! errors, which in a hyperbolic system stays close to a true orbit from a
//! nearby start (shadowing): its statistics are the attractor's, its state
//! is not the scene's. Every event from the horizon on is flagged
//! `shadow`, and the run states no bound. A pile-up of events a run
//! going past its horizon cannot order goes on as it computes, until the
//! Zeno watch's own resolution catches it, and is named the same way.
//!
//! Where the run jumps whole periods of a periodic orbit (replaying its
//! bound over them), the horizon is looked for at the jump's end: it is
//! dated to within the periods jumped at once.

use crate::time::Time;

/// The share of the state's scale at which a run's error marks its
/// horizon.
pub const FRACTION: f64 = 1e-3;

/// Where a run's horizon is, and whether the run has gone past it.
#[derive(Debug, Clone, Default)]
pub(crate) struct Horizon {
    at: Option<Time>,
    /// Whether the run may go past it (`--past-horizon`).
    past: bool,
    /// Whether it has: events are shadows, and no bound is carried.
    shadow: bool,
}

impl Horizon {
    /// Not reached yet; `past`: a run that goes on past it.
    pub fn new(past: bool) -> Self {
        Horizon {
            past,
            ..Horizon::default()
        }
    }

    /// The horizon, if reached.
    pub fn at(&self) -> Option<Time> {
        self.at
    }

    /// Whether the run has gone past its horizon.
    #[inline(always)]
    pub fn shadow(&self) -> bool {
        self.shadow
    }

    /// The run's error has reached [`FRACTION`] of its state at `t`: a
    /// run that may go past its horizon goes on from here as a
    /// pseudo-orbit.
    pub fn reached(&mut self, t: Time) {
        if self.at.is_none() {
            self.at = Some(t);
            self.shadow = self.past;
        }
    }

    /// The bound can no longer decide what happens at `t`, for the reason
    /// `why`: a run that may go past its horizon goes on; any other
    /// stops, its reason naming the horizon and the way past it.
    pub fn undecided(&mut self, t: Time, why: String) -> Result<(), String> {
        self.reached(t);
        if self.past {
            self.shadow = true;
            return Ok(());
        }
        let at = self.at.unwrap_or(t).value();
        Err(format!(
            "{why}. This is the run's horizon (t = {at}): past it the computed state is one of \
             many pseudo-orbits, not the scene's answer; `--past-horizon` (`past_horizon` in a \
             sweep or from Python) goes on as a pseudo-orbit, its events flagged `shadow`"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_time_reached_is_the_horizon() {
        let mut h = Horizon::new(false);
        assert_eq!(h.at(), None);
        h.reached(Time::new(2.0));
        h.reached(Time::new(1.0));
        assert_eq!(h.at().map(Time::value), Some(2.0));
        // Reached, not undecided: a run that may not go past it goes on
        // carrying its bound.
        assert!(!h.shadow());
        let why = h
            .undecided(Time::new(3.0), "an event in doubt".into())
            .unwrap_err();
        assert!(
            why.starts_with("an event in doubt. This is the run's horizon (t = 2)"),
            "{why}"
        );
        assert!(why.contains("--past-horizon"), "{why}");
    }

    #[test]
    fn a_run_that_may_go_past_it_does_from_the_horizon() {
        let mut h = Horizon::new(true);
        assert!(h.undecided(Time::new(5.0), String::new()).is_ok());
        assert!(h.shadow());
        assert_eq!(h.at().map(Time::value), Some(5.0));
        let mut h = Horizon::new(true);
        h.reached(Time::new(4.0));
        assert!(h.shadow());
    }
}
