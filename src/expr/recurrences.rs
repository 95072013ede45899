//! Taylor coefficients of any order, by automatic recurrences along the
//! tape (as heyoka does): each instruction computes the `k`-th normalised
//! coefficient of its value from the first `k` of its operands.
//!
//! For a flow `x' = f(x)` ([`Series::flow`]) the orders are built up in
//! turn: once every register has its order `k`, the state's order `k + 1`
//! is `f_k / (k + 1)`. A guard's series along the step ([`Series::compose`])
//! is the same recurrences with the state's series as inputs. The
//! recurrences come from differentiating each function's defining
//! relation: `p = a^c` from `a p' = c a' p`, `e = exp a` from `e' = a' e`,
//! `sin` and `cos` together, `tan` from `t' = (1 + t^2) a'`, `asin` and
//! `acos` from `sqrt(1 - a^2) y' = +-a'`, `atan2(y, x)` from
//! `(x^2 + y^2) theta' = x y' - y x'`. Each keeps at most two helper series
//! (the partner `cos` of a `sin`, the `1 - a^2` and its root of an `asin`).
//!
//! `abs`, `min` and `max` follow the branch their value takes at the
//! series' origin: a series is not told where a branch switches, so a
//! method that trusts a whole step to one series must not take them (see
//! [`Tape::smooth`]).

use crate::expr::tape::{Fun, Fun2, Op, Reg, Tape};

/// Scratch for the series of one tape.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Orders kept per register (`order + 1` coefficients).
    width: usize,
    /// Coefficients, register by register.
    main: Vec<f64>,
    /// First and second helper series of each register.
    aux: [Vec<f64>; 2],
    /// The tape lowered for the orders' loop (its constants and inputs
    /// aside).
    program: Vec<Step>,
    /// Each input register: where its input's coefficients start among the
    /// inputs', and where its own do.
    loads: Vec<(usize, usize)>,
}

/// One instruction as the orders' loop runs it: offsets into the
/// coefficients resolved, constant operands told apart once per series
/// instead of once per order. Constants are written before the loop and
/// inputs copied in as they become known, outside it.
#[derive(Debug, Clone, Copy)]
enum Step {
    Add(At),
    Sub(At),
    Neg(At),
    /// `a * b`, `a` constant.
    ScaledRight(At),
    /// `a * b`, `b` constant.
    ScaledLeft(At),
    Mul(At),
    /// `a * a`.
    Square(At),
    /// `a / b`, `b` constant.
    DivConst(At),
    Div(At),
    /// `a^b`, `b` constant.
    PowConst(At),
    Pow(At),
    Call(Fun, At),
    Call2(Fun2, At),
}

/// Which recurrence an instruction's coefficients follow: the one
/// classification of a tape's instructions, read by the orders' loop here
/// ([`Step`]) and by the compiled lowering (`compiled/series.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Recurrence {
    /// A constant: its value, then zeros.
    Const(f64),
    /// An input: its series, copied in.
    Input(u32),
    Add(Reg, Reg),
    Sub(Reg, Reg),
    Neg(Reg),
    /// `a * b`, `a` constant.
    ScaledRight(Reg, Reg),
    /// `a * b`, `b` constant.
    ScaledLeft(Reg, Reg),
    /// `a * a`.
    Square(Reg),
    Mul(Reg, Reg),
    /// `a / b`, `b` constant.
    DivConst(Reg, Reg),
    Div(Reg, Reg),
    /// `a^b`, `b` constant.
    PowConst(Reg, Reg),
    Pow(Reg, Reg),
    Call(Fun, Reg),
    Call2(Fun2, Reg, Reg),
}

