//! The mechanism in the strain formulation: a hybrid automaton with the exact
//! flow of the linear oscillator, the guard `eps = 0` while closing, and the
//! elastic reset `eps' -> -eps'` (docs/physics.md s.2).
//!
//! Below the critical load (`eta < 1`) the trivial state is stable and sits
//! on the constraint: orbits with small energy chatter against it, and the
//! engine's Zeno watch hands them to the `resting` mode, where the strain
//! stays at zero (the load keeps the unit shut, so it never leaves).
//!
//! The flight is also offered as an ODE (second order, and linear), so that
//! every method can run it and be measured against the closed form.

use nalgebra::{DMatrix, DVector};

use crate::engine::{Direction, Flow, Guard, HybridModel, Jump, Mode, Name};
use crate::models::mechanism::closed_form::Mechanism;

/// Free flight: the linear oscillator, closing on the impact guard `eps = 0`.
pub const FLIGHT: Mode = 0;
/// Resting contact at `eps = 0` below the critical load, after chattering.
pub const RESTING: Mode = 1;

const STATE: &[Name] = &[Name::new("strain"), Name::new("strain_rate")];
const FLIGHT_GUARDS: &[Guard] = &[Guard::affine("impact", Direction::Falling)];

/// State `[eps, eps']`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrainMechanism {
    /// The mechanism's load ratio and frequency.
    pub mechanism: Mechanism,
}

impl HybridModel for StrainMechanism {
    fn dimension(&self) -> usize {
        2
    }

    fn state_names(&self, _: Mode) -> &[Name] {
        STATE
    }

    fn mode_name(&self, mode: Mode) -> &str {
        if mode == RESTING { "resting" } else { "flight" }
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        if mode == RESTING { &[] } else { FLIGHT_GUARDS }
    }

    fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
        x[0]
    }

    fn flow(&self, mode: Mode) -> Flow {
        if mode == RESTING {
            Flow::Frozen
        } else {
            Flow::Exact
        }
    }

    fn has_rhs(&self, mode: Mode) -> bool {
        mode == FLIGHT
    }

    /// The linear oscillator (45), for numerical methods.
    fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
        let omega = self.mechanism.omega;
        dx[0] = x[1];
        dx[1] = -omega * omega * (x[0] - self.mechanism.centre());
    }

    fn second_order(&self, mode: Mode) -> bool {
        mode == FLIGHT
    }

    fn linear(&self, mode: Mode) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let w2 = self.mechanism.omega.powi(2);
        (mode == FLIGHT).then(|| {
            (
                DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w2, 0.0]),
                DVector::from_vec(vec![0.0, w2 * self.mechanism.centre()]),
            )
        })
    }

    fn advance(&self, _: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        (x[0], x[1]) = self.mechanism.flow(x0[0], x0[1], tau);
    }

    fn next_crossing(&self, _: Mode, _: usize, x0: &[f64]) -> Option<f64> {
        self.mechanism.time_to_closing(x0[0], x0[1])
    }

    fn reset(&self, mode: Mode, _: usize, x: &mut [f64]) -> Jump {
        // The crossing is exact up to rounding: put the state on the
        // constraint so the next flight starts from eps = 0 exactly.
        x[0] = 0.0;
        x[1] = -x[1];
        Jump::to(mode)
    }

    fn energy(&self, _: Mode, x: &[f64]) -> Option<f64> {
        Some(self.mechanism.energy(x[0], x[1]))
    }

    /// The closed form oscillates about the centre `eta - 1`: near the
    /// constraint its strain is a difference of numbers that size.
    fn exact_flow_scale(&self) -> f64 {
        self.mechanism.centre()
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        self.mechanism.energy_scale(initial_energy)
    }

    fn settle(&self, _: Mode, x: &mut [f64]) -> Option<Mode> {
        // Only below the critical load does the load hold the unit shut.
        (self.mechanism.eta < 1.0).then(|| {
            x.copy_from_slice(&[0.0, 0.0]);
            RESTING
        })
    }
}
