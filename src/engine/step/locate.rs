//! Finding the first crossing of a guard inside one integration step.
//!
//! The step's dense output is a polynomial in the normalised step time
//! `s in [0, 1]` (a quartic for Dormand-Prince and Stormer-Verlet, degree
//! seven for DOP853). What is guaranteed:
//!
//! - **Affine guards** (declared with [`Guard::affine`]) are polynomials of
//!   the same degree in `s`. We recover one from `degree + 1` equispaced
//!   samples and isolate every one of
//!   its real roots in `[0, 1]` by recursion on derivatives: between two
//!   consecutive critical points a polynomial is monotone, so each sign
//!   change there is exactly one root. A guard that dips through zero and
//!   back inside one step (the classic miss of an endpoint sign check) is
//!   found whenever the interpolant itself dips, i.e. whenever the dip is
//!   deeper than the interpolation error, which the tolerances bound.
//! - **Other guards** are sampled at 17 points per step; a dip that enters
//!   and leaves between two samples can be missed.
//!
//! A crossing is a passage from strictly before zero (in the guard's
//! direction) to zero or beyond. Each bracket is refined on the guard itself
//! by the Illinois method to a few ulps, and the crossing returned is the
//! bracket end that has just crossed: a guard must come strictly back
//! before it can fire again, so an event whose reset leaves the state where
//! it was is not found twice.
//!
//! A guard that has just fired and gone on through (a marker) starts the
//! next step spent ([`Start::Spent`]): on exactly zero, whatever side
//! rounding left it on, so that only a return and a new passage cross.
//!
//! A state that sits on a guard at the start of a step has not crossed it.
//! After a reset the engine asks whether such a guard should fire at once
//! (`leaves_zero`, [`Start::OnZero`]): it does if it is on or past zero and
//! moves further in its direction (either way, for a guard of either
//! direction) where it first visibly moves (by more than 1e-10 of the
//! step's guard values; a rate too small to show before the curvature takes
//! over is rounding). That is how an event at `t = 0`, or a reset that
//! fails to turn the motion around (resting contact), shows up. A guard
//! that leaves zero the other way is not scanned for crossings before it
//! has visibly left: a dip of rounding size there is not an event.
//!
//! [`Guard::affine`]: crate::engine::Guard::affine

use crate::engine::model::{Direction, Guard};
use crate::numerics::polynomial::eval_plain;
use crate::numerics::real_roots::{
    MAX_DEGREE, critical_points, derivative, polynomial_through, refine,
};

/// How a guard stands where a step starts, which decides what counts as
/// its first crossing in the step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// As its value says: it crosses when it passes from strictly before
    /// zero (in its direction) to zero or beyond; a guard past zero must
    /// first come back.
    Armed,
    /// It sits on zero after a reset or at `t = 0`: it fires at once if it
    /// moves further its way (either way, for a guard of either
    /// direction), and otherwise counts as just before zero.
    OnZero,
    /// It has just fired and the state went on through (a marker: a
    /// Poincare section, a threshold): it counts as exactly on zero,
    /// whatever side rounding left it on, and must come back before it can
    /// cross again. A crossing fires once.
    Spent,
}

/// What one step says about one guard.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepScan {
    /// The earliest `s in [0, 1]` at which the guard crosses zero in its
    /// direction.
    pub crossing: Option<f64>,
    /// How clearly the step decides: for a crossing that curves back (a
    /// graze), the depth its dip would reach, `g'^2 / (2 |g''|)` (which also
    /// says how far an error moves the crossing); without a crossing, the
    /// smallest height of a turning point still short of zero (a piece of
    /// a step halved around a crossing may report a turning point before it
    /// instead, which only errs towards caution); infinite where the guard
    /// does not curve back, stays clearly clear of zero, or is not affine.
    /// A margin below the integration error means the method cannot tell a
    /// graze from a near miss.
    pub margin: f64,
    /// Where in the step (`s in [0, 1]`) the margin was measured: a graze
    /// after an earlier event of the step does not matter, for the step is
    /// taken again after it.
    pub margin_at: f64,
}

impl StepScan {
    /// No crossing, nothing near.
    pub const CLEAR: StepScan = StepScan {
        crossing: None,
        margin: f64::INFINITY,
        margin_at: 1.0,
    };

