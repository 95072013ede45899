//! The chain's exact, event-local flow: Taylor series in short windows,
//! with a certified truncation and a certified reach of each impact.
//!
//! In scaled time `sigma = omega t` (`omega^2 = k / m`) and scaled velocity
//! `u = v / omega`, the free chain is
//! `Delta_n' = u_n - u_{n-1}` (`u_0 = 0`, the wall) and
//! `u_n' = Delta_{n+1} - Delta_n` (`Delta_{N+1} = (F - F_cr) / k`, a constant
//! ghost that carries the end load). Its Taylor coefficients follow from
//! the state by the same two differences, `c_{k+1} = (difference of c_k) /
//! (k + 1)`, so every coefficient of order `k` is at most `2^k / k!` times
//! the largest state component `S`.
//!
//! Time is cut into windows of `sigma`-length [`WINDOW`]. At each window
//! start (an internal guard) every unit is expanded to order `K`, the
//! smallest with `(2 theta)^(K+1) / (K+1)! < 2^-60` (theta = the window):
//! the truncation error is below `2^-60 S`, far under round-off. Each
//! unit's gap is then a polynomial on the window, and its next impact the
//! first falling root of it ([`search_fall`]), found by certified bounds, so
//! none is missed and all come in strict time order through the engine's
//! queue.
//!
//! The series are stored coefficient-major ([`Series`]), so the window
//! start's evaluation, recursion and proof that a gap cannot fall through
//! zero before the window ends (it stays above zero, or starts at or above
//! zero and rises all along) each run along rows of all units at once. Most
//! gaps are so proven; the engine then drops their guards without a search
//! ([`LocalModel::quiet`]).
//!
//! An impact at unit `j` changes the velocities of nodes `j - 1` and `j`
//! only. A unit or node `d` places beyond them first feels that change in
//! its coefficient of order `2d` (along a single path, `theta^(2d) / (2d)!`
//! times the jump); pushing the jump through the recursion with absolute
//! values bounds every later order too, and orders past the series' own
//! by `2^k / k!`. Units within the reach `D` (the smallest `d` bringing the
//! whole bound over the rest of the window under `2^-60`, tabled by eighths
//! of the window and rounded up) are re-expanded from the impact's instant
//! (each keeps its own clock, the time its series starts at), the rest keep
//! their series, which are still exact to below round-off. So an impact
//! costs O(K D) whatever N is, and only the `2D + 1` guards within the
//! reach are re-predicted (those proven open to the window's end at once).
//!
//! Resting contact (docs/physics.md s.4): a shut unit is pushed shut only at
//! the loaded end with `F < F_cr` (inside, `Delta_n'' = omega^2 (Delta_{n+1} +
//! Delta_{n-1}) >= 0` at a shut unit), so units resting shut form one end block
//! `a..=N` whose nodes `a - 1..=N` move as a rigid body; the series recursion
//! gives them the block's acceleration. Its contact force is least in unit `a`;
//! a `release` guard watches it and frees unit `a` when it would pull. An
//! impact reaching the block breaks it up, and the end may come to rest again
//! at once; units chattering shut at the end faster than the run can resolve
//! are settled into it when the engine's Zeno watch asks. Contact forces within
//! round-off of zero count as zero both ways, so a unit on the edge is neither
//! captured nor released over and over.

use crate::engine::bound::ROUNDOFF_ULPS;
use crate::engine::{Accuracy, Direction, ErrorEstimate, Fired, Guard, Labels, LocalModel};
use crate::numerics::first_crossing::{integral, search_fall};
use crate::time::Time;

use super::collide::{Step, alone, cascade_with};
use super::tangent::{After, Tangent};
use super::window_series::{MAX_COLUMN, Series, blocks};
use super::{Chain, impact_labels};

/// Window length in scaled time `omega t`: longer windows mean fewer full
/// re-expansions but longer series and a wider reach per impact.
pub const WINDOW: f64 = 0.035;

/// Spans of the rest of a window the reach is tabled for: an impact late in
/// a window reaches less far before the next re-expansion.
const REACH_STEPS: usize = 8;

/// Truncation and reach bounds are below this fraction of the state scale.
const CERTIFIED: f64 = 1.0 / (1u64 << 60) as f64;

