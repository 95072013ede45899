//! Events of a Runge-Kutta pair placed on its steps, not on its dense
//! output.
//!
//! A pair's dense output is one order below its steps (a quartic for
//! Dormand-Prince 5(4), degree seven for DOP853), and at loose tolerances
//! its error inside a step is many times the step's error estimate: a
//! crossing found on it alone was 9.4e-3 off at rtol 1e-3 on a one-line
//! flow, 7.6 times the event-time bound the estimate gave (3.4 times at
//! 1e-4). [`sharpen`]
//! re-takes the step from its start to exactly the crossing, so the state
//! there is a step's, with the error the bound carries, and moves the
//! crossing to where the guard is zero along the flow from there.

use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::EmbeddedPair;
use crate::engine::step::crossing::{Crossing, Sharpened};

/// Sharpen a crossing found on `pair`'s dense output: re-take the step from
/// `y0` to exactly its `tau` (one step's evaluations), then follow the flow
/// from there by its second-order Taylor polynomial (two more: the rate at
/// `tau` and the rate one Newton step along it) and find the guard's zero
/// on that by secant steps, nudged forward until it has crossed. Where the
/// guard's value there puts the crossing beyond the polynomial's `reach`,
/// the step is re-taken to where it says, up to [`ROUNDS`] times. The
/// polynomial's error is cubic in the correction that remains: far below
/// round-off. A crossing moves by no more than its `room` either way (the
/// events' order is kept; an event due at the same instant keeps it where
/// it is), and not before the step's start. Returns how it moved, with the
/// state there in `x`; where it cannot, it keeps the dense output's answer
/// and says by how much the state there is off the step re-taken to it
/// (`x` is scratch). The stages are spent: the next step starts afresh, as
/// after every event.
pub fn sharpen<P: EmbeddedPair, M: HybridModel + ?Sized>(
    pair: &mut P,
    model: &M,
    mode: Mode,
    y0: &[f64],
    crossing: &Crossing,
    x: &mut [f64],
) -> Sharpened {
    let &Crossing {
        tau,
        reach,
        room,
        guard,
        crossed,
        ..
    } = crossing;
    let h = pair.dense_h();
    let (a, b) = ((tau - 1e-4 * h).max(0.0), (tau + 1e-4 * h).min(h));
    pair.dense_eval(a, x);
    let g_a = guard(x);
    pair.dense_eval(b, x);
    let slope = (guard(x) - g_a) / (b - a);
    pair.parts().0.fsal = false;
    rate_into(pair, model, mode, y0, 0);
    // Where the dense output errs by more than the polynomial reaches, the
    // step is re-taken to where the guard's value says the crossing is, a
    // few times.
    let mut at = tau;
    let mut start = Vec::new();
    let (mut first, mut off) = (f64::NAN, f64::NAN);
    for round in 0..ROUNDS {
        if round > 0 {
            *pair.trial_end() = std::mem::take(&mut start);
        }
        pair.attempt(model, mode, y0, at);
        start = std::mem::take(pair.trial_end());
        first = -guard(&start) / slope;
        if round == 0 {
            pair.dense_eval(tau, x);
            off = largest_gap(&start, x, pair.control().bounded);
        }
        let moved = at + first - tau;
        if first.is_nan() || first.abs() <= reach || !(at + first > 0.0 && moved.abs() <= room) {
            break;
        }
        at += first;
    }
    if first.is_nan() || first.abs() > 2.0 * reach {
        // A flat or undefined slope, or a crossing out of reach: the flow
        // is not asked about states far from the crossing, and the dense
        // output's answer stands, erring by what the step re-taken to it
        // says.
        *pair.trial_end() = start;
        return Sharpened::Kept(off);
    }
    rate_into(pair, model, mode, &start, 1);
    // One Newton step along, in stage 3 (free too).
    let (control, stages, _) = pair.parts();
    let (low, high) = stages.split_at_mut(3);
    for i in 0..x.len() {
        high[0][i] = start[i] + first * low[1][i];
    }
    model.rhs(mode, &high[0], &mut low[2]);
    control.evaluations += 1;
    let (rate, later) = (&stages[1], &stages[2]);
    // x(tau + s) = start + s f + s^2/2 f'f, with f'f from the two rates.
    let mut along = |s: f64, x: &mut [f64]| {
        for i in 0..x.len() {
            let bend = if first == 0.0 {
                0.0
            } else {
                (later[i] - rate[i]) / first
            };
            x[i] = start[i] + s * (rate[i] + 0.5 * s * bend);
        }
        guard(x)
    };
    let floor = f64::EPSILON * tau.abs().max(f64::MIN_POSITIVE);
    let found = zero_along(&mut along, first, slope, floor, crossed, x);
    *pair.trial_end() = start;
    match found {
        Some(s) if s.abs() <= reach && at + s >= 0.0 && (at + s - tau).abs() <= room => {
            Sharpened::Moved(at + s - tau)
        }
        _ => Sharpened::Kept(off),
    }
}

