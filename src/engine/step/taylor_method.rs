//! Taylor's method: each step is the flow's own Taylor series, of an order
//! and over a step chosen from the tolerance, and each guard's crossing is
//! found on the guard's own Taylor series along the step.
//!
//! The model gives the series ([`HybridModel::flow_series`] and
//! [`HybridModel::guard_series`]; a model compiled from expressions gets
//! them by automatic recurrences). Following Jorba and Zou (2005), as
//! heyoka does: with the tolerance `eps = min(rtol, atol)`, the order is
//! `p = ceil(-ln(eps) / 2) + 1`, and the step is `h = rho / e^2 *
//! exp(-0.7 / (p - 1))`, where `rho` estimates the series' radius of
//! convergence from its last two coefficients (relative to the state's
//! size where `rtol` governs, absolute where `atol` does). The first term
//! left out is then about `eps` of the state. A step whose series no
//! longer solves the flow at its end (a switch ahead in a saturated
//! function, which no coefficient shows) is halved until it does.
//!
//! A guard's series on the step is a polynomial of degree `p`; its first
//! crossing in the guard's direction is found by the certified search of
//! [`first_fall`] (every piece of the step proven free of a crossing,
//! monotone through one, or halved), so no root of the polynomial in the
//! step is missed. A crossing that curves back, or a near miss, reports how
//! deep its dip or how high its turning point is, which the run compares
//! with its error to refuse a graze it cannot decide.
//!
//! [`HybridModel::flow_series`]: crate::engine::HybridModel::flow_series
//! [`HybridModel::guard_series`]: crate::engine::HybridModel::guard_series

use crate::engine::bound::tangent::Rates;
use crate::engine::model::{Direction, HybridModel, Mode};
use crate::engine::step::adaptive::{StepFailure, Tolerances};
use crate::engine::step::locate::{Start, StepScan};
use crate::numerics::first_crossing::{eval2, first_fall};
use crate::numerics::polynomial::{eval_compensated_rows, eval_rows, shift};

/// The tolerance `taylor` takes unless told: machine epsilon, as heyoka.
pub const DEFAULT_TOLERANCE: f64 = f64::EPSILON;

/// Taylor's method's working state: the series of the current step.
#[derive(Debug, Clone)]
pub struct Taylor {
    tolerances: Tolerances,
    order: usize,
    /// `series[i * (order + 1) + k]`: coefficient `k` of component `i`.
    series: Vec<f64>,
    /// Each guard's series along the current step, one after another
    /// (`order + 1` each), computed with the step.
    guards: Vec<f64>,
    /// A guard's series, scratch for its search.
    guard: Vec<f64>,
    h: f64,
    /// `e^2` and `exp(-0.7 / (p - 1))`, the step rule's `h = rho / e^2 *
    /// exp(-0.7 / (p - 1))` (one `exp` per run, not per step).
    shrink: (f64, f64),
    local_error: f64,
    /// The state at a step's end (scratch for the step's check), and the
    /// flow there.
    end: Vec<f64>,
    /// Whether `end` holds the accepted step's end.
    end_known: bool,
    rate: Vec<f64>,
    /// The flow at the step's start: the series' first coefficients.
    start_rate: Vec<f64>,
    /// Series asked of the model (flows and guards).
    evaluations: u64,
}

impl Taylor {
    /// Taylor's method on states of `dimension` components.
    pub fn new(dimension: usize, tolerances: Tolerances) -> Self {
        let order = order_for(tolerances);
        Taylor {
            tolerances,
            order,
            series: vec![0.0; dimension * (order + 1)],
            guards: Vec::new(),
            guard: vec![0.0; order + 1],
            h: 0.0,
            shrink: (
                std::f64::consts::E.powi(2),
                (-0.7 / (order - 1) as f64).exp(),
            ),
            local_error: 0.0,
            end: vec![0.0; dimension],
            end_known: false,
            rate: vec![0.0; dimension],
            start_rate: vec![0.0; dimension],
            evaluations: 0,
        }
    }

    /// The series' order.
    pub fn order(&self) -> usize {
        self.order
    }

    /// Nothing to forget: a step depends only on its start.
    pub fn restart(&mut self) {}

