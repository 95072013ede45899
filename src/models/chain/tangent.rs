//! How fast the chain's round-off grows: a tangent vector carried beside
//! its exact flow, through every impact, and the run's horizon read off it.
//!
//! The exact flow rounds: about [`ROUNDOFF_ULPS`] ulps of the state at each
//! impact and each window's re-expansion. Between impacts such an error
//! moves with the free chain, which is linear and keeps its energy norm
//! (`sum u^2 + sum Delta^2`, the wall and the load's ghost doing no work on
//! a difference of states); an impact changes it by its saltation matrix
//! (an error `d` moves the impact by `d / closing speed`, which turns into
//! jumps of the velocities as large as the jump of the accelerations times
//! that), and slow impacts amplify. So the chain carries one tangent vector
//! `delta`, started generic: it grows as the leading Lyapunov vector does,
//! and every error the run has made since grows with it. The estimate is
//! `E <- E |delta+| / |delta-| + eps` at each impact (and the window's
//! rounding at each window): not a bound (one direction stands for all,
//! a simultaneous impact's other units are carried by their swaps alone),
//! but what the chain's ensembles measure, and the horizon is where it
//! reaches [`FRACTION`] of the state's scale (docs/physics.md s.7).
//!
//! `delta` needs a few digits, not the state's sixteen, and only its
//! direction: the free flow keeps its norm exactly, so the estimate grows
//! at impacts alone, by each impact's local change of the norm. Its series
//! are of order [`ORDER`] over windows of [`WINDOWS`] of the state's
//! (`theta = 0.105`: truncation `(2 theta)^3 / 3! ~ 2e-3`, in `delta`'s
//! direction, which its norm, taken in full and set to one at each window,
//! does not count), and an impact re-expands it over [`REACH`] units beyond
//! the units it touched (what it leaves out of the rest of the window is
//! below `(2 theta)^(2 REACH) / (2 REACH)! ~ 1e-4` of the jump). The
//! horizons of the release scenes moved by 3% from the state's own order
//! and reach to these; what this costs is in the chain bench
//! (`cargo bench --bench chain`).

use crate::engine::bound::ROUNDOFF_ULPS;
use crate::engine::bound::horizon::FRACTION;
use crate::time::Time;

use super::collide::Step;
use super::window_series::{Series, blocks};

/// The tangent's series order.
const ORDER: usize = 2;

/// Units beyond those an impact touched that it re-expands.
const REACH: usize = 2;

/// The state's windows in one of the tangent's.
const WINDOWS: usize = 3;

/// Nodes an impact's scratch holds on the stack (more in vectors).
const SHORT: usize = 8;

/// Units each way a series of order [`ORDER`] draws on.
const SPREAD: usize = ORDER.div_ceil(2);

/// The tangent vector, its norm, and the estimate it grows.
#[derive(Debug, Clone)]
pub(super) struct Tangent {
    units: usize,
    /// Series of `delta Delta_n` and `delta u_n`, as the state's (column
    /// `n` for index `n`), and the scaled time since the window start each
    /// begins at.
    series: Series,
    origin: Vec<f64>,
    /// An impact's window, re-expanded from its instant.
    scratch: Series,
    sweep: [Vec<f64>; 3],
    /// The first column of the scratch window, and the energy norm over
    /// the units about to be stored, as loaded.
    loaded: (usize, f64),
    /// Scratch for an impact: the nodes' velocities, their tangents and
    /// accelerations, as they were and permuted.
    nodes: [Vec<f64>; 5],
    /// `|delta|^2` in the energy norm as carried (1 after each window).
    norm2: f64,
    /// The state's window length, and how many of them the tangent's
    /// current window has seen end.
    window: f64,
    elapsed: usize,
    /// The error estimate, its growth at each rounding, where it reaches
    /// the horizon, and that place.
    estimate: f64,
    rounding: f64,
    scale: f64,
    limit: f64,
    horizon: Option<Time>,
}