/// The chain with its exact event-local flow.
#[derive(Debug, Clone)]
pub struct TaylorChain {
    /// The chain's parameters.
    pub chain: Chain,
    /// Series order `K`.
    order: usize,
    /// Reach `D` of an impact, in units each way, by what is left of the
    /// window: entry `j` holds for up to `(j + 1) / REACH_STEPS` of it.
    reaches: [usize; REACH_STEPS],
    /// Units each way that a series of order `K` draws on: `ceil(K / 2)`.
    spread: usize,
    omega: f64,
    /// `(F - F_cr) / k`: the ghost elongation beyond the loaded end.
    ghost: f64,
    /// Start of the current window.
    start: Time,
    /// Window length in time.
    span: f64,
    /// Per index `0..=N+1` (1..N used): the scaled time since `start` at
    /// which its series begins (its clock).
    origin: Vec<f64>,
    /// Series of gaps `Delta_n` and scaled velocities `u_n`, column `n`
    /// for index `n` (0 the wall, N + 1 the ghost).
    series: Series,
    /// Per unit, whether its gap is proven open from its series' start to
    /// the window's end (set whenever the series is): most units are, and
    /// their predictions cost nothing.
    open: Vec<bool>,
    guards: Vec<Guard>,
    /// A gap this close to zero counts as shut in a simultaneous impact.
    shut_below: f64,
    /// The series of an impact's reach, re-expanded from its instant.
    scratch: Series,
    /// Where each series is evaluated (its own time since its origin), and
    /// the gaps and velocities there, per column: a window's end, or the
    /// instant of an impact.
    sweep: [Vec<f64>; 3],
    /// The cascade's view of an impact's reach: which units are shut, and
    /// the node velocities (kept to spare an allocation per impact).
    scratch_shut: Vec<bool>,
    scratch_nodes: Vec<f64>,
    /// `integral of Delta_1 d sigma` over finished series of unit 1, and
    /// the impulses the wall gave: the wall's side of the momentum balance.
    wall_integral: f64,
    wall_impulse: f64,
    momentum_initial: f64,
    /// First unit of the end block in resting contact, if any: units
    /// `a..=N` shut, nodes `a - 1..=N` moving as one (at rest with the wall
    /// if `a` is 1).
    block: Option<usize>,
    /// Since when the whole chain rests shut against the wall (block from
    /// unit 1), whose contact force then balances the end load.
    held_since: Option<Time>,
    /// A tangent vector carried through the impacts: how fast round-off
    /// grows, and the horizon (with the constraint on; a free chain's
    /// errors do not grow).
    tangent: Option<Tangent>,
    /// Windows and impacts so far: the rounding a free chain's estimate
    /// sums.
    roundings: u64,
    /// The state's scale (scaled gaps and velocities).
    scale: f64,
    /// An impact's cascade, step by step.
    steps: Vec<Step>,
}

/// Guard name of an impact (with `rel_velocity` 0: a unit coming to rest
/// shut, in resting contact).
pub const IMPACT: &str = "impact";

/// Guard name of the end of resting contact: the end block's first unit
/// is pulled open.
pub const RELEASE: &str = "release";

impl TaylorChain {
    /// The chain starting with unit gaps `gaps` (elongations `Delta_n`) and
    /// node velocities `velocities`, both of length N.
    pub fn new(chain: Chain, gaps: &[f64], velocities: &[f64]) -> Result<Self, String> {
        let n = chain.units;
        if n == 0 {
            return Err("a chain needs at least one unit".into());
        }
        if gaps.len() != n || velocities.len() != n {
            return Err(format!(
                "{} gaps and {} velocities given for {n} units",
                gaps.len(),
                velocities.len()
            ));
        }
        for (name, x) in [
            ("mass", chain.mass),
            ("stiffness", chain.stiffness),
            ("critical load", chain.critical_load),
        ] {
            if !(x.is_finite() && x > 0.0) {
                return Err(format!("the {name} must be positive and finite, not {x}"));
            }
        }
        if !chain.load.is_finite() || gaps.iter().chain(velocities).any(|x| !x.is_finite()) {
            return Err("the load and the initial state must be finite".into());
        }
        if chain.constraint && gaps.iter().any(|&d| d < 0.0) {
            return Err(
                "a unit starts with a negative gap (strain below zero) while the constraint is on"
                    .into(),
            );
        }
        let order = order_for(WINDOW);
        let reaches =
            std::array::from_fn(|j| reach_for(WINDOW * (j + 1) as f64 / REACH_STEPS as f64, order));
        let omega = (chain.stiffness / chain.mass).sqrt();
        let ghost = (chain.load - chain.critical_load) / chain.stiffness;
        let mut guards = if chain.constraint {
            let mut impacts = vec![Guard::affine(IMPACT, Direction::Falling); n];
            impacts.push(Guard::affine(RELEASE, Direction::Falling).as_crossing());
            impacts
        } else {
            Vec::new()
        };
        guards.push(Guard::affine("window", Direction::Falling).as_internal());
        let scale = gaps
            .iter()
            .map(|d| d.abs())
            .chain(velocities.iter().map(|v| (v / omega).abs()))
            .fold(ghost.abs(), f64::max);
        let mut model = TaylorChain {
            order,
            reaches,
            spread: order.div_ceil(2),
            omega,
            ghost,
            start: Time::new(0.0),
            span: WINDOW / omega,
            origin: vec![0.0; n + 2],
            series: Series::new(order, n),
            open: vec![false; n + 2],
            guards,
            shut_below: 16.0 * f64::EPSILON * scale,
            scratch: Series::new(order, 0),
            sweep: Default::default(),
            scratch_shut: Vec::new(),
            scratch_nodes: Vec::new(),
            wall_integral: 0.0,
            wall_impulse: 0.0,
            momentum_initial: chain.mass * velocities.iter().sum::<f64>(),
            block: None,
            held_since: None,
            tangent: chain.constraint.then(|| Tangent::new(n, scale, WINDOW)),
            roundings: 0,
            scale,
            steps: Vec::new(),
            chain,
        };
        model.series.gap[1..=n].copy_from_slice(gaps);
        for (u, v) in model.series.vel[1..=n].iter_mut().zip(velocities) {
            *u = v / omega;
        }
        model.series.expand(ghost, None);
        model.series.open_over(1, WINDOW, &mut model.open[1..=n]);
        Ok(model)
    }

