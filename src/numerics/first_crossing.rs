//! Taylor polynomials of exact flows: evaluation, and the certified first
//! crossing of zero on an interval.
//!
//! A model that propagates its state by truncated Taylor series (with a
//! truncation bound below round-off) has each guard as a polynomial
//! `p(s) = sum c_k s^k` in the time `s` since the series' origin. Its next
//! event is the first `s` in `(a, b]` where `p` falls from positive to zero.
//! [`first_fall`] finds it without sampling: on each piece of the interval
//! it bounds `p` from below by its second-order expansion at the piece's
//! left end plus a bound on `p'''` over the whole interval, so a piece is
//! either proven free of a falling crossing, proven monotone with one
//! root (then refined), or halved. Pieces are visited left to right, so the
//! first root found is the earliest; none can be missed.

use crate::numerics::fused::mul_add;
use crate::numerics::polynomial::{eval, shift};

/// `(p(s), p'(s), p''(s))` of `p = sum c[k] s^k`.
pub fn eval2(c: &[f64], s: f64) -> (f64, f64, f64) {
    if s == 0.0 {
        // A series searched from its own origin, the common case: the sums
        // below would come to the same numbers, one dependent step per
        // coefficient later.
        let at = |k: usize| c.get(k).copied().unwrap_or(0.0);
        return (at(0), at(1), 2.0 * at(2));
    }
    let (mut p, mut d1, mut d2) = (0.0, 0.0, 0.0);
    for &ck in c.iter().rev() {
        d2 = mul_add(d2, s, 2.0 * d1);
        d1 = mul_add(d1, s, p);
        p = mul_add(p, s, ck);
    }
    (p, d1, d2)
}

/// `(p(s), p'(s), p''(s), sum |c[k]| |s|^k)`: the last bounds the rounding
/// of `p(s)` (relative, a few ulps of it).
fn eval2_with_size(c: &[f64], s: f64) -> (f64, f64, f64, f64) {
    let (mut p, mut d1, mut d2, mut size) = (0.0, 0.0, 0.0, 0.0);
    let a = s.abs();
    for &ck in c.iter().rev() {
        d2 = mul_add(d2, s, 2.0 * d1);
        d1 = mul_add(d1, s, p);
        p = mul_add(p, s, ck);
        size = mul_add(size, a, ck.abs());
    }
    (p, d1, d2, size)
}

/// The integral of `p` from 0 to `s`.
pub fn integral(c: &[f64], s: f64) -> f64 {
    let k = c.len() as f64;
    c.iter()
        .rev()
        .enumerate()
        .fold(0.0, |acc, (i, &ck)| acc * s + ck / (k - i as f64))
        * s
}

/// `k (k-1) (k-2)` for the orders of the series most models use, tabled:
/// a chain's root searches would otherwise convert each order to a float.
const FALLING: [f64; 32] = {
    let mut falling = [0.0; 32];
    let mut k = 3;
    while k < 32 {
        falling[k] = (k * (k - 1) * (k - 2)) as f64;
        k += 1;
    }
    falling
};

/// A bound on `|p'''|` over `[0, b]`: `sum |c_k| k (k-1) (k-2) b^(k-3)`.
fn third_derivative_bound(c: &[f64], b: f64) -> f64 {
    let mut bound = 0.0;
    for (k, &ck) in c.iter().enumerate().skip(3).rev() {
        let weight = FALLING.get(k).copied().unwrap_or_else(|| {
            let k = k as f64;
            k * (k - 1.0) * (k - 2.0)
        });
        bound = mul_add(bound, b, ck.abs() * weight);
    }
    // Rounding in the sum above is relative and tiny; pad it all the same.
    bound * (1.0 + 1e-12)
}

/// Deepest halving of the interval: below it a piece is narrower than the
/// floats can tell apart, and the computed sign decides (a graze within
/// round-off).
const MAX_DEPTH: u32 = 80;