/// The recurrence of `tape`'s instruction `r`.
pub(crate) fn recurrence(tape: &Tape, r: usize) -> Recurrence {
    match tape.ops[r] {
        Op::Const(c) => Recurrence::Const(c),
        Op::Input(i) => Recurrence::Input(i),
        Op::Add(a, b) => Recurrence::Add(a, b),
        Op::Sub(a, b) => Recurrence::Sub(a, b),
        Op::Neg(a) => Recurrence::Neg(a),
        Op::Mul(a, b) if constant(tape, a) => Recurrence::ScaledRight(a, b),
        Op::Mul(a, b) if constant(tape, b) => Recurrence::ScaledLeft(a, b),
        Op::Mul(a, b) if a == b => Recurrence::Square(a),
        Op::Mul(a, b) => Recurrence::Mul(a, b),
        Op::Div(a, b) if constant(tape, b) => Recurrence::DivConst(a, b),
        Op::Div(a, b) => Recurrence::Div(a, b),
        Op::Pow(a, b) if constant(tape, b) => Recurrence::PowConst(a, b),
        Op::Pow(a, b) => Recurrence::Pow(a, b),
        Op::Call(f, a) => Recurrence::Call(f, a),
        Op::Call2(f, a, b) => Recurrence::Call2(f, a, b),
    }
}

/// Where a [`Step`] reads and writes: the offsets of its operands'
/// coefficients and of its own (`b` is `a` for one operand).
#[derive(Debug, Clone, Copy)]
struct At {
    a: usize,
    b: usize,
    out: usize,
}

impl Series {
    fn prepare(&mut self, tape: &Tape, order: usize) {
        self.width = order + 1;
        let len = tape.ops.len() * self.width;
        let [aux0, aux1] = &mut self.aux;
        // Every coefficient is written before it is read (a constant's
        // here), so what a buffer held before needs no clearing; nor does
        // a buffer shrink (a flow's series and a guard's alternate).
        for buffer in [&mut self.main, aux0, aux1] {
            if buffer.len() < len {
                buffer.resize(len, 0.0);
            }
        }
        let w = self.width;
        self.program.clear();
        self.loads.clear();
        for r in 0..tape.ops.len() {
            let out = r * w;
            let at = |a: Reg, b: Reg| At {
                a: a as usize * w,
                b: b as usize * w,
                out,
            };
            self.program.push(match recurrence(tape, r) {
                Recurrence::Const(c) => {
                    self.main[out..out + w].fill(0.0);
                    self.main[out] = c;
                    continue;
                }
                Recurrence::Input(i) => {
                    self.loads.push((i as usize * w, out));
                    continue;
                }
                Recurrence::Add(a, b) => Step::Add(at(a, b)),
                Recurrence::Sub(a, b) => Step::Sub(at(a, b)),
                Recurrence::Neg(a) => Step::Neg(at(a, a)),
                Recurrence::ScaledRight(a, b) => Step::ScaledRight(at(a, b)),
                Recurrence::ScaledLeft(a, b) => Step::ScaledLeft(at(a, b)),
                Recurrence::Square(a) => Step::Square(at(a, a)),
                Recurrence::Mul(a, b) => Step::Mul(at(a, b)),
                Recurrence::DivConst(a, b) => Step::DivConst(at(a, b)),
                Recurrence::Div(a, b) => Step::Div(at(a, b)),
                Recurrence::PowConst(a, b) => Step::PowConst(at(a, b)),
                Recurrence::Pow(a, b) => Step::Pow(at(a, b)),
                Recurrence::Call(f, a) => Step::Call(f, at(a, a)),
                Recurrence::Call2(f, a, b) => Step::Call2(f, at(a, b)),
            });
        }
    }

    /// Coefficient `k` of every register, in order, their operands known to
    /// order `k`.
    #[inline]
    fn order(&mut self, k: usize) {
        for i in 0..self.program.len() {
            let m = &mut self.main;
            match self.program[i] {
                Step::Add(At { a, b, out }) => m[out + k] = m[a + k] + m[b + k],
                Step::Sub(At { a, b, out }) => m[out + k] = m[a + k] - m[b + k],
                Step::Neg(At { a, out, .. }) => m[out + k] = -m[a + k],
                Step::ScaledRight(At { a, b, out }) => m[out + k] = m[a] * m[b + k],
                Step::ScaledLeft(At { a, b, out }) => m[out + k] = m[a + k] * m[b],
                Step::Mul(At { a, b, out }) => m[out + k] = product(m, a, m, b, k, 0),
                Step::Square(At { a, out, .. }) => m[out + k] = square(m, a, k),
                Step::DivConst(At { a, b, out }) => m[out + k] = m[a + k] / m[b],
                Step::Div(At { a, b, out }) => {
                    let sum = if k == 0 {
                        0.0
                    } else {
                        product(m, b, m, out, k, 1)
                    };
                    m[out + k] = (m[a + k] - sum) / m[b];
                }
                Step::PowConst(At { a, b, out }) => {
                    self.main[out + k] = self.pow(a, b, true, out, k)
                }
                Step::Pow(At { a, b, out }) => self.main[out + k] = self.pow(a, b, false, out, k),
                Step::Call(f, At { a, out, .. }) => self.main[out + k] = self.call(f, a, out, k),
                Step::Call2(f, At { a, b, out }) => {
                    self.main[out + k] = self.call2(f, a, b, out, k)
                }
            }
        }
    }

