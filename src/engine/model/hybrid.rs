//! What a hybrid model tells the engine: its state, its modes, the flow in
//! each mode, its guards and its resets.
//!
//! A model is data plus a few pure functions; the [`simulate`] owns the
//! event queue, event location, the loop and the log. The required methods
//! are the minimum for a model with an ODE flow; everything else has a
//! default.
//!
//! [`simulate`]: crate::engine::simulate

use nalgebra::{DMatrix, DVector};

use crate::engine::model::affine_flow::AffineFlow;
use crate::engine::model::labels::Labels;
use crate::engine::model::names::Name;

/// Index of a discrete mode. Models name their modes with [`HybridModel::mode_name`].
pub type Mode = usize;

/// Which way a guard function must cross zero for its event to fire.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// From positive to negative (a gap closing).
    Falling,
    /// From negative to positive.
    Rising,
    /// Either way.
    Either,
}

impl Direction {
    /// Whether a change of the guard from `before` to `after` is a crossing
    /// this direction accepts. Landing exactly on zero counts.
    pub fn accepts(self, before: f64, after: f64) -> bool {
        match self {
            Direction::Falling => before > 0.0 && after <= 0.0,
            Direction::Rising => before < 0.0 && after >= 0.0,
            Direction::Either => (before > 0.0 && after <= 0.0) || (before < 0.0 && after >= 0.0),
        }
    }
}

/// A guard: a function of the state whose zero crossing fires an event.
///
/// A model's guards built from literals are a constant slice or a static
/// (`const WALL: &[Guard] = &[Guard::affine("wall", Direction::Falling)];`):
/// a guard owns its [`Name`], so a constant array of them cannot be
/// borrowed for longer than the function it is used in.
#[derive(Debug, Clone, PartialEq)]
pub struct Guard {
    /// Name used in the event log and the summary (`impact`, `bounce`...).
    pub name: Name,
    /// Which way the guard must cross zero to fire.
    pub direction: Direction,
    /// The guard is an affine function of the state. Along a polynomial
    /// interpolant it is then a polynomial of the same degree, whose roots
    /// the engine isolates exactly: no crossing inside a step can be missed.
    pub affine: bool,
    /// An internal switch (a change of chart) rather than a physical event:
    /// it is neither logged nor counted as an event.
    pub internal: bool,
    /// The guard bounds the state (an impact, a wall): the state must stay
    /// on the side the guard crosses from. After its reset, if the state is
    /// on zero and still moving through (resting contact), it fires again at
    /// once, which the Zeno watch then recognises. A guard that only marks a
    /// passage (a Poincare section, a threshold) is not a barrier: its reset
    /// may leave the state where it was, and it fires once per passage.
    pub barrier: bool,
}

impl Guard {
    /// An affine barrier guard: the common case (an impact).
    pub const fn affine(name: &'static str, direction: Direction) -> Self {
        Guard {
            name: Name::new(name),
            direction,
            affine: true,
            internal: false,
            barrier: true,
        }
    }

    /// Mark this guard as a passage marker rather than a barrier (see
    /// [`Guard::barrier`]).
    pub const fn as_crossing(mut self) -> Self {
        self.barrier = false;
        self
    }

    /// Mark this guard as an internal switch (see [`Guard::internal`]).
    pub const fn as_internal(mut self) -> Self {
        self.internal = true;
        self
    }
}

/// How the state evolves in a mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Flow {
    /// The model supplies the exact flow map ([`HybridModel::advance`]) and
    /// the exact next crossing of each guard ([`HybridModel::next_crossing`]).
    Exact,
    /// An ODE `x' = f(x)` ([`HybridModel::rhs`]) integrated numerically.
    Ode,
    /// The state does not change (resting contact, a stuck mode).
    Frozen,
}

/// Which guards a reset can change the predicted crossing of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Affects {
    /// Every guard of the new mode is re-predicted.
    All,
    /// Only guards `first..first + count` are re-predicted; the others keep
    /// their queued times (only meaningful for [`Flow::Exact`] modes).
    Range {
        /// The first guard re-predicted.
        first: usize,
        /// How many guards, from `first` on.
        count: usize,
    },
}