    /// A crossing at `s`, nothing near before it.
    pub fn at(s: f64) -> StepScan {
        StepScan {
            crossing: Some(s),
            ..StepScan::CLEAR
        }
    }
}

/// Scan one step for `guard`, where `g(s)` is the guard along the step.
///
/// With [`Start::OnZero`] (a guard that sits on zero at `s = 0` after a
/// reset), the guard fires at `s = 0` if it moves further its way, and
/// otherwise counts as being just before zero: a return to zero that comes
/// sooner than rounding lets the guard rise visibly above it (a reset that
/// barely turned the motion round) is still a crossing. With
/// [`Start::Spent`] it starts at exactly zero, from where only a return and
/// a new passage cross. See the module docs.
pub fn scan_step(
    guard: &Guard,
    start: Start,
    interpolant: Interpolant,
    resolution: f64,
    mut g: impl FnMut(f64) -> f64,
) -> StepScan {
    let check_start = start == Start::OnZero;
    let g0 = if start == Start::Spent { 0.0 } else { g(0.0) };
    let start = if check_start {
        just_before_zero(guard.direction, g0)
    } else {
        g0
    };
    if !guard.affine {
        let cuts: [f64; 16] = std::array::from_fn(|k| (k + 1) as f64 / 16.0);
        let crossing = scan_from(guard.direction, 0.0, &cuts, start, &mut g, &|_| f64::NAN);
        return StepScan {
            crossing,
            ..StepScan::CLEAR
        };
    }
    // Fits of a fixed size, so their loops unroll: a quartic takes
    // polynomials up to degree four, a septic the rest.
    let (septic, depth) = match interpolant {
        Interpolant::Polynomial { degree } => {
            debug_assert!(degree <= MAX_DEGREE, "no fit for degree {degree}");
            (degree > 4, MAX_DEPTH)
        }
        Interpolant::Other => (false, 0),
    };
    let piece = Piece {
        a: 0.0,
        b: 1.0,
        start,
        g_a: g0,
        check_start,
    };
    if septic {
        scan_piece::<8>(guard.direction, piece, resolution, &mut g, depth)
    } else {
        scan_piece::<5>(guard.direction, piece, resolution, &mut g, depth)
    }
}

/// What the step's dense output is, as far as event location cares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolant {
    /// A polynomial of at most this degree (at most seven) in the step
    /// time: the polynomial through `degree + 1` samples of an affine guard
    /// is the guard itself.
    Polynomial {
        /// The bound on the degree, at most seven.
        degree: usize,
    },
    /// Anything else (the exact linear propagator): pieces are halved until
    /// a quartic fits.
    Other,
}

/// A part `[a, b]` of the step, with the guard's value at `a` (`start` is
/// the value the scan treats it as having, see [`just_before_zero`]).
#[derive(Debug, Clone, Copy)]
struct Piece {
    a: f64,
    b: f64,
    start: f64,
    g_a: f64,
    check_start: bool,
}

/// The fraction of a piece's guard values below which a guard leaving zero
/// has not visibly moved (see [`leaves_zero`]).
const VISIBLE: f64 = 1e-10;
/// Halvings allowed when the interpolant is not a polynomial.
const MAX_DEPTH: u32 = 24;
/// A quartic fits a polynomial interpolant to round-off; a worse fit means
/// the interpolant is something else (the exact linear propagator).
const FIT_TOLERANCE: f64 = 1e-13;

