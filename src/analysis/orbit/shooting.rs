//! Newton shooting for a periodic orbit through a Poincare section: the
//! state `x` just after a section event with `P(x) = x` (plus whole
//! forcing periods on the clock, for a forced system), `P` the section map
//! of [`Section`].
//!
//! Each iteration solves `(DP - I) dx = -(P(x) - x)` on the free
//! components by least squares (SVD): a conservative system's orbits come
//! in families, along which `DP - I` is singular, and the step then keeps
//! to the other directions. An orbit is returned only verified: its
//! residual recomputed by a plain run (no derivatives) from the state found.

use nalgebra::{DMatrix, DVector};

use crate::analysis::orbit::section::{Return, Section};
use crate::engine::Mode;
use crate::engine::model::names::Name;

/// Newton iterations at most.
pub const MAX_ITERATIONS: usize = 30;

/// Where Newton stops: the residual below this fraction of the state's
/// size.
pub const TOLERANCE: f64 = 1e-12;

/// How far outside the unit circle a multiplier still counts as on it
/// (stable): multipliers read through difference Jacobians (guards and
/// resets that give none of their own, as the angle formulation's chart
/// changes) are good to about 1e-8, and a conservative orbit's sit on the
/// circle.
pub const ON_THE_CIRCLE: f64 = 1e-7;

/// What a search asks: the section guard, the events per period, a
/// transient to let die out first, and the period of a forcing (for an
/// automaton that reads the clock).
#[derive(Debug, Clone)]
pub struct OrbitRequest {
    /// The guard whose events are the section.
    pub guard: String,
    /// Section events per period.
    pub events: usize,
    /// Time run before the search starts from the next section event.
    pub settle: f64,
    /// The forcing's period, where the automaton reads the clock: the
    /// orbit's period is a whole number of them.
    pub forcing_period: Option<f64>,
    /// Set from outside (Ctrl-C) to end the search or the branch at the
    /// next return of the section map.
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// When the search or the branch must end (`--wall`): the run under
    /// way fails there, and the search or branch ends saying so.
    pub deadline: Option<std::time::Instant>,
}

/// A periodic orbit found (or why not).
#[derive(Debug, Clone, PartialEq)]
pub struct Orbit {
    /// Whether Newton converged and the plain run confirmed it.
    pub converged: bool,
    /// `converged`, or why not.
    pub status: String,
    /// The period.
    pub period: f64,
    /// Section events per period.
    pub events_per_period: usize,
    /// The mode just after the section event.
    pub mode: Name,
    /// The state just after the section event, by name.
    pub section_state: Vec<(Name, f64)>,
    /// The monodromy matrix's eigenvalues, `(re, im)`, saltation matrices
    /// included: first the trivial 1 of the flow's direction (or of the
    /// clock), then the others by decreasing modulus.
    pub multipliers: Vec<(f64, f64)>,
    /// Whether every multiplier but the trivial one lies within the unit
    /// circle (to [`ON_THE_CIRCLE`]).
    pub stable: bool,
    /// `|P(x) - x|` (on the free components) recomputed by a plain run.
    pub residual: f64,
    /// Newton iterations taken.
    pub iterations: usize,
    /// The residual at each iteration.
    pub residuals: Vec<f64>,
}

/// The search's unknowns and what closes the orbit.
#[derive(Debug, Clone)]
pub struct Unknowns {
    /// The components Newton moves (not the parameters held as states).
    pub free: Vec<usize>,
    /// The clock's component, and the forcing period its time closes on.
    pub clock: Option<(usize, f64)>,
}

impl Unknowns {
    /// `P(x) - x` on the free components, the clock closing on the
    /// nearest whole number (at least one) of forcing periods.
    pub fn residual(&self, x: &[f64], back: &[f64], elapsed: f64) -> DVector<f64> {
        DVector::from_iterator(
            self.free.len(),
            self.free.iter().map(|&i| {
                let shift = match self.clock {
                    Some((c, period)) if c == i => (elapsed / period).round().max(1.0) * period,
                    _ => 0.0,
                };
                back[i] - x[i] - shift
            }),
        )
    }

    /// The size residuals are measured against: the largest free
    /// component but the clock (whose time grows with every period), at
    /// least 1.
    pub fn scale(&self, x: &[f64]) -> f64 {
        let clock = self.clock.map(|(c, _)| c);
        self.free
            .iter()
            .filter(|&&i| Some(i) != clock)
            .fold(1.0_f64, |m, &i| m.max(x[i].abs()))
    }

