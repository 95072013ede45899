//! An automaton as the tools see it ([`Family`]): the compiled model, the
//! file's initial mode and state, and its parameters, which are held as
//! states by recompiling the definition with them as states
//! ([`Definition::with_parameters_as_states`]), so their derivatives stay
//! exact.

use crate::engine::{Family, HybridModel, Mode, Promoted};
use crate::models::automaton::model::Automaton;
use crate::models::automaton::scene::AutomatonScene;

impl Family for AutomatonScene {
    fn model(&self) -> &(dyn HybridModel + Sync) {
        &*self.automaton
    }

    fn modes(&self) -> usize {
        self.automaton.modes().len()
    }

    fn start(&self) -> (Mode, Vec<f64>) {
        (
            self.automaton.initial_mode(),
            self.automaton.initial().to_vec(),
        )
    }

    fn start_from(&self, state: &[f64]) -> (Mode, Vec<f64>) {
        (self.automaton.initial_mode_at(state), state.to_vec())
    }

    fn parameters(&self) -> Vec<String> {
        self.definition
            .parameters
            .iter()
            .map(|(p, _)| p.clone())
            .collect()
    }

    fn promoted(&self, names: &[String]) -> Result<Promoted, String> {
        let (definition, initial_slopes) = self
            .definition
            .with_parameters_as_states(names, "parameter")
            .map_err(|e| e.reason)?;
        let model = Automaton::compile(&definition).map_err(|e| e.reason)?;
        let states = self.definition.states.len();
        let n = model.dimension();
        let slopes = initial_slopes
            .iter()
            .enumerate()
            .map(|(k, initial)| {
                let mut s = vec![0.0; n];
                s[..states].copy_from_slice(initial);
                s[states + k] = 1.0;
                s
            })
            .collect();
        Ok(Promoted {
            mode: model.initial_mode(),
            start: model.initial().to_vec(),
            parameters: (states..states + names.len()).collect(),
            slopes,
            model: Box::new(model),
        })
    }

    fn start_with(&self, parameter: &str, value: f64) -> Result<(Mode, Vec<f64>), String> {
        let mut x0 = self.automaton.initial().to_vec();
        let initial = self
            .definition
            .initial_with(parameter, value)
            .map_err(|e| e.reason)?;
        x0[..initial.len()].copy_from_slice(&initial);
        Ok((self.automaton.initial_mode(), x0))
    }

    fn moves_the_forcing(&self, parameter: &str) -> bool {
        self.definition.sets_the_forcing(parameter)
    }
}
