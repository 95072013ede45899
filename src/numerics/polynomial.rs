//! Polynomials `p(s) = sum c[k] s^k` (coefficients from the constant term
//! up): one Horner evaluator, with the multiply-add step as a parameter.
//!
//! Event location on a Runge-Kutta dense output rounds each step twice
//! ([`eval_plain`]), as it always has; the chain's Taylor series fuse each
//! step into one rounding where the target can ([`eval`]). The two differ
//! in the last bits only, and each keeps the results it was tested with.

use crate::numerics::double_double::two_sum;
use crate::numerics::fused::mul_add;

/// `p(s)` by Horner's rule, each step `step(acc, s, c[k])`.
#[inline(always)]
fn horner(c: &[f64], s: f64, step: impl Fn(f64, f64, f64) -> f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &ck| step(acc, s, ck))
}

/// `p(s)`, each step fused where the target has FMA.
pub fn eval(c: &[f64], s: f64) -> f64 {
    horner(c, s, mul_add)
}

/// `p(s)`, each step `acc * s + c` with two roundings.
pub fn eval_plain(c: &[f64], s: f64) -> f64 {
    horner(c, s, |acc, s, ck| acc * s + ck)
}

/// `p(s)` by compensated Horner (Graillat, Langlois and Louvet): each
/// step's rounding errors, found exactly (a fused multiply-add gives the
/// product's, Knuth's two-sum the sum's), are summed by a second Horner
/// pass and added at the end. The result is as accurate as Horner's rule
/// in twice the working precision, rounded once: what a Taylor step's state
/// needs, whose terms cancel to a few times less than their sum.
pub fn eval_compensated(c: &[f64], s: f64) -> f64 {
    eval_compensated_plus(c, s, -0.0)
}

/// `p(s) + extra` by compensated Horner (see [`eval_compensated`]), with
/// `extra` (a term far below `p(s)`: a residual the coefficients could not
/// hold) added to the error terms before the one rounding.
pub fn eval_compensated_plus(c: &[f64], s: f64, extra: f64) -> f64 {
    let Some((&last, rest)) = c.split_last() else {
        return extra;
    };
    let (mut sum, mut error) = (last, 0.0);
    for &ck in rest.iter().rev() {
        let product = sum * s;
        let product_error = sum.mul_add(s, -product);
        let next = product + ck;
        let t = next - product;
        let sum_error = (product - (next - t)) + (ck - t);
        error = error * s + (product_error + sum_error);
        sum = next;
    }
    sum + (error + extra)
}

/// Re-expand `c` about `a`, in place: the coefficients of `p(a + s)` in
/// `s` (a Taylor shift by synthetic division, O(len^2)). At `a = 0` there
/// is nothing to shift, and nothing is done (the sums would only add
/// zeros).
pub fn shift(c: &mut [f64], a: f64) {
    let len = c.len();
    for k in (0..len).filter(|_| a != 0.0) {
        for j in (k..len - 1).rev() {
            c[j] += a * c[j + 1];
        }
    }
}

/// Each row of `rows` (coefficients `width` apiece, one polynomial after
/// another) at `s` into `out`: [`eval`] of each, bit for bit, four rows in
/// lockstep (one row's chain of fused steps waits on each last one; four
/// fill the time it leaves idle).
pub fn eval_rows(rows: &[f64], width: usize, s: f64, out: &mut [f64]) {
    if width == 0 {
        // Every row is the empty polynomial.
        return out.fill(0.0);
    }
    let count = out.len().min(rows.len() / width);
    let whole = count / 4 * 4;
    let (fours, rest) = rows[..count * width].split_at(whole * width);
    let (four_out, rest_out) = out[..count].split_at_mut(whole);
    for (group, out) in fours
        .chunks_exact(4 * width)
        .zip(four_out.chunks_exact_mut(4))
    {
        fused_lockstep::<4>(group, width, s, out);
    }
    match rest_out.len() {
        1 => fused_lockstep::<1>(rest, width, s, rest_out),
        2 => fused_lockstep::<2>(rest, width, s, rest_out),
        3 => fused_lockstep::<3>(rest, width, s, rest_out),
        _ => {}
    }
}

/// [`eval`] of `L` rows of `width` coefficients at once.
#[inline(always)]
fn fused_lockstep<const L: usize>(group: &[f64], width: usize, s: f64, out: &mut [f64]) {
    let mut sum = [0.0; L];
    for k in (0..width).rev() {
        for l in 0..L {
            sum[l] = mul_add(sum[l], s, group[l * width + k]);
        }
    }
    out[..L].copy_from_slice(&sum);
}

