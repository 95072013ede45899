//! The brute-force bifurcation diagram a continued branch is drawn over:
//! at evenly spaced values of the parameter, the states just after many
//! section events once a transient has passed, from plain runs (in
//! parallel, one value each).

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use rayon::prelude::*;

use crate::analysis::orbit::{Section, start};
use crate::engine::Family;
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

/// At each of `values` of `parameter` of `family`, from the scene's
/// start: `settle` run through, then the states after the next `events`
/// events of `guard`, each within `t_max` of the one before; runs not
/// begun once `stop` is set or `deadline` passed, cut short if under way.
pub fn brute_force(
    family: &dyn Family,
    parameter: &str,
    values: &[f64],
    guard: &str,
    (settle, events, t_max): (f64, usize, f64),
    (stop, deadline): (Option<&Arc<AtomicBool>>, Option<Instant>),
) -> Result<Vec<Column>, SceneError> {
    let promoted = family
        .promoted(&[parameter.to_string()])
        .map_err(|why| SceneError::field("param", why))?;
    let section = Section {
        family,
        model: &*promoted.model,
        guard,
        events: 1,
        t_max,
        stop,
        deadline,
    };
    Ok(values
        .par_iter()
        .map(|&value| {
            let (mode, x0) = promoted.start_at(family, parameter, value);
            let mut states = Vec::with_capacity(events);
            if let Ok((mut mode, mut x)) = start(&section, mode, &x0, settle, &mut ()) {
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