    /// Expand the flow at `y0` and choose the step, at most `h_max`.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        let p = self.order;
        let w = p + 1;
        self.end_known = false;
        model.flow_series(mode, y0, p, &mut self.series);
        self.evaluations += 1;
        if !self.series.iter().all(|c| c.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        for (f, c) in self.start_rate.iter_mut().zip(self.series.chunks_exact(w)) {
            *f = c[1];
        }
        let norm = |k: usize| {
            self.series
                .chunks_exact(w)
                .fold(0.0_f64, |m, c| m.max(c[k].abs()))
        };
        // The clock, the run's time, carries no error and sets no scale.
        let clock = model.clock();
        let size = y0
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != clock)
            .fold(0.0_f64, |m, (_, x)| m.max(x.abs()));
        let Tolerances { rtol, atol } = self.tolerances;
        // Relative where the state is large enough for rtol to govern.
        let scale = if rtol * size > atol { size } else { 1.0 };
        // The last two coefficients' sizes, each read once.
        let flow_norms = [norm(p - 1), norm(p)];
        let radius = |n: f64, k: usize| {
            if n == 0.0 {
                f64::INFINITY
            } else {
                (scale / n).powf(1.0 / k as f64)
            }
        };
        let mut rho = radius(flow_norms[0], p - 1).min(radius(flow_norms[1], p));
        let flow_rho = rho;
        let mut limited_by = None;
        // A guard's series must converge over the step too: a flow whose
        // series ends (a polynomial, a clock) says nothing of a guard that
        // reads the clock through a sine. Each guard's radius, measured
        // alike, may shorten the step.
        let guards = model.guards(mode).len();
        self.guards.resize(guards * w, 0.0);
        for g in 0..guards {
            let c = &mut self.guards[g * w..(g + 1) * w];
            model.guard_series(mode, g, &self.series, p, c);
            self.evaluations += 1;
            // A guard whose last two coefficients are no larger than the
            // flow's (a guard that is a state component: a section, an
            // impact's coordinate) converges at least as far: its radius,
            // a power as costly as a step's series, is not needed. Equal,
            // or smaller by far more than a power's rounding.
            let within = |k: usize, flow: f64| {
                let n = c[k].abs();
                n == flow || n <= flow * (1.0 - 1e-12)
            };
            if within(p - 1, flow_norms[0]) && within(p, flow_norms[1]) {
                continue;
            }
            let guard_rho = radius(c[p - 1].abs(), p - 1).min(radius(c[p].abs(), p));
            if guard_rho < rho {
                (rho, limited_by) = (guard_rho, Some(g));
            }
        }
        let mut h = (rho / self.shrink.0 * self.shrink.1).min(h_max);
        let allowed = (rtol * size).max(atol);
        let last = flow_norms[1];
        loop {
            if !(h >= h_min) {
                return Err(match limited_by {
                    Some(guard) => StepFailure::GuardCollapsed { h, guard },
                    None => StepFailure::Collapsed { h },
                });
            }
            // The last term kept, the size of the first left out; or that
            // term as the radius puts it, where the last term kept is small
            // by parity (an even function's odd terms vanish at its centre:
            // x' = sin t from 0 keeps a zero last term at odd orders).
            self.local_error =
                (last * h.powi(p as i32)).max(scale * (h / flow_rho).powi(p as i32 + 1));
            if self.solves_the_flow(model, mode, h, allowed) {
                break;
            }
            h *= 0.5;
        }
        self.h = h;
        Ok(())
    }

    /// Whether the series still solves the flow at the end of a step of
    /// length `h`: its derivative against the flow at the state it gives
    /// (the defect), times `h`, within 1000 times the tolerance (a series
    /// the step rule trusts misses it by about `p` times) or the rounding
    /// of both. The step's radius is read off the coefficients, and a
    /// switch ahead in a saturated function (`tanh(v / eps)` at `v / eps =
    /// 60`) leaves them all below the rounding: the series cannot see it
    /// coming, the flow at the step's end can.
    fn solves_the_flow<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        h: f64,
        allowed: f64,
    ) -> bool {
        if !model.has_rhs(mode) {
            return true;
        }
        let w = self.order + 1;
        let mut end = std::mem::take(&mut self.end);
        let mut rate = std::mem::take(&mut self.rate);
        self.eval(h, &mut end);
        model.rhs(mode, &end, &mut rate);
        let tolerance = 1e3 * allowed.max(self.local_error);
        // Four components at a time, and the last one to three together:
        // their Horner chains run side by side.
        let whole = rate.len() / 4 * 4;
        let (fours, rest) = self.series.split_at(whole * w);
        let rest = &rest[..(rate.len() - whole) * w];
        let solves = fours
            .chunks_exact(4 * w)
            .zip(rate[..whole].chunks_exact(4))
            .all(|(c, f)| defects_within::<4>(c, f, h, tolerance))
            && match rate.len() - whole {
                1 => defects_within::<1>(rest, &rate[whole..], h, tolerance),
                2 => defects_within::<2>(rest, &rate[whole..], h, tolerance),
                3 => defects_within::<3>(rest, &rate[whole..], h, tolerance),
                _ => true,
            };
        (self.end, self.rate) = (end, rate);
        self.end_known = solves;
        solves
    }

    /// Length of the last step.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// The flow at the start and at the end of a stretch `tau` from
    /// `offset` into the step, where the step knows both: the whole step,
    /// checked against the flow at its end.
    pub fn rates(&self, offset: f64, tau: f64) -> Rates<'_> {
        (offset == 0.0 && tau == self.h && self.end_known).then_some((&self.start_rate, &self.rate))
    }

    /// The state `tau` into the step: each component's series summed, by
    /// compensated Horner (the terms of a step of a sizeable part of a
    /// period cancel, and plain Horner's few ulps per step would add up
    /// over millions of steps to the phase error the run is after).
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        eval_compensated_rows(&self.series, self.order + 1, tau, x);
    }

    /// The state at the end of the step (found by the step's own check of
    /// its series, where the flow has a right-hand side).
    pub fn end(&self, x: &mut [f64]) {
        if self.end_known {
            x.copy_from_slice(&self.end);
        } else {
            self.eval(self.h, x);
        }
    }

    /// The state at `tau` into the step to working precision (plain
    /// Horner, fused): what a linearisation of the step samples, which
    /// needs none of [`Taylor::eval`]'s compensation.
    pub fn sample(&self, tau: f64, x: &mut [f64]) {
        eval_rows(&self.series, self.order + 1, tau, x);
    }

    /// The last term kept, at the step's length.
    pub fn local_error(&self) -> f64 {
        self.local_error
    }

    /// Series asked of the model so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }

    /// The first crossing of `guard` in its direction on the rest of the
    /// step from `offset` into it (zero: the whole step), as a fraction of
    /// that rest, and how clearly it decides (see [`StepScan`]; turning
    /// points are looked for only where the guard may come within
    /// `uncertainty` of zero). How the guard counts at `offset` is
    /// `start`'s (see [`Start`]). From inside the step (a marker that fired
    /// there, the step going on) the guard's series is re-expanded at
    /// `offset` by a Taylor shift.
    pub fn locate<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        start: Start,
        uncertainty: f64,
        offset: f64,
    ) -> Result<StepScan, String> {
        let w = self.order + 1;
        let c = &mut self.guard;
        c.copy_from_slice(&self.guards[guard * w..(guard + 1) * w]);
        shift(c, offset);
        locate_on_series(model, mode, guard, c, self.h - offset, start, uncertainty)
    }
}

