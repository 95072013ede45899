//! Sensitivities through flows and resets: a model and the derivatives of
//! its state with respect to chosen directions of its initial state,
//! carried together as one larger model that the engine runs as any other.
//!
//! The state is `[x; S_1; ...; S_m; tau_1; ...; tau_m]`: the model's state
//! `x` (`n` components), for each direction `j` the derivative `S_j` of `x`
//! along it (`S_j(0)` is the direction), and `tau_j`, the derivative of the
//! last event's time along it. A parameter is a direction once the model
//! holds it as a state that never changes ([`Family::promoted`]: an
//! automaton recompiles its definition, other models are rebuilt from the
//! parameters' values).
//!
//! - Along a flow, `S_j' = J(x) S_j` (the variational equations), with `J`
//!   the model's exact Jacobian where it gives one
//!   ([`HybridModel::jacobian`]), central differences otherwise; `tau`
//!   stands still.
//! - At an event of guard `g`, with `R` the reset's Jacobian and `f-`, `f+`
//!   the rates just before and after: `tau_j = -grad g . S_j / (grad g .
//!   f-)`, the event time's derivative, and `S_j <- R S_j - (f+ - R f-)
//!   tau_j`, the saltation matrix applied ([`saltation::matrix`], the one
//!   the error bounds use: docs/physics.md's impacts, and any reset: a
//!   change of mode, a restitution).
//!
//! A linear model stays linear (`[A, I (x) A]`), so the exact propagator
//! runs its sensitivities too; every method with a right-hand side does.
//!
//! [`Family::promoted`]: crate::engine::Family::promoted

use nalgebra::{DMatrix, DVector};

use crate::engine::bound::saltation;
use crate::engine::model::labels::Labels;
use crate::engine::model::names::Name;
use crate::engine::model::{Flow, Guard, HybridModel, Jump, Mode};
use crate::numerics::central_difference::step_for;

/// A model with the derivatives of its state along `m` directions.
#[derive(Debug)]
pub struct Variational<'m, M: HybridModel + ?Sized> {
    model: &'m M,
    n: usize,
    m: usize,
    /// Each mode's state names: the model's, then `d{x}/d{p}` for each
    /// direction `p`, then `dt/d{p}`.
    names: Vec<Vec<Name>>,
}

impl<'m, M: HybridModel + ?Sized> Variational<'m, M> {
    /// `model` with the derivatives along the directions named
    /// `directions` (for the state's names), over the modes `0..modes`.
    pub fn new(model: &'m M, modes: usize, directions: &[String]) -> Self {
        let n = model.dimension();
        let names = (0..modes)
            .map(|mode| {
                let base = model.state_names(mode);
                // A model that names no states (a chain's are many) names
                // none of their derivatives either: names and values are
                // paired in order, and a partial list would mislabel them.
                if base.is_empty() {
                    return Vec::new();
                }
                let mut names: Vec<Name> = base.to_vec();
                for p in directions {
                    names.extend(base.iter().map(|x| Name::from(format!("d{x}/d{p}"))));
                }
                names.extend(directions.iter().map(|p| Name::from(format!("dt/d{p}"))));
                names
            })
            .collect();
        Variational {
            model,
            n,
            m: directions.len(),
            names,
        }
    }

    /// The starting state: `x0` and the directions `s0` (each `n` long),
    /// no event yet.
    pub fn initial(&self, x0: &[f64], s0: &[Vec<f64>]) -> Vec<f64> {
        let mut x = x0.to_vec();
        for s in s0 {
            x.extend_from_slice(s);
        }
        x.extend(std::iter::repeat_n(0.0, self.m));
        x
    }

    /// The derivatives of the state along direction `j`, from a state of
    /// this model.
    pub fn sensitivity<'x>(&self, x: &'x [f64], j: usize) -> &'x [f64] {
        &x[self.n * (1 + j)..self.n * (2 + j)]
    }

    /// The derivative of the last event's time along direction `j`.
    pub fn event_time_sensitivity(&self, x: &[f64], j: usize) -> f64 {
        x[self.n * (1 + self.m) + j]
    }

    /// The model's Jacobian at `x` in `mode` (row-major `n x n`).
    fn jacobian(&self, mode: Mode, x: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut jac = vec![0.0; n * n];
        if self.model.jacobian(mode, x, &mut jac) {
            return jac;
        }
        let (mut y, mut up, mut down) = (x.to_vec(), vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let h = step_for(x[j]);
            y[j] = x[j] + h;
            self.model.rhs(mode, &y, &mut up);
            y[j] = x[j] - h;
            self.model.rhs(mode, &y, &mut down);
            y[j] = x[j];
            for i in 0..n {
                jac[i * n + j] = (up[i] - down[i]) / (2.0 * h);
            }
        }
        jac
    }

    /// The rate of the model's state at `x` in `mode` (zero if frozen).
    fn rate(&self, mode: Mode, x: &[f64]) -> Vec<f64> {
        let mut f = vec![0.0; self.n];
        if self.model.flow(mode) != Flow::Frozen {
            self.model.rhs(mode, x, &mut f);
        }
        f
    }
}