    /// Series order and reach of an impact (units each way), for reports.
    pub fn order_and_reach(&self) -> (usize, usize) {
        (self.order, self.reaches[REACH_STEPS - 1])
    }

    /// Scaled time of `t` since the window start.
    fn sigma(&self, t: Time) -> f64 {
        self.omega * t.since(self.start)
    }

    /// `(Delta_n, u_n)` of index `n` at scaled time `sigma` in the window.
    fn state(&self, n: usize, sigma: f64) -> (f64, f64) {
        let tau = (sigma - self.origin[n]).max(0.0);
        let s = &self.series;
        (s.value(&s.gap, n, tau), s.value(&s.vel, n, tau))
    }

    /// `integral of Delta_1 d sigma` over the first `tau` of unit 1's series.
    fn wall_area(&self, tau: f64) -> f64 {
        integral(self.gap_series(1, &mut [0.0; MAX_COLUMN]), tau)
    }

    /// The gap series of unit `n`, into `out`.
    fn gap_series<'o>(&self, n: usize, out: &'o mut [f64; MAX_COLUMN]) -> &'o [f64] {
        self.series.column(&self.series.gap, n, out)
    }

    /// Unit gaps `Delta_n` and node velocities `v_n` at `t` (not before the
    /// last event).
    pub fn state_at(&self, t: Time) -> (Vec<f64>, Vec<f64>) {
        let sigma = self.sigma(t);
        (1..=self.chain.units)
            .map(|n| {
                let (d, u) = self.state(n, sigma);
                (d, u * self.omega)
            })
            .unzip()
    }

    /// Total momentum `sum m v` at `t`.
    pub fn momentum(&self, t: Time) -> f64 {
        let sigma = self.sigma(t);
        let sum: f64 = (1..=self.chain.units).map(|n| self.state(n, sigma).1).sum();
        self.chain.mass * self.omega * sum
    }

    /// The loaded end's displacement `y_N = sum Delta_n` at `t`.
    pub fn right_end(&self, t: Time) -> f64 {
        let sigma = self.sigma(t);
        (1..=self.chain.units).map(|n| self.state(n, sigma).0).sum()
    }

    /// What the momentum at `t` should be by the impulse balance: the
    /// initial momentum plus the end load's and the wall's impulses,
    /// `P(0) + (F - F_cr) t - k integral(Delta_1) + wall impacts`. The
    /// difference from [`momentum`](Self::momentum) is the balance error.
    pub fn momentum_by_impulses(&self, t: Time) -> f64 {
        let c = &self.chain;
        let tau = (self.sigma(t) - self.origin[1]).max(0.0);
        let area = (self.wall_integral + self.wall_area(tau)) / self.omega;
        let held = self
            .held_since
            .map_or(0.0, |since| (c.critical_load - c.load) * t.since(since));
        self.momentum_initial + (c.load - c.critical_load) * t.value() - c.stiffness * area
            + self.wall_impulse
            + held
    }

    /// When `series`, which starts on unit `unit`'s clock, first falls
    /// through zero at or after `now` within the window. The search skips
    /// `first_fall`'s cheap bound: for a gap it is the open proof, which
    /// has failed when a gap is searched, and the release is rare.
    fn first_root(&self, unit: usize, series: &[f64], now: Time) -> Result<Option<Time>, String> {
        let origin = self.origin[unit];
        // An impact tied with the window's end may start a series a hair
        // past it; the time of a root may round to before `now`.
        let end = (WINDOW - origin).max(0.0);
        let from = (self.sigma(now) - origin).clamp(0.0, end);
        let root = search_fall(series, from, end).map_err(|why| format!("unit {unit}: {why}"))?;
        Ok(root.map(|tau| {
            let t = self.start.after((origin + tau) / self.omega);
            if t < now { now } else { t }
        }))
    }

    /// Re-expand every unit at the end of the window and start the next.
    fn next_window(&mut self) {
        let n = self.chain.units;
        self.wall_integral += self.wall_area(WINDOW - self.origin[1]);
        let [tau, gaps, vels] = &mut self.sweep;
        tau.clear();
        tau.extend(self.origin[1..=n].iter().map(|o| (WINDOW - o).max(0.0)));
        tau.resize(blocks(n), 0.0);
        gaps.resize(blocks(n), 0.0);
        vels.resize(blocks(n), 0.0);
        self.series.values(1, tau, gaps, vels);
        self.series.gap[1..=n].copy_from_slice(&gaps[..n]);
        self.series.vel[1..=n].copy_from_slice(&vels[..n]);
        self.origin.fill(0.0);
        self.series.expand(self.ghost, self.block);
        self.series.open_over(1, WINDOW, &mut self.open[1..=n]);
        self.start = self.start.after(self.span);
        self.roundings += 1;
        if let Some(tangent) = &mut self.tangent {
            tangent.next_window(self.block, self.start);
        }
    }

    /// Resolve the impact of unit `unit` at `t` and re-expand the units
    /// within reach of every velocity it changed.
    fn impact(&mut self, unit: usize, t: Time) -> Fired {
        let n = self.chain.units;
        let sigma = self.sigma(t);
        let (mut lo, mut hi) = (unit, unit);
        self.roundings += 1;
        loop {
            let (r_lo, r_hi) = self.reach_around(lo, hi, sigma);
            let w_lo = self.load_window(r_lo, r_hi, sigma);
            self.steps.clear();
            // Column of index i in the scratch series; node 0 (the wall)
            // reads zero there.
            let col = |i: usize| i + 1 - w_lo;
            let u_at = |node: usize, v: &[f64]| if node == 0 { 0.0 } else { v[col(node)] };
            let rel_velocity =
                self.omega * (u_at(unit - 1, &self.scratch.vel) - u_at(unit, &self.scratch.vel));
            // Not closing after all (a graze within round-off, or a unit
            // coming to rest shut) changes no velocity, but the unit is
            // still re-expanded from here with its gap clamped to zero, so
            // that its series agrees with the state it was found in.
            let others_shut = (r_lo..=r_hi).fold(false, |any, i| {
                any | ((i != unit) & (self.scratch.gap[col(i)] <= self.shut_below))
            });
            let (touched, wall) = if others_shut {
                let mut shut = std::mem::take(&mut self.scratch_shut);
                shut.clear();
                shut.extend(
                    (r_lo..=r_hi).map(|i| i == unit || self.scratch.gap[col(i)] <= self.shut_below),
                );
                let mut v = std::mem::take(&mut self.scratch_nodes);
                v.clear();
                v.extend((r_lo - 1..=r_hi).map(|i| u_at(i, &self.scratch.vel)));
                let steps = &mut self.steps;
                let (touched, wall) = cascade_with(r_lo, &shut, &mut v, |step| steps.push(step));
                self.scratch_shut = shut;
                if let Some(touched) = touched.as_ref()
                    && (*touched.start() < lo || *touched.end() > hi)
                {
                    self.scratch_nodes = v;
                    // A packed block passed the impact on: widen the reach
                    // and start again from the state before it.
                    lo = lo.min(*touched.start());
                    hi = hi.max(*touched.end());
                    continue;
                }
                for (k, node) in (r_lo - 1..=r_hi).enumerate().filter(|(_, node)| *node > 0) {
                    self.scratch.vel[col(node)] = v[k];
                }
                self.scratch_nodes = v;
                (touched, wall)
            } else {
                // The common case, a unit closing between open ones: the
                // cascade's first pass, without its bookkeeping.
                let nodes = [
                    u_at(unit - 1, &self.scratch.vel),
                    u_at(unit, &self.scratch.vel),
                ];
                match alone(unit, nodes) {
                    Some([left, right]) => {
                        self.steps.push(if unit == 1 { None } else { Some(0) });
                        if unit > 1 {
                            self.scratch.vel[col(unit - 1)] = left;
                        }
                        self.scratch.vel[col(unit)] = right;
                        let wall = if unit == 1 { right - nodes[1] } else { 0.0 };
                        (Some(unit..=unit), wall)
                    }
                    None => (None, 0.0),
                }
            };
            let touched = touched.unwrap_or(unit..=unit);
            // Momentum the wall gave (flips of node 1 only).
            self.wall_impulse += self.chain.mass * self.omega * wall;
            for i in touched.clone().chain(std::iter::once(unit)) {
                let g = &mut self.scratch.gap[col(i)];
                // Shut means zero: drop the round-off overlap.
                *g = g.max(0.0);
            }
            // A collision with the resting end block breaks it up; the end
            // may come to rest again at once.
            if self.block.is_some_and(|a| *touched.end() + 1 >= a) {
                self.set_block(None, t);
            }
            if r_hi == n {
                self.settle_end(r_lo, w_lo, t, self.shut_below);
            }
            self.store_window(r_lo, r_hi, w_lo, sigma);
            // The tangent moves where the velocities did: the steps, taken
            // over the cascade's nodes from `r_lo - 1` (or the lone
            // unit's two), counted from the first touched node.
            let first = touched.start() - 1;
            let offset = if others_shut {
                first + 1 - r_lo
            } else {
                first + 1 - unit
            };
            for step in self.steps.iter_mut() {
                *step = step.map(|i| i - offset);
            }
            let fired =
                (!self.steps.is_empty()).then_some((unit, (first, touched.end() + 1 - first)));
            // Its own reach around them (see `tangent`), or the state's
            // where that reaches the end block (which may have changed).
            if r_hi == n {
                self.carry_tangent(fired, (r_lo, r_hi), (w_lo, sigma), t);
            } else if fired.is_some() {
                let reach = Tangent::reach(touched.clone(), n);
                self.carry_tangent(fired, reach, (w_lo, sigma), t);
            }
            return Fired {
                affects: self.guards_of(r_lo, r_hi),
                labels: impact_labels(unit, Some(rel_velocity)),
            };
        }
    }

    /// Carry the tangent over a change to units `r_lo..=r_hi` at `sigma`
    /// (at `t`; the state's window from `w_lo`, after the reset): the
    /// impact of `unit`, if its cascade moved velocities (`self.steps`,
    /// over `nodes`: the first and how many); then held to the end block
    /// as it now is.
    fn carry_tangent(
        &mut self,
        fired: Option<(usize, (usize, usize))>,
        (r_lo, r_hi): (usize, usize),
        (w_lo, sigma): (usize, f64),
        t: Time,
    ) {
        let Some(tangent) = &mut self.tangent else {
            return;
        };
        tangent.load(r_lo, r_hi, sigma);
        if let Some((unit, nodes)) = fired {
            let after = After {
                first: w_lo,
                gap: &self.scratch.gap[1..],
                vel: &self.scratch.vel[1..],
                ghost: self.ghost,
            };
            tangent.collide(unit, nodes, &self.steps, &after);
        }
        tangent.store(r_lo, r_hi, sigma, self.block, t);
    }

    /// The end block's first unit is pulled open: the block shrinks by it.
    fn release(&mut self, t: Time) -> Fired {
        let n = self.chain.units;
        let a = self
            .block
            .expect("the release guard is predicted only with a block");
        let sigma = self.sigma(t);
        self.set_block((a < n).then_some(a + 1), t);
        let (r_lo, r_hi) = self.reach_around(a.saturating_sub(1).max(1), n, sigma);
        let w_lo = self.load_window(r_lo, r_hi, sigma);
        self.store_window(r_lo, r_hi, w_lo, sigma);
        self.carry_tangent(None, (r_lo, r_hi), (w_lo, sigma), t);
        Fired {
            affects: self.guards_of(r_lo, r_hi),
            labels: impact_labels(a, None),
        }
    }

    /// The reach of a change at `sigma`, for the rest of the window: the
    /// entry for the shortest tabled span at least as long (rounding up).
    fn reach_at(&self, sigma: f64) -> usize {
        let left = (WINDOW - sigma).max(0.0) / WINDOW * (1.0 + 1e-12);
        let j = (left * REACH_STEPS as f64).ceil() as usize;
        self.reaches[j.clamp(1, REACH_STEPS) - 1]
    }

    /// Units `lo - D ..= hi + D` (`D` the reach at `sigma`), and the whole
    /// end block with the node on its left if the window their series draw
    /// on (the spread beyond) comes to it: a rigid block passes a change on
    /// at once, and the free recursion must not be run across it.
    fn reach_around(&self, lo: usize, hi: usize, sigma: f64) -> (usize, usize) {
        let (n, reach) = (self.chain.units, self.reach_at(sigma));
        let (r_lo, r_hi) = (lo.saturating_sub(reach).max(1), (hi + reach).min(n));
        match self.block {
            Some(a) if r_hi + self.spread + 1 >= a => (r_lo.min(a.saturating_sub(1).max(1)), n),
            _ => (r_lo, r_hi),
        }
    }

    /// The state at `sigma` of the units within the series' spread of
    /// `r_lo..=r_hi`, into the scratch series' order 0 (column 1 is unit
    /// `w_lo`); returns `w_lo`.
    fn load_window(&mut self, r_lo: usize, r_hi: usize, sigma: f64) -> usize {
        let n = self.chain.units;
        let (w_lo, w_hi) = (
            r_lo.saturating_sub(self.spread).max(1),
            (r_hi + self.spread).min(n),
        );
        let (origin, tau) = (&self.origin, &mut self.sweep[0]);
        self.series
            .load(&mut self.scratch, origin, (w_lo, w_hi), sigma, tau);
        w_lo
    }

    /// Expand the scratch window and keep the series of `r_lo..=r_hi`,
    /// which start at `sigma`.
    fn store_window(&mut self, r_lo: usize, r_hi: usize, w_lo: usize, sigma: f64) {
        let n = self.chain.units;
        let reaches_end = w_lo + self.scratch.width() - 3 == n;
        let ghost = if reaches_end { self.ghost } else { 0.0 };
        let block = self.block.filter(|_| reaches_end).map(|a| a + 1 - w_lo);
        self.scratch.expand(ghost, block);
        if r_lo == 1 {
            // The wall force's integral so far on unit 1's series, before
            // the series is replaced.
            self.wall_integral += self.wall_area(sigma - self.origin[1]);
        }
        let count = r_hi - r_lo + 1;
        self.series
            .copy_columns(&self.scratch, r_lo + 1 - w_lo, r_lo, count);
        self.origin[r_lo..=r_hi].fill(sigma);
        let span = (WINDOW - sigma).max(0.0);
        let open = &mut self.open[r_lo..=r_hi];
        self.scratch.open_over(r_lo + 1 - w_lo, span, open);
    }

    /// The guards whose predictions a change to units `r_lo..=r_hi` moves:
    /// their impacts, and the release if the change reaches the end.
    fn guards_of(&self, r_lo: usize, r_hi: usize) -> std::ops::Range<usize> {
        let n = self.chain.units;
        r_lo - 1..if r_hi == n { n + 1 } else { r_hi }
    }

    /// If units at the loaded end are shut, at no relative speed, and
    /// pushed shut (docs/physics.md s.4: resting contact), make them the end
    /// block: their nodes then move as one. Works on the scratch window
    /// (order 0), which reaches the end; the block stays inside
    /// `r_lo + 1..` (or starts at the wall) so that it is re-expanded.
    ///
    /// Only the end can be pushed shut: an interior shut unit is pulled
    /// open by its neighbours' tension. With the block `a..=N`, the contact
    /// force is least in unit `a`, and positive while
    /// `(N - a + 1) Delta_{a-1} < (F_cr - F) / k`.
    fn settle_end(&mut self, r_lo: usize, w_lo: usize, t: Time, speeds: f64) -> bool {
        let n = self.chain.units;
        if self.block.is_some() || self.ghost >= 0.0 {
            return false;
        }
        let gap = |i: usize, g: &[f64]| g[i + 1 - w_lo];
        let node = |i: usize, v: &[f64]| if i == 0 { 0.0 } else { v[i + 1 - w_lo] };
        let floor = if r_lo == 1 { 1 } else { r_lo + 1 };
        let mut a = n + 1;
        while a > floor {
            let unit = a - 1;
            let resting = gap(unit, &self.scratch.gap) <= self.shut_below
                && (node(unit - 1, &self.scratch.vel) - node(unit, &self.scratch.vel)).abs()
                    <= speeds;
            if !resting {
                break;
            }
            a = unit;
        }
        // Longest block first; if its first unit is clearly pulled (beyond
        // round-off, the same margin the release keeps), the rest is pushed.
        if a >= 2
            && a <= n
            && (n - a + 1) as f64 * gap(a - 1, &self.scratch.gap) + self.ghost > self.force_noise(a)
        {
            a += 1;
        }
        if a > n {
            return false;
        }
        // Shut exactly, and one velocity: their mean, which keeps the
        // momentum (the speeds differ by round-off only); at rest against
        // the wall if the block reaches it.
        let nodes = a - 1..=n;
        let mean = if a == 1 {
            0.0
        } else {
            nodes
                .clone()
                .map(|i| node(i, &self.scratch.vel))
                .sum::<f64>()
                / (n - a + 2) as f64
        };
        for i in a..=n {
            self.scratch.gap[i + 1 - w_lo] = 0.0;
        }
        let mut removed = 0.0;
        for i in nodes.filter(|&i| i > 0) {
            let v = &mut self.scratch.vel[i + 1 - w_lo];
            removed += *v - mean;
            *v = mean;
        }
        // What the wall took when the block stopped against it.
        self.wall_impulse -= self.chain.mass * self.omega * removed;
        self.set_block(Some(a), t);
        true
    }

    /// Round-off in the contact force of a block from unit `a` (scaled, as
    /// the gaps): forces within it count as zero, so that a unit whose force
    /// reads about zero is neither captured nor released over and over.
    fn force_noise(&self, a: usize) -> f64 {
        self.shut_below * (self.chain.units - a + 2) as f64
    }

    /// Units chattering shut at the end faster than the run can resolve
    /// (the engine's Zeno watch): rest them in the end block, their nodes'
    /// speeds merged (momentum kept, the tiny kinetic energy of their
    /// relative motion lost), if the end pushes them shut.
    fn settle_chatter(&mut self, unit: usize, t: Time) -> Option<Fired> {
        let n = self.chain.units;
        let sigma = self.sigma(t);
        let far = unit + self.reach_at(sigma) < n;
        if self.block.is_some_and(|a| unit + 1 < a) || self.block.is_none() && far {
            return None;
        }
        self.set_block(None, t);
        let (r_lo, r_hi) = self.reach_around(unit, n, sigma);
        let w_lo = self.load_window(r_lo, r_hi, sigma);
        if !self.settle_end(r_lo, w_lo, t, f64::INFINITY) {
            return None;
        }
        self.store_window(r_lo, r_hi, w_lo, sigma);
        self.carry_tangent(None, (r_lo, r_hi), (w_lo, sigma), t);
        Some(Fired {
            affects: self.guards_of(r_lo, r_hi),
            labels: impact_labels(unit, None),
        })
    }

    /// Change the end block, keeping the account of the wall's hold.
    fn set_block(&mut self, block: Option<usize>, t: Time) {
        let c = &self.chain;
        if let Some(since) = self.held_since.take() {
            self.wall_impulse += (c.critical_load - c.load) * t.since(since);
        }
        if block == Some(1) {
            self.held_since = Some(t);
        }
        self.block = block;
    }
}