    /// Bring the clock back into its first forcing period (the same
    /// forcing phase), so the states Newton sees keep their precision.
    pub fn fold_clock(&self, x: &mut [f64]) {
        if let Some((c, period)) = self.clock {
            x[c] = x[c].rem_euclid(period);
        }
    }

    /// `DP - I` on the free components.
    pub fn newton_matrix(&self, r: &Return) -> DMatrix<f64> {
        let k = self.free.len();
        DMatrix::from_fn(k, k, |a, b| {
            r.jacobian[(self.free[a], self.free[b])] - if a == b { 1.0 } else { 0.0 }
        })
    }
}

/// The largest component of `v`, relative to the state's size.
fn size(v: &DVector<f64>, unknowns: &Unknowns, x: &[f64]) -> f64 {
    v.amax() / unknowns.scale(x)
}

/// Relative size below which a singular value counts as zero.
const RANK_CUTOFF: f64 = 1e-10;

/// `a x = b` by least squares: directions `a` barely moves are left alone.
/// Also says whether there were such directions (`a` singular); `None`
/// where `a` is not finite or the SVD does not converge.
pub fn least_squares(a: &DMatrix<f64>, b: &DVector<f64>) -> Option<(DVector<f64>, bool)> {
    if !a.iter().chain(b.iter()).all(|v| v.is_finite()) {
        return None;
    }
    let svd = a.clone().try_svd(true, true, f64::EPSILON, 10_000)?;
    let cutoff = RANK_CUTOFF * svd.singular_values.max().max(f64::MIN_POSITIVE);
    let singular = svd.singular_values.iter().any(|&s| s <= cutoff);
    svd.solve(b, cutoff).ok().map(|x| (x, singular))
}

/// The orbit's multipliers on the free components, and whether it is
/// stable (all within the unit circle but the trivial one).
///
/// The monodromy matrix `M` has the trivial multiplier 1 along the flow
/// (or the clock), exactly; where the orbit is conservative a second 1
/// makes `M` a Jordan block, whose computed eigenvalues split by the
/// square root of its rounding (1e-8). The section map's Jacobian
/// `DP = M + f+ dtau^T` has the same eigenvalues but 0 in place of the
/// trivial one (`DP f = 0`): its eigenvalues, the one nearest 0 replaced by an
/// exact 1, are the multipliers, to round-off.
pub fn multipliers(r: &Return, unknowns: &Unknowns) -> (Vec<(f64, f64)>, bool) {
    let k = unknowns.free.len();
    let jacobian = DMatrix::from_fn(k, k, |a, b| {
        r.jacobian[(unknowns.free[a], unknowns.free[b])]
    });
    if !jacobian.iter().all(|v| v.is_finite()) {
        return (Vec::new(), false);
    }
    let mut eigen: Vec<(f64, f64)> = jacobian
        .complex_eigenvalues()
        .iter()
        .map(|z| (z.re, z.im))
        .collect();
    let trivial = eigen
        .iter()
        .enumerate()
        .min_by(|a, b| (a.1.0.hypot(a.1.1)).total_cmp(&b.1.0.hypot(b.1.1)))
        .map(|(i, _)| i);
    if let Some(i) = trivial {
        eigen.remove(i);
    }
    let stable = eigen.iter().all(|z| z.0.hypot(z.1) <= 1.0 + ON_THE_CIRCLE);
    eigen.sort_by(|a, b| (b.0.hypot(b.1)).total_cmp(&a.0.hypot(a.1)));
    eigen.insert(0, (1.0, 0.0));
    (eigen, stable)
}