/// Most pieces examined before the search gives up (an error, never a
/// guess): a polynomial that hugs zero within round-off over a long
/// stretch must not cost exponential time.
const MAX_PIECES: u32 = 4096;

/// Longest series [`Piece::classify_shifted`] re-expands.
const MAX_SHIFTED: usize = 64;

/// The first `s` in `(a, b]` (`0 <= a <= b`) where `p` crosses zero falling
/// (from positive to `<= 0`), or `Some(a)` if `p(a) <= 0` and `p` is moving
/// down through zero at `a` already (its first nonzero derivative there is
/// negative). `None` if there is none: in particular a `p` that rises from
/// zero, or stays exactly on it, has not crossed. An error if the bounds
/// cannot decide within 4096 pieces.
pub fn first_fall(c: &[f64], a: f64, b: f64) -> Result<Option<f64>, String> {
    // Cheap proof of no root, the common case: p(s) >= c_0 - sum |c_k| b^k
    // on [0, b]. A constant p never crosses either.
    let reach = c
        .iter()
        .skip(1)
        .rev()
        .fold(0.0, |acc, ck| mul_add(acc, b, ck.abs()))
        * b;
    let constant = c.first().copied().unwrap_or(0.0);
    if constant - reach * (1.0 + 1e-12) > 0.0 || reach == 0.0 {
        return Ok(None);
    }
    search_fall(c, a, b)
}

/// [`first_fall`] without its first, cheap proof that `p` stays above
/// zero on `[0, b]` (`c_0 > sum_{k >= 1} |c_k| b^k`, or `p` constant), for a
/// caller that has tried that proof, or an equivalent one, already. The
/// search is complete without it, only slower where it would have settled
/// the question.
pub fn search_fall(c: &[f64], a: f64, b: f64) -> Result<Option<f64>, String> {
    let (mut from, mut at) = (a, eval2(c, a));
    if at.0 <= 0.0 {
        // On (or a round-off below) zero: the first derivative that is not
        // zero says whether p is going down through it now.
        let shifted = shifted_to(c, a, at);
        match shifted.iter().skip(1).copied().find(|&x| x != 0.0) {
            Some(slope) if slope < 0.0 => return Ok(Some(a)),
            // Stays exactly on zero.
            None => return Ok(None),
            Some(_) if at.0 < 0.0 => {}
            // Rising from exactly zero: prove it positive on (a, a + h]
            // and search on from there.
            Some(_) if b <= a => return Ok(None),
            Some(_) => match lift(&shifted, b - a) {
                Some(h) if a + h >= b => return Ok(None),
                Some(h) => (from, at) = (a + h, eval2(c, a + h)),
                None => return Err(format!("cannot tell which way p leaves zero at {a:e}")),
            },
        }
        // The proven lift may be below round-off: if p already reads zero
        // and falling there, that is where it crosses.
        if at.0 <= 0.0 && at.1 < 0.0 {
            return Ok(Some(from));
        }
    }
    let bound = Piece {
        c,
        third: third_derivative_bound(c, b),
        budget: std::cell::Cell::new(MAX_PIECES),
        gave_up: std::cell::Cell::new(false),
    };
    let end = eval(c, b);
    // Falling all the way from above zero to below it (most impacts' steps,
    // a guard's approach): one root, refined at once, where the pieces
    // would halve the step until one of them showed as much.
    if at.0 > 0.0 && end <= 0.0 && falls_throughout(c, b) {
        return Ok(Some(bound.refine((from, at), (b, end))));
    }
    let root = bound.search((from, b), (at, end), &mut None, 0);
    if bound.gave_up.get() {
        return Err(format!(
            "the first root on [{a:e}, {b:e}] could not be isolated within {MAX_PIECES} pieces \
             (the polynomial stays within round-off of zero over a stretch)"
        ));
    }
    Ok(root)
}

