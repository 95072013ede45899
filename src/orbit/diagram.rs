//! The brute-force bifurcation diagram a continued branch is drawn over:
//! at evenly spaced values of the parameter, the states just after many
//! section events once a transient has passed, from plain runs (in
//! parallel, one value each).

use rayon::prelude::*;

use crate::models::automaton::{Automaton, Definition};
use crate::orbit::{Section, start};
use crate::scene::SceneError;

/// The section states seen at one value of the parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The parameter.
    pub parameter: f64,
    /// The state just after each section event recorded (every
    /// component); none where the runs stopped (no events, a graze).
    pub states: Vec<Vec<f64>>,
}

/// At each of `values` of `parameter`, from the scene's initial state:
/// `settle` run through, then the states after the next `events` events of
/// `guard`, each within `t_max` of the one before.
pub fn brute_force(
    definition: &Definition,
    parameter: &str,
    values: &[f64],
    guard: &str,
    (settle, events, t_max): (f64, usize, f64),
) -> Result<Vec<Column>, SceneError> {
    let (promoted, _) = definition.with_parameters_as_states(&[parameter.to_string()], "param")?;
    let model = Automaton::compile(&promoted)?;
    let p = definition.states.len();
    let section = Section {
        model: &model,
        guard,
        events: 1,
        t_max,
        stop: None,
    };
    Ok(values
        .par_iter()
        .map(|&value| {
            // The start at this value: initial values may depend on it.
            let mut x0 = model.initial().to_vec();
            if let Ok(initial) = definition.initial_with(parameter, value) {
                x0[..p].copy_from_slice(&initial);
            }
            x0[p] = value;
            let mut states = Vec::with_capacity(events);
            if let Ok((mut mode, mut x)) = start(&section, model.initial_mode(), &x0, settle) {
                states.push(x.clone());
                while states.len() < events {
                    match section.plain(mode, &x) {
                        Ok((_, m, next)) => {
                            (mode, x) = (m, next);
                            states.push(x.clone());
                        }
                        Err(_) => break,
                    }
                }
            }
            Column {
                parameter: value,
                states,
            }
        })
        .collect())
}
