//! A model built from parameter values, with those parameters held as
//! states that never change: `[x; p]`. The model at `p` is rebuilt for
//! every evaluation (cheap for a model that is a handful of numbers, as
//! the mechanism and the chain are), so a tool can move `p` with the state
//! (continuation) or carry derivatives along it (sensitivities).
//!
//! What does not depend on `p` (names, guards, the kind of flow) is the
//! base model's. The model's exact reset Jacobians and guard gradients are
//! passed on (their columns along `p` by differences); its flow's Jacobian
//! and linear form are not (the variational equations take differences,
//! and the exact linear propagator does not run it), nor its Taylor series.

use crate::engine::model::labels::Labels;
use crate::engine::model::names::Name;
use crate::engine::model::{Flow, Guard, HybridModel, Jump, Mode};
use crate::numerics::central_difference::step_for;

/// `base`'s structure, with its numbers from `build(p)`.
pub struct WithParameters<M, F> {
    base: M,
    build: F,
    n: usize,
    /// How many parameters.
    p: usize,
    /// Each mode's state names, then the parameters'.
    names: Vec<Vec<Name>>,
}

impl<M: HybridModel, F: Fn(&[f64]) -> M> WithParameters<M, F> {
    /// `base` over its modes `0..modes`, the parameters `parameters` held
    /// as states, the model at their values built by `build`.
    pub fn new(base: M, modes: usize, parameters: &[String], build: F) -> Self {
        let names = (0..modes)
            .map(|mode| {
                // A model that names no states (a chain's are many) names
                // no parameters either.
                let mut names = base.state_names(mode).to_vec();
                if !names.is_empty() {
                    names.extend(parameters.iter().map(|p| Name::from(p.as_str())));
                }
                names
            })
            .collect();
        WithParameters {
            n: base.dimension(),
            p: parameters.len(),
            base,
            build,
            names,
        }
    }

    fn at(&self, x: &[f64]) -> M {
        (self.build)(&x[self.n..])
    }
}

/// The positions in `known` of the parameters `names`, each known and
/// named once; a refusal names the one at fault.
pub fn positions(names: &[String], known: &[&str]) -> Result<Vec<usize>, String> {
    let mut which = Vec::new();
    for name in names {
        let k = known.iter().position(|p| p == name).ok_or_else(|| {
            format!(
                "no parameter is called `{name}` (parameters: {})",
                known.join(", ")
            )
        })?;
        if which.contains(&k) {
            return Err(format!("`{name}` is named twice"));
        }
        which.push(k);
    }
    Ok(which)
}

impl<M, F> std::fmt::Debug for WithParameters<M, F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WithParameters")
            .field("n", &self.n)
            .finish()
    }
}

impl<M: HybridModel, F: Fn(&[f64]) -> M> HybridModel for WithParameters<M, F> {
    fn dimension(&self) -> usize {
        self.n + self.p
    }

    fn state_names(&self, mode: Mode) -> &[Name] {
        &self.names[mode]
    }

    fn mode_name(&self, mode: Mode) -> &str {
        self.base.mode_name(mode)
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        self.base.guards(mode)
    }

    fn guard(&self, mode: Mode, guard: usize, x: &[f64]) -> f64 {
        self.at(x).guard(mode, guard, &x[..self.n])
    }