/// Whether `p' < 0` on all of `[0, b]`: below the convex quadratic
/// `c_1 + 2 c_2 s + R s^2`, `R = sum_{k >= 3} max(0, k c_k) b^(k - 3)` (the
/// rising terms at their largest, `s^(k - 1) <= s^2 b^(k - 3)`), which is
/// largest at an end of the step.
fn falls_throughout(c: &[f64], b: f64) -> bool {
    let (Some(&c1), Some(&c2)) = (c.get(1), c.get(2)) else {
        return c.get(1).is_some_and(|&c1| c1 < 0.0);
    };
    let rising = (c.iter().enumerate().skip(3).rev()).fold(0.0, |acc, (k, ck)| {
        mul_add(acc, b, (k as f64 * ck).max(0.0))
    });
    let at_end = c1 + 2.0 * c2 * b + rising * b * b;
    let pad = 1e-12 * (c1.abs() + 2.0 * (c2 * b).abs() + rising * b * b);
    c1 < 0.0 && at_end + pad < 0.0
}

/// The coefficients of `p(a + h)` in `h`: `p^(k)(a) / k!`. The first three
/// are taken from `(p, p', p'')` at `a` as already evaluated (the same
/// numbers the caller decided on); the rest by a Taylor shift (synthetic
/// division), which only a zero of `p` at `a` needs.
fn shifted_to(c: &[f64], a: f64, (p, d1, d2): (f64, f64, f64)) -> Vec<f64> {
    let mut shifted = c.to_vec();
    // At `a = 0` (a series that starts at the event just past) nothing
    // moves.
    shift(&mut shifted, a);
    for (k, x) in [p, d1, 0.5 * d2].into_iter().enumerate() {
        if let Some(s) = shifted.get_mut(k) {
            *s = x;
        }
    }
    shifted
}

/// A width `h <= width` over which `sum_k s_k h^k`, zero at `h = 0` with
/// its first nonzero coefficient `s_m > 0`, is provably positive:
/// `s_m > sum_{k > m} |s_k| h^(k - m)`.
fn lift(shifted: &[f64], width: f64) -> Option<f64> {
    let m = shifted.iter().skip(1).position(|&x| x != 0.0)? + 1;
    let mut h = width;
    while h > 0.0 {
        let rest = shifted[m + 1..]
            .iter()
            .rev()
            .fold(0.0, |acc, sk| (acc + sk.abs()) * h);
        if shifted[m] - rest * (1.0 + 1e-12) > 0.0 {
            return Some(h);
        }
        h *= 0.5;
    }
    None
}

struct Piece<'c> {
    c: &'c [f64],
    third: f64,
    /// Pieces left to examine: a polynomial that hugs zero within
    /// round-off over a long stretch must not cost exponential time.
    budget: std::cell::Cell<u32>,
    /// Set when a piece was left undecided for want of budget.
    gave_up: std::cell::Cell<bool>,
}

enum Verdict {
    /// No falling crossing on the piece.
    Clear,
    /// Strictly decreasing on it, from positive to `<= 0`: one root.
    Root,
    Unknown,
}

/// A piece's polynomial re-expanded at its left end, once computed: the
/// left half of a piece has the same left end, and the same expansion.
type Shifted = Option<[f64; MAX_SHIFTED]>;