/// The state at an impact that the saltation reads, after the reset (the
/// velocities before it are the cascade's steps undone): the gap of unit
/// `first + i` in `gap[i]`, the scaled velocity of node `first + i` in
/// `vel[i]` (node 0, the wall, is at rest), and `ghost`, the load's
/// constant gap beyond unit N.
pub(super) struct After<'a> {
    pub first: usize,
    pub gap: &'a [f64],
    pub vel: &'a [f64],
    pub ghost: f64,
}

impl Tangent {
    /// A generic tangent of unit norm for a chain of `units` whose state
    /// is of size `scale` (scaled gaps and velocities), its windows made of
    /// the state's, `window` long.
    pub fn new(units: usize, scale: f64, window: f64) -> Self {
        let mut series = Series::new(ORDER, units);
        // Generic and reproducible: a fixed sequence spread over [-1, 1].
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut draw = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        };
        for n in 1..=units {
            series.gap[n] = draw();
            series.vel[n] = draw();
        }
        let norm2: f64 = (1..=units)
            .map(|n| series.gap[n].powi(2) + series.vel[n].powi(2))
            .sum();
        let scale_by = norm2.sqrt().recip();
        for n in 1..=units {
            series.gap[n] *= scale_by;
            series.vel[n] *= scale_by;
        }
        series.expand(0.0, None);
        let rounding = ROUNDOFF_ULPS * f64::EPSILON * scale;
        Tangent {
            units,
            series,
            origin: vec![0.0; units + 2],
            scratch: Series::new(ORDER, 0),
            sweep: Default::default(),
            loaded: (1, 0.0),
            nodes: Default::default(),
            norm2: 1.0,
            window,
            elapsed: 0,
            estimate: rounding,
            rounding,
            scale,
            limit: FRACTION * scale,
            horizon: None,
        }
    }

    /// Where the estimate first reached [`FRACTION`] of the state's scale.
    pub fn horizon(&self) -> Option<Time> {
        self.horizon
    }

    /// The error estimate so far.
    pub fn estimate(&self) -> f64 {
        self.estimate
    }

    /// The units an impact that touched units `touched` re-expands, of a
    /// chain of `units`.
    pub fn reach(touched: std::ops::RangeInclusive<usize>, units: usize) -> (usize, usize) {
        (
            touched.start().saturating_sub(REACH).max(1),
            (touched.end() + REACH).min(units),
        )
    }

    /// The estimate grows by `growth` and a rounding at `t`, up to the
    /// state's scale: an error cannot outgrow the state's own range.
    fn grow(&mut self, growth: f64, t: Time) {
        if growth.is_finite() {
            self.estimate = (self.estimate * growth + self.rounding).min(self.scale);
        }
        // A state of no size has no horizon to reach.
        if self.horizon.is_none() && self.limit > 0.0 && !(self.estimate < self.limit) {
            self.horizon = Some(t);
        }
    }

    /// The state's window ends at `t`, a rounding of the state's: at the
    /// end of the tangent's too, re-expand every unit from there (the end
    /// block from `block`), with the norm taken in full and set to one.
    pub fn next_window(&mut self, block: Option<usize>, t: Time) {
        self.grow(1.0, t);
        self.elapsed += 1;
        if self.elapsed < WINDOWS {
            return;
        }
        self.elapsed = 0;
        let (n, span) = (self.units, WINDOWS as f64 * self.window);
        let [tau, gaps, vels] = &mut self.sweep;
        tau.clear();
        tau.extend(self.origin[1..=n].iter().map(|o| (span - o).max(0.0)));
        tau.resize(blocks(n), 0.0);
        gaps.resize(blocks(n), 0.0);
        vels.resize(blocks(n), 0.0);
        self.series.values(1, tau, gaps, vels);
        let norm2: f64 = (0..n).map(|i| gaps[i] * gaps[i] + vels[i] * vels[i]).sum();
        let scale_by = norm2.sqrt().recip();
        // A tangent that vanished or overflowed keeps its last direction.
        if scale_by.is_finite() && scale_by > 0.0 {
            for (row, values) in [
                (&mut self.series.gap, &gaps[..n]),
                (&mut self.series.vel, &vels[..n]),
            ] {
                for (x, v) in row[1..=n].iter_mut().zip(values) {
                    *x = v * scale_by;
                }
            }
            self.norm2 = 1.0;
        }
        self.origin.fill(0.0);
        self.series.expand(0.0, block);
    }

    /// The tangent's own time of the state's scaled time `sigma` in its
    /// window.
    fn since_start(&self, sigma: f64) -> f64 {
        self.elapsed as f64 * self.window + sigma
    }

    /// The tangent at scaled time `sigma` of units `lo - SPREAD..=hi +
    /// SPREAD` into the scratch window's order 0, before a change to units
    /// `lo..=hi` (those [`store`](Self::store) keeps).
    pub fn load(&mut self, lo: usize, hi: usize, sigma: f64) {
        let (n, sigma) = (self.units, self.since_start(sigma));
        let (w_lo, w_hi) = (lo.saturating_sub(SPREAD).max(1), (hi + SPREAD).min(n));
        let (origin, tau) = (&self.origin, &mut self.sweep[0]);
        self.series
            .load(&mut self.scratch, origin, (w_lo, w_hi), sigma, tau);
        let norm = self.norm_over(lo, hi, w_lo);
        self.loaded = (w_lo, norm);
    }

    /// `sum delta Delta^2 + delta u^2` over units `lo..=hi` of the scratch
    /// window from `w_lo`.
    fn norm_over(&self, lo: usize, hi: usize, w_lo: usize) -> f64 {
        let (gap, vel) = (&self.scratch.gap, &self.scratch.vel);
        (lo..=hi)
            .map(|i| gap[i + 1 - w_lo].powi(2) + vel[i + 1 - w_lo].powi(2))
            .sum()
    }

    /// The impact of unit `fired` (loaded), resolved by the cascade
    /// `steps` over the `len` node velocities from node `first_node` (a
    /// signed permutation `P` of them, see [`Step`]): the saltation matrix
    /// applied to the loaded tangent. `q = delta Delta_fired / g'` (`g'`
    /// the fired gap's rate) moves the impact in time, and `delta+ = P
    /// delta + (f+ - P f-) q`: the velocities take the jump of the
    /// accelerations (`Delta_(i+1) - Delta_i` at node `i`), each gap that
    /// of its rate `u_m - u_(m-1)`.
    pub fn collide(
        &mut self,
        fired: usize,
        (first_node, len): (usize, usize),
        steps: &[Step],
        state: &After,
    ) {
        let (n, w_lo) = (self.units, self.loaded.0);
        // No unit 0 (the wall is node 0), the ghost past unit N.
        let gap = |m: usize| match m {
            0 => 0.0,
            m if m > n => state.ghost,
            m => state.gap[m - state.first],
        };
        let after = |node: usize| {
            if node == 0 {
                0.0
            } else {
                state.vel[node - state.first]
            }
        };
        if let [step] = steps {
            // The common case, a lone unit: its two nodes swapped (or node
            // 1 flipped against the wall).
            return self.alone(
                fired,
                *step,
                (gap(fired - 1), gap(fired + 1)),
                after(fired - 1),
                after(fired),
            );
        }
        let nodes = first_node..first_node + len;
        let accel = |i: usize| if i == 0 { 0.0 } else { gap(i + 1) - gap(i) };
        // On the stack for a lone impact or a short cascade.
        let mut stack = [[0.0; SHORT]; 5];
        let [u, a, du, pu, pa] = if len <= SHORT {
            stack.each_mut().map(|x| &mut x[..len])
        } else {
            self.nodes.each_mut().map(|x| {
                x.resize(len, 0.0);
                &mut x[..]
            })
        };
        for (k, i) in nodes.clone().enumerate() {
            pu[k] = after(i);
            a[k] = accel(i);
            du[k] = if i == 0 {
                0.0
            } else {
                self.scratch.vel[i + 1 - w_lo]
            };
        }
        let step_on = |x: &mut [f64], step: Step| match step {
            Some(i) => x.swap(i, i + 1),
            None => x[1] = -x[1],
        };
        // The velocities before: the steps undone, last first (each is its
        // own inverse).
        u.copy_from_slice(pu);
        for &step in steps.iter().rev() {
            step_on(u, step);
        }
        pa.copy_from_slice(a);
        for &step in steps {
            step_on(pa, step);
            step_on(du, step);
        }
        let vel = |node: usize| {
            if nodes.contains(&node) {
                u[node - first_node]
            } else {
                after(node)
            }
        };
        let q = self.scratch.gap[fired + 1 - w_lo] / (vel(fired) - vel(fired - 1));
        for (k, node) in nodes.clone().enumerate().filter(|(_, node)| *node > 0) {
            self.scratch.vel[node + 1 - w_lo] = du[k] + (a[k] - pa[k]) * q;
        }
        // Node velocities before and after, outside the cascade unmoved.
        let speed = |v: &[f64], node: usize| {
            if nodes.contains(&node) {
                v[node - first_node]
            } else {
                after(node)
            }
        };
        for m in first_node.max(1)..=(first_node + len).min(n) {
            let rate = |v: &[f64]| speed(v, m) - speed(v, m - 1);
            self.scratch.gap[m + 1 - w_lo] += (rate(pu) - rate(u)) * q;
        }
    }

    /// [`collide`](Self::collide) for a lone unit `fired` whose nodes were
    /// swapped (`step` `Some`, or node 1 flipped: `None`), with the gaps on
    /// either side of it and the speeds of its nodes after the impact (its
    /// own gap is shut).
    fn alone(
        &mut self,
        fired: usize,
        step: Step,
        (left, right): (f64, f64),
        u_left: f64,
        u_right: f64,
    ) {
        let (n, w_lo) = (self.units, self.loaded.0);
        let col = |i: usize| i + 1 - w_lo;
        // Rates before, and accelerations of the two nodes (`Delta_(i+1) -
        // Delta_i`, the fired gap zero).
        let closing = match step {
            Some(_) => u_left - u_right,
            None => -u_right,
        };
        let q = self.scratch.gap[col(fired)] / closing;
        let (a_left, a_right) = (-left, right);
        match step {
            Some(_) => {
                let (du_left, du_right) = (
                    self.scratch.vel[col(fired - 1)],
                    self.scratch.vel[col(fired)],
                );
                if fired > 1 {
                    self.scratch.vel[col(fired - 1)] = du_right + (a_left - a_right) * q;
                }
                self.scratch.vel[col(fired)] = du_left + (a_right - a_left) * q;
                // The fired gap's rate reverses, its neighbours' take the
                // jump of the node they share (`-closing` each).
                self.scratch.gap[col(fired)] -= 2.0 * closing * q;
                if fired > 1 {
                    self.scratch.gap[col(fired - 1)] += closing * q;
                }
                if fired < n {
                    self.scratch.gap[col(fired + 1)] += closing * q;
                }
            }
            None => {
                let du = self.scratch.vel[col(1)];
                self.scratch.vel[col(1)] = -du + 2.0 * a_right * q;
                // Node 1's rate reverses: its gap's with it, the next
                // gap's the other way.
                self.scratch.gap[col(1)] -= 2.0 * closing * q;
                if n > 1 {
                    self.scratch.gap[col(2)] += 2.0 * closing * q;
                }
            }
        }
    }

    /// Keep the loaded window's units `lo..=hi` (after a change at scaled
    /// time `sigma`, at `t`): held to the end block from `block` (its gaps
    /// shut, its nodes at their mean speed, at rest if it reaches the
    /// wall), re-expanded, the norm's change added and the estimate grown.
    pub fn store(&mut self, lo: usize, hi: usize, sigma: f64, block: Option<usize>, t: Time) {
        let (n, (w_lo, before)) = (self.units, self.loaded);
        let sigma = self.since_start(sigma);
        let width = self.scratch.width() - 2;
        let reaches_end = w_lo + width - 1 == n;
        let block = block.filter(|_| reaches_end);
        if let Some(a) = block {
            let (gap, vel) = (&mut self.scratch.gap, &mut self.scratch.vel);
            let nodes = a.saturating_sub(1).max(w_lo)..=n;
            let mean = if a == 1 {
                0.0
            } else {
                nodes.clone().map(|i| vel[i + 1 - w_lo]).sum::<f64>() / nodes.clone().count() as f64
            };
            for i in nodes {
                vel[i + 1 - w_lo] = mean;
            }
            for i in a.max(w_lo)..=n {
                gap[i + 1 - w_lo] = 0.0;
            }
        }
        let after = self.norm_over(lo, hi, w_lo);
        let norm2 = (self.norm2 + after - before).max(0.0);
        let growth = (norm2 / self.norm2).sqrt();
        self.norm2 = norm2;
        self.scratch
            .expand(0.0, block.map(|a| a.max(w_lo) + 1 - w_lo));
        self.series
            .copy_columns(&self.scratch, lo + 1 - w_lo, lo, hi - lo + 1);
        self.origin[lo..=hi].fill(sigma);
        self.grow(growth, t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::bound::saltation;
    use crate::engine::bound::tangent::guard_gradient;
    use crate::engine::{HybridModel, Mode};
    use crate::models::chain::Chain;
    use crate::models::chain::collide::cascade_with;

    /// The tangent of `units` at scaled time 0: its order-0 row.
    fn loaded(tangent: &mut Tangent, units: usize) -> (Vec<f64>, Vec<f64>) {
        tangent.load(1, units, 0.0);
        let w_lo = tangent.loaded.0;
        let column = |row: &[f64], i: usize| row[i + 1 - w_lo];
        (1..=units)
            .map(|i| {
                (
                    column(&tangent.scratch.gap, i),
                    column(&tangent.scratch.vel, i),
                )
            })
            .unzip()
    }

    #[test]
    fn an_impact_maps_the_tangent_by_the_engines_saltation_matrix() {
        // Four units under a load (a ghost beyond the end), unit 3
        // closing: the tangent after the impact against the saltation
        // matrix the engine builds from the chain as an ODE (positions and
        // velocities: ode.rs), in the tangent's gaps and scaled speeds.
        let units = 4;
        let chain = Chain::in_scene_units(units, 2.0, 1.0, 0.5, true);
        let omega = (chain.stiffness / chain.mass).sqrt();
        let ghost = (chain.load - chain.critical_load) / chain.stiffness;
        // A lone unit, node 1 at the wall, and a cascade (node 1 into the
        // shut units 2 and 3: three swaps), each resolved as the chain's
        // impact resolves it.
        for (fired, gaps, speeds) in [
            (3, [0.3, 0.2, 0.0, 0.1], [0.4, 0.9, -0.2, 0.1]),
            (1, [0.0, 0.25, 0.1, 0.05], [-0.7, 0.3, 0.1, -0.4]),
            (2, [0.3, 0.0, 0.0, 0.1], [0.9, 0.2, -0.1, 0.05]),
        ] {
            let mut tangent = Tangent::new(units, 1.0, 0.035);
            let (d_gap, d_vel) = loaded(&mut tangent, units);
            // Node velocities after the reset from node 0, unit gaps from
            // unit 0 (zero).
            let (mut gap, mut vel) = (vec![0.0], vec![0.0]);
            gap.extend(gaps);
            vel.extend(speeds.map(|v| v / omega));
            let shut: Vec<bool> = gaps.iter().map(|&g| g == 0.0).collect();
            let mut steps = Vec::new();
            let (touched, _) = cascade_with(1, &shut, &mut vel, |s| steps.push(s));
            let touched = touched.unwrap();
            let first = touched.start() - 1;
            for s in &mut steps {
                *s = s.map(|i| i - first);
            }
            let nodes = (first, touched.end() + 1 - first);
            let after = After {
                first: 0,
                gap: &gap,
                vel: &vel,
                ghost,
            };
            tangent.collide(fired, nodes, &steps, &after);
            let w_lo = tangent.loaded.0;
            let after: Vec<f64> = (1..=units)
                .map(|i| tangent.scratch.gap[i + 1 - w_lo])
                .chain((1..=units).map(|i| tangent.scratch.vel[i + 1 - w_lo]))
                .collect();
            // The engine's S, in positions y_n = sum of gaps and speeds.
            let mut x: Vec<f64> = gaps
                .iter()
                .scan(0.0, |y, d| {
                    *y += d;
                    Some(*y)
                })
                .collect();
            x.extend(speeds);
            let (n, mode) = (2 * units, 0 as Mode);
            let mut reset = vec![0.0; n * n];
            assert!(chain.reset_jacobian(mode, fired - 1, &x, &mut reset));
            let (mut gradient, mut probe) = (vec![0.0; n], vec![0.0; n]);
            guard_gradient(&chain, mode, fired - 1, &x, &mut gradient, &mut probe);
            let (mut rate_before, mut rate_after, mut x_after) =
                (vec![0.0; n], vec![0.0; n], x.clone());
            chain.rhs(mode, &x, &mut rate_before);
            chain.reset(mode, fired - 1, &mut x_after);
            chain.rhs(mode, &x_after, &mut rate_after);
            let mut s = vec![0.0; n * n];
            saltation::matrix(&reset, &gradient, &rate_before, &rate_after, &mut s);
            let mut d: Vec<f64> = d_gap
                .iter()
                .scan(0.0, |y, g| {
                    *y += g;
                    Some(*y)
                })
                .collect();
            d.extend(d_vel.iter().map(|u| u * omega));
            let mapped: Vec<f64> = (0..n)
                .map(|i| (0..n).map(|j| s[i * n + j] * d[j]).sum())
                .collect();
            let expected: Vec<f64> = (0..units)
                .map(|i| mapped[i] - if i > 0 { mapped[i - 1] } else { 0.0 })
                .chain(mapped[units..].iter().map(|v| v / omega))
                .collect();
            for (k, (a, e)) in after.iter().zip(&expected).enumerate() {
                assert!(
                    (a - e).abs() < 1e-12 * e.abs().max(1.0),
                    "unit {fired}, {k}: {a} vs {e}"
                );
            }
            // More than the swap alone: the impact's shift in time moved
            // the gaps beside it and the velocities.
            let mut swapped: Vec<f64> = d_gap.iter().chain(&d_vel).copied().collect();
            for step in &steps {
                // Node `first + i` is at `units + first + i - 1`.
                match step {
                    Some(i) => swapped.swap(units + first + i - 1, units + first + i),
                    None => swapped[units] = -swapped[units],
                }
            }
            let shift = after
                .iter()
                .zip(&swapped)
                .fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()));
            assert!(shift > 0.01, "unit {fired}: {shift}");
        }
    }

    #[test]
    fn the_free_flow_keeps_the_energy_norm_and_the_estimate_only_sums_roundings() {
        // No impact: window after window the norm stays one (to the series'
        // truncation), and the estimate grows by a rounding each.
        let units = 40;
        let mut tangent = Tangent::new(units, 1.0, 0.035);
        let start = tangent.estimate();
        for k in 1..=200 {
            tangent.next_window(None, Time::new(k as f64));
        }
        let rounding = ROUNDOFF_ULPS * f64::EPSILON;
        let grown = tangent.estimate() - start;
        assert!(
            (grown - 200.0 * rounding).abs() < 1e-12 * grown,
            "{grown:e}"
        );
        assert_eq!(tangent.horizon(), None);
    }
}