impl LocalModel for TaylorChain {
    fn mode_name(&self) -> &'static str {
        "chain"
    }

    fn guards(&self) -> &[Guard] {
        &self.guards
    }

    fn predict(&self, guard: usize, now: Time) -> Result<Option<Time>, String> {
        let n = self.chain.units;
        if guard + 1 == self.guards.len() {
            return Ok(Some(self.start.after(self.span)));
        }
        if guard == n {
            // The release watches the end block's least contact force,
            // `(F_cr - F) / k - (N - a + 1) Delta_{a-1}`, through the gap
            // left of it.
            let Some(a) = self.block.filter(|&a| a >= 2) else {
                return Ok(None);
            };
            let scale = (n - a + 1) as f64;
            let mut force = [0.0; MAX_COLUMN];
            let len = self.gap_series(a - 1, &mut force).len();
            for f in &mut force[..len] {
                *f *= -scale;
            }
            // Released once the force is clearly below zero.
            force[0] -= self.ghost - self.force_noise(a);
            return self.first_root(a - 1, &force[..len], now);
        }
        if self.block.is_some_and(|a| guard + 1 >= a) {
            // Resting in the end block: no impact until it is released.
            return Ok(None);
        }
        let unit = guard + 1;
        if self.open[unit] {
            return Ok(None);
        }
        let mut series = [0.0; MAX_COLUMN];
        let series = self.gap_series(unit, &mut series);
        self.first_root(unit, series, now)
    }

    fn quiet(&self, guard: usize) -> bool {
        // Impact guards exist only with the constraint on.
        self.chain.constraint && guard < self.chain.units && self.open[guard + 1]
    }

    fn fire(&mut self, guard: usize, t: Time) -> Result<Fired, String> {
        if guard + 1 == self.guards.len() {
            self.next_window();
            return Ok(Fired {
                affects: 0..self.guards.len(),
                labels: Labels::NONE,
            });
        }
        if guard == self.chain.units {
            return Ok(self.release(t));
        }
        Ok(self.impact(guard + 1, t))
    }

    fn horizon(&self) -> Option<Time> {
        self.tangent.as_ref().and_then(Tangent::horizon)
    }

    fn accuracy(&self) -> Accuracy {
        let rounding = ROUNDOFF_ULPS * f64::EPSILON * self.scale;
        let (value, made_by) = match &self.tangent {
            Some(tangent) => (
                tangent.estimate(),
                "16 ulps of the state at each impact and window, each grown as a tangent vector \
                 carried through every impact since grows (the leading Lyapunov vector in effect), \
                 up to the state's scale: an estimate of how round-off grows, not a bound",
            ),
            None => (
                rounding * self.roundings as f64,
                "16 ulps of the state at each window, summed (the free chain does not amplify \
                 them): an estimate of its round-off, not a bound",
            ),
        };
        Accuracy {
            bound: None,
            estimate: Some(ErrorEstimate {
                value,
                made_by: format!(
                    "{made_by}; of the unit gaps and the velocities over the frequency sqrt(k / m)"
                ),
            }),
        }
    }

    fn settle(&mut self, guard: usize, t: Time) -> Option<Fired> {
        (guard < self.chain.units)
            .then(|| self.settle_chatter(guard + 1, t))
            .flatten()
    }

    fn energy(&self, t: Time) -> Option<f64> {
        let sigma = self.sigma(t);
        let (mut quadratic, mut length) = (0.0, 0.0);
        for n in 1..=self.chain.units {
            let (d, u) = self.state(n, sigma);
            quadratic += d * d + u * u;
            length += d;
        }
        let c = &self.chain;
        Some(0.5 * c.stiffness * quadratic + (c.critical_load - c.load) * length)
    }
}