/// What a reset did: the mode after it, and which predictions it spoiled.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Jump {
    /// The mode after the reset.
    pub mode: Mode,
    /// Which guards' predictions the reset spoiled.
    pub affects: Affects,
    /// What the event is called in the log and the counts, where the
    /// reset names it otherwise than its guard (a switching surface
    /// reached: crossed, or slid on); `None` keeps the guard's name.
    pub event: Option<Name>,
    /// The guard of the new mode whose surface the state starts on, leaving
    /// it along the flow (a sliding that ends where the flow turns
    /// tangent): it neither fires there nor can be said to move its way,
    /// so it starts spent, and fires when the state comes back.
    pub leaves: Option<usize>,
}

impl Jump {
    /// Go to `mode` and re-predict every guard.
    pub fn to(mode: Mode) -> Self {
        Jump {
            mode,
            affects: Affects::All,
            event: None,
            leaves: None,
        }
    }

    /// The same, the event called `name` in the log.
    pub fn named(self, name: Name) -> Self {
        Jump {
            event: Some(name),
            ..self
        }
    }

    /// The same, the state leaving the surface of guard `guard` of the new
    /// mode (see [`Jump::leaves`]).
    pub fn leaving(self, guard: usize) -> Self {
        Jump {
            leaves: Some(guard),
            ..self
        }
    }
}

/// A hybrid automaton: modes with flows, guards and resets.
///
/// States are `&[f64]` of length [`dimension`](HybridModel::dimension); the
/// meaning of each component may differ from mode to mode (a chart switch
/// changes coordinates). Time is autonomous: flows depend on the elapsed
/// time `tau` since the last event, never on the absolute clock; a forced
/// model carries the clock as a state of rate one and names it
/// ([`clock`](HybridModel::clock)), which the engine keeps equal to the
/// run's own time.
pub trait HybridModel {
    /// Length of the continuous state.
    fn dimension(&self) -> usize;

    /// Names of the state components in `mode`, for logs and summaries
    /// (from literals: `names!["x", "v"]`).
    fn state_names(&self, mode: Mode) -> &[Name];

    /// Name of a mode, for logs and summaries.
    fn mode_name(&self, mode: Mode) -> &str;

    /// The guards active in `mode`; guard indices are positions in this slice.
    fn guards(&self, mode: Mode) -> &[Guard];

    /// The value of guard `guard` at state `x`.
    fn guard(&self, mode: Mode, guard: usize, x: &[f64]) -> f64;

    /// How the state moves in `mode`.
    fn flow(&self, mode: Mode) -> Flow;