/// The first crossing of `guard` in its direction on a step of length `h`
/// along which the guard's series is `series` (negated in place where the
/// guard rises), as a fraction of the step, and how clearly the step
/// decides (see [`Taylor::locate`]).
pub(crate) fn locate_on_series<M: HybridModel + ?Sized>(
    model: &M,
    mode: Mode,
    guard: usize,
    series: &mut [f64],
    h: f64,
    start: Start,
    uncertainty: f64,
) -> Result<StepScan, String> {
    if !series.iter().all(|c| c.is_finite()) {
        return Err(format!(
            "the series of guard `{}` is not finite",
            model.guards(mode)[guard].name
        ));
    }
    // A spent guard starts on zero: from exactly zero a series only
    // crosses once it has come back (its slope there decides which way it
    // leaves), whichever side rounding left the located state on.
    if start == Start::Spent {
        series[0] = 0.0;
    }
    let check_start = start == Start::OnZero;
    let (first, (margin, at)) = match model.guards(mode)[guard].direction {
        Direction::Falling => falls(series, h, check_start, uncertainty)?,
        Direction::Rising => {
            series.iter_mut().for_each(|c| *c = -*c);
            falls(series, h, check_start, uncertainty)?
        }
        Direction::Either => {
            let (a, ma) = falls(series, h, check_start, uncertainty)?;
            series.iter_mut().for_each(|c| *c = -*c);
            let (b, mb) = falls(series, h, check_start, uncertainty)?;
            let first = match (a, b) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            (first, if ma.0 <= mb.0 { ma } else { mb })
        }
    };
    Ok(StepScan {
        crossing: first.map(|tau| (tau / h).min(1.0)),
        margin,
        margin_at: (at / h).min(1.0),
    })
}

