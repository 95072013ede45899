//! Reading a flow's tape as `x' = A x + b + sum_k (c_k cos(w_k t) + s_k
//! sin(w_k t))`: affine in the state, driven by sines of the clock `t` (a
//! forced oscillator, `v' = -x - 2 zeta v + A cos(w t)`), which the exact
//! linear propagator runs in closed form ([`AffineFlow`]).
//!
//! Each register's value is held as a combination of the inputs, a
//! constant and the waves; a product or quotient by a constant, a sum and
//! a negation keep that form, `cos` and `sin` of `w t + phi` make a wave,
//! and any function of constants alone is a constant. Anything else (a
//! product of two states, a sine of a state, `t^2`) is not of the form.

use nalgebra::{DMatrix, DVector};

use super::tape::{Fun, Op, Tape};
use crate::engine::model::affine_flow::{AffineFlow, Wave};

/// The most distinct frequencies read (each adds two components to the
/// propagator's state).
const MOST_WAVES: usize = 4;

/// A register's value: `linear[j]` times input `j`, plus `linear[n]`, plus
/// `(w, c, s)` for each `c cos(w t) + s sin(w t)`.
#[derive(Debug, Clone)]
struct Value {
    linear: Vec<f64>,
    waves: Vec<(f64, f64, f64)>,
}

impl Value {
    fn constant(n: usize, c: f64) -> Self {
        let mut linear = vec![0.0; n + 1];
        linear[n] = c;
        Value {
            linear,
            waves: Vec::new(),
        }
    }

    /// Its value, if it is a constant.
    fn as_constant(&self) -> Option<f64> {
        let (vars, c) = self.linear.split_at(self.linear.len() - 1);
        (self.waves.is_empty() && vars.iter().all(|v| *v == 0.0)).then_some(c[0])
    }

    /// Each coefficient through `f` (a product or a quotient by a
    /// constant, taken as the tape takes it).
    fn each(mut self, f: impl Fn(f64) -> f64) -> Self {
        self.linear.iter_mut().for_each(|v| *v = f(*v));
        for (_, c, s) in &mut self.waves {
            (*c, *s) = (f(*c), f(*s));
        }
        self
    }

    fn plus(mut self, other: &Value, sign: f64) -> Self {
        for (v, o) in self.linear.iter_mut().zip(&other.linear) {
            *v += sign * o;
        }
        for &(w, c, s) in &other.waves {
            self.add_wave(w, sign * c, sign * s);
        }
        self
    }

    fn add_wave(&mut self, w: f64, c: f64, s: f64) {
        match self.waves.iter_mut().find(|(known, _, _)| *known == w) {
            Some((_, kc, ks)) => {
                *kc += c;
                *ks += s;
            }
            None => self.waves.push((w, c, s)),
        }
    }

    /// `cos` or `sin` of this value, where it is `w t + phi`.
    fn sine(&self, f: Fun, clock: usize) -> Option<Value> {
        let n = self.linear.len() - 1;
        let others = (0..n).filter(|&j| j != clock);
        if !self.waves.is_empty() || others.clone().any(|j| self.linear[j] != 0.0) {
            return None;
        }
        let (w, phi) = (self.linear[clock], self.linear[n]);
        // cos(-w t + phi) = cos(w t - phi), sin(-w t + phi) = -sin(w t - phi).
        let (w, phi, sign) = if w < 0.0 {
            (-w, -phi, if f == Fun::Sin { -1.0 } else { 1.0 })
        } else {
            (w, phi, 1.0)
        };
        let (sp, cp) = phi.sin_cos();
        // cos(w t + phi) = cos phi cos(w t) - sin phi sin(w t);
        // sin(w t + phi) = sin phi cos(w t) + cos phi sin(w t).
        let (c, s) = match f {
            Fun::Cos => (cp, -sp),
            Fun::Sin => (sp, cp),
            _ => return None,
        };
        let mut value = Value::constant(n, 0.0);
        value.waves.push((w, sign * c, sign * s));
        Some(value)
    }
}

