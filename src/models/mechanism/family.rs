//! The mechanism as the tools see it ([`Family`]): the formulation's
//! hybrid model, where the scene starts in it, and its parameters `eta`
//! and `omega`, held as states by rebuilding the model from them
//! ([`WithParameters`]).
//!
//! In the angle formulation the section `impact` is `theta` crossing zero:
//! the two sides' strain charts are mirror images in the same coordinates
//! `(eps, eps')`, so an orbit that returns on the other side is periodic
//! in the strain ([`Family::same_motion`]).

use crate::engine::model::with_parameters::{WithParameters, positions};
use crate::engine::{Family, HybridModel, Mode, Promoted};
use crate::models::mechanism::angle::{self, AngleMechanism};
use crate::models::mechanism::scene::{Formulation, Initial, MechanismScene};
use crate::models::mechanism::strain::{self, FLIGHT, StrainMechanism};
use crate::models::mechanism::{Charts, Mechanism};
use crate::numerics::central_difference::step_for;

const PARAMETERS: [&str; 2] = ["eta", "omega"];

/// A mechanism scene's model and start.
#[derive(Debug, Clone)]
pub struct MechanismFamily {
    strain: StrainMechanism,
    angle: Option<AngleMechanism>,
    initial: Initial,
}

impl MechanismFamily {
    /// The family of `scene`'s formulation.
    pub fn new(scene: &MechanismScene) -> Self {
        let angle = match scene.formulation {
            Formulation::Strain => None,
            Formulation::Angle(charts) => Some(AngleMechanism {
                mechanism: scene.mechanism,
                charts,
            }),
        };
        MechanismFamily {
            strain: StrainMechanism {
                mechanism: scene.mechanism,
            },
            angle,
            initial: scene.initial,
        }
    }

    /// Where a run of the mechanism `m` starts.
    fn start_of(&self, m: Mechanism) -> Result<(Mode, Vec<f64>), String> {
        let (eps, rate) = match self.initial {
            Initial::Strain { strain, rate } => (strain, rate),
            Initial::Energy { energy, phase } => m.state_with_energy(energy, phase)?,
            Initial::Angle { angle, rate } => angle::strain_of_angle(angle, rate),
        };
        match (self.angle, self.initial) {
            (None, _) => Ok((FLIGHT, vec![eps, rate])),
            (Some(a), Initial::Angle { angle, rate }) => {
                let (mode, x) = a.start_from_angle(angle, rate);
                Ok((mode, x.to_vec()))
            }
            (Some(a), _) => a
                .start_from_strain(eps, rate)
                .map(|(mode, x)| (mode, x.to_vec())),
        }
    }

    /// The mechanism with `names` set from `values`.
    fn set(base: Mechanism, names: &[usize], values: &[f64]) -> Mechanism {
        let mut m = base;
        for (&k, &v) in names.iter().zip(values) {
            if k == 0 { m.eta = v } else { m.omega = v }
        }
        m
    }
}

impl Family for MechanismFamily {
    fn model(&self) -> &(dyn HybridModel + Sync) {
        match &self.angle {
            Some(angle) => angle,
            None => &self.strain,
        }
    }

    fn modes(&self) -> usize {
        if self.angle.is_some() {
            angle::RESTING + 1
        } else {
            strain::RESTING + 1
        }
    }

    fn start(&self) -> (Mode, Vec<f64>) {
        // The scene was validated: its own start exists.
        self.start_of(self.strain.mechanism)
            .unwrap_or((FLIGHT, vec![0.0, 0.0]))
    }

    fn parameters(&self) -> Vec<String> {
        PARAMETERS.iter().map(|p| p.to_string()).collect()
    }

    fn promoted(&self, names: &[String]) -> Result<Promoted, String> {
        let which = positions(names, &PARAMETERS)?;
        let base = self.strain.mechanism;
        let values: Vec<f64> = which
            .iter()
            .map(|&k| if k == 0 { base.eta } else { base.omega })
            .collect();
        let (mode, x0) = self.start_of(base)?;
        let n = x0.len();
        // The start's derivative along each parameter: central differences
        // (an energy's start moves with eta; the others do not move).
        let slopes = (0..which.len())
            .map(|j| {
                let h = step_for(values[j]);
                let moved = |d: f64| {
                    let mut v = values.clone();
                    v[j] += d;
                    self.start_of(Self::set(base, &which, &v))
                        .ok()
                        .filter(|(m, _)| *m == mode)
                        .map(|(_, x)| x)
                };
                let (Some(up), Some(down)) = (moved(h), moved(-h)) else {
                    return Err(format!(
                        "the start moves out of its chart or its energy's reach as `{}` moves: \
                         its derivative along it is not defined here",
                        PARAMETERS[which[j]]
                    ));
                };
                let mut s = vec![0.0; n + which.len()];
                for i in 0..n {
                    s[i] = (up[i] - down[i]) / (2.0 * h);
                }
                s[n + j] = 1.0;
                Ok(s)
            })
            .collect::<Result<Vec<_>, String>>()?;
        let mut start = x0;
        start.extend_from_slice(&values);
        let parameters = (n..n + which.len()).collect();
        let model: Box<dyn HybridModel + Send + Sync> = match self.angle {
            None => Box::new(WithParameters::new(
                self.strain,
                self.modes(),
                names,
                move |p: &[f64]| StrainMechanism {
                    mechanism: Self::set(base, &which, p),
                },
            )),
            Some(a) => Box::new(WithParameters::new(
                a,
                self.modes(),
                names,
                move |p: &[f64]| AngleMechanism {
                    mechanism: Self::set(base, &which, p),
                    charts: a.charts,
                },
            )),
        };
        Ok(Promoted {
            model,
            mode,
            start,
            parameters,
            slopes,
        })
    }

    fn start_with(&self, parameter: &str, value: f64) -> Result<(Mode, Vec<f64>), String> {
        let k = PARAMETERS
            .iter()
            .position(|p| *p == parameter)
            .ok_or_else(|| format!("no parameter is called `{parameter}`"))?;
        self.start_of(Self::set(self.strain.mechanism, &[k], &[value]))
    }

    fn same_motion(&self, a: Mode, b: Mode) -> bool {
        let strain_chart = |m| m == angle::STRAIN_POSITIVE || m == angle::STRAIN_NEGATIVE;
        a == b
            || (self.angle.is_some_and(|x| x.charts == Charts::Switch)
                && strain_chart(a)
                && strain_chart(b))
    }
}