/// Whether each of `L` components' series (`c`, one after another) solves
/// the flow at `h`: the series' derivative there against the flow `f`,
/// times `h`, within `tolerance` or the rounding of both. The rounding's
/// scale (the terms' sizes) is summed only for a component the tolerance
/// alone does not pass: almost every step passes without it.
fn defects_within<const L: usize>(c: &[f64], f: &[f64], h: f64, tolerance: f64) -> bool {
    let w = c.len() / L;
    // The series' derivatives at h.
    let mut slope = [0.0; L];
    // `k` as a float counted down (exact), not converted at each term: a
    // conversion writes part of a register and waits for its last value.
    let mut weight = (w - 1) as f64;
    for k in (1..w).rev() {
        for l in 0..L {
            slope[l] = slope[l] * h + weight * c[l * w + k];
        }
        weight -= 1.0;
    }
    (0..L).all(|l| {
        let miss = (slope[l] - f[l]).abs() * h;
        miss <= tolerance || {
            // The sizes of the derivative's terms (f's beside them).
            let row = &c[l * w..(l + 1) * w];
            let (mut size, mut weight) = (f[l].abs(), (w - 1) as f64);
            for ck in row[1..].iter().rev() {
                size = size * h + weight * ck.abs();
                weight -= 1.0;
            }
            miss <= tolerance + 16.0 * f64::EPSILON * size * h
        }
    })
}

/// The order for `tolerances`: `ceil(-ln(eps) / 2) + 1`, `eps = min(rtol,
/// atol)`, at least 2 and at most [`MAX_ORDER`].
pub fn order_for(tolerances: Tolerances) -> usize {
    let eps = tolerances.rtol.min(tolerances.atol).max(f64::MIN_POSITIVE);
    ((-eps.ln() / 2.0).ceil() as usize + 1).clamp(2, MAX_ORDER)
}

/// The highest order taken (tolerances down to 1e-51).
pub const MAX_ORDER: usize = 60;

/// The first fall of `c` through zero on `[0, h]` (see [`first_fall`]),
/// and the margin with where it was measured: for a crossing that curves
/// back, the depth its dip would reach, `p'^2 / (2 p'')`; without one, the
/// lowest turning point still above zero, where it may come within
/// `uncertainty` of zero; infinite when nothing comes that close.
fn falls(
    c: &[f64],
    h: f64,
    check_start: bool,
    uncertainty: f64,
) -> Result<(Option<f64>, (f64, f64)), String> {
    const CLEAR: (f64, f64) = (f64::INFINITY, f64::INFINITY);
    // Most steps: the guard stays further from zero than the errors can
    // move it, which its coefficients show at once.
    let pull = pull_down(c, h);
    if stays_above_with(c, h, uncertainty, pull) || (check_start && rises_clear(c, pull)) {
        return Ok((None, CLEAR));
    }
    // Rising all the way (a marker's opposite passage, half of every
    // oscillation's crossings): nothing falls, and nothing turns to come
    // near zero; the searches below would find as much.
    if rises_throughout(c, h) {
        return Ok((None, CLEAR));
    }
    // Series are at most MAX_ORDER + 1 long: scratch on the stack.
    let n = c.len();
    let mut scratch = [0.0; MAX_ORDER + 1];
    let from = if !check_start && c[0] <= 0.0 {
        // Already past zero: it must come back up before it can cross.
        let back = &mut scratch[..n];
        back.iter_mut().zip(c).for_each(|(b, x)| *b = -x);
        // Most such steps stay past it (a marker's far side, half of every
        // oscillation; the step after a marker fired, leaving zero): proven
        // by its falling terms alone, where the search's own first proof
        // weighs every term.
        if stays_above_with(back, h, 0.0, pull_down(back, h)) || rises_throughout(back, h) {
            return Ok((None, CLEAR));
        }
        match first_fall(back, 0.0, h)? {
            Some(up) => up,
            None => return Ok((None, CLEAR)),
        }
    } else {
        0.0
    };
    let crossing = first_fall(c, from, h)?;
    let end = crossing.unwrap_or(h);
    let mut margin = CLEAR;
    let slope = &mut scratch[..n - 1];
    for (k, d) in slope.iter_mut().enumerate() {
        *d = (k + 1) as f64 * c[k + 1];
    }
    // Turning points (the slope rising through zero) before the crossing,
    // unless the guard stays clear of zero or falls all the way there.
    let near = !stays_above(c, end, uncertainty);
    let falling_throughout = !near
        || slope
            .iter()
            .skip(1)
            .rev()
            .fold(0.0, |acc, d| (acc + d.max(0.0)) * end)
            + slope.first().copied().unwrap_or(0.0)
            < 0.0;
    if !falling_throughout {
        slope.iter_mut().for_each(|d| *d = -*d);
        let minus_slope = &*slope;
        let mut at = from;
        for _ in 0..8 {
            match first_fall(minus_slope, at, end)? {
                // A guard already rising where the search starts is not at a
                // turning point there.
                Some(turn) if turn > at => {
                    let (value, _, _) = eval2(c, turn);
                    if value > 0.0 && value < margin.0 {
                        margin = (value, turn);
                    }
                    if turn >= end {
                        break;
                    }
                    at = turn + (end - turn) * 1e-9;
                }
                _ => break,
            }
        }
    }
    if let Some(t) = crossing {
        let (_, slope, curvature) = eval2(c, t);
        let depth = slope * slope / (2.0 * curvature);
        if curvature > 0.0 && t > 0.0 && depth < margin.0 {
            margin = (depth, t);
        }
    }
    Ok((crossing, margin))
}