/// Highest series order a window may need.
const MAX_ORDER: usize = MAX_COLUMN - 1;

/// The smallest order whose truncation over a window is certified.
fn order_for(window: f64) -> usize {
    let x = 2.0 * window;
    (1..=MAX_ORDER)
        .find(|&k| tail(x, k + 1) < CERTIFIED)
        .expect("the window is short enough for a series of order 15")
}

/// The smallest reach beyond which an impact's effect is certified. The
/// velocity jump (at most `2S` at nodes `j - 1` and `j`) is pushed through
/// the recursion with absolute values, which bounds every coefficient it
/// changes; the orders beyond are bounded as in the truncation.
fn reach_for(window: f64, order: usize) -> usize {
    // Orders past the series' own, so that the rest is well below the cut.
    let order = order + 8;
    let width = 2 * order + 4;
    let centre = width; // lattice index of node and unit j
    let size = 2 * width + 1;
    let mut gap = vec![0.0; size];
    let mut vel = vec![0.0; size];
    vel[centre - 1] = 2.0;
    vel[centre] = 2.0;
    let mut bound_gap = vec![0.0; size];
    let mut bound_vel = vel.clone();
    let mut power = 1.0;
    for k in 0..order {
        let inv = 1.0 / (k + 1) as f64;
        let next_gap: Vec<f64> = (0..size)
            .map(|i| (vel[i] + if i > 0 { vel[i - 1] } else { 0.0 }) * inv)
            .collect();
        let next_vel: Vec<f64> = (0..size)
            .map(|i| (gap[i] + if i + 1 < size { gap[i + 1] } else { 0.0 }) * inv)
            .collect();
        gap = next_gap;
        vel = next_vel;
        power *= window;
        for i in 0..size {
            bound_gap[i] += gap[i] * power;
            bound_vel[i] += vel[i] * power;
        }
    }
    let beyond = 2.0 * tail(2.0 * window, order + 1);
    (1..width - 1)
        .find(|&d| {
            let outside = (0..size).filter(|&i| i + d < centre || i > centre + d);
            outside
                .map(|i| bound_gap[i].max(bound_vel[i]) + beyond)
                .all(|b| b < CERTIFIED)
        })
        .expect("the lattice is wide enough for a window below 1")
}

