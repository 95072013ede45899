//! A chain of N mechanisms (docs/physics.md s.4; paper (54)-(55)), as hybrid
//! models on the generic engine.
//!
//! Nodes `y_0 = 0` (fixed) to `y_N`; unit `n` joins nodes `n - 1` and `n`
//! with elongation `Delta_n = y_n - y_{n-1} >= 0` and axial force
//! `N_n = F_cr + k Delta_n`; `m y_n'' = N_{n+1} - N_n`, `m y_N'' = F - N_N`.
//! Guard `n` is `Delta_n` closing; its reset is the elastic collision of the
//! unit's two nodes (equal masses swap velocities; unit 1 flips `v_1`
//! against the wall), repeated over every unit that closes at the same
//! instant until none does ([`collide`]).
//!
//! Two descriptions of the same chain:
//! - [`event_local::TaylorChain`], the exact event-local one (the default): the
//!   free chain propagated by Taylor series with certified truncation and
//!   a certified reach of each impact, so an event costs the same at any N;
//! - [`Chain`] as a linear second-order ODE ([`ode`]), which the numerical
//!   methods and the linear propagator run: the independent second path.
//!
//! [`modal()`] is the exact solution of the unconstrained chain; [`coarse`]
//! holds the coarse-grained fields a chain is compared by.

use crate::engine::{Direction, Guard, Label, Labels};

pub mod coarse;
pub mod collide;
pub mod ensemble;
pub mod event_local;
pub mod family;
pub mod modal;
pub mod ode;
pub(crate) mod run;
pub mod scene;
mod scene_model;
mod tangent;
pub mod window_series;

pub use event_local::TaylorChain;
pub use modal::modal;

/// The chain's parameters, in the scene units of docs/physics.md s.4 or any.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// N, the number of units (and of moving nodes).
    pub units: usize,
    /// Node mass `m`.
    pub mass: f64,
    /// Unit stiffness `k`.
    pub stiffness: f64,
    /// Critical load `F_cr` (the axial force of a closed unit).
    pub critical_load: f64,
    /// End load `F`.
    pub load: f64,
    /// Whether units are unilateral (`false`: the classical linear chain).
    pub constraint: bool,
    pub(crate) guards: Vec<Guard>,
}

impl Chain {
    /// A chain of `units` units with these parameters (see the fields); with
    /// the constraint, each unit has an `impact` guard.
    pub fn new(
        units: usize,
        mass: f64,
        stiffness: f64,
        critical_load: f64,
        load: f64,
        constraint: bool,
    ) -> Self {
        let guards = if constraint {
            vec![Guard::affine("impact", Direction::Falling); units]
        } else {
            Vec::new()
        };
        Chain {
            units,
            mass,
            stiffness,
            critical_load,
            load,
            constraint,
            guards,
        }
    }

    /// The chain of docs/physics.md s.4's scene units: length `length`, wave
    /// speed `c`, so `m = L / N`, `F_cr = c^2`, `k = F_cr N / L`, end load
    /// `eta F_cr`.
    pub fn in_scene_units(
        units: usize,
        length: f64,
        wave_speed: f64,
        eta: f64,
        constraint: bool,
    ) -> Self {
        let critical_load = wave_speed * wave_speed;
        let n = units as f64;
        Chain::new(
            units,
            length / n,
            critical_load * n / length,
            critical_load,
            eta * critical_load,
            constraint,
        )
    }

    /// The state with every unit at `strain`, at rest: the homogeneous
    /// static deformation (Cauchy-Born) a release starts from. The unit
    /// length `2 l` is `critical_load / stiffness` (docs/physics.md s.4).
    pub fn homogeneous(&self, strain: f64) -> Vec<f64> {
        let delta = strain * self.unit_length();
        let positions = (1..=self.units).map(|n| delta * n as f64);
        positions
            .chain(std::iter::repeat_n(0.0, self.units))
            .collect()
    }

    /// The closed length `2 l = F_cr / k` of a unit: a unit's elongation
    /// over it is its strain.
    pub fn unit_length(&self) -> f64 {
        self.critical_load / self.stiffness
    }

    /// Elongation of unit `n` (1-based) in state `x`.
    pub fn elongation(&self, x: &[f64], n: usize) -> f64 {
        x[n - 1] - if n > 1 { x[n - 2] } else { 0.0 }
    }

    /// Total linear momentum `sum m v`.
    pub fn momentum(&self, x: &[f64]) -> f64 {
        self.mass * x[self.units..].iter().sum::<f64>()
    }
}

/// What the log says of a chain's event: the unit (1 = next to the wall)
/// and, for an impact, the closing speed `y'_{n-1} - y'_n` just before it.
pub fn impact_labels(unit: usize, rel_velocity: Option<f64>) -> Labels {
    Labels::NONE
        .with("unit", Label::Count(unit as u64))
        .with_some("rel_velocity", rel_velocity.map(Label::Number))
}