/// Whether `sum c_k s^k` stays above `level` on `[0, h]`, by either of two
/// lower bounds: `c_0 + sum_{k >= 1} min(0, c_k) h^k` (the terms that can
/// pull it down, at their largest), or the concave quadratic `c_0 + c_1 s -
/// B s^2` with `B = sum_{k >= 2} max(0, -c_k) h^(k - 2)` (`s^k <= s^2 h^(k -
/// 2)`), which is smallest at an end of the step and keeps a rising start.
fn stays_above(c: &[f64], h: f64, level: f64) -> bool {
    stays_above_with(c, h, level, pull_down(c, h))
}

/// `sum_{k >= 2} min(0, c_k) h^(k - 1)`: how far the terms from the second
/// on can pull `p` down over `[0, h]`, divided by `h`; the sum both quick
/// proofs start from, and what most steps of a run end on. Two Horner
/// chains in `h^2`, the even terms' and the odd terms', run side by side
/// where one chain's operations would each wait on the last. The terms
/// share a sign, so either order rounds to a few ulps of their sum, far
/// inside the proofs' margin of `1e-12` of it.
fn pull_down(c: &[f64], h: f64) -> f64 {
    // `min(0, x)`; a NaN coefficient (none reaches here) would give 0.
    let pull = |x: f64| if x < 0.0 { x } else { 0.0 };
    let h2 = h * h;
    // Term j of `terms` is `c_(j + 2)`, of power `h^(j + 1)`.
    let terms = c.get(2..).unwrap_or(&[]);
    let (mut even, mut odd) = (0.0, 0.0);
    let mut j = terms.len();
    if j % 2 == 1 {
        j -= 1;
        even = pull(terms[j]);
    }
    // One loop for both chains, so that each step of one runs beside the
    // other's.
    while j >= 2 {
        j -= 2;
        even = even * h2 + pull(terms[j]);
        odd = odd * h2 + pull(terms[j + 1]);
    }
    even * h + odd * h2
}

/// [`stays_above`] given `from_two = pull_down(c, h)`.
fn stays_above_with(c: &[f64], h: f64, level: f64, from_two: f64) -> bool {
    // One step more of the fold gives the sum from k = 1.
    let (c0, c1) = (c[0], c.get(1).copied().unwrap_or(0.0));
    let from_one = if c.len() > 1 {
        (from_two + c1.min(0.0)) * h
    } else {
        0.0
    };
    let margin = 1.0 + 1e-12;
    if c0 + from_one * margin > level {
        return true;
    }
    // B h^2 is h times from_two.
    let end = c0 + c1 * h + from_two * h * margin;
    c0 > level && end > level
}