/// Each row of `rows` (coefficients `width` apiece, one polynomial after
/// another) at `s` into `out`, by compensated Horner
/// ([`eval_compensated`], bit for bit). Rows run four in lockstep, and the
/// last one to three together: each row's Horner chain waits on its last
/// step, and independent chains fill the time one would leave idle.
pub fn eval_compensated_rows(rows: &[f64], width: usize, s: f64, out: &mut [f64]) {
    eval_compensated_rows_plus(rows, width, s, |_| -0.0, out, None);
}

/// Row `i` of `rows` at `s`, plus `extra(i)`, into `out[i]`:
/// [`eval_compensated_plus`] of each row, bit for bit, in lockstep as
/// [`eval_compensated_rows`]; and, where `lo` is given, what rounding
/// each to `out[i]` left out, into `lo[i]`.
pub fn eval_compensated_rows_plus(
    rows: &[f64],
    width: usize,
    s: f64,
    extra: impl Fn(usize) -> f64,
    out: &mut [f64],
    mut lo: Option<&mut [f64]>,
) {
    if width == 0 {
        for (i, o) in out.iter_mut().enumerate() {
            *o = extra(i);
        }
        if let Some(lo) = lo {
            lo.fill(0.0);
        }
        return;
    }
    let count = out.len().min(rows.len() / width);
    let whole = count / 4 * 4;
    let (fours, rest) = rows[..count * width].split_at(whole * width);
    let (four_out, rest_out) = out[..count].split_at_mut(whole);
    for (g, (group, out)) in fours
        .chunks_exact(4 * width)
        .zip(four_out.chunks_exact_mut(4))
        .enumerate()
    {
        let lo = lo.as_deref_mut().map(|lo| &mut lo[4 * g..4 * g + 4]);
        lockstep::<4>(group, width, s, |l| extra(4 * g + l), out, lo);
    }
    let last = |l| extra(whole + l);
    let rest_lo = lo.map(|lo| &mut lo[whole..count]);
    match rest_out.len() {
        1 => lockstep::<1>(rest, width, s, last, rest_out, rest_lo),
        2 => lockstep::<2>(rest, width, s, last, rest_out, rest_lo),
        3 => lockstep::<3>(rest, width, s, last, rest_out, rest_lo),
        _ => {}
    }
}