    /// The series of the flow `x' = f(x)` from `x0`, `f` being `tape`
    /// (whose outputs are the rates of its inputs, in order): `out[i *
    /// (order + 1) + k]` is the `k`-th normalised coefficient of `x_i`.
    pub fn flow(&mut self, tape: &Tape, x0: &[f64], order: usize, out: &mut [f64]) {
        self.prepare(tape, order);
        let w = self.width;
        for (i, &x) in x0.iter().enumerate() {
            out[i * w] = x;
        }
        // The registers' order `order` would give the state's `order + 1`,
        // which the series does not keep.
        for k in 0..order {
            for &(from, to) in &self.loads {
                self.main[to + k] = out[from + k];
            }
            self.order(k);
            for (i, &o) in tape.outputs.iter().enumerate() {
                out[i * w + k + 1] = self.main[o as usize * w + k] / (k + 1) as f64;
            }
        }
    }

    /// The series of `tape`'s first output when its inputs follow `inputs`
    /// (laid out as [`Series::flow`] writes them), into `out` (`order + 1`).
    pub fn compose(&mut self, tape: &Tape, inputs: &[f64], order: usize, out: &mut [f64]) {
        // A guard that is one of the inputs (a section's `x`, an impact's
        // `theta`): its series is that input's, as the loop below would
        // copy it through.
        if let ([Op::Input(i)], [0]) = (&tape.ops[..], &tape.outputs[..]) {
            let from = *i as usize * (order + 1);
            out[..=order].copy_from_slice(&inputs[from..=from + order]);
            return;
        }
        self.prepare(tape, order);
        let w = self.width;
        for &(from, to) in &self.loads {
            self.main[to..to + w].copy_from_slice(&inputs[from..from + w]);
        }
        for k in 0..=order {
            self.order(k);
        }
        let o = tape.outputs[0] as usize * self.width;
        out[..=order].copy_from_slice(&self.main[o..o + order + 1]);
    }

    /// Coefficient `k` of `a^b`.
    fn pow(&mut self, a: usize, b: usize, constant_exponent: bool, out: usize, k: usize) -> f64 {
        let m = &self.main;
        let kf = k as f64;
        if constant_exponent {
            if k == 0 {
                return m[a].powf(m[b]);
            }
            // a p' = c a' p.
            let c = m[b];
            let sum = conv(m, a, m, out, k, 1, |j| c * j as f64 - (k - j) as f64);
            return sum / (kf * m[a]);
        }
        // exp(b log a): aux 0 holds log a, aux 1 holds b log a.
        let log = log_coefficient(m, a, &self.aux[0], out, k);
        self.aux[0][out + k] = log;
        let exponent = product(m, b, &self.aux[0], out, k, 0);
        self.aux[1][out + k] = exponent;
        if k == 0 {
            m[a].powf(m[b])
        } else {
            conv(&self.aux[1], out, m, out, k, 1, |j| j as f64) / kf
        }
    }

