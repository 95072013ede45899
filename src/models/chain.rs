//! A chain of N mechanisms (PHYSICS.md s.4; paper (54)-(55)), as a hybrid
//! model on the generic engine.
//!
//! Nodes `y_0 = 0` (fixed) to `y_N`; unit `n` joins nodes `n - 1` and `n`
//! with elongation `Delta_n = y_n - y_{n-1} >= 0` and axial force
//! `N_n = F_cr + k Delta_n`; `m y_n'' = N_{n+1} - N_n`, `m y_N'' = F - N_N`.
//! State `[y_1..y_N, v_1..v_N]`. Guard `n` is `Delta_n` closing; its reset
//! is the elastic collision of the unit's two nodes (equal masses swap
//! velocities; unit 1 flips `v_1` against the wall), repeated over every
//! unit that closes at the same instant until none does (a Newton's cradle).
//!
//! This first slice offers the flow as a linear, second-order ODE, so the
//! numerical methods run it (Dormand-Prince, Stormer-Verlet, the linear
//! propagator), and [`modal`] gives the exact solution of the unconstrained
//! chain. An exact event-local propagation, resting contact and scenes are
//! still to come (issue 4).

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use crate::engine::{Direction, Flow, Guard, HybridModel, Jump, Mode};

/// The chain's parameters, in the scene units of PHYSICS.md s.4 or any.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
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
    guards: Vec<Guard>,
}

impl Chain {
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

    /// The chain of PHYSICS.md s.4's scene units: length `length`, wave
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
    /// length `2 l` is `critical_load / stiffness` (PHYSICS.md s.4).
    pub fn homogeneous(&self, strain: f64) -> Vec<f64> {
        let delta = strain * self.critical_load / self.stiffness;
        let positions = (1..=self.units).map(|n| delta * n as f64);
        positions
            .chain(std::iter::repeat_n(0.0, self.units))
            .collect()
    }

    /// Elongation of unit `n` (1-based) in state `x`.
    pub fn elongation(&self, x: &[f64], n: usize) -> f64 {
        x[n - 1] - if n > 1 { x[n - 2] } else { 0.0 }
    }

    /// Total linear momentum `sum m v`.
    pub fn momentum(&self, x: &[f64]) -> f64 {
        self.mass * x[self.units..].iter().sum::<f64>()
    }

    /// Resolve every collision at this instant: swap (or flip) the
    /// velocities of each closing unit's nodes until no unit closes. A unit
    /// takes part if it is shut to within a few ulps of its nodes' positions
    /// and closing.
    fn collide(&self, x: &mut [f64]) {
        let n = self.units;
        let window = 8.0 * f64::EPSILON;
        // Each pass fixes at least one closing pair; with equal masses the
        // swaps sort the velocities of a packed block, so N^2 passes bound it.
        for _ in 0..n * n + 1 {
            let mut changed = false;
            for unit in 1..=n {
                let gap = self.elongation(x, unit);
                let left = if unit > 1 { x[n + unit - 2] } else { 0.0 };
                let right = x[n + unit - 1];
                let closing = left - right;
                let scale = x[unit - 1]
                    .abs()
                    .max(if unit > 1 { x[unit - 2].abs() } else { 0.0 });
                if closing > 0.0 && gap <= window * scale {
                    if unit > 1 {
                        x.swap(n + unit - 2, n + unit - 1);
                    } else {
                        x[n] = -x[n];
                    }
                    changed = true;
                }
            }
            if !changed {
                return;
            }
        }
    }
}

impl HybridModel for Chain {
    fn dimension(&self) -> usize {
        2 * self.units
    }

    fn state_names(&self, _: Mode) -> &[&'static str] {
        // Nodes are many; the log names the two halves of the state.
        &[]
    }

    fn mode_name(&self, _: Mode) -> &'static str {
        "chain"
    }

    fn guards(&self, _: Mode) -> &[Guard] {
        &self.guards
    }

    fn guard(&self, _: Mode, guard: usize, x: &[f64]) -> f64 {
        self.elongation(x, guard + 1)
    }

    fn flow(&self, _: Mode) -> Flow {
        Flow::Ode
    }

    fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
        let n = self.units;
        let force = |unit: usize| self.critical_load + self.stiffness * self.elongation(x, unit);
        for node in 1..=n {
            dx[node - 1] = x[n + node - 1];
            let pull = if node < n { force(node + 1) } else { self.load };
            dx[n + node - 1] = (pull - force(node)) / self.mass;
        }
    }

    fn second_order(&self, _: Mode) -> bool {
        true
    }

    fn linear(&self, _: Mode) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let n = self.units;
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        let mut b = DVector::zeros(2 * n);
        let w = self.stiffness / self.mass;
        for node in 0..n {
            a[(node, n + node)] = 1.0;
            a[(n + node, node)] = if node + 1 < n { -2.0 * w } else { -w };
            if node > 0 {
                a[(n + node, node - 1)] = w;
            }
            if node + 1 < n {
                a[(n + node, node + 1)] = w;
            }
        }
        b[2 * n - 1] = (self.load - self.critical_load) / self.mass;
        Some((a, b))
    }

    fn reset(&self, mode: Mode, _: usize, x: &mut [f64]) -> Jump {
        self.collide(x);
        Jump::to(mode)
    }

    fn energy(&self, _: Mode, x: &[f64]) -> Option<f64> {
        let n = self.units;
        let kinetic: f64 = x[n..].iter().map(|v| 0.5 * self.mass * v * v).sum();
        let elastic: f64 = (1..=n)
            .map(|unit| {
                let d = self.elongation(x, unit);
                self.critical_load * d + 0.5 * self.stiffness * d * d
            })
            .sum();
        Some(kinetic + elastic - self.load * x[n - 1])
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        initial_energy.abs().max(f64::MIN_POSITIVE)
    }
}

/// The exact solution of the unconstrained chain, by its normal modes:
/// `M y'' = -K y + f` with `K` the fixed-free stiffness matrix, solved as
/// the static deflection plus independent oscillations of the modes.
pub fn modal(chain: &Chain, x0: &[f64], t: f64) -> Vec<f64> {
    let n = chain.units;
    let w = chain.stiffness / chain.mass;
    let mut k = DMatrix::zeros(n, n);
    for i in 0..n {
        k[(i, i)] = if i + 1 < n { 2.0 * w } else { w };
        if i + 1 < n {
            k[(i, i + 1)] = -w;
            k[(i + 1, i)] = -w;
        }
    }
    let mut f = DVector::zeros(n);
    f[n - 1] = (chain.load - chain.critical_load) / chain.mass;
    let eigen = SymmetricEigen::new(k);
    // Static deflection: K y_s = f, solved in the modal basis.
    let q = &eigen.eigenvectors;
    let fq = q.transpose() * f;
    let y0 = DVector::from_row_slice(&x0[..n]);
    let v0 = DVector::from_row_slice(&x0[n..]);
    let statics = fq.zip_map(&eigen.eigenvalues, |fi, l| fi / l);
    let a0 = q.transpose() * y0 - &statics;
    let b0 = q.transpose() * v0;
    let (mut position, mut velocity) = (DVector::zeros(n), DVector::zeros(n));
    for j in 0..n {
        let omega = eigen.eigenvalues[j].sqrt();
        let (s, c) = (omega * t).sin_cos();
        position[j] = statics[j] + a0[j] * c + b0[j] * s / omega;
        velocity[j] = -a0[j] * omega * s + b0[j] * c;
    }
    let y = q * position;
    let v = q * velocity;
    y.iter().chain(v.iter()).copied().collect()
}
