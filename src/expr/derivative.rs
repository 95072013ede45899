//! Exact derivatives of a tape's outputs with respect to its inputs, by
//! forward-mode differentiation along the tape: each register carries its
//! value and its gradient, each instruction applies its derivative rule.
//! For an affine tape the gradients are the coefficients themselves, which
//! is how the linear propagator gets `A` without differences.
//!
//! A smooth flow's Jacobian, which error bounds ask for several times a
//! step, is also compiled once into a tape of its own ([`jacobian_tape`]):
//! the rates differentiated symbolically, their common subexpressions
//! shared, so that a Jacobian costs one pass over a few instructions
//! instead of a gradient per register.

use std::cell::RefCell;

use nalgebra::DMatrix;

use crate::expr::Ast;
use crate::expr::symbolic::derivative;
use crate::expr::tape::{Fun, Fun2, Op, Reg, Scope, Tape};

/// The Jacobian (outputs x `n` inputs) of `tape` at `x`.
pub fn jacobian(tape: &Tape, x: &[f64]) -> DMatrix<f64> {
    let n = x.len();
    let mut out = vec![0.0; tape.outputs.len() * n];
    jacobian_into(tape, x, &mut out);
    DMatrix::from_row_slice(tape.outputs.len(), n, &out)
}

/// The Jacobian of `tape` at `x` into `out`, row-major (outputs x `n`
/// inputs), in scratch registers: what the engine's error bounds ask for
/// at every step.
pub fn jacobian_into(tape: &Tape, x: &[f64], out: &mut [f64]) {
    SCRATCH.with_borrow_mut(|(value, grad)| {
        let n = x.len();
        let m = tape.ops.len();
        value.resize(m, 0.0);
        grad.resize(m * n, 0.0);
        forward(tape, x, value, grad);
        for (o, &r) in tape.outputs.iter().enumerate() {
            out[o * n..(o + 1) * n].copy_from_slice(&grad[r as usize * n..(r as usize + 1) * n]);
        }
    })
}

/// The Jacobian of the rates `asts` (one per input of `scope`, in order)
/// as a tape whose outputs are its entries, row-major; `None` where a rate
/// is not smooth (`abs`, `sign`, `min`, `max`: forward differentiation
/// takes their branch at the point) or the derivatives grow past `budget`
/// instructions (the forward pass is then the cheaper).
pub fn jacobian_tape(asts: &[&Ast], scope: &Scope, budget: usize) -> Option<Tape> {
    let varies = |name: &str| scope.inputs.iter().any(|i| i == name);
    let mut entries = Vec::with_capacity(asts.len() * scope.inputs.len());
    for ast in asts {
        for input in &scope.inputs {
            entries.push(derivative(ast, input, &varies).ok()?);
        }
    }
    let tape = Tape::compile(&entries.iter().collect::<Vec<_>>(), scope).ok()?;
    (tape.smooth() && tape.ops.len() <= budget).then_some(tape)
}