/// Newton from `x` (just after a section event, in `mode`); `on_iteration`
/// hears each iteration's residual.
pub fn shoot(
    section: &Section,
    unknowns: &Unknowns,
    mode: Mode,
    x: Vec<f64>,
    on_iteration: &mut dyn FnMut(usize, f64),
) -> Orbit {
    let names = names(section, mode, x.len(), None);
    let mut x = x;
    unknowns.fold_clock(&mut x);
    let mut residuals = Vec::new();
    // Whether a Newton step met a rank-deficient matrix: said if Newton
    // then fails (an orbit in a family meets one at every step).
    let mut singular = false;
    let failed = |status: String, residuals: Vec<f64>, x: &[f64]| Orbit {
        converged: false,
        status,
        period: f64::NAN,
        events_per_period: section.events,
        mode: section.model.mode_name(mode).into(),
        section_state: names.iter().cloned().zip(x.iter().copied()).collect(),
        multipliers: Vec::new(),
        stable: false,
        residual: f64::NAN,
        iterations: residuals.len(),
        residuals,
    };
    for _ in 0..MAX_ITERATIONS {
        if let Some(why) = section.spent() {
            return failed(why, residuals, &x);
        }
        let back = match section.map(mode, &x) {
            Ok(back) => back,
            Err(why) => return failed(format!("the section map failed: {why}"), residuals, &x),
        };
        if !section.family.same_motion(mode, back.mode) {
            return failed(
                format!(
                    "the run returns to the section in mode `{}`, not `{}`: not an orbit of {} events",
                    section.model.mode_name(back.mode),
                    section.model.mode_name(mode),
                    section.events
                ),
                residuals,
                &x,
            );
        }
        let r = unknowns.residual(&x, &back.state, back.elapsed);
        let norm = size(&r, unknowns, &x);
        residuals.push(norm);
        on_iteration(residuals.len() - 1, norm);
        if norm <= TOLERANCE {
            return verified(section, unknowns, mode, &x, &back, residuals);
        }
        let a = unknowns.newton_matrix(&back);
        let Some((step, rank_deficient)) = least_squares(&a, &(-&r)) else {
            return failed(
                "the Newton matrix is not finite (a graze on the way round?)".into(),
                residuals,
                &x,
            );
        };
        singular |= rank_deficient;
        for (k, &i) in unknowns.free.iter().enumerate() {
            // A component the section pins (its row of `DP` is zero: a
            // sliding surface's state at a `leave`, the other state where
            // a side turns tangent) takes Newton's step for that row
            // exactly, `x_i = P(x)_i`: the least squares' rounding would
            // start the next return off the surface.
            if (0..back.jacobian.ncols()).all(|j| back.jacobian[(i, j)] == 0.0) {
                x[i] = back.state[i];
            } else {
                x[i] += step[k];
            }
        }
        unknowns.fold_clock(&mut x);
        if !x.iter().all(|v| v.is_finite()) {
            return failed(
                "the Newton step left the finite numbers".into(),
                residuals,
                &x,
            );
        }
    }
    let last = residuals.last().copied().unwrap_or(f64::NAN);
    let why = if singular {
        " (a singular Jacobian on the way: the orbit may be degenerate, or a family's)"
    } else {
        ""
    };
    failed(
        format!(
            "no orbit near the start: the residual is still {last:.2e} after {MAX_ITERATIONS} Newton iterations{why}"
        ),
        residuals,
        &x,
    )
}

/// The names of the `n` components of a state in `mode`: the model's,
/// else the family's (with `parameter`'s name at its component, for a
/// model that holds one as a state), else `x0`, `x1`, ... (a chain names
/// its nodes only for the tools).
pub(crate) fn names(
    section: &Section,
    mode: Mode,
    n: usize,
    parameter: Option<(usize, &str)>,
) -> Vec<Name> {
    let own = section.model.state_names(mode);
    if own.len() == n {
        return own.to_vec();
    }
    let mut listed = section.family.state_names();
    if let Some((p, name)) = parameter.filter(|_| listed.len() + 1 == n) {
        listed.insert(p, name.to_string());
    }
    if listed.len() == n {
        return listed.into_iter().map(Name::from).collect();
    }
    (0..n).map(|i| Name::from(format!("x{i}"))).collect()
}

/// The orbit at `x`, which Newton accepted: its period and multipliers
/// from `back`, its residual recomputed by a plain run.
fn verified(
    section: &Section,
    unknowns: &Unknowns,
    mode: Mode,
    x: &[f64],
    back: &Return,
    residuals: Vec<f64>,
) -> Orbit {
    let names = names(section, mode, x.len(), None);
    let (multipliers, stable) = multipliers(back, unknowns);
    let plain = section.plain(mode, x);
    let (converged, status, residual) = match plain {
        Ok((elapsed, _, state)) => {
            let r = unknowns.residual(x, &state, elapsed);
            let residual = size(&r, unknowns, x);
            if residual <= 1e3 * TOLERANCE {
                (true, "converged".to_string(), residual)
            } else {
                (
                    false,
                    format!(
                        "not verified: a plain run from the orbit found misses it by {residual:.2e}"
                    ),
                    residual,
                )
            }
        }
        Err(why) => (false, format!("not verified: {why}"), f64::NAN),
    };
    Orbit {
        converged,
        status,
        period: back.elapsed,
        events_per_period: section.events,
        mode: section.model.mode_name(mode).into(),
        section_state: names.iter().cloned().zip(x.iter().copied()).collect(),
        multipliers,
        stable,
        residual,
        iterations: residuals.len() - 1,
        residuals,
    }
}