    fn flow(&self, mode: Mode) -> Flow {
        self.base.flow(mode)
    }

    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) {
        self.at(x).rhs(mode, &x[..self.n], &mut dx[..self.n]);
        dx[self.n..].fill(0.0);
    }

    fn has_rhs(&self, mode: Mode) -> bool {
        self.base.has_rhs(mode)
    }

    fn advance(&self, mode: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        self.at(x0)
            .advance(mode, &x0[..self.n], tau, &mut x[..self.n]);
        x[self.n..].copy_from_slice(&x0[self.n..]);
    }

    fn next_crossing(&self, mode: Mode, guard: usize, x0: &[f64]) -> Option<f64> {
        self.at(x0).next_crossing(mode, guard, &x0[..self.n])
    }

    fn reset(&self, mode: Mode, guard: usize, x: &mut [f64]) -> Jump {
        let model = self.at(x);
        model.reset(mode, guard, &mut x[..self.n])
    }

    fn terminal(&self, mode: Mode, guard: usize) -> bool {
        self.base.terminal(mode, guard)
    }

    fn stop_reason(&self, mode: Mode) -> Option<String> {
        self.base.stop_reason(mode)
    }

    fn energy(&self, mode: Mode, x: &[f64]) -> Option<f64> {
        self.at(x).energy(mode, &x[..self.n])
    }

    fn resets_keep_energy(&self) -> bool {
        self.base.resets_keep_energy()
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        self.base.energy_scale(initial_energy)
    }

    fn settle(&self, mode: Mode, x: &mut [f64]) -> Option<Mode> {
        let model = self.at(x);
        model.settle(mode, &mut x[..self.n])
    }

    fn labels(&self, mode: Mode, guard: usize, before: &[f64]) -> Labels {
        self.at(before).labels(mode, guard, &before[..self.n])
    }

    /// The model's exact reset Jacobian where it gives one, its columns
    /// along the parameters by central differences (a reset that reads
    /// no parameter gives zeros there).
    fn reset_jacobian(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        let (n, dim) = (self.n, self.n + self.p);
        let mut own = vec![0.0; n * n];
        if !self.at(x).reset_jacobian(mode, guard, &x[..n], &mut own) {
            return false;
        }
        out[..dim * dim].fill(0.0);
        for i in 0..n {
            out[i * dim..i * dim + n].copy_from_slice(&own[i * n..(i + 1) * n]);
        }
        for k in n..dim {
            out[k * dim + k] = 1.0;
            let h = step_for(x[k]);
            let (mut up, mut down) = (x.to_vec(), x.to_vec());
            up[k] += h;
            down[k] -= h;
            self.reset(mode, guard, &mut up);
            self.reset(mode, guard, &mut down);
            for i in 0..n {
                out[i * dim + k] = (up[i] - down[i]) / (2.0 * h);
            }
        }
        true
    }

    /// The model's exact guard gradient where it gives one, its entries
    /// along the parameters by central differences.
    fn guard_gradient(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        let n = self.n;
        if !self
            .at(x)
            .guard_gradient(mode, guard, &x[..n], &mut out[..n])
        {
            return false;
        }
        for k in n..n + self.p {
            let h = step_for(x[k]);
            let (mut up, mut down) = (x.to_vec(), x.to_vec());
            up[k] += h;
            down[k] -= h;
            out[k] = (self.guard(mode, guard, &up) - self.guard(mode, guard, &down)) / (2.0 * h);
        }
        true
    }

    fn clock(&self) -> Option<usize> {
        self.base.clock()
    }

    fn bounded_dimension(&self) -> usize {
        self.n
    }

    fn may_be_undefined(&self) -> bool {
        self.base.may_be_undefined()
    }

    fn diagnose(&self, mode: Mode, x: &[f64]) -> Option<String> {
        self.at(x).diagnose(mode, &x[..self.n])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{Direction, Options, simulate};
    use crate::names;

    /// `x' = -k x` from 1, a marker at `x = 1/2`: with `k` a state.
    struct Decay(f64);
    const HALF: &[Guard] = &[Guard::affine("half", Direction::Falling).as_crossing()];

    impl HybridModel for Decay {
        fn dimension(&self) -> usize {
            1
        }
        fn state_names(&self, _: Mode) -> &[Name] {
            names!["x"]
        }
        fn mode_name(&self, _: Mode) -> &str {
            "decay"
        }
        fn guards(&self, _: Mode) -> &[Guard] {
            HALF
        }
        fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
            x[0] - 0.5
        }
        fn flow(&self, _: Mode) -> Flow {
            Flow::Ode
        }
        fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
            dx[0] = -self.0 * x[0];
        }
        fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump {
            Jump::to(mode)
        }
    }

    #[test]
    fn the_parameter_rides_along_and_sets_the_flow() {
        let model = WithParameters::new(Decay(1.0), 1, &["k".to_string()], |p: &[f64]| Decay(p[0]));
        assert_eq!(model.dimension(), 2);
        assert_eq!(model.state_names(0), ["x", "k"]);
        let out = simulate(&model, 0, &[1.0, 3.0], &Options::until(1.0), &mut ());
        assert_eq!(out.events, 1);
        assert_eq!(out.final_state[1], 3.0);
        assert!((out.final_state[0] - (-3.0f64).exp()).abs() < 1e-9);
    }
}