thread_local! {
    /// Values and gradients of every register (models are shared, read
    /// only, between the threads of a sweep).
    static SCRATCH: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// Every register's value and gradient (`n` inputs each) along `tape` at
/// `x`.
fn forward(tape: &Tape, x: &[f64], value: &mut [f64], grad: &mut [f64]) {
    let n = x.len();
    for (i, &op) in tape.ops.iter().enumerate() {
        value[i] = op.value(&value, x);
        let (done, rest) = grad.split_at_mut(i * n);
        let g = &mut rest[..n];
        let dg = |r: Reg| &done[r as usize * n..(r as usize + 1) * n];
        let v = |r: Reg| value[r as usize];
        // g = ca * grad(a) + cb * grad(b)
        let mut combine = |a: Option<(Reg, f64)>, b: Option<(Reg, f64)>| {
            for k in 0..n {
                g[k] = a.map_or(0.0, |(r, c)| c * dg(r)[k]) + b.map_or(0.0, |(r, c)| c * dg(r)[k]);
            }
        };
        match op {
            Op::Const(_) => combine(None, None),
            Op::Input(j) => {
                combine(None, None);
                g[j as usize] = 1.0;
            }
            Op::Add(a, b) => combine(Some((a, 1.0)), Some((b, 1.0))),
            Op::Sub(a, b) => combine(Some((a, 1.0)), Some((b, -1.0))),
            Op::Mul(a, b) => combine(Some((a, v(b))), Some((b, v(a)))),
            Op::Div(a, b) => combine(Some((a, 1.0 / v(b))), Some((b, -v(a) / (v(b) * v(b))))),
            Op::Neg(a) => combine(Some((a, -1.0)), None),
            Op::Pow(a, b) => {
                let (base, exponent) = (v(a), v(b));
                let cb = if base > 0.0 {
                    value[i] * base.ln()
                } else {
                    0.0
                };
                combine(
                    Some((a, exponent * base.powf(exponent - 1.0))),
                    Some((b, cb)),
                )
            }
            Op::Call(f, a) => combine(Some((a, slope(f, v(a), value[i]))), None),
            Op::Call2(f, a, b) => {
                let (ca, cb) = slopes(f, v(a), v(b), value[i]);
                combine(Some((a, ca)), Some((b, cb)))
            }
        }
    }
}

/// `f'(a)`, given `fa = f(a)`.
fn slope(f: Fun, a: f64, fa: f64) -> f64 {
    match f {
        Fun::Sin => a.cos(),
        Fun::Cos => -a.sin(),
        Fun::Tan => 1.0 + fa * fa,
        Fun::Asin => 1.0 / (1.0 - a * a).sqrt(),
        Fun::Acos => -1.0 / (1.0 - a * a).sqrt(),
        Fun::Atan => 1.0 / (1.0 + a * a),
        Fun::Sinh => a.cosh(),
        Fun::Cosh => a.sinh(),
        Fun::Tanh => 1.0 - fa * fa,
        Fun::Exp => fa,
        Fun::Log => 1.0 / a,
        Fun::Sqrt => 0.5 / fa,
        Fun::Abs => {
            if a == 0.0 {
                0.0
            } else {
                a.signum()
            }
        }
        Fun::Sign => 0.0,
    }
}

/// The partial derivatives of `f(a, b)`, given `fab = f(a, b)`.
fn slopes(f: Fun2, a: f64, b: f64, fab: f64) -> (f64, f64) {
    match f {
        Fun2::Atan2 => {
            let r2 = a * a + b * b;
            (b / r2, -a / r2)
        }
        Fun2::Min => {
            if a <= b {
                (1.0, 0.0)
            } else {
                (0.0, 1.0)
            }
        }
        Fun2::Max => {
            if a >= b {
                (1.0, 0.0)
            } else {
                (0.0, 1.0)
            }
        }
        Fun2::Hypot => (a / fab, b / fab),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::parse::parse;
    use crate::expr::tape::Scope;

    /// Every function's derivative against a central difference.
    #[test]
    fn derivatives_match_central_differences() {
        let scope = Scope {
            inputs: vec!["x".into(), "y".into()],
            constants: vec![],
        };
        let texts = [
            "sin(x)*cos(y) + tan(x/3)",
            "asin(x/2) + acos(y/3) + atan(x*y)",
            "sinh(x) - cosh(y) + tanh(x - y)",
            "exp(x)*log(y) + sqrt(x + y) + abs(x - 2*y)",
            "x^3 / y^2 - x^-1 + pow(y, 2.5) + x^y",
            "atan2(x, y) + hypot(x, y) + min(x, y) * max(x, y) - (-x)",
        ];
        let (x, y) = (0.7, 1.3);
        for text in texts {
            let ast = parse(text).unwrap();
            let tape = Tape::compile(&[&ast], &scope).unwrap();
            let jac = jacobian(&tape, &[x, y]);
            for k in 0..2 {
                let h = 1e-6;
                let mut plus = [x, y];
                let mut minus = [x, y];
                plus[k] += h;
                minus[k] -= h;
                let mut regs = vec![0.0; tape.registers()];
                let (mut fp, mut fm) = ([0.0], [0.0]);
                tape.eval(&plus, &mut regs, &mut fp);
                tape.eval(&minus, &mut regs, &mut fm);
                let fd = (fp[0] - fm[0]) / (2.0 * h);
                // Central differences err by h^2 f''' / 6 and 1e-16 / h.
                assert!(
                    (jac[(0, k)] - fd).abs() < 1e-8 * fd.abs().max(1.0),
                    "{text} d/d{k}: {} vs {fd}",
                    jac[(0, k)]
                );
            }
        }
    }

    /// The compiled Jacobian agrees with forward differentiation wherever
    /// the rates are smooth, and is not compiled where they are not.
    #[test]
    fn the_compiled_jacobian_is_the_forward_one() {
        let scope = Scope {
            inputs: vec!["x".into(), "y".into(), "t".into()],
            constants: vec![("c".into(), 0.3)],
        };
        let rates = [
            "y",
            "-x - 2 * x * y + c * cos(t)",
            "1",
            "sin(x) * exp(-y / 3) + x^3 / y^2 + atan2(x, y) + hypot(x, t)",
            "sqrt(x + y) * log(y) - tan(x / 3) + x^y + asin(x / 2) - cosh(y)",
        ];
        let point = [0.7, 1.3, 0.4];
        for (first, second) in [(0, 1), (0, 3), (4, 2)] {
            let asts = [
                parse(rates[first]).unwrap(),
                parse(rates[second]).unwrap(),
                parse("1").unwrap(),
            ];
            let asts: Vec<&Ast> = asts.iter().collect();
            let flow = Tape::compile(&asts, &scope).unwrap();
            let compiled = jacobian_tape(&asts, &scope, 1000).expect("smooth rates compile");
            let mut got = [0.0; 9];
            compiled.eval_scratch(&point, &mut got);
            let want = jacobian(&flow, &point);
            for (k, g) in got.iter().enumerate() {
                let w = want[(k / 3, k % 3)];
                assert!(
                    (g - w).abs() <= 1e-14 * w.abs().max(1.0),
                    "{} / {}: entry {k}, {g} vs {w}",
                    rates[first],
                    rates[second]
                );
            }
            assert!(jacobian_tape(&asts, &scope, 2).is_none(), "past its budget");
        }
        for rough in ["abs(x) * y", "min(x, y)", "sign(y) + x"] {
            let ast = parse(rough).unwrap();
            let one = parse("1").unwrap();
            assert!(
                jacobian_tape(&[&ast, &ast, &one], &scope, 1000).is_none(),
                "{rough}"
            );
        }
    }

    #[test]
    fn an_affine_tape_gives_its_coefficients_exactly() {
        let scope = Scope {
            inputs: vec!["x".into(), "v".into()],
            constants: vec![("w".into(), 1.3)],
        };
        let asts = [
            parse("v").unwrap(),
            parse("-w^2 * x + 0.25 * v - 3").unwrap(),
        ];
        let tape = Tape::compile(&asts.iter().collect::<Vec<_>>(), &scope).unwrap();
        let jac = jacobian(&tape, &[0.0, 0.0]);
        assert_eq!(
            jac,
            DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -(1.3f64 * 1.3), 0.25])
        );
    }
}