    /// Coefficient `k` of `f(a)`, keeping its helper series.
    fn call(&mut self, f: Fun, a: usize, out: usize, k: usize) -> f64 {
        let (m, [aux, aux2]) = (&self.main, &mut self.aux);
        let kf = k as f64;
        let a0 = m[a];
        // sum_{j=1}^{k} j a_j y_{k-j}: the coefficient k - 1 of a' y.
        let slope_times = |y: &[f64]| slopes_times(&m[a..=a + k], &y[out..out + k], &[]).0;
        // sum_{j=1}^{k-1} j y_j z_{k-j}: the part of (z y')_(k-1) below y_k.
        let known = |y: &[f64], z: &[f64]| -> f64 {
            let mut sum = 0.0;
            for j in 1..k {
                sum += j as f64 * y[out + j] * z[out + k - j];
            }
            sum
        };
        match f {
            Fun::Sin | Fun::Cos | Fun::Sinh | Fun::Cosh => {
                // The function and its partner (cos of sin, ...) in aux.
                let (hyperbolic, is_sin) = match f {
                    Fun::Sin => (false, true),
                    Fun::Cos => (false, false),
                    Fun::Sinh => (true, true),
                    _ => (true, false),
                };
                if k == 0 {
                    let (s, c) = if hyperbolic {
                        (a0.sinh(), a0.cosh())
                    } else {
                        a0.sin_cos()
                    };
                    let (value, partner) = if is_sin { (s, c) } else { (c, s) };
                    aux[out] = partner;
                    return value;
                }
                // s' = a' c, c' = -+ a' s (minus for the circular cos).
                let (from_partner, from_value) =
                    slopes_times(&m[a..=a + k], &aux[out..out + k], &m[out..out + k]);
                let (value_from_partner, partner_from_value) = (from_partner / kf, from_value / kf);
                let sign = if hyperbolic { 1.0 } else { -1.0 };
                // For sin: value' = a' partner, partner' = -a' value.
                // For cos: value' = -a' partner, partner' = a' value.
                let (value, partner) = if is_sin {
                    (value_from_partner, sign * partner_from_value)
                } else {
                    (sign * value_from_partner, partner_from_value)
                };
                aux[out + k] = partner;
                value
            }
            Fun::Tan | Fun::Tanh => {
                // t' = (1 +- t^2) a', the factor in aux.
                let sign = if f == Fun::Tan { 1.0 } else { -1.0 };
                if k == 0 {
                    let t = if f == Fun::Tan { a0.tan() } else { a0.tanh() };
                    aux[out] = 1.0 + sign * t * t;
                    return t;
                }
                let t = slope_times(aux) / kf;
                // The factor's order k needs t_k itself.
                let mut square = 2.0 * m[out] * t;
                for j in 1..k {
                    square += m[out + j] * m[out + k - j];
                }
                aux[out + k] = sign * square;
                t
            }
            Fun::Exp => {
                if k == 0 {
                    a0.exp()
                } else {
                    slope_times(m) / kf
                }
            }
            Fun::Log => log_coefficient(m, a, m, out, k),
            Fun::Sqrt => sqrt_coefficient(|j| m[a + j], m, out, k),
            Fun::Asin | Fun::Acos | Fun::Atan => {
                // w = 1 -+ a^2 in aux; for asin/acos its root in aux2.
                let sign = if f == Fun::Atan { 1.0 } else { -1.0 };
                let mut square = 0.0;
                for j in 0..=k {
                    square += m[a + j] * m[a + k - j];
                }
                aux[out + k] = if k == 0 { 1.0 } else { 0.0 } + sign * square;
                let scale = if f == Fun::Atan {
                    aux
                } else {
                    let root = sqrt_coefficient(|j| aux[out + j], aux2, out, k);
                    aux2[out + k] = root;
                    aux2
                };
                if k == 0 {
                    return match f {
                        Fun::Asin => a0.asin(),
                        Fun::Acos => a0.acos(),
                        _ => a0.atan(),
                    };
                }
                // scale y' = +-a'.
                let direction = if f == Fun::Acos { -1.0 } else { 1.0 };
                (direction * kf * m[a + k] - known(m, scale)) / (kf * scale[out])
            }
            Fun::Abs => {
                let sign = if a0 < 0.0 { -1.0 } else { 1.0 };
                sign * m[a + k]
            }
            // Constant on each side of its switch (which a non-smooth tape
            // never asks a series across).
            Fun::Sign => 0.0,
        }
    }

