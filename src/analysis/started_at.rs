//! A family started elsewhere: the same model, parameters and rules, from
//! a mode and state a tool chose (where a basin's orbit was seen), so the
//! tools written against a family's start (the orbit finder, the
//! Lyapunov spectrum) run from there.

use crate::engine::{Family, HybridModel, Mode, Promoted};

/// `family`, starting in `mode` at `state`.
pub struct StartedAt<'f> {
    /// The family.
    pub family: &'f dyn Family,
    /// The mode it starts in.
    pub mode: Mode,
    /// The state it starts at.
    pub state: Vec<f64>,
}

impl Family for StartedAt<'_> {
    fn model(&self) -> &(dyn HybridModel + Sync) {
        self.family.model()
    }

    fn modes(&self) -> usize {
        self.family.modes()
    }

    fn start(&self) -> (Mode, Vec<f64>) {
        (self.mode, self.state.clone())
    }

    fn start_from(&self, state: &[f64]) -> (Mode, Vec<f64>) {
        self.family.start_from(state)
    }

    fn state_names(&self) -> Vec<String> {
        self.family.state_names()
    }

    fn parameters(&self) -> Vec<String> {
        self.family.parameters()
    }

    /// Refused: where a started state's components go among the
    /// parameters held as states is the family's own layout, which the
    /// tools that start elsewhere (orbits, spectra) do not need.
    fn promoted(&self, _: &[String]) -> Result<Promoted, String> {
        Err("a family started elsewhere holds no parameters as states".into())
    }

    fn moves_the_forcing(&self, parameter: &str) -> bool {
        self.family.moves_the_forcing(parameter)
    }

    fn same_motion(&self, a: Mode, b: Mode) -> bool {
        self.family.same_motion(a, b)
    }
}