    /// The right-hand side `dx = f(x)` of an [`Flow::Ode`] mode.
    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) {
        let _ = (x, dx);
        unreachable!("mode {} declares no ODE", self.mode_name(mode))
    }

    /// Whether [`rhs`](HybridModel::rhs) is implemented for `mode`, so that
    /// a numerical method can integrate it (also when its natural flow is
    /// exact, to compare methods).
    fn has_rhs(&self, mode: Mode) -> bool {
        self.flow(mode) == Flow::Ode
    }

    /// Whether the state in `mode` is `[q; v]` with `q' = v` and `v' = a(q)`
    /// independent of `v`: what Stormer-Verlet needs.
    fn second_order(&self, mode: Mode) -> bool {
        let _ = mode;
        false
    }

    /// Whether the model gives the Taylor series of its flow in `mode` and
    /// of its guards along it ([`flow_series`](HybridModel::flow_series),
    /// [`guard_series`](HybridModel::guard_series)): what Taylor's method
    /// needs.
    fn has_series(&self, mode: Mode) -> bool {
        let _ = mode;
        false
    }

    /// The normalised Taylor coefficients of orders `0..=order` of the flow
    /// from `x` in `mode`: `series[i * (order + 1) + k]` is `x_i^(k)(0) / k!`.
    fn flow_series(&self, mode: Mode, x: &[f64], order: usize, series: &mut [f64]) {
        let _ = (x, order, series);
        unreachable!("mode {} gives no Taylor series", self.mode_name(mode))
    }

    /// The Taylor coefficients of guard `guard` along a flow whose series
    /// is `series` (laid out as [`flow_series`](HybridModel::flow_series)
    /// writes it), into `out` (`order + 1` of them).
    fn guard_series(
        &self,
        mode: Mode,
        guard: usize,
        series: &[f64],
        order: usize,
        out: &mut [f64],
    ) {
        let _ = (guard, series, order, out);
        unreachable!("mode {} gives no Taylor series", self.mode_name(mode))
    }

    /// `(A, b)` if the flow in `mode` is linear, `x' = A x + b`: what the
    /// exact linear propagator needs.
    fn linear(&self, mode: Mode) -> Option<(DMatrix<f64>, DVector<f64>)> {
        let _ = mode;
        None
    }

    /// The Jacobian of the flow in `mode` in the state, where it is the same
    /// everywhere, its clock's column zero (the clock carries no error): a
    /// linear flow's `A`, or that of a linear flow driven by a function of
    /// time, `x' = A x + f(t)`. An error then moves by `exp(tau A)` over a
    /// stretch `tau`, exactly, wherever the state is.
    fn constant_jacobian(&self, mode: Mode) -> Option<DMatrix<f64>> {
        self.linear(mode).map(|(a, _)| a)
    }

    /// Whether the flow in `mode` is linear (what [`linear`](HybridModel::linear)
    /// says), without building its matrices: a model whose `A` is large
    /// answers cheaply.
    fn is_linear(&self, mode: Mode) -> bool {
        self.linear(mode).is_some()
    }

    /// The flow in `mode` as the exact linear propagator runs it: a linear
    /// flow (what [`linear`](HybridModel::linear) says), or one driven by
    /// sines of the clock as well ([`AffineFlow`]).
    fn affine_flow(&self, mode: Mode) -> Option<AffineFlow> {
        self.linear(mode).map(AffineFlow::linear)
    }

    /// Whether [`affine_flow`](HybridModel::affine_flow) is some, without
    /// building it.
    fn has_affine_flow(&self, mode: Mode) -> bool {
        self.is_linear(mode)
    }

    /// The exact flow map of a [`Flow::Exact`] mode: `x` is the state
    /// `tau >= 0` after `x0`.
    fn advance(&self, mode: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        let _ = (x0, tau, x);
        unreachable!("mode {} declares no exact flow", self.mode_name(mode))
    }

    /// The exact elapsed time from `x0` to the next crossing of `guard` in
    /// its direction, for [`Flow::Exact`] modes; `None` if it never crosses.
    /// `Some(0.0)` means `x0` is on the guard and moving through it now.
    fn next_crossing(&self, mode: Mode, guard: usize, x0: &[f64]) -> Option<f64> {
        let _ = (guard, x0);
        unreachable!("mode {} declares no exact crossings", self.mode_name(mode))
    }

    /// Apply the reset of `guard`, which has just fired at state `x`.
    fn reset(&self, mode: Mode, guard: usize, x: &mut [f64]) -> Jump;

    /// Whether the transition of `guard` in `mode` only marks a passage (a
    /// Poincare section, a threshold): it resets nothing (its reset's
    /// Jacobian is the identity) and stays in its mode, so its saltation
    /// is the identity. The run still goes on from the state it located,
    /// which is located as exactly as a reset's.
    fn marks_only(&self, mode: Mode, guard: usize) -> bool {
        let _ = (mode, guard);
        false
    }

    /// Whether the run ends at the event of `guard` in `mode` (status
    /// `completed`, at the event's time, in the state after its reset).
    fn terminal(&self, mode: Mode, guard: usize) -> bool {
        let _ = (mode, guard);
        false
    }

    /// Why a run that enters `mode` cannot go on, if it cannot: a mode
    /// that stands for an answer the model does not have (a switching
    /// surface both sides flow away from, where the solution is not
    /// unique). The run stops there, `failed`, with this reason.
    fn stop_reason(&self, mode: Mode) -> Option<String> {
        let _ = mode;
        None
    }

    /// The conserved (or monitored) energy at `x`, if the model has one.
    fn energy(&self, mode: Mode, x: &[f64]) -> Option<f64> {
        let _ = (mode, x);
        None
    }

    /// Whether every reset keeps the energy (an elastic impact, a change of
    /// chart). A model whose resets may change it (a restitution below
    /// one) says no: its energy is then audited along the flows, each
    /// reset's change, which the log shows, moving what it is held to.
    fn resets_keep_energy(&self) -> bool {
        true
    }

    /// The size of the numbers the model's exact flows
    /// ([`advance`](HybridModel::advance)) compute with, where it exceeds
    /// the state's own (0 otherwise): a closed form about a centre rounds
    /// to ulps of the centre, however small the state. The round-off
    /// allowance of a run by the closed forms is scaled by the larger of
    /// the two ([`bound`](crate::engine::bound)).
    fn exact_flow_scale(&self) -> f64 {
        0.0
    }

    /// The scale that relative energy errors are measured against, given
    /// the initial energy.
    fn energy_scale(&self, initial_energy: f64) -> f64 {
        initial_energy.abs()
    }

    /// Called when the events of one guard accumulate faster than the run
    /// can resolve (a Zeno point), with the state `x` in `mode` just after
    /// the last of them. A model that knows the limit (resting contact)
    /// writes its state into `x` and returns the mode to go on in; `None`
    /// ends the run there.
    fn settle(&self, mode: Mode, x: &mut [f64]) -> Option<Mode> {
        let _ = (mode, x);
        None
    }

    /// What to label the event of `guard` at state `before` with in the
    /// log (a chain's unit and the closing speed of an impact, say); none
    /// by default.
    fn labels(&self, mode: Mode, guard: usize, before: &[f64]) -> Labels {
        let _ = (mode, guard, before);
        Labels::NONE
    }

    /// The Jacobian of `mode`'s right-hand side at `x` into `jac`
    /// (row-major `n x n`), where the model knows it exactly; `false`, and
    /// the engine takes differences, where it does not.
    fn jacobian(&self, mode: Mode, x: &[f64], jac: &mut [f64]) -> bool {
        let _ = (mode, x, jac);
        false
    }

    /// The gradient of `guard` at `x` in `mode` into `out`, where the
    /// model knows it exactly; `false` (differences are taken) where not.
    fn guard_gradient(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        let _ = (mode, guard, x, out);
        false
    }

    /// The Jacobian of `guard`'s reset at `x` in `mode` into `out`
    /// (row-major `n x n`), where the model knows it exactly; `false`
    /// where not.
    fn reset_jacobian(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        let _ = (mode, guard, x, out);
        false
    }

    /// The state component that is the clock, if the model reads time (a
    /// forced system, whose clock is a state of rate one so that its flows
    /// stay autonomous). The engine writes its run's time into it, the
    /// clock's initial value added, wherever a stretch of flow starts, at
    /// every event (before and after the reset) and at the end: a clock
    /// integrated step by step would drift from the run's double-double
    /// time by a rounding per step.
    fn clock(&self) -> Option<usize> {
        None
    }

    /// How many leading components of the state the run's error bound is
    /// about (all, unless the state carries more than the model's own:
    /// the derivatives of [`crate::engine::bound::variational`], whose errors
    /// say nothing of where the events are).
    fn bounded_dimension(&self) -> usize {
        self.dimension()
    }

    /// Whether a guard or a reset may be undefined somewhere (a model read
    /// from a file, whose expressions may take a square root of a negative
    /// number): the run then checks every guard where each stretch of flow
    /// starts and ends, and stops at a value that is not finite.
    fn may_be_undefined(&self) -> bool {
        false
    }

    /// Which guard or reset value is not finite at `x` (the guard's slot,
    /// before the reset for a reset), in a sentence naming its expression.
    fn diagnose_guard(&self, mode: Mode, guard: usize, x: &[f64], reset: bool) -> Option<String> {
        let _ = (mode, guard, x, reset);
        None
    }

    /// A sentence explaining why a numerical flow may fail at `x`, added to
    /// the engine's own message (e.g. a coordinate singularity).
    fn diagnose(&self, mode: Mode, x: &[f64]) -> Option<String> {
        let _ = (mode, x);
        None
    }
}