/// [`eval_compensated_plus`] of `L` rows of `width >= 1` coefficients at
/// once, row `l` plus `extra(l)`.
#[inline(always)]
fn lockstep<const L: usize>(
    group: &[f64],
    width: usize,
    s: f64,
    extra: impl Fn(usize) -> f64,
    out: &mut [f64],
    lo: Option<&mut [f64]>,
) {
    let mut sum: [f64; L] = std::array::from_fn(|l| group[l * width + width - 1]);
    let mut error = [0.0; L];
    for k in (0..width - 1).rev() {
        for l in 0..L {
            let ck = group[l * width + k];
            let product = sum[l] * s;
            let product_error = sum[l].mul_add(s, -product);
            let next = product + ck;
            let t = next - product;
            let sum_error = (product - (next - t)) + (ck - t);
            error[l] = error[l] * s + (product_error + sum_error);
            sum[l] = next;
        }
    }
    match lo {
        Some(lo) => {
            for l in 0..L {
                (out[l], lo[l]) = two_sum(sum[l], error[l] + extra(l));
            }
        }
        None => {
            for l in 0..L {
                out[l] = sum[l] + (error[l] + extra(l));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_evaluate_a_polynomial_written_out() {
        // 2 - 3 s + s^3 at s = 1.5: 2 - 4.5 + 3.375 = 0.875, exact in binary.
        let c = [2.0, -3.0, 0.0, 1.0];
        assert_eq!(eval(&c, 1.5), 0.875);
        assert_eq!(eval_plain(&c, 1.5), 0.875);
        assert_eq!(eval(&[], 3.0), 0.0);
        assert_eq!(eval_compensated(&c, 1.5), 0.875);
        assert_eq!(eval_compensated(&[], 3.0), 0.0);
    }

    /// Nine rows of 7 terms that cancel.
    const WIDTH: usize = 7;
    fn nine_rows() -> Vec<f64> {
        (0..9 * WIDTH)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) * 1.3f64.powi((k % WIDTH) as i32))
            .collect()
    }

    /// One to nine rows (groups of four, of two, and one left over), at
    /// several points: `rows_at` must give each row's `alone`, bit for
    /// bit, and zeros for rows of no terms.
    fn each_row_alone(
        rows_at: impl Fn(&[f64], usize, f64, &mut [f64]),
        alone: impl Fn(&[f64], f64) -> f64,
    ) {
        let (width, rows) = (WIDTH, nine_rows());
        for count in 1..=9 {
            for s in [0.0, -0.7, 0.37, 1.9] {
                let mut out = vec![f64::NAN; count];
                rows_at(&rows[..count * width], width, s, &mut out);
                for (o, c) in out.iter().zip(rows.chunks_exact(width)) {
                    assert_eq!(o.to_bits(), alone(c, s).to_bits(), "{count} at {s}");
                }
            }
        }
        let mut out = [1.0; 3];
        rows_at(&[], 0, 0.5, &mut out);
        assert!(out.iter().all(|o| *o == 0.0));
    }

    #[test]
    fn plain_rows_in_lockstep_are_each_row_alone() {
        each_row_alone(eval_rows, eval);
    }

    #[test]
    fn rows_in_lockstep_are_each_row_alone() {
        each_row_alone(eval_compensated_rows, eval_compensated);
        let (width, rows) = (WIDTH, nine_rows());
        // With an extra term per row: each row's own `plus`.
        let extra = |i: usize| 1e-17 * (i as f64 - 3.0);
        for count in 1..=9 {
            let mut out = vec![f64::NAN; count];
            eval_compensated_rows_plus(&rows[..count * width], width, 0.37, extra, &mut out, None);
            for (i, (o, c)) in out.iter().zip(rows.chunks_exact(width)).enumerate() {
                let alone = eval_compensated_plus(c, 0.37, extra(i));
                assert_eq!(o.to_bits(), alone.to_bits(), "{count}, row {i}");
            }
        }
    }

    #[test]
    fn the_rounding_left_out_carries_each_row_to_double_double() {
        // Rows whose terms cancel to a small value: `hi + lo` must agree
        // with a double-double Horner to far below an ulp of `hi` (the
        // rounding of `hi` alone leaves up to half of one), and `hi` must
        // be the row's value without `lo` asked for.
        use crate::numerics::double_double::DoubleDouble;
        let width = 9;
        let rows: Vec<f64> = (0..5 * width)
            .map(|k| ((k * 37 % 11) as f64 - 5.0) / 3.0 * 1.3f64.powi((k % width) as i32))
            .collect();
        for s in [-0.7, 0.37, 1.9] {
            let mut out = vec![f64::NAN; 5];
            let mut lo = vec![f64::NAN; 5];
            eval_compensated_rows_plus(&rows, width, s, |_| 1e-17, &mut out, Some(&mut lo));
            for (i, c) in rows.chunks_exact(width).enumerate() {
                let exact = c.iter().rev().fold(DoubleDouble::default(), |acc, &c| {
                    acc * s + DoubleDouble::from(c)
                }) + DoubleDouble::from(1e-17);
                let off = ((out[i] - exact.hi) + (lo[i] - exact.lo)).abs();
                let scale: f64 = c.iter().map(|c| c.abs()).sum::<f64>() * s.abs().max(1.0).powi(8);
                assert!(off < 1e-30 * scale, "row {i} at {s}: {off:.1e}");
                assert_eq!(
                    out[i].to_bits(),
                    eval_compensated_plus(c, s, 1e-17).to_bits()
                );
            }
        }
    }

    #[test]
    fn a_shifted_polynomial_is_the_same_polynomial_about_its_new_origin() {
        // 2 - 3 s + s^3 about s = 1.5: p(1.5 + u) = 0.875 + 3.75 u + 4.5 u^2
        // + u^3, exact in binary.
        let mut c = [2.0, -3.0, 0.0, 1.0];
        shift(&mut c, 1.5);
        assert_eq!(c, [0.875, 3.75, 4.5, 1.0]);
        shift(&mut c, 0.0);
        assert_eq!(c, [0.875, 3.75, 4.5, 1.0]);
        shift(&mut c, -1.5);
        assert_eq!(c, [2.0, -3.0, 0.0, 1.0]);
        shift(&mut [], 2.0);
    }

    #[test]
    fn compensated_horner_keeps_what_plain_horner_loses_to_cancellation() {
        // (s - 1)^7 expanded, near its root: the terms are about 100 and
        // cancel to about 1e-14; plain Horner loses the result in their
        // rounding, the compensated one keeps it to a few ulps.
        let c = [-1.0, 7.0, -21.0, 35.0, -35.0, 21.0, -7.0, 1.0];
        let s = 1.01;
        let exact = 0.01_f64.powi(7);
        let compensated = eval_compensated(&c, s);
        assert!(
            (compensated - exact).abs() < 1e-3 * exact,
            "{compensated} vs {exact}"
        );
        assert!((eval_plain(&c, s) - exact).abs() > 1e-2 * exact);
    }
}