impl Piece<'_> {
    /// The first falling crossing on `[x0, x1]`, given `(p, p', p'')` at
    /// `x0` and `p` at `x1`, and the expansion at `x0` where known. Each
    /// value is computed once: a half takes its ends' values from its
    /// parent (`p` at the middle from the same Horner sum as alone).
    fn search(
        &self,
        (x0, x1): (f64, f64),
        (at0, end): ((f64, f64, f64), f64),
        shifted: &mut Shifted,
        depth: u32,
    ) -> Option<f64> {
        let verdict = match self.classify(x1 - x0, at0, end) {
            Verdict::Unknown => self.classify_shifted(x0, x1 - x0, end, shifted),
            known => known,
        };
        match verdict {
            Verdict::Clear => None,
            Verdict::Root => Some(self.refine((x0, at0), (x1, end))),
            Verdict::Unknown => {
                let mid = 0.5 * (x0 + x1);
                let budget = self.budget.get();
                if budget == 0 {
                    // Given up; `first_fall` reports it.
                    self.gave_up.set(true);
                    return None;
                }
                self.budget.set(budget - 1);
                if depth >= MAX_DEPTH || mid <= x0 || mid >= x1 {
                    // A graze narrower than round-off: the computed sign decides.
                    return (at0.0 > 0.0 && end <= 0.0).then_some(x1);
                }
                let at_mid = eval2(self.c, mid);
                self.search((x0, mid), (at0, at_mid.0), shifted, depth + 1)
                    .or_else(|| self.search((mid, x1), (at_mid, end), &mut None, depth + 1))
            }
        }
    }

    /// What the expansion at the left end (value `p`, slope `d1`, curvature
    /// `d2`) and the bound on the third derivative prove over a piece of
    /// width `w` whose right end has the value `end`.
    fn classify(&self, w: f64, (p, d1, d2): (f64, f64, f64), end: f64) -> Verdict {
        // |p''| <= curvature on the piece, so the slope stays within
        // d1 +- curvature w and p >= p + d1 h - curvature h^2 / 2.
        let curvature = d2.abs() + self.third * w;
        if d1 - curvature * w > 0.0 {
            // Strictly rising: nothing falls.
            return Verdict::Clear;
        }
        if d1 + curvature * w < 0.0 {
            // Strictly falling: a root only if it starts above zero and ends
            // at or below it (from below zero it never was positive).
            return if p > 0.0 && end <= 0.0 {
                Verdict::Root
            } else {
                Verdict::Clear
            };
        }
        let lowest_at_end = p + d1 * w - 0.5 * curvature * w * w;
        let above = p > 0.0 && lowest_at_end > 0.0;
        // Below zero throughout (p is at most the larger of its start and
        // p + d1 w + curvature w^2 / 2): never positive, nothing to fall
        // from. A turning point's search meets this at every crossing.
        let below = p < 0.0 && p + d1 * w + 0.5 * curvature * w * w < 0.0;
        // From exactly zero, rising faster than the curvature can turn it.
        let lifting = p == 0.0 && d1 - 0.5 * curvature * w > 0.0;
        if above || below || lifting {
            Verdict::Clear
        } else {
            Verdict::Unknown
        }
    }

    /// The same questions answered from the series re-expanded at `x0`
    /// (O(K^2), so only where the cheap bounds failed): on `[0, w]`,
    /// `p >= c_0 + sum_k min(0, c_k) h^k`, and `p'` lies between `c_1 +
    /// sum_k min(0, k c_k) h^(k-1)` and the same with `max`. Unlike a bound
    /// on the third derivative over the whole interval, these follow a
    /// polynomial that is flat to many orders at `x0` (a unit shut and at
    /// rest, its neighbours just starting to move).
    fn classify_shifted(&self, x0: f64, w: f64, end: f64, shifted: &mut Shifted) -> Verdict {
        let len = self.c.len();
        if len > MAX_SHIFTED {
            return Verdict::Unknown;
        }
        let c: &[f64] = match shifted {
            Some(c) => c,
            None => {
                // Written where it is kept: a copy would cost a search
                // that one piece settles as much as the shift.
                let c = shifted.insert([0.0; MAX_SHIFTED]);
                c[..len].copy_from_slice(self.c);
                // From the series' own origin (most searches) nothing moves.
                shift(&mut c[..len], x0);
                c
            }
        };
        let c = &c[..len];
        let (mut low, mut high) = (c[0], c[0]);
        let (mut slope_low, mut slope_high) = (
            c.get(1).copied().unwrap_or(0.0),
            c.get(1).copied().unwrap_or(0.0),
        );
        let mut power = 1.0;
        for (k, &ck) in c.iter().enumerate().skip(1) {
            // power = w^(k-1) here.
            low += ck.min(0.0) * power * w;
            high += ck.max(0.0) * power * w;
            if k >= 2 {
                let term = k as f64 * ck * power;
                slope_low += term.min(0.0);
                slope_high += term.max(0.0);
            }
            power *= w;
        }
        let pad = 1e-12;
        if slope_low > 0.0 && slope_low.abs() > pad * slope_high.abs() {
            return Verdict::Clear;
        }
        if slope_high < 0.0 {
            return if c[0] > 0.0 && end <= 0.0 {
                Verdict::Root
            } else {
                Verdict::Clear
            };
        }
        if c[0] > 0.0 && low > pad * c[0] {
            return Verdict::Clear;
        }
        if c[0] < 0.0 && high < pad * c[0] {
            // Never positive: nothing to fall from.
            return Verdict::Clear;
        }
        Verdict::Unknown
    }

    /// The root of a strictly decreasing `p` on `[lo, hi]` with `p(lo) > 0 >=
    /// p(hi)` (value, slope and curvature at `lo` given), to a few ulps or
    /// until `p` is zero to rounding: Newton's method, kept inside the
    /// bracket (bisecting when a step leaves it).
    fn refine(&self, (mut lo, at_lo): (f64, (f64, f64, f64)), (mut hi, p_hi): (f64, f64)) -> f64 {
        // Start from the root of the second-order expansion at `lo`, off
        // by the third-order term only (a Newton step or two from the
        // root); the secant point if that root is not in the bracket.
        let (p_lo, d1, d2) = at_lo;
        let denominator = -d1 + (d1 * d1 - 2.0 * d2 * p_lo).max(0.0).sqrt();
        let mut quadratic = lo + 2.0 * p_lo / denominator;
        if lo == 0.0 && self.c.len() > 4 {
            // At the series' origin (most searches) the third- and
            // fourth-order terms are at hand: a Newton step on the quartic
            // leaves the guess off by the fifth-order term, so the first
            // full evaluation's step most often lands within half an ulp.
            let (h, c3, c4) = (quadratic, self.c[3], self.c[4]);
            let slope = d1 + d2 * h + (3.0 * c3 + 4.0 * c4 * h) * h * h;
            quadratic = h - (c3 + c4 * h) * h * h * h / slope;
        }
        let secant = lo + (hi - lo) * p_lo / (p_lo - p_hi);
        let mut x = if quadratic > lo && quadratic < hi {
            quadratic
        } else if secant > lo && secant < hi {
            secant
        } else {
            0.5 * (lo + hi)
        };
        for _ in 0..100 {
            let (p, d1, d2, size) = eval2_with_size(self.c, x);
            if p > 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            let newton = x - p / d1;
            // Zero to rounding: further Newton steps would only chase the
            // noise of the evaluation (a slow closing makes that noise a
            // step far wider than a few ulps of x).
            if p.abs() <= 4.0 * f64::EPSILON * size {
                // One last step, from values already in hand, lands
                // within that noise, most often far inside it.
                if newton >= lo && newton <= hi {
                    x = newton;
                }
                break;
            }
            // Newton's step leaves an error of at most |p''| / (2 |p'|)
            // times its square, |p''| taken over the step (its value here
            // plus the bound on p''' times the step: near an inflection
            // the value here alone could be zero). Below half an ulp of the
            // root, the step lands on it and one more evaluation could
            // only confirm it. (Multiplied out: a second division would
            // wait on the first.)
            let step = newton - x;
            let curvature = d2.abs() + self.third * step.abs();
            if newton > lo
                && newton < hi
                && curvature * step * step <= 0.5 * f64::EPSILON * newton.abs() * d1.abs()
            {
                x = newton;
                break;
            }
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if (next - x).abs() <= 4.0 * f64::EPSILON * x.abs() || next <= lo || next >= hi {
                break;
            }
            x = next;
        }
        // Converged, or the bracket closed to adjacent floats: the last
        // iterate is within a few ulps of the root, on either side.
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Coefficients of `prod (s - r_i)` times `scale`.
    fn from_roots(roots: &[f64], scale: f64) -> Vec<f64> {
        let mut c = vec![scale];
        for &r in roots {
            let mut next = vec![0.0; c.len() + 1];
            for (k, &ck) in c.iter().enumerate() {
                next[k + 1] += ck;
                next[k] -= r * ck;
            }
            c = next;
        }
        c
    }

    #[test]
    fn the_third_derivative_bound_sums_each_order_weighed_alone() {
        // Orders past the tabled ones too: both ways of weighing agree.
        let c: Vec<f64> = (0..40)
            .map(|k| (-0.7f64).powi(k) / (k + 1) as f64)
            .collect();
        let b: f64 = 0.9;
        let by_hand: f64 = (3..c.len())
            .map(|k| {
                let k_f = k as f64;
                c[k].abs() * k_f * (k_f - 1.0) * (k_f - 2.0) * b.powi(k as i32 - 3)
            })
            .sum();
        let bound = third_derivative_bound(&c, b);
        assert!(bound >= by_hand, "{bound} < {by_hand}");
        assert!(bound <= by_hand * (1.0 + 1e-10), "{bound} > {by_hand}");
    }

    #[test]
    fn evaluation_with_derivatives_matches_the_expanded_forms() {
        let c = [1.0, -2.0, 0.5, 3.0];
        let s: f64 = 0.7;
        let (p, d1, d2) = eval2(&c, s);
        assert!((p - (1.0 - 2.0 * s + 0.5 * s * s + 3.0 * s.powi(3))).abs() < 1e-15);
        assert!((d1 - (-2.0 + s + 9.0 * s * s)).abs() < 1e-15);
        assert!((d2 - (1.0 + 18.0 * s)).abs() < 1e-14);
        assert!((integral(&c, s) - (s - s * s + s.powi(3) / 6.0 + 0.75 * s.powi(4))).abs() < 1e-15);
    }

    #[test]
    fn finds_the_first_of_several_falling_roots() {
        // Positive at 0; falls through 0.3, rises through 0.5, falls through 0.9.
        let c = from_roots(&[0.3, 0.5, 0.9], -1.0);
        let s = first_fall(&c, 0.0, 1.0).unwrap().unwrap();
        assert!((s - 0.3).abs() < 1e-15, "{s}");
        let s = first_fall(&c, 0.6, 1.0).unwrap().unwrap();
        assert!((s - 0.9).abs() < 1e-15, "{s}");
    }

    #[test]
    fn a_double_crossing_inside_a_short_dip_is_not_missed() {
        // Dips below zero between 0.4 and 0.4 + 1e-6 only; the root of a
        // dip that narrow is conditioned to about eps / 1e-6.
        let c = from_roots(&[0.4, 0.4 + 1e-6], 1.0);
        let s = first_fall(&c, 0.0, 1.0).unwrap().unwrap();
        assert!((s - 0.4).abs() < 1e-9, "{s}");
        // A dip that stays 1e-12 above zero never crosses.
        let mut c = from_roots(&[0.4, 0.4], 1.0);
        c[0] += 1e-12;
        assert_eq!(first_fall(&c, 0.0, 1.0).unwrap(), None);
    }

    #[test]
    fn rising_from_zero_or_staying_on_it_is_not_a_crossing() {
        assert_eq!(first_fall(&[0.0, 1.0, -0.1], 0.0, 1.0).unwrap(), None);
        assert_eq!(first_fall(&[0.0, 0.0, 0.0], 0.0, 1.0).unwrap(), None);
        assert_eq!(first_fall(&[0.0, 0.0, 1.0], 0.0, 1.0).unwrap(), None);
        // A triple zero falling through (p = -(s - 0.5)^3 at 0.5) fires now;
        // rising through it does not.
        let c = from_roots(&[0.5, 0.5, 0.5], -1.0);
        assert_eq!(first_fall(&c, 0.5, 1.0).unwrap(), Some(0.5));
        let c = from_roots(&[0.5, 0.5, 0.5], 1.0);
        assert_eq!(first_fall(&c, 0.5, 1.0).unwrap(), None);
        // Closing through zero right now fires now.
        assert_eq!(first_fall(&[0.0, -1.0], 0.0, 1.0).unwrap(), Some(0.0));
        assert_eq!(
            first_fall(&[-1e-18, 1.0, -4.0], 0.0, 1.0)
                .unwrap()
                .map(|s| (s - 0.25).abs() < 1e-9),
            Some(true)
        );
    }

    #[test]
    fn the_root_is_within_a_few_ulps() {
        let c = [1.0, -3.0, 0.5];
        let s = first_fall(&c, 0.0, 1.0).unwrap().unwrap();
        let exact = 3.0 - 7.0f64.sqrt();
        assert!(
            (s - exact).abs() <= 8.0 * f64::EPSILON * exact,
            "{s} {exact}"
        );
    }

    #[test]
    fn a_fall_all_the_way_is_proven_and_a_turn_is_not() {
        // p' = -2 + s - 0.3 s^2 < 0 on [0, 1]; p' = -1 + 2 s turns at 1/2;
        // p' = 0.1 + ... rises at the start.
        assert!(falls_throughout(&[1.0, -2.0, 0.5, -0.1], 1.0));
        assert!(!falls_throughout(&[1.0, -1.0, 1.0], 1.0));
        assert!(!falls_throughout(&[1.0, 0.1, -1.0], 1.0));
        // Its largest rising term counts at the step's end: -1 + 0.9 s^2
        // falls on [0, 1], not on [0, 1.1].
        assert!(falls_throughout(&[1.0, -1.0, 0.0, 0.3], 1.0));
        assert!(!falls_throughout(&[1.0, -1.0, 0.0, 0.3], 1.1));
        // The root it then refines: (1 - 2 s)(1 + s^2), from 1 down
        // through 1/2.
        let c = [1.0, -2.0, 1.0, -2.0];
        assert!(falls_throughout(&c, 0.9));
        let root = first_fall(&c, 0.0, 0.9).unwrap().unwrap();
        assert!((root - 0.5).abs() <= 4.0 * f64::EPSILON, "{root}");
    }

    #[test]
    fn newton_does_not_stop_early_at_an_inflection() {
        // p = 0.1 - u - 10 u^3, u = s - 0.5: falling everywhere, root near
        // s = 0.5922, an inflection at s = 0.5 where p'' = 0. A first guess
        // there (the bracket's start values are chosen to put it there)
        // takes a Newton step of 0.1 whose error p'' alone would call zero.
        // 0.1 - (s - 0.5) - 10 (s - 0.5)^3 in powers of s.
        let c = [0.1 + 0.5 + 1.25, -1.0 - 7.5, 15.0, -10.0];
        let p = |s: f64| eval(&c, s);
        let piece = Piece {
            c: &c,
            third: third_derivative_bound(&c, 1.0),
            budget: std::cell::Cell::new(MAX_PIECES),
            gave_up: std::cell::Cell::new(false),
        };
        let (lo, hi) = (0.4, 1.0);
        assert!(p(lo) > 0.0 && p(hi) < 0.0);
        let root = piece.refine((lo, (0.1, -1.0, 0.0)), (hi, p(hi)));
        // The root solves u + 10 u^3 = 0.1.
        let u = root - 0.5;
        assert!((u + 10.0 * u * u * u - 0.1).abs() < 1e-15, "{root}");
        // And p is zero there to the rounding of its evaluation.
        let size: f64 = c.iter().rev().fold(0.0, |acc, x| acc * root + x.abs());
        assert!(p(root).abs() <= 4.0 * f64::EPSILON * size, "{root}");
    }

    /// A guard's slope at the guard's own crossing (a section's `-px` where
    /// `x` crosses: below zero, flat, curving up) never rises above zero:
    /// nothing falls, settled on the whole interval at once rather than by
    /// halving toward the flat start; and a polynomial that does climb
    /// above zero and fall back is still caught.
    #[test]
    fn staying_below_zero_is_settled_at_once() {
        let flat_minimum = [-0.2765, 0.0, 0.0504, 0.001];
        let piece = Piece {
            c: &flat_minimum,
            third: third_derivative_bound(&flat_minimum, 0.19),
            budget: std::cell::Cell::new(MAX_PIECES),
            gave_up: std::cell::Cell::new(false),
        };
        let at0 = eval2(&flat_minimum, 0.0);
        let end = eval(&flat_minimum, 0.19);
        assert_eq!(piece.search((0.0, 0.19), (at0, end), &mut None, 0), None);
        assert_eq!(piece.budget.get(), MAX_PIECES, "no piece was halved");
        assert_eq!(search_fall(&flat_minimum, 0.0, 0.19).unwrap(), None);
        // -0.1 + s^2 - s^3 / 0.9: up through zero near 0.35, back down near 0.8.
        let climbs = [-0.1, 0.0, 1.0, -1.0 / 0.9];
        let s = search_fall(&climbs, 0.0, 1.0).unwrap().expect("falls back");
        assert!(eval(&climbs, s).abs() < 1e-15 && s > 0.5, "{s}");
    }

    #[test]
    fn the_search_alone_settles_what_the_cheap_bound_would() {
        // Without the cheap bound in front, the search itself must clear a
        // gap that stays positive or constant, and still find roots.
        let stays_positive = [1.0, 0.1, -0.2]; // 1 + 0.1 s - 0.2 s^2 >= 0.9
        assert_eq!(search_fall(&stays_positive, 0.0, 1.0).unwrap(), None);
        assert_eq!(search_fall(&[0.5], 0.0, 1.0).unwrap(), None);
        assert_eq!(search_fall(&[-0.5], 0.0, 1.0).unwrap(), None);
        assert_eq!(search_fall(&[0.0, 0.0, 0.0], 0.0, 1.0).unwrap(), None);
        let c = from_roots(&[0.3, 0.5, 0.9], -1.0);
        for (from, root) in [(0.0, 0.3), (0.6, 0.9)] {
            let s = search_fall(&c, from, 1.0).unwrap().unwrap();
            assert!((s - root).abs() < 1e-15, "{s} {root}");
        }
        assert_eq!(search_fall(&[0.0, 1.0, -0.1], 0.0, 1.0).unwrap(), None);
    }

    #[test]
    fn roots_of_higher_degree_are_within_their_conditioning() {
        // The second-order start is off by the higher terms here: the
        // refinement must still end within a few ulps, whichever way it
        // stops.
        for (roots, scale) in [
            (vec![0.3, 0.7, 1.2], -1.0),
            (vec![0.01234, 0.5, 0.8, 1.5, 2.0], -1.0),
            (vec![0.3333, 0.34, 3.0, -1.0, -2.0, 4.0, 5.0], -2.5),
        ] {
            let c = from_roots(&roots, scale);
            let s = first_fall(&c, 0.0, 1.0).unwrap().unwrap();
            // A root is conditioned to the rounding of p there over |p'|
            // (wide for the two close roots of the last case).
            let r = roots[0];
            let size: f64 = c
                .iter()
                .enumerate()
                .map(|(k, x)| x.abs() * r.powi(k as i32))
                .sum();
            let slope = eval2(&c, r).1.abs();
            let conditioned = 4.0 * f64::EPSILON * (r + size / slope);
            assert!((s - r).abs() <= conditioned, "{s} {r} {conditioned:e}");
        }
    }
}