/// The largest gap between `a` and `b` over their first `bounded`
/// components.
fn largest_gap(a: &[f64], b: &[f64], bounded: usize) -> f64 {
    (a.iter().zip(b).take(bounded)).fold(0.0, |m: f64, (a, b)| m.max((a - b).abs()))
}

/// How far `pair`'s dense output `tau` into its last step (from `y0`) may
/// be from the solution: its gap to the step re-taken to `tau` on `spare`
/// (a pair of the same kind, whose stages this spends), plus that step's
/// own error bound (twice its estimate, as a step's; see
/// [`EmbeddedPair::local_error`]). `x` is scratch.
pub fn dense_error<P: EmbeddedPair, M: HybridModel + ?Sized>(
    pair: &P,
    spare: &mut P,
    model: &M,
    mode: Mode,
    (y0, tau): (&[f64], f64),
    x: &mut [f64],
) -> f64 {
    rate_into(spare, model, mode, y0, 0);
    let trial = spare.attempt(model, mode, y0, tau);
    pair.dense_eval(tau, x);
    let bounded = pair.control().bounded;
    largest_gap(spare.trial_end(), x, bounded) + 2.0 * trial.largest
}

/// How many times a step is re-taken towards a crossing the dense output
/// misplaced by more than the polynomial reaches.
const ROUNDS: usize = 4;

/// Stage `stage` of `pair` holds `f(y)`.
fn rate_into<P: EmbeddedPair, M: HybridModel + ?Sized>(
    pair: &mut P,
    model: &M,
    mode: Mode,
    y: &[f64],
    stage: usize,
) {
    let (control, stages, _) = pair.parts();
    model.rhs(mode, y, &mut stages[stage]);
    control.evaluations += 1;
}

/// The zero of `along(s)` (the guard at `s` past the dense crossing, which
/// writes the state there into `x`) by secant steps from 0 and `first`,
/// then moved forward until `crossed` holds. `x` ends at the returned `s`.
fn zero_along(
    along: &mut impl FnMut(f64, &mut [f64]) -> f64,
    first: f64,
    slope: f64,
    floor: f64,
    crossed: &dyn Fn(f64) -> bool,
    x: &mut [f64],
) -> Option<f64> {
    let (mut s0, mut g0) = (0.0, along(0.0, x));
    let (mut s1, mut g1) = (first, along(first, x));
    for _ in 0..8 {
        if g1 == 0.0 || g1 == g0 {
            break;
        }
        let s2 = s1 - g1 * (s1 - s0) / (g1 - g0);
        if !s2.is_finite() || s2 == s1 {
            break;
        }
        (s0, g0) = (s1, g1);
        (s1, g1) = (s2, along(s2, x));
    }
    // Rounding may leave the zero a hair short of crossing: step forward,
    // doubling, from the distance the slope says is left.
    let mut nudge = (g1 / slope).abs().max(floor);
    for _ in 0..16 {
        if !(s1.is_finite() && g1.is_finite()) {
            return None;
        }
        if crossed(g1) {
            return Some(s1);
        }
        s1 += nudge;
        nudge *= 2.0;
        g1 = along(s1, x);
    }
    None
}