/// Scan one piece with the polynomial of degree `N - 1` through `N`
/// equispaced samples of it. Where it misses the guard between the samples by more
/// than round-off and comes that close to zero, a crossing could hide in
/// the misfit: halve the piece and scan both halves.
fn scan_piece<const N: usize>(
    direction: Direction,
    piece: Piece,
    resolution: f64,
    g: &mut impl FnMut(f64) -> f64,
    depth: u32,
) -> StepScan {
    let Piece {
        a,
        b,
        start,
        g_a,
        check_start,
    } = piece;
    let w = b - a;
    let degree = N - 1;
    let step = 1.0 / degree as f64;
    let samples: [f64; N] = std::array::from_fn(|k| match k {
        0 => g_a,
        k if k == degree => g(b),
        k => g(a + k as f64 * step * w),
    });
    let fitted = polynomial_through(&samples);
    let poly = &fitted[..];
    // Most steps: the guard stays clearly on one side, which a bound on the
    // polynomial's variation shows without finding its turning points.
    let variation: f64 = poly[1..].iter().map(|c| c.abs()).sum();
    // (A start on exactly zero, a spent guard, has no side yet.)
    if depth >= MAX_DEPTH && !check_start && start != 0.0 && start.signum() == poly[0].signum() {
        let clearance = poly[0].abs() - variation;
        let before = match direction {
            Direction::Falling => poly[0] > 0.0,
            Direction::Rising => poly[0] < 0.0,
            Direction::Either => true,
        };
        if clearance > resolution && (before || direction == Direction::Either) {
            return StepScan::CLEAR;
        }
    }
    let turning = critical_points(poly);
    if depth < MAX_DEPTH {
        let scale = samples
            .iter()
            .fold(f64::MIN_POSITIVE, |m, v| m.max(v.abs()));
        let misfit = (0..degree)
            .map(|k| (k as f64 + 0.5) * step)
            .map(|u| (g(a + u * w) - eval_plain(poly, u)).abs())
            .fold(0.0, f64::max);
        let nearest = turning
            .iter()
            .chain(&[0.0, 1.0])
            .map(|u| eval_plain(poly, *u).abs())
            .fold(f64::INFINITY, f64::min);
        let crosses = samples.windows(2).any(|p| p[0].signum() != p[1].signum());
        if misfit > FIT_TOLERANCE * scale && (crosses || nearest <= 8.0 * misfit) {
            let mid = 0.5 * (a + b);
            let g_mid = g(mid);
            let left = scan_piece::<N>(
                direction,
                Piece { b: mid, ..piece },
                resolution,
                g,
                depth + 1,
            );
            if left.crossing.is_some() {
                return left;
            }
            // A guard armed on zero that is still exactly on zero at the
            // midpoint stays armed (see `scan_from`).
            let armed = start.abs() == f64::MIN_POSITIVE && g_mid == 0.0;
            let right_piece = Piece {
                a: mid,
                b,
                start: if armed { start } else { g_mid },
                g_a: g_mid,
                check_start: false,
            };
            let right = scan_piece::<N>(direction, right_piece, resolution, g, depth + 1);
            let nearer = if left.margin <= right.margin {
                left
            } else {
                right
            };
            return StepScan {
                crossing: right.crossing,
                ..nearer
            };
        }
    }
    // Only a polynomial that fits can say which way the guard leaves zero.
    let mut from = (a, start);
    if check_start {
        match leaves_zero(direction, poly, &samples) {
            Leaves::Inward => return StepScan::at(a),
            Leaves::Outward(u) if u > 0.0 => {
                let s = a + u * w;
                from = (s, g(s));
            }
            _ => {}
        }
    }
    let mut cuts = [b; MAX_DEGREE];
    for (cut, u) in cuts.iter_mut().zip(turning.iter()) {
        *cut = a + u * w;
    }
    let crossing = scan_from(
        direction,
        from.0,
        &cuts[..=turning.len()],
        from.1,
        g,
        &|s| eval_plain(poly, (s - a) / w),
    );
    let local = crossing.map(|s| (s - a) / w);
    let (margin, at) = margin(direction, poly, local, turning.as_slice());
    StepScan {
        crossing,
        margin,
        margin_at: a + at * w,
    }
}

/// See [`StepScan::margin`]: the margin, and where in `[0, 1]` it was
/// measured.
fn margin(
    direction: Direction,
    poly: &[f64],
    crossing: Option<f64>,
    turning: &[f64],
) -> (f64, f64) {
    // `inward` is the sign of the side a crossing goes to.
    let inward = match direction {
        Direction::Falling => -1.0,
        Direction::Rising => 1.0,
        Direction::Either => return (f64::INFINITY, 1.0),
    };
    match crossing {
        Some(s) => {
            let d1 = derivative(poly);
            let d2 = derivative(&d1[..poly.len() - 1]);
            let (slope, curvature) = (
                eval_plain(&d1[..poly.len() - 1], s),
                eval_plain(&d2[..poly.len().saturating_sub(2)], s),
            );
            if curvature * inward < 0.0 {
                (slope * slope / (2.0 * curvature.abs()), s)
            } else {
                (f64::INFINITY, 1.0)
            }
        }
        None => turning
            .iter()
            .map(|&s| (eval_plain(poly, s) * -inward, s))
            .filter(|(height, _)| *height > 0.0)
            .fold((f64::INFINITY, 1.0), |best, next| {
                if next.0 < best.0 { next } else { best }
            }),
    }
}