/// `sum_{j >= k} x^j / j!` bounded by its first term over `1 - x / (k + 1)`.
fn tail(x: f64, k: usize) -> f64 {
    let first = (1..=k).fold(1.0, |acc, j| acc * x / j as f64);
    first / (1.0 - x / (k + 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_window_gives_a_modest_order_and_reach() {
        let order = order_for(WINDOW);
        // Minimal: one order less would not certify the truncation.
        assert!(tail(2.0 * WINDOW, order + 1) < CERTIFIED);
        assert!(tail(2.0 * WINDOW, order) > CERTIFIED);
        // The nearest node outside the reach first feels a jump of 2 in its
        // order-2D coefficient, along a single path: 2 theta^(2D) / (2D)!.
        // That lone term must be certified, and must not be one reach closer.
        let reach = reach_for(WINDOW, order) as i32;
        let leading =
            |d: i32| 2.0 * WINDOW.powi(2 * d) / (1..=2 * d).map(f64::from).product::<f64>();
        assert!(leading(reach) < CERTIFIED, "{reach}");
        assert!(leading(reach - 1) > CERTIFIED, "{reach}");
        assert!(order < 16 && reach < 8, "{order} {reach}");
    }

    #[test]
    fn an_impact_late_in_a_window_reaches_less_far() {
        let chain = Chain::in_scene_units(30, 2.0, 1.0, 0.0, true);
        let model = TaylorChain::new(chain, &[0.01; 30], &[0.0; 30]).unwrap();
        let full = model.order_and_reach().1;
        assert_eq!(model.reach_at(0.0), full);
        assert_eq!(model.reach_at(WINDOW * 0.01), full);
        // With an eighth of the window left, the span is short enough to
        // certify a lower reach; never past the window's end.
        assert!(model.reach_at(WINDOW * 0.9) < full);
        assert_eq!(model.reach_at(WINDOW * 1.5), model.reach_at(WINDOW));
        // The table is rounded up: a span just under a tabled one takes
        // its entry, one just over the next, which is never lower.
        for j in 1..REACH_STEPS {
            let at = WINDOW * (1.0 - j as f64 / REACH_STEPS as f64);
            let (under, over) = (at + 1e-6 * WINDOW, at - 1e-6 * WINDOW);
            let tabled = reach_for(WINDOW * j as f64 / REACH_STEPS as f64, model.order);
            assert_eq!(model.reach_at(under), tabled);
            assert!(model.reach_at(over) >= tabled);
        }
    }
}