/// Whether `p(s) = sum c_k s^k` is strictly increasing on `[0, h]`: its
/// slope's falling terms at their largest, `c_1 + sum_{k >= 2} min(0, k
/// c_k) h^(k - 1)`, stay above zero (that sum padded for its rounding).
fn rises_throughout(c: &[f64], h: f64) -> bool {
    let mut falling = 0.0;
    for (k, &ck) in c.iter().enumerate().skip(2).rev() {
        falling = falling * h + (k as f64 * ck).min(0.0);
    }
    let rate = c.get(1).copied().unwrap_or(0.0);
    rate + falling * h * (1.0 + 1e-12) > 0.0
}

/// Whether `sum c_k s^k`, leaving zero (`c_0 = 0`, just after a reset put
/// the guard there), stays above zero on `(0, h]`, given `pull =
/// pull_down(c, h)`: `p(s) >= s (c_1 + pull)`, a rise no term can turn back
/// within the step.
fn rises_clear(c: &[f64], pull: f64) -> bool {
    c[0] == 0.0 && c.len() > 1 && c[1] + pull * (1.0 + 1e-12) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_follow_the_tolerance() {
        let tol = |e: f64| Tolerances { rtol: e, atol: e };
        assert_eq!(order_for(tol(1e-15)), 19);
        assert_eq!(order_for(tol(1e-12)), 15);
        assert_eq!(
            order_for(Tolerances {
                rtol: 1e-6,
                atol: 1e-16
            }),
            20
        );
    }

    /// The cosine arc of the mechanism after an impact, on a step of one
    /// radian: `eps = -0.2 + A cos(t + phi)` written as its series.
    fn arc(eps0: f64, rate0: f64, h: f64) -> (Vec<f64>, f64) {
        // eps'' = -(eps + 0.2): coefficients by the recurrence.
        let mut c = vec![eps0, rate0];
        for k in 2..=24 {
            let previous = c[k - 2] + if k == 2 { 0.2 } else { 0.0 };
            c.push(-previous / (k * (k - 1)) as f64);
        }
        (c, h)
    }

    #[test]
    fn the_quick_proofs_settle_a_rise_from_zero_and_an_arch_and_no_more() {
        // Leaving eps = 0 at 0.447: positive on all of (0, 1], which the
        // terms-at-their-worst bound cannot show (it starts at zero) and the
        // rise bound does.
        let (c, h) = arc(0.0, 0.4472135954999579, 1.0);
        assert!(rises_clear(&c, pull_down(&c, h)));
        assert!(!stays_above(&c, h, 1e-15));
        // The same rise is brought back to zero within 2.5 (the flight):
        // neither proof may claim that step.
        assert!(!rises_clear(&c, pull_down(&c, 2.5)));
        assert!(!stays_above(&c, 2.5, 0.0));
        // An arch over the apex, 0.25 up, falling to about 0.15 at its end:
        // the quadratic bound proves it above 0.1, not above 0.2.
        let (c, h) = arc(0.25, 0.1, 1.0);
        let end: f64 = c.iter().sum();
        assert!(end > 0.1 && end < 0.2, "{end}");
        assert!(stays_above(&c, h, 0.1));
        assert!(!stays_above(&c, h, 0.2));
    }

    #[test]
    fn a_rise_throughout_is_proven_where_the_slope_stays_positive_and_no_further() {
        // p = -0.3 + s - 0.2 s^2: p' = 1 - 0.4 s, positive up to s = 2.5.
        let c = [-0.3, 1.0, -0.2];
        assert!(rises_throughout(&c, 2.0));
        assert!(rises_throughout(&c, 2.49));
        assert!(!rises_throughout(&c, 2.6));
        // A rising term counts for nothing: p' = -0.1 + 3 s^2 dips below
        // zero at the start, whatever it reaches later.
        assert!(!rises_throughout(&[0.0, -0.1, 0.0, 1.0], 1.0));
        // The cosine arc after an impact, leaving zero at 0.447: its apex
        // at t = atan2(0.447, 0.2) = 1.15; rising over a step of 1, not
        // over one of 1.5 that passes it.
        let (c, _) = arc(0.0, 0.4472135954999579, 1.0);
        assert!(rises_throughout(&c, 1.0));
        assert!(!rises_throughout(&c, 1.5));
        // A falls() on a series that rises throughout finds nothing.
        let (found, margin) = falls(&[-0.3, 1.0, -0.2], 2.0, false, 1e-9).unwrap();
        assert_eq!((found, margin.0), (None, f64::INFINITY));
    }

    #[test]
    fn four_defects_at_once_are_each_defect_alone() {
        // The series of e^t (coefficients 1/k!) against the flow e^h, and
        // three others off by growing amounts: four lanes must pass exactly
        // when each lane alone passes, at tolerances either side of the
        // defects.
        let (w, h) = (20, 0.5_f64);
        let factorial = |k: usize| (1..=k).map(|i| i as f64).product::<f64>();
        let c: Vec<f64> = (0..4)
            .flat_map(|l| (0..w).map(move |k| (1.0 + 1e-9 * l as f64) / factorial(k)))
            .collect();
        let f = [h.exp(); 4];
        for tolerance in [1e-14, 1e-10, 3e-10, 1e-9, 1.0] {
            let alone = (0..4)
                .all(|l| defects_within::<1>(&c[l * w..(l + 1) * w], &f[l..=l], h, tolerance));
            assert_eq!(
                defects_within::<4>(&c, &f, h, tolerance),
                alone,
                "{tolerance}"
            );
        }
        assert!(defects_within::<1>(&c[..w], &f[..1], h, 1e-14));
        assert!(!defects_within::<1>(&c[3 * w..], &f[..1], h, 1e-10));
    }

    #[test]
    fn the_pull_is_the_negative_terms_summed() {
        // -3 h - 0.5 h^2 (from c_2 and c_3; c_4 is positive) at h = 2:
        // -6 - 2, exact in binary; nothing below c_2 counts.
        assert_eq!(pull_down(&[-9.0, -9.0, -3.0, -0.5, 4.0], 2.0), -8.0);
        // Every length, odd and even, against the terms summed one by one.
        let c: Vec<f64> = (0..26)
            .map(|k| ((k * 7 % 5) as f64 - 2.0) / (k + 1) as f64)
            .collect();
        for len in 0..=c.len() {
            let written: f64 = (2..len)
                .map(|k| c[k].min(0.0) * 0.9f64.powi(k as i32 - 1))
                .sum();
            let chained = pull_down(&c[..len], 0.9);
            assert!(
                (chained - written).abs() <= 1e-15 * written.abs(),
                "{len}: {chained} against {written}"
            );
        }
    }

    #[test]
    fn a_fall_a_graze_and_a_near_miss() {
        // (s - 1)(s - 2) falls through zero at 1 (coming from above) and rises at 2.
        let (t, (margin, _)) = falls(&[2.0, -3.0, 1.0], 3.0, false, 0.0).unwrap();
        assert!((t.unwrap() - 1.0).abs() < 1e-15);
        // Slope -1 and curvature 2 at the root: a dip of 1/4 if it curves back.
        assert!((margin - 0.25).abs() < 1e-12, "{margin}");
        // (s - 1)^2 + 1e-6: a near miss whose turning point is 1e-6 above zero.
        let (t, (margin, at)) = falls(&[1.0 + 1e-6, -2.0, 1.0], 3.0, false, 0.0).unwrap();
        assert!(
            (at - 1.0).abs() < 1e-9,
            "the turning point is at 1, not {at}"
        );
        assert_eq!(t, None);
        assert!((margin - 1e-6).abs() < 1e-12, "{margin}");
        // Starting below zero and falling further: no crossing without check_start...
        assert_eq!(falls(&[-1e-3, -1.0], 1.0, false, 0.0).unwrap().0, None);
        // ...and at once with it (a reset that did not turn the motion round).
        assert_eq!(falls(&[0.0, -1.0], 1.0, true, 0.0).unwrap().0, Some(0.0));
        // On zero and rising, then back: the bounce's return.
        let (t, _) = falls(&[0.0, 1.0, -1.0], 2.0, true, 0.0).unwrap();
        assert!((t.unwrap() - 1.0).abs() < 1e-15);
        // Just above zero and rising (a state just after an impact): no
        // turning point at the start, so nothing near.
        let (t, (margin, _)) = falls(&[5e-17, 1.0, 1.0], 2.0, true, 0.0).unwrap();
        assert_eq!((t, margin), (None, f64::INFINITY));
        // Far from zero for the whole step: decided from the coefficients.
        assert_eq!(
            falls(&[1.0, -0.1, 0.01], 2.0, false, 1e-3).unwrap().1.0,
            f64::INFINITY
        );
    }
}
