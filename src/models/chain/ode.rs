//! The chain as a linear, second-order ODE in positions and velocities,
//! `[y_1..y_N, v_1..v_N]`: what Dormand-Prince, Stormer-Verlet and the
//! linear propagator integrate. Every step costs O(N) and every guard is
//! scanned on every step, so this path is for checking the exact one
//! ([`super::TaylorChain`]) and for small chains.

use nalgebra::{DMatrix, DVector};

use super::collide::{cascade, cascade_with};
use super::{Chain, impact_labels};
use crate::engine::{Flow, Guard, HybridModel, Jump, Labels, Mode, Name};

impl HybridModel for Chain {
    fn dimension(&self) -> usize {
        2 * self.units
    }

    fn state_names(&self, _: Mode) -> &[Name] {
        // Nodes are many; the log names the two halves of the state.
        &[]
    }

    fn mode_name(&self, _: Mode) -> &str {
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

    /// Linear springs between the shocks: known without the `2N x 2N`
    /// matrix.
    fn is_linear(&self, _: Mode) -> bool {
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
        let n = self.units;
        let mut v = Vec::with_capacity(n + 1);
        v.push(0.0);
        v.extend_from_slice(&x[n..]);
        let _ = cascade(1, &self.shut(x), &mut v);
        x[n..].copy_from_slice(&v[1..]);
        Jump::to(mode)
    }

    /// Positions stay; velocities are permuted and node 1's maybe
    /// flipped, as the cascade at `x` does: a signed permutation, exact.
    fn reset_jacobian(&self, _: Mode, _: usize, x: &[f64], out: &mut [f64]) -> bool {
        let n = self.units;
        let dim = 2 * n;
        // Which node's velocity (1-based, 0 the wall) each slot holds, and its sign.
        let mut from: Vec<(usize, f64)> = (0..=n).map(|k| (k, 1.0)).collect();
        let mut v = Vec::with_capacity(n + 1);
        v.push(0.0);
        v.extend_from_slice(&x[n..]);
        let _ = cascade_with(1, &self.shut(x), &mut v, |step| match step {
            Some(i) => from.swap(i, i + 1),
            None => from[1].1 = -from[1].1,
        });
        out[..dim * dim].fill(0.0);
        for i in 0..n {
            out[i * dim + i] = 1.0;
        }
        for slot in 1..=n {
            let (node, sign) = from[slot];
            if node > 0 {
                out[(n + slot - 1) * dim + n + node - 1] = sign;
            }
        }
        true
    }

    /// A unit's elongation `y_n - y_{n-1}`.
    fn guard_gradient(&self, _: Mode, guard: usize, _: &[f64], out: &mut [f64]) -> bool {
        out.fill(0.0);
        out[guard] = 1.0;
        if guard > 0 {
            out[guard - 1] = -1.0;
        }
        true
    }

    fn labels(&self, _: Mode, guard: usize, x: &[f64]) -> Labels {
        let n = self.units;
        let left = if guard > 0 { x[n + guard - 1] } else { 0.0 };
        impact_labels(guard + 1, Some(left - x[n + guard]))
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

impl Chain {
    /// Which units take part in an impact at `x`: those shut to within a
    /// few ulps of their nodes' positions (the cascade checks that they
    /// close).
    fn shut(&self, x: &[f64]) -> Vec<bool> {
        let window = 8.0 * f64::EPSILON;
        (1..=self.units)
            .map(|unit| {
                let scale = x[unit - 1]
                    .abs()
                    .max(if unit > 1 { x[unit - 2].abs() } else { 0.0 });
                self.elongation(x, unit) <= window * scale
            })
            .collect()
    }
}