/// `flow` (`n` outputs of `n` inputs, input `clock` the clock) as an
/// affine flow driven by sines of the clock, if it is one and reads at
/// least one sine (a flow with none is [`Tape::affine`]).
pub fn driven(flow: &Tape, n: usize, clock: usize) -> Option<AffineFlow> {
    let mut values: Vec<Value> = Vec::with_capacity(flow.ops.len());
    // Each constant register's value, for functions of constants alone.
    let mut constants = vec![f64::NAN; flow.ops.len()];
    for (i, op) in flow.ops.iter().enumerate() {
        let v = |r: u32| &values[r as usize];
        let c = |r: u32| values[r as usize].as_constant();
        let value = match *op {
            Op::Const(x) => Value::constant(n, x),
            Op::Input(j) => {
                let mut value = Value::constant(n, 0.0);
                value.linear[j as usize] = 1.0;
                value
            }
            Op::Add(a, b) => v(a).clone().plus(v(b), 1.0),
            Op::Sub(a, b) => v(a).clone().plus(v(b), -1.0),
            Op::Neg(a) => v(a).clone().each(|x| -x),
            Op::Mul(a, b) => match (c(a), c(b)) {
                (Some(x), _) => v(b).clone().each(|y| x * y),
                (_, Some(y)) => v(a).clone().each(|x| x * y),
                _ => return None,
            },
            Op::Div(a, b) => match c(b) {
                Some(y) => v(a).clone().each(|x| x / y),
                None => return None,
            },
            Op::Call(f @ (Fun::Cos | Fun::Sin), a) if c(a).is_none() => v(a).sine(f, clock)?,
            op if op.operands().all(|r| c(r).is_some()) => {
                Value::constant(n, op.value(&constants, &[]))
            }
            _ => return None,
        };
        constants[i] = value.as_constant().unwrap_or(f64::NAN);
        values.push(value);
    }
    let outputs: Vec<&Value> = flow.outputs.iter().map(|&r| &values[r as usize]).collect();
    let mut frequencies: Vec<f64> = Vec::new();
    for &(w, c, s) in outputs.iter().flat_map(|v| &v.waves) {
        // A wave that cancelled (`cos(t) - cos(t)`) drives nothing.
        if (c, s) != (0.0, 0.0) && !frequencies.contains(&w) {
            frequencies.push(w);
        }
    }
    if frequencies.is_empty()
        || frequencies.len() > MOST_WAVES
        || !frequencies.iter().all(|w| w.is_finite())
    {
        return None;
    }
    let a = DMatrix::from_fn(n, n, |i, j| outputs[i].linear[j]);
    let b = DVector::from_fn(n, |i, _| outputs[i].linear[n]);
    let waves: Vec<Wave> = frequencies
        .iter()
        .map(|&w| {
            let part = |i: usize| {
                outputs[i]
                    .waves
                    .iter()
                    .find(|(known, _, _)| *known == w)
                    .map_or((0.0, 0.0), |&(_, c, s)| (c, s))
            };
            Wave {
                frequency: w,
                cos: DVector::from_fn(n, |i, _| part(i).0),
                sin: DVector::from_fn(n, |i, _| part(i).1),
            }
        })
        .collect();
    let finite = a.iter().chain(b.iter()).all(|x| x.is_finite())
        && waves
            .iter()
            .all(|w| w.cos.iter().chain(w.sin.iter()).all(|x| x.is_finite()));
    finite.then_some(AffineFlow { a, b, waves })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::parse::parse;
    use crate::expr::{Ast, Scope};

    /// `texts` as the flow of `[x, v, t]`, the clock last.
    fn flow(texts: &[&str]) -> Tape {
        let scope = Scope {
            inputs: vec!["x".into(), "v".into(), "t".into()],
            constants: vec![("w".into(), 0.8), ("k".into(), 4.0)],
        };
        let asts: Vec<Ast> = texts.iter().map(|t| parse(t).unwrap()).collect();
        Tape::compile(&asts.iter().collect::<Vec<_>>(), &scope).unwrap()
    }

    /// `A x + b + sum_k (c_k cos(w_k t) + s_k sin(w_k t))` at `x`.
    fn rebuilt(flow: &AffineFlow, x: &[f64]) -> Vec<f64> {
        let t = x[x.len() - 1];
        let mut out: Vec<f64> = (&flow.a * DVector::from_column_slice(x) + &flow.b)
            .iter()
            .copied()
            .collect();
        for wave in &flow.waves {
            let (c, s) = ((wave.frequency * t).cos(), (wave.frequency * t).sin());
            for (i, o) in out.iter_mut().enumerate() {
                *o += wave.cos[i] * c + wave.sin[i] * s;
            }
        }
        out
    }

    #[test]
    fn a_forced_flow_is_its_matrix_and_waves_at_every_state() {
        // Phases, negative frequencies, a sum of two frequencies, a wave
        // over a constant, the clock's own rate and the clock beside a
        // wave: each rebuilt equals the tape's own value at many states.
        let cases: &[&[&str]] = &[
            &["v", "-2 * 0.05 * v - x + cos(w * t)", "1"],
            &["v + sin(-w * t + 0.3)", "-x - k * cos(2 * t - 1) / 2", "1"],
            &[
                "3 * cos(w * t) - 2 * sin(w * t) + x / k",
                "cos(0.5) * x + t",
                "1",
            ],
            &["v + cos(w * t) - cos(t * w)", "-x + sin(t)", "1"],
        ];
        for texts in cases {
            let tape = flow(texts);
            let driven = driven(&tape, 3, 2).unwrap_or_else(|| panic!("{texts:?}"));
            assert!(driven.waves.iter().all(|w| w.frequency > 0.0), "{texts:?}");
            for (k, x) in [[0.3, -1.2, 0.0], [1.5, 0.25, 7.0], [-2.0, 3.0, 123.456]]
                .iter()
                .enumerate()
            {
                let mut want = vec![0.0; 3];
                tape.eval_scratch(x, &mut want);
                for (got, want) in rebuilt(&driven, x).iter().zip(&want) {
                    assert!(
                        (got - want).abs() <= 1e-14 * (1.0 + want.abs()),
                        "{texts:?} at {k}: {got} vs {want}"
                    );
                }
            }
        }
        // Frequencies: one, two (w and 2), and one where two cancel.
        let count = |texts: &[&str]| driven(&flow(texts), 3, 2).unwrap().waves.len();
        assert_eq!(count(cases[0]), 1);
        assert_eq!(count(cases[1]), 2);
        assert_eq!(count(cases[3]), 1);
    }

    #[test]
    fn what_is_not_affine_in_the_state_or_reads_no_sine_is_not_driven() {
        for texts in [
            ["v", "-x + x * cos(t)", "1"],
            ["v", "-x + cos(x)", "1"],
            ["v", "-x + cos(t)^2", "1"],
            ["v", "-x + t * cos(t)", "1"],
            ["v", "-x + exp(-t)", "1"],
            ["v", "-x + cos(t * t)", "1"],
            ["v * v", "cos(t)", "1"],
            // Affine, with no wave: the plain linear flow's.
            ["v", "-x + t", "1"],
            // Five frequencies: more than the propagator takes.
            [
                "cos(t) + cos(2 * t)",
                "cos(3 * t) + cos(4 * t) + cos(5 * t)",
                "1",
            ],
        ] {
            assert!(driven(&flow(&texts), 3, 2).is_none(), "{texts:?}");
        }
    }
}