    /// Coefficient `k` of `f(a, b)`.
    fn call2(&mut self, f: Fun2, a: usize, b: usize, out: usize, k: usize) -> f64 {
        let (m, [aux, _]) = (&self.main, &mut self.aux);
        let kf = k as f64;
        match f {
            Fun2::Min | Fun2::Max => {
                let take_a = if f == Fun2::Min {
                    m[a] <= m[b]
                } else {
                    m[a] >= m[b]
                };
                if take_a { m[a + k] } else { m[b + k] }
            }
            Fun2::Hypot | Fun2::Atan2 => {
                // w = a^2 + b^2 in aux.
                let mut square = 0.0;
                for j in 0..=k {
                    square += m[a + j] * m[a + k - j] + m[b + j] * m[b + k - j];
                }
                aux[out + k] = square;
                if f == Fun2::Hypot {
                    return sqrt_coefficient(|j| aux[out + j], m, out, k);
                }
                if k == 0 {
                    return m[a].atan2(m[b]);
                }
                // atan2(y = a, x = b): w theta' = x y' - y x'.
                let mut sum = 0.0;
                for j in 1..=k {
                    sum += j as f64 * (m[b + k - j] * m[a + j] - m[a + k - j] * m[b + j]);
                }
                for j in 1..k {
                    sum -= j as f64 * m[out + j] * aux[out + k - j];
                }
                sum / (kf * aux[out])
            }
        }
    }
}

/// `sum_{j = lo..=k} weight(j) x[xs + j] y[ys + k - j]`: the Cauchy
/// product's coefficient `k`, weighted.
#[inline(always)]
fn conv(
    x: &[f64],
    xs: usize,
    y: &[f64],
    ys: usize,
    k: usize,
    lo: usize,
    weight: impl Fn(usize) -> f64,
) -> f64 {
    // Sliced first, so that the loop needs no bounds checks.
    let n = k + 1 - lo;
    let (x, y) = (&x[xs + lo..xs + lo + n], &y[ys..ys + n]);
    let mut sum = 0.0;
    for j in 0..n {
        sum += weight(lo + j) * x[j] * y[n - 1 - j];
    }
    sum
}

/// `sum_{j = lo..=k} x[xs + j] y[ys + k - j]`: [`conv`] unweighted, walked
/// by iterators (`y` backwards), which need no bounds checks where
/// indexing `y[n - 1 - j]` kept them (and unroll). The same products
/// summed in the same order.
#[inline(always)]
fn product(x: &[f64], xs: usize, y: &[f64], ys: usize, k: usize, lo: usize) -> f64 {
    let n = k + 1 - lo;
    let (x, y) = (&x[xs + lo..xs + lo + n], &y[ys..ys + n]);
    let mut sum = 0.0;
    for (a, b) in x.iter().zip(y.iter().rev()) {
        sum += a * b;
    }
    sum
}

/// Coefficient `k` of `x^2` from `x`'s orders `0..=k` (at `xs`): each
/// pair `x_j x_(k-j)`, `j < k - j`, once, in increasing `j` from `+0`, the
/// sum doubled (exactly), then the middle term `x_(k/2)^2` of an even `k`.
/// Half the terms of [`product`], and fewer roundings: heyoka sums a
/// square so too. Order 0 is the product's, `0 + x_0^2`.
#[inline(always)]
fn square(x: &[f64], xs: usize, k: usize) -> f64 {
    if k == 0 {
        return product(x, xs, x, xs, 0, 0);
    }
    let mut sum = 0.0;
    for j in 0..=(k - 1) / 2 {
        sum += x[xs + j] * x[xs + k - j];
    }
    sum += sum;
    if k.is_multiple_of(2) {
        sum += x[xs + k / 2] * x[xs + k / 2];
    }
    sum
}

/// `sum_{j=1}^{k} j a_j y_{k-j}` and the same with `z` (if given: empty
/// for none), `k + 1 = a.len()`, `y` and `z` holding orders `0..k`: the
/// coefficient `k - 1` of `a' y` and `a' z`, in one pass.
#[inline(always)]
fn slopes_times(a: &[f64], y: &[f64], z: &[f64]) -> (f64, f64) {
    let (mut with_y, mut with_z) = (0.0, 0.0);
    let k = y.len();
    let (a, y) = (&a[..k + 1], &y[..k]);
    // `j` as a float counted alongside (exact: the same numbers as `j as
    // f64`, without a conversion per term).
    let mut jf = 0.0;
    if z.is_empty() {
        for j in 1..=k {
            jf += 1.0;
            with_y += jf * a[j] * y[k - j];
        }
    } else {
        let z = &z[..k];
        for j in 1..=k {
            jf += 1.0;
            let rate = jf * a[j];
            with_y += rate * y[k - j];
            with_z += rate * z[k - j];
        }
    }
    (with_y, with_z)
}