/// A value of the guard strictly on the side it crosses from.
fn just_before_zero(direction: Direction, g0: f64) -> f64 {
    match direction {
        Direction::Falling => f64::MIN_POSITIVE,
        Direction::Rising => -f64::MIN_POSITIVE,
        Direction::Either => g0,
    }
}

/// Walk the pieces `[a, cuts[0]], [cuts[0], cuts[1]], ...` and refine the
/// first one whose ends the direction accepts.
fn scan_from(
    direction: Direction,
    a: f64,
    cuts: &[f64],
    g_a: f64,
    g: &mut impl FnMut(f64) -> f64,
    fallback: &dyn Fn(f64) -> f64,
) -> Option<f64> {
    let (mut left, mut g_left) = (a, g_a);
    for &right in cuts {
        if right <= left {
            continue;
        }
        let g_right = g(right);
        // A guard that sat on zero (see `just_before_zero`) and is still
        // exactly there has not crossed yet (a packed unit at rest stays
        // packed); it stays armed for when it does leave zero.
        if g_right == 0.0 && g_left.abs() == f64::MIN_POSITIVE {
            left = right;
            continue;
        }
        if direction.accepts(g_left, g_right) {
            return Some(refine(left, g_left, right, g_right, g, fallback));
        }
        (left, g_left) = (right, g_right);
    }
    None
}

/// Which way a guard at `s = 0` after a reset goes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Leaves {
    /// On or past zero and moving further its way: it fires at once.
    Inward,
    /// Back the way it came, visibly so from this `s` (in the piece) on.
    Outward(f64),
    /// Still before zero, or not visibly moving within the piece: scanned
    /// as usual.
    Undecided,
}

/// Which way a directed guard that sits on (or just past) zero at `s = 0`
/// leaves it, read where the polynomial first moves from its start by
/// more than [`VISIBLE`] of the samples' size: a rate too small to show
/// before the curvature takes over is noise of the fit (the samples are
/// differences of states far larger than the guard) or an excursion far
/// below anything the step resolves.
fn leaves_zero(direction: Direction, poly: &[f64], samples: &[f64]) -> Leaves {
    // A guard of either direction on zero crosses whichever way it moves.
    let sign = match direction {
        Direction::Falling => -1.0,
        Direction::Rising => 1.0,
        Direction::Either => 0.0,
    };
    if poly[0] * sign < 0.0 {
        // Still before zero: it has not crossed, and the scan finds when it does.
        return Leaves::Undecided;
    }
    let floor = VISIBLE * samples.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let mut s = f64::EPSILON;
    while s <= 1.0 {
        let moved = eval_plain(poly, s) - poly[0];
        if moved.abs() > floor {
            return if sign == 0.0 || moved * sign > 0.0 {
                Leaves::Inward
            } else {
                Leaves::Outward(s)
            };
        }
        s *= 2.0;
    }
    Leaves::Undecided
}

#[cfg(test)]
mod tests {
    use super::*;

    const FALLING: Guard = Guard::affine("g", Direction::Falling);

    fn first_crossing(guard: &Guard, check_start: bool, g: impl FnMut(f64) -> f64) -> Option<f64> {
        let start = if check_start {
            Start::OnZero
        } else {
            Start::Armed
        };
        scan_step(
            guard,
            start,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            g,
        )
        .crossing
    }

    #[test]
    fn finds_a_dip_that_both_ends_of_the_step_miss() {
        // g(s) = (s - 0.4)(s - 0.6): positive at both ends, negative between.
        let root = first_crossing(&FALLING, false, |s| (s - 0.4) * (s - 0.6)).unwrap();
        assert!((root - 0.4).abs() < 1e-14, "root {root}");
    }