impl<M: HybridModel + ?Sized> HybridModel for Variational<'_, M> {
    fn dimension(&self) -> usize {
        self.n * (1 + self.m) + self.m
    }

    fn state_names(&self, mode: Mode) -> &[Name] {
        &self.names[mode]
    }

    fn mode_name(&self, mode: Mode) -> &str {
        self.model.mode_name(mode)
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        self.model.guards(mode)
    }

    fn guard(&self, mode: Mode, guard: usize, x: &[f64]) -> f64 {
        self.model.guard(mode, guard, &x[..self.n])
    }

    fn flow(&self, mode: Mode) -> Flow {
        match self.model.flow(mode) {
            Flow::Frozen => Flow::Frozen,
            _ => Flow::Ode,
        }
    }

    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) {
        let n = self.n;
        self.model.rhs(mode, &x[..n], &mut dx[..n]);
        let jac = self.jacobian(mode, &x[..n]);
        for j in 0..self.m {
            let s = &x[n * (1 + j)..n * (2 + j)];
            for i in 0..n {
                dx[n * (1 + j) + i] = (0..n).map(|k| jac[i * n + k] * s[k]).sum();
            }
        }
        dx[n * (1 + self.m)..].fill(0.0);
    }

    fn has_rhs(&self, mode: Mode) -> bool {
        self.model.has_rhs(mode)
    }

    fn is_linear(&self, mode: Mode) -> bool {
        self.model.is_linear(mode)
    }

    /// `[A, I (x) A]`: the sensitivities of a linear flow follow its
    /// matrix.
    fn linear(&self, mode: Mode) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let (a, b) = self.model.linear(mode)?;
        let (n, dim) = (self.n, self.dimension());
        let mut big = DMatrix::zeros(dim, dim);
        for block in 0..=self.m {
            big.view_mut((block * n, block * n), (n, n)).copy_from(&a);
        }
        let mut c = DVector::zeros(dim);
        c.rows_mut(0, n).copy_from(&b);
        Some((big, c))
    }

    fn reset(&self, mode: Mode, guard: usize, x: &mut [f64]) -> Jump {
        let (n, m) = (self.n, self.m);
        let before = x[..n].to_vec();
        // The guard's gradient and the reset's Jacobian: the model's exact
        // ones where it gives them, else central differences (exact for
        // affine guards and resets, to round-off; about 1e-10 otherwise).
        let mut gradient = vec![0.0; n];
        let mut reset = vec![0.0; n * n];
        let exact_gradient = self
            .model
            .guard_gradient(mode, guard, &before, &mut gradient);
        let exact_reset = self.model.reset_jacobian(mode, guard, &before, &mut reset);
        if !(exact_gradient && exact_reset) {
            let (mut up, mut down) = (before.clone(), before.clone());
            for k in 0..n {
                let h = step_for(before[k]);
                up.copy_from_slice(&before);
                up[k] += h;
                down.copy_from_slice(&before);
                down[k] -= h;
                if !exact_gradient {
                    gradient[k] = (self.model.guard(mode, guard, &up)
                        - self.model.guard(mode, guard, &down))
                        / (2.0 * h);
                }
                if !exact_reset {
                    self.model.reset(mode, guard, &mut up);
                    self.model.reset(mode, guard, &mut down);
                    for i in 0..n {
                        reset[i * n + k] = (up[i] - down[i]) / (2.0 * h);
                    }
                }
            }
        }
        let jump = self.model.reset(mode, guard, &mut x[..n]);
        let rate_before = self.rate(mode, &before);
        let rate_after = self.rate(jump.mode, &x[..n]);
        let mut salt = vec![0.0; n * n];
        let (closing, _) =
            saltation::matrix(&reset, &gradient, &rate_before, &rate_after, &mut salt);
        for j in 0..m {
            let s: Vec<f64> = x[n * (1 + j)..n * (2 + j)].to_vec();
            for i in 0..n {
                x[n * (1 + j) + i] = (0..n).map(|k| salt[i * n + k] * s[k]).sum();
            }
            x[n * (1 + m) + j] =
                -gradient.iter().zip(&s).map(|(g, v)| g * v).sum::<f64>() / closing;
        }
        jump
    }

    fn terminal(&self, mode: Mode, guard: usize) -> bool {
        self.model.terminal(mode, guard)
    }

    fn energy(&self, mode: Mode, x: &[f64]) -> Option<f64> {
        self.model.energy(mode, &x[..self.n])
    }

    fn resets_keep_energy(&self) -> bool {
        self.model.resets_keep_energy()
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        self.model.energy_scale(initial_energy)
    }

    fn labels(&self, mode: Mode, guard: usize, before: &[f64]) -> Labels {
        self.model.labels(mode, guard, &before[..self.n])
    }

    /// The model's own clock: its derivatives stay zero.
    fn clock(&self) -> Option<usize> {
        self.model.clock()
    }

    /// The error bound is the model's state's, not its derivatives'.
    fn bounded_dimension(&self) -> usize {
        self.n
    }

    fn may_be_undefined(&self) -> bool {
        self.model.may_be_undefined()
    }

    fn diagnose_guard(&self, mode: Mode, guard: usize, x: &[f64], reset: bool) -> Option<String> {
        self.model.diagnose_guard(mode, guard, &x[..self.n], reset)
    }

    fn diagnose(&self, mode: Mode, x: &[f64]) -> Option<String> {
        self.model.diagnose(mode, &x[..self.n])
    }
}