/// Coefficient `k` of `log a` (`a` at `a_at` in `a_series`), its earlier
/// coefficients at `out` in `log_series`: `a l' = a'`.
fn log_coefficient(a_series: &[f64], a_at: usize, log_series: &[f64], out: usize, k: usize) -> f64 {
    let a0 = a_series[a_at];
    if k == 0 {
        return a0.ln();
    }
    let mut sum = 0.0;
    for j in 1..k {
        sum += j as f64 * log_series[out + j] * a_series[a_at + k - j];
    }
    (a_series[a_at + k] - sum / k as f64) / a0
}

/// Coefficient `k` of `sqrt(w)`, `w_j` given by `w`, the root's earlier
/// coefficients at `out` in `root`: `s^2 = w`.
fn sqrt_coefficient(w: impl Fn(usize) -> f64, root: &[f64], out: usize, k: usize) -> f64 {
    if k == 0 {
        return w(0).sqrt();
    }
    let mut sum = 0.0;
    for j in 1..k {
        sum += root[out + j] * root[out + k - j];
    }
    (w(k) - sum) / (2.0 * root[out])
}

/// Whether register `r` of `tape` is a constant.
fn constant(tape: &Tape, r: u32) -> bool {
    matches!(tape.ops[r as usize], Op::Const(_))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::expr::parse::parse;
    use crate::expr::tape::Scope;

    /// The tape of `texts` over `inputs`, with a constant `c = 0.3`.
    pub(crate) fn tape(texts: &[&str], inputs: &[&str]) -> Tape {
        let scope = Scope {
            inputs: inputs.iter().map(|s| s.to_string()).collect(),
            constants: vec![("c".into(), 0.3)],
        };
        let asts: Vec<_> = texts.iter().map(|t| parse(t).unwrap()).collect();
        Tape::compile(&asts.iter().collect::<Vec<_>>(), &scope).unwrap()
    }

    fn factorial(k: usize) -> f64 {
        (1..=k).map(|i| i as f64).product()
    }

    /// x' = v, v' = -x from (1, 0): x = cos t, v = -sin t.
    #[test]
    fn a_square_sums_each_pair_once_and_doubles_it() {
        // (1 + 2 s + 3 s^2 + 4 s^3 + 5 s^4)^2: 1, 4, 10, 20, 35, in integers
        // (exact either way), and the product's value where they round.
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        for (k, want) in [1.0, 4.0, 10.0, 20.0, 35.0].into_iter().enumerate() {
            assert_eq!(square(&x, 0, k), want, "order {k}");
        }
        let x = [0.7, -0.31, 0.123, 1.0 / 3.0, -0.2718, 0.05];
        for k in 0..x.len() {
            let (s, p) = (square(&x, 0, k), product(&x, 0, &x, 0, k, 0));
            assert!(
                (s - p).abs() <= 4.0 * f64::EPSILON * p.abs().max(0.1),
                "order {k}: {s} against {p}"
            );
        }
    }

    #[test]
    fn the_harmonic_oscillator_expands_to_cosine_and_sine() {
        let t = tape(&["v", "-x"], &["x", "v"]);
        let order = 20;
        let mut out = vec![0.0; 2 * (order + 1)];
        Series::default().flow(&t, &[1.0, 0.0], order, &mut out);
        for k in 0..=order {
            let cos = if k % 2 == 0 {
                (-1f64).powi(k as i32 / 2) / factorial(k)
            } else {
                0.0
            };
            let minus_sin = if k % 2 == 1 {
                -(-1f64).powi((k as i32 - 1) / 2) / factorial(k)
            } else {
                0.0
            };
            // Each order divides once more: a few ulps by order 20.
            assert!((out[k] - cos).abs() <= 1e-15 * cos.abs(), "x_{k}");
            assert!(
                (out[order + 1 + k] - minus_sin).abs() <= 1e-15 * minus_sin.abs(),
                "v_{k}"
            );
        }
    }

    /// x' = x^2 from 1 is 1 / (1 - t): every coefficient 1; x' = -x^1.5
    /// from 1 is (1 + t/2)^-2.
    #[test]
    fn nonlinear_flows_expand_to_their_closed_forms() {
        let order = 15;
        let mut out = vec![0.0; order + 1];
        Series::default().flow(&tape(&["x^2"], &["x"]), &[1.0], order, &mut out);
        assert!(out.iter().all(|&c| (c - 1.0).abs() < 1e-15), "{out:?}");
        Series::default().flow(&tape(&["-x^1.5"], &["x"]), &[1.0], order, &mut out);
        // (1 + t/2)^-2 = sum (k + 1) (-1/2)^k t^k.
        for (k, &c) in out.iter().enumerate() {
            let want = (k + 1) as f64 * (-0.5f64).powi(k as i32);
            assert!((c - want).abs() < 1e-14 * want.abs(), "{k}: {c} vs {want}");
        }
    }

    /// One scratch serves every tape of a thread: what an earlier series
    /// left in it (longer tapes, constants where the next has a product,
    /// higher orders) changes nothing.
    #[test]
    fn a_scratch_reused_across_tapes_expands_as_a_fresh_one() {
        let tapes = [
            tape(&["v * c + 2", "-sin(x) + c"], &["x", "v"]),
            tape(&["x * v", "x / (1 + v^2) - exp(v) * cos(x)"], &["x", "v"]),
            tape(&["v", "-x"], &["x", "v"]),
        ];
        let mut shared = Series::default();
        for (order, t) in [
            (24, &tapes[0]),
            (12, &tapes[1]),
            (20, &tapes[2]),
            (24, &tapes[1]),
        ] {
            let (mut reused, mut fresh) = (vec![0.0; 2 * (order + 1)], vec![0.0; 2 * (order + 1)]);
            shared.flow(t, &[0.4, -0.3], order, &mut reused);
            Series::default().flow(t, &[0.4, -0.3], order, &mut fresh);
            assert_eq!(reused, fresh, "order {order}");
        }
    }

    /// Every function of a moving argument: the series summed at a small
    /// time equals the function evaluated there, to the size of the first
    /// term left out.
    #[test]
    fn every_function_composes_with_a_moving_argument() {
        let texts = [
            "sin(x)",
            "cos(x)",
            "tan(x)",
            "sinh(x)",
            "cosh(x)",
            "tanh(x)",
            "exp(x)",
            "log(x)",
            "sqrt(x)",
            "asin(x - 0.3)",
            "acos(x - 0.3)",
            "atan(x)",
            "abs(x - 2)",
            "x^c",
            "x^y",
            "x / y",
            "x * y - y",
            "atan2(x, y)",
            "atan2(y, -x)",
            "hypot(x, y)",
            "min(x, y)",
            "max(x, y)",
            "pow(x, 3) - x^-2",
        ];
        // x(t) = 0.7 + 0.4 t - 0.3 t^2, y(t) = 1.1 - 0.2 t + 0.5 t^3.
        let order = 24;
        let w = order + 1;
        let mut inputs = vec![0.0; 2 * w];
        inputs[..3].copy_from_slice(&[0.7, 0.4, -0.3]);
        inputs[w..w + 4].copy_from_slice(&[1.1, -0.2, 0.0, 0.5]);
        let s = 0.05;
        let (x, y) = (0.7 + 0.4 * s - 0.3 * s * s, 1.1 - 0.2 * s + 0.5 * s * s * s);
        for text in texts {
            let t = tape(&[text], &["x", "y"]);
            let mut out = vec![0.0; w];
            Series::default().compose(&t, &inputs, order, &mut out);
            let summed = out.iter().rev().fold(0.0, |acc, c| acc * s + c);
            let mut direct = [0.0];
            t.eval(&[x, y], &mut vec![0.0; t.registers()], &mut direct);
            assert!(
                (summed - direct[0]).abs() < 1e-14 * direct[0].abs().max(1.0),
                "{text}: {summed} vs {}",
                direct[0]
            );
        }
    }
}