    #[test]
    fn finds_the_first_of_four_roots_of_a_quartic() {
        let g = |s: f64| (s - 0.1) * (s - 0.2) * (s - 0.7) * (s - 0.8);
        assert!((first_crossing(&FALLING, false, g).unwrap() - 0.1).abs() < 1e-14);
        let rising = Guard::affine("g", Direction::Rising);
        assert!((first_crossing(&rising, false, g).unwrap() - 0.2).abs() < 1e-14);
    }

    #[test]
    fn a_guard_leaving_zero_does_not_fire_again() {
        assert_eq!(first_crossing(&FALLING, true, |s| s * (1.2 - s)), None);
    }

    #[test]
    fn a_guard_on_zero_moving_in_fires_at_once_when_asked() {
        assert_eq!(first_crossing(&FALLING, true, |s| -s), Some(0.0));
        // Resting contact: zero value and rate, pushed through.
        assert_eq!(first_crossing(&FALLING, true, |s| -s * s), Some(0.0));
        // Without the start check it has not crossed (it never was before zero).
        assert_eq!(first_crossing(&FALLING, false, |s| -s), None);
    }

    #[test]
    fn a_return_to_zero_within_rounding_after_a_reset_still_fires() {
        // Rate 1e-30 after the reset: the guard's excursion above zero is far
        // below rounding of the step's samples, yet it must fire near 0.
        let g = |s: f64| 1e-30 * s - 0.25 * s * s;
        let root = first_crossing(&FALLING, true, g).unwrap();
        assert!(root < 1e-10, "root {root}");
        // Without the start check, a guard never seen above zero has not crossed.
        assert_eq!(
            first_crossing(&FALLING, false, |s: f64| -0.25 * s * s),
            None
        );
    }

    #[test]
    fn a_rate_lost_in_the_fit_does_not_decide_the_way_a_guard_leaves_zero() {
        // A shut unit opening (curvature 1.2e-6 over the step), computed as
        // a difference of states of size one (rounded to 1e-16) whose fit
        // carries a rate of -2e-15: it leaves zero upwards and must not fire
        // (seen in a cradle with DOP853).
        let g = |s: f64| ((-2e-15 * s + 1.2e-6 * s * s) / 1e-16).round() * 1e-16;
        for degree in [4, 7] {
            let scan = scan_step(
                &FALLING,
                Start::OnZero,
                Interpolant::Polynomial { degree },
                f64::INFINITY,
                g,
            );
            assert_eq!(scan.crossing, None, "degree {degree}");
        }
        // The same with the dip the noisy rate makes (-3e-24 deep at
        // s = 8e-10) really there: too shallow to be an event, not a graze.
        let dip = |s: f64| -2e-15 * s + 1.2e-6 * s * s;
        for degree in [4, 7] {
            let scan = scan_step(
                &FALLING,
                Start::OnZero,
                Interpolant::Polynomial { degree },
                1e-20,
                dip,
            );
            assert_eq!(scan.crossing, None, "degree {degree}");
            assert_eq!(scan.margin, f64::INFINITY, "degree {degree}");
        }
        // A rate that shows before the curvature takes over still decides.
        assert_eq!(
            first_crossing(&FALLING, true, |s| -1e-3 * s + 1.2e-6 * s * s),
            Some(0.0)
        );
    }

    #[test]
    fn a_guard_that_stays_on_zero_has_not_crossed() {
        // A packed unit at rest: the guard is zero all through the step.
        assert_eq!(first_crossing(&FALLING, true, |_| 0.0), None);
        // Zero (to rounding) for a while, then closing: it fires when it goes.
        let g = |s: f64| if s < 0.5 { 0.0 } else { -(s - 0.5) };
        let scan = scan_step(
            &FALLING,
            Start::OnZero,
            Interpolant::Other,
            f64::INFINITY,
            g,
        );
        let root = scan.crossing.unwrap();
        assert!((0.49..=0.51).contains(&root), "root {root}");
    }

    #[test]
    fn a_guard_just_past_zero_must_come_back_before_firing_again() {
        // Just fired (slightly past zero), goes further, returns, crosses again.
        let g = |s: f64| -1e-17 - s * (0.3 - s) * (0.7 - s);
        let root = first_crossing(&FALLING, false, g).unwrap();
        assert!((root - 0.7).abs() < 1e-14, "root {root}");
    }

