//! A guard's crossing found on a step's dense output, as the integrators
//! hand it to be placed more closely (see `sharpen.rs`), and what that
//! did to it.

/// A crossing found on a step's dense output, `tau` into the step, for
/// [`Integrator::sharpen`](crate::engine::step::integrator::Integrator::sharpen): how far it may move, the guard, and which of
/// the guard's values count as having crossed.
pub struct Crossing<'a> {
    /// Time of the crossing into the step, as the dense output puts it.
    pub tau: f64,
    /// The largest correction to `tau` that is accepted from the flow
    /// followed past a step's end (the range of its polynomial).
    pub reach: f64,
    /// How far the crossing may move either way and keep the events'
    /// order (the time to the next queued event; none where one is due at
    /// the same instant, a simultaneous event).
    pub room: f64,
    /// The guard, as a function of the state.
    pub guard: &'a dyn Fn(&[f64]) -> f64,
    /// Whether a value of the guard counts as having crossed.
    pub crossed: &'a dyn Fn(f64) -> bool,
    /// The guard's place among its mode's guards.
    pub slot: usize,
}

/// What sharpening did to a crossing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sharpened {
    /// Moved it by this much, with the state there.
    Moved(f64),
    /// Kept the dense output's: the state there errs by up to this much
    /// more than the step's error (the gap to the step re-taken to it; 0
    /// where the method's dense output is its step; not finite where the
    /// re-taken step blew up).
    Kept(f64),
}
