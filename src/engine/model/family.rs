//! What the tools ask of a model: the model itself, where it starts, and
//! its parameters, which a tool may vary or hold as states. Periodic
//! orbits, continuation, brute-force diagrams and sensitivities are
//! written once against a [`Family`], so each works on every model that
//! gives one: the mechanism in both formulations, the chain, automata.

use crate::engine::model::{HybridModel, Mode};

/// A model whose tools can run it: the model and where it starts, and the
/// same model with parameters held as states.
pub trait Family: Send + Sync {
    /// The model at its own parameter values.
    fn model(&self) -> &(dyn HybridModel + Sync);

    /// The modes a run may enter: `0..modes()`.
    fn modes(&self) -> usize;

    /// The mode and state the scene starts in.
    fn start(&self) -> (Mode, Vec<f64>);

    /// A start at `state` (every component given, the clock too where the
    /// model carries one): the mode a run from it begins in, and the
    /// state. By default the scene's own mode; a model whose mode depends
    /// on where the state lies (a region of a discontinuous flow) says so.
    fn start_from(&self, state: &[f64]) -> (Mode, Vec<f64>) {
        (self.start().0, state.to_vec())
    }

    /// The names of the state's components where the scene starts, for a
    /// tool's directions (`initial.NAME`) and reports.
    fn state_names(&self) -> Vec<String> {
        let (mode, _) = self.start();
        self.model()
            .state_names(mode)
            .iter()
            .map(|s| s.to_string())
            .collect()
    }

    /// The parameters a tool may vary, by name.
    fn parameters(&self) -> Vec<String>;

    /// The model with `names` (known [`parameters`](Family::parameters),
    /// each once) held as states that never change, after the model's
    /// own: what a sensitivity along a parameter or a continuation in one
    /// runs. A refusal says why in one line.
    fn promoted(&self, names: &[String]) -> Result<Promoted, String>;

    /// The starting state with `parameter` at `value` (an initial value
    /// may be given by the parameters, as an energy is).
    fn start_with(&self, parameter: &str, value: f64) -> Result<(Mode, Vec<f64>), String> {
        let _ = (parameter, value);
        Ok(self.start())
    }

    /// Whether `parameter` sets the period of a forcing (it enters a
    /// function of the clock), which an orbit of a forced system holds
    /// fixed.
    fn moves_the_forcing(&self, parameter: &str) -> bool {
        let _ = parameter;
        false
    }

    /// Whether a state in mode `a` moves as the same state in mode `b`
    /// does: mirror images written in the same coordinates (the two sides
    /// of the angle formulation's strain chart). An orbit that returns in
    /// the mirror mode is periodic in those coordinates.
    fn same_motion(&self, a: Mode, b: Mode) -> bool {
        a == b
    }
}

/// A model with parameters held as states, as [`Family::promoted`] gives
/// it.
pub struct Promoted {
    /// The model: its own state, then the parameters in the order named.
    pub model: Box<dyn HybridModel + Send + Sync>,
    /// The mode it starts in.
    pub mode: Mode,
    /// Where it starts, the parameters at their values.
    pub start: Vec<f64>,
    /// Each parameter's component of the state (after the model's own
    /// states; an automaton keeps its clock last, a rebuilt model keeps it
    /// where it was).
    pub parameters: Vec<usize>,
    /// For each parameter, the derivative of the whole starting state
    /// along it: its unit vector, and the initial values it gives.
    pub slopes: Vec<Vec<f64>>,
}

impl Promoted {
    /// Where a family promoted in the one `parameter` starts with it at
    /// `value`: the family's own start there (an initial value may depend
    /// on it; its plain start where the family cannot say), the parameter's
    /// component set to `value`.
    pub fn start_at(&self, family: &dyn Family, parameter: &str, value: f64) -> (Mode, Vec<f64>) {
        let p = self.parameters[0];
        let (mode, own) = family
            .start_with(parameter, value)
            .unwrap_or_else(|_| family.start());
        let mut rest = own.into_iter();
        let x0 = (0..self.start.len())
            .map(|i| {
                if i == p {
                    value
                } else {
                    rest.next().unwrap_or(0.0)
                }
            })
            .collect();
        (mode, x0)
    }
}

impl std::fmt::Debug for Promoted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Promoted")
            .field("dimension", &self.model.dimension())
            .field("mode", &self.mode)
            .field("start", &self.start)
            .field("parameters", &self.parameters)
            .finish()
    }
}