    #[test]
    fn a_spent_guard_fires_only_after_it_comes_back() {
        // Located a rounding short of zero (the near side), going on
        // through: the crossing just fired is not found again...
        let rising = Guard::affine("g", Direction::Rising).as_crossing();
        let g = |s: f64| -1e-17 + s * (0.7 - s);
        let scan = scan_step(
            &rising,
            Start::Spent,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            g,
        );
        assert_eq!(scan.crossing, None);
        // ...while armed it would be, at once.
        let armed = scan_step(
            &rising,
            Start::Armed,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            g,
        );
        assert!(armed.crossing.is_some_and(|s| s < 1e-12));
        // Back below zero at 0.7 and up again at 0.9: that passage fires.
        let g = |s: f64| -1e-17 + s * (0.7 - s) * (0.9 - s);
        let root = scan_step(
            &rising,
            Start::Spent,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            g,
        )
        .crossing
        .unwrap();
        assert!((root - 0.9).abs() < 1e-14, "root {root}");
    }

    #[test]
    fn a_guard_of_either_direction_on_zero_fires_whichever_way_it_moves() {
        let either = Guard::affine("g", Direction::Either);
        for sign in [1.0, -1.0] {
            let scan = scan_step(
                &either,
                Start::OnZero,
                Interpolant::Polynomial { degree: 4 },
                f64::INFINITY,
                |s| sign * s,
            );
            assert_eq!(scan.crossing, Some(0.0), "sign {sign}");
        }
    }

    #[test]
    fn returns_the_side_that_has_crossed() {
        let root = first_crossing(&FALLING, false, |s| 0.3 - s).unwrap();
        assert!(0.3 - root <= 0.0 && 0.3 - root > -1e-15);
    }

    #[test]
    fn a_graze_has_a_small_margin_and_an_impact_a_large_one() {
        // Dips to -1e-6 and back: margin = depth = 1e-6.
        let graze = scan_step(
            &FALLING,
            Start::Armed,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            |s| (s - 0.5).powi(2) - 1e-6,
        );
        assert!(graze.crossing.is_some());
        assert!(
            (graze.margin - 1e-6).abs() < 1e-12,
            "margin {}",
            graze.margin
        );
        // Turns back 1e-6 short of zero: a near miss, margin 1e-6.
        let miss = scan_step(
            &FALLING,
            Start::Armed,
            Interpolant::Polynomial { degree: 4 },
            f64::INFINITY,
            |s| (s - 0.5).powi(2) + 1e-6,
        );
        assert_eq!(miss.crossing, None);
        assert!((miss.margin - 1e-6).abs() < 1e-12);
        // Accelerating through zero: nothing to decide.
        assert_eq!(
            scan_step(
                &FALLING,
                Start::Armed,
                Interpolant::Polynomial { degree: 4 },
                f64::INFINITY,
                |s| 0.1 - s * s
            )
            .margin,
            f64::INFINITY
        );
    }

    #[test]
    fn a_dip_hidden_in_the_misfit_of_a_non_polynomial_guard_is_found() {
        // Not a polynomial: a narrow dip 1e-9 deep around s = 0.3. A quartic
        // through five samples cannot see it; halving until the fit is
        // exact does.
        let g = |s: f64| 1e-3 + (s - 0.3).powi(2) - 1.001e-3 * (-((s - 0.3) / 0.01).powi(2)).exp();
        let scan = scan_step(&FALLING, Start::Armed, Interpolant::Other, f64::INFINITY, g);
        let root = scan.crossing.expect("the dip must be found");
        assert!((root - 0.3).abs() < 0.01, "root {root}");
        assert!(g(root) <= 0.0 && g(root - 1e-9) > 0.0);
    }

    #[test]
    fn sampled_guards_find_sign_changes() {
        let guard = Guard {
            affine: false,
            ..FALLING
        };
        let root = first_crossing(&guard, false, |s| (3.0 * s).cos()).unwrap();
        assert!((root - std::f64::consts::FRAC_PI_6).abs() < 1e-14);
    }
}
