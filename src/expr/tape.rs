//! Syntax trees compiled to a register tape: one instruction per distinct
//! subexpression, evaluated in order into a slice of registers.
//!
//! Names are resolved at compile time against a [`Scope`]: inputs (the
//! state, the clock) become loads, parameters and `pi` become constants.
//! Instructions whose operands are all constant are folded; an instruction
//! already on the tape (same operation, same operands) is reused, so the
//! expressions compiled into one tape share their common subexpressions;
//! integer powers become products (and a quotient for negative ones), so
//! that every power of a series is a product of series; what no output
//! needs is dropped.
//! The same tape is what the Taylor recurrences and derivatives walk.

use std::cell::RefCell;

use rustc_hash::FxHashMap;

use crate::expr::parse::{Ast, Binary};

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fun {
    /// `sin`
    Sin,
    /// `cos`
    Cos,
    /// `tan`
    Tan,
    /// `asin`
    Asin,
    /// `acos`
    Acos,
    /// `atan`
    Atan,
    /// `sinh`
    Sinh,
    /// `cosh`
    Cosh,
    /// `tanh`
    Tanh,
    /// `exp`
    Exp,
    /// `log` (natural)
    Log,
    /// `sqrt`
    Sqrt,
    /// `abs`
    Abs,
    /// `sign`: -1, 0 or 1 (in a flow, a switching surface: see
    /// `src/models/automaton/filippov.rs`)
    Sign,
}

/// A function of two arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fun2 {
    /// `atan2(y, x)`
    Atan2,
    /// `min(a, b)`
    Min,
    /// `max(a, b)`
    Max,
    /// `hypot(a, b)`
    Hypot,
}

pub(crate) const FUNS: [(&str, Fun); 14] = [
    ("sin", Fun::Sin),
    ("cos", Fun::Cos),
    ("tan", Fun::Tan),
    ("asin", Fun::Asin),
    ("acos", Fun::Acos),
    ("atan", Fun::Atan),
    ("sinh", Fun::Sinh),
    ("cosh", Fun::Cosh),
    ("tanh", Fun::Tanh),
    ("exp", Fun::Exp),
    ("log", Fun::Log),
    ("sqrt", Fun::Sqrt),
    ("abs", Fun::Abs),
    ("sign", Fun::Sign),
];

pub(crate) const FUNS2: [(&str, Fun2); 4] = [
    ("atan2", Fun2::Atan2),
    ("min", Fun2::Min),
    ("max", Fun2::Max),
    ("hypot", Fun2::Hypot),
];

impl Fun {
    /// `f(a)`.
    pub fn apply(self, a: f64) -> f64 {
        match self {
            Fun::Sin => a.sin(),
            Fun::Cos => a.cos(),
            Fun::Tan => a.tan(),
            Fun::Asin => a.asin(),
            Fun::Acos => a.acos(),
            Fun::Atan => a.atan(),
            Fun::Sinh => a.sinh(),
            Fun::Cosh => a.cosh(),
            Fun::Tanh => a.tanh(),
            Fun::Exp => a.exp(),
            Fun::Log => a.ln(),
            Fun::Sqrt => a.sqrt(),
            Fun::Abs => a.abs(),
            Fun::Sign => {
                if a == 0.0 || a.is_nan() {
                    a
                } else {
                    a.signum()
                }
            }
        }
    }
}

impl Fun2 {
    /// `f(a, b)`.
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Fun2::Atan2 => a.atan2(b),
            Fun2::Min => a.min(b),
            Fun2::Max => a.max(b),
            Fun2::Hypot => a.hypot(b),
        }
    }
}

/// Register index.
pub type Reg = u32;

/// One instruction; operands are earlier registers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Op {
    /// A constant.
    Const(f64),
    /// Input number `i` (a state component, the clock).
    Input(u32),
    /// `a + b`
    Add(Reg, Reg),
    /// `a - b`
    Sub(Reg, Reg),
    /// `a * b`
    Mul(Reg, Reg),
    /// `a / b`
    Div(Reg, Reg),
    /// `-a`
    Neg(Reg),
    /// `a^b`
    Pow(Reg, Reg),
    /// `f(a)`
    Call(Fun, Reg),
    /// `f(a, b)`
    Call2(Fun2, Reg, Reg),
}

impl Op {
    /// The value of this instruction, given the registers before it.
    #[inline(always)]
    pub fn value(self, regs: &[f64], inputs: &[f64]) -> f64 {
        let r = |i: Reg| regs[i as usize];
        match self {
            Op::Const(c) => c,
            Op::Input(i) => inputs[i as usize],
            Op::Add(a, b) => r(a) + r(b),
            Op::Sub(a, b) => r(a) - r(b),
            Op::Mul(a, b) => r(a) * r(b),
            Op::Div(a, b) => r(a) / r(b),
            Op::Neg(a) => -r(a),
            Op::Pow(a, b) => r(a).powf(r(b)),
            Op::Call(f, a) => f.apply(r(a)),
            Op::Call2(f, a, b) => f.apply(r(a), r(b)),
        }
    }

    /// The registers this instruction reads.
    pub fn operands(self) -> impl Iterator<Item = Reg> {
        let (a, b) = match self {
            Op::Const(_) | Op::Input(_) => (None, None),
            Op::Neg(a) | Op::Call(_, a) => (Some(a), None),
            Op::Add(a, b)
            | Op::Sub(a, b)
            | Op::Mul(a, b)
            | Op::Div(a, b)
            | Op::Pow(a, b)
            | Op::Call2(_, a, b) => (Some(a), Some(b)),
        };
        a.into_iter().chain(b)
    }

    /// The same instruction reading `map[r]` for each register `r`.
    fn renumbered(self, map: &[Reg]) -> Op {
        let m = |r: Reg| map[r as usize];
        match self {
            Op::Const(_) | Op::Input(_) => self,
            Op::Add(a, b) => Op::Add(m(a), m(b)),
            Op::Sub(a, b) => Op::Sub(m(a), m(b)),
            Op::Mul(a, b) => Op::Mul(m(a), m(b)),
            Op::Div(a, b) => Op::Div(m(a), m(b)),
            Op::Neg(a) => Op::Neg(m(a)),
            Op::Pow(a, b) => Op::Pow(m(a), m(b)),
            Op::Call(f, a) => Op::Call(f, m(a)),
            Op::Call2(f, a, b) => Op::Call2(f, m(a), m(b)),
        }
    }

    /// A hashable identity: the same key means the same value.
    fn key(self) -> (u8, u64, u64) {
        let r = |a: Reg| a as u64;
        match self {
            Op::Const(c) => (0, c.to_bits(), 0),
            Op::Input(i) => (1, i as u64, 0),
            Op::Add(a, b) => (2, r(a.min(b)), r(a.max(b))),
            Op::Sub(a, b) => (3, r(a), r(b)),
            Op::Mul(a, b) => (4, r(a.min(b)), r(a.max(b))),
            Op::Div(a, b) => (5, r(a), r(b)),
            Op::Neg(a) => (6, r(a), 0),
            Op::Pow(a, b) => (8, r(a), r(b)),
            Op::Call(f, a) => (16 + f as u8, r(a), 0),
            Op::Call2(f, a, b) => (48 + f as u8, r(a), r(b)),
        }
    }
}

/// What names mean in the expressions of one tape.
#[derive(Debug, Clone, Default)]
pub struct Scope {
    /// Input names, in input order.
    pub inputs: Vec<String>,
    /// Named constants (parameters).
    pub constants: Vec<(String, f64)>,
}

impl Scope {
    /// Every name an expression may use here, functions aside.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.inputs
            .iter()
            .map(String::as_str)
            .chain(self.constants.iter().map(|(n, _)| n.as_str()))
            .chain(["pi"])
    }
}

/// Why an expression does not compile, and the character it points at.
#[derive(Debug, Clone, PartialEq)]
pub struct CompileError {
    /// Character position (0-based) of the offending name.
    pub at: usize,
    /// What is wrong there.
    pub message: String,
}

/// A compiled tape: instructions and the registers holding its outputs.
#[derive(Debug, Clone, PartialEq)]
pub struct Tape {
    /// The instructions, in evaluation order.
    pub ops: Vec<Op>,
    /// The register of each output.
    pub outputs: Vec<Reg>,
}

impl Tape {
    /// Compile `asts` (one per output) against `scope` into one tape.
    pub fn compile(asts: &[&Ast], scope: &Scope) -> Result<Tape, CompileError> {
        let mut builder = Builder {
            scope,
            ops: Vec::new(),
            folded: Vec::new(),
            seen: FxHashMap::default(),
        };
        let outputs = asts
            .iter()
            .map(|ast| builder.node(ast))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(prune(builder.ops, outputs))
    }

    /// Registers an evaluation needs.
    pub fn registers(&self) -> usize {
        self.ops.len()
    }

    /// Evaluate every register from `inputs` (`regs` at least
    /// [`registers`](Tape::registers) long).
    #[inline]
    pub fn run(&self, inputs: &[f64], regs: &mut [f64]) {
        for (i, op) in self.ops.iter().enumerate() {
            regs[i] = op.value(regs, inputs);
        }
    }

    /// Evaluate the outputs at `inputs` into `out`.
    #[inline]
    pub fn eval(&self, inputs: &[f64], regs: &mut [f64], out: &mut [f64]) {
        self.run(inputs, regs);
        for (o, &r) in out.iter_mut().zip(&self.outputs) {
            *o = regs[r as usize];
        }
    }

    /// Whether some instruction reads input `i`.
    pub fn reads(&self, i: u32) -> bool {
        self.ops.contains(&Op::Input(i))
    }

    /// Evaluate the outputs at `inputs` into `out`, in this thread's
    /// scratch registers (a model evaluated through `&self`).
    #[inline]
    pub fn eval_scratch(&self, inputs: &[f64], out: &mut [f64]) {
        SCRATCH.with_borrow_mut(|regs| {
            if regs.len() < self.ops.len() {
                regs.resize(self.ops.len(), 0.0);
            }
            self.eval(inputs, regs, out);
        })
    }

    /// The first output at `inputs`, in scratch registers.
    #[inline]
    pub fn eval1(&self, inputs: &[f64]) -> f64 {
        let mut out = [0.0];
        self.eval_scratch(inputs, &mut out);
        out[0]
    }

    /// Whether every output is an affine function of the inputs (`A x + b`),
    /// judged from the instructions: products and quotients by constants,
    /// sums, negations; anything else of an input is not.
    pub fn affine(&self) -> bool {
        self.affine_beside(None)
    }

    /// Whether every output is `A x + f(t)`: affine in the inputs other
    /// than `forcing` (the clock `t`), with constant coefficients, plus any
    /// function of `forcing` alone. A driven linear oscillator's flow is;
    /// its Jacobian in the state is then the same everywhere. Judged as
    /// [`affine`](Tape::affine) is, a term that reads only `forcing` being
    /// free to enter any function or product but another such term's.
    pub fn affine_beside(&self, forcing: Option<u32>) -> bool {
        // Each register's kind, ordered: a constant, a function of the
        // forcing alone, affine in the others, neither.
        const CONSTANT: u8 = 0;
        const FORCING: u8 = 1;
        const AFFINE: u8 = 2;
        const OTHER: u8 = 3;
        let mut kind = vec![CONSTANT; self.ops.len()];
        for (i, op) in self.ops.iter().enumerate() {
            let k = |r: Reg| kind[r as usize];
            kind[i] = match *op {
                Op::Const(_) => CONSTANT,
                Op::Input(j) if Some(j) == forcing => FORCING,
                Op::Input(_) => AFFINE,
                Op::Add(a, b) | Op::Sub(a, b) => k(a).max(k(b)),
                Op::Neg(a) => k(a),
                Op::Mul(a, b) if k(a) == CONSTANT || k(b) == CONSTANT => k(a).max(k(b)),
                Op::Div(a, b) if k(b) == CONSTANT => k(a),
                _ => match op.operands().map(k).max().unwrap_or(CONSTANT) {
                    kind if kind <= FORCING => kind,
                    _ => OTHER,
                },
            };
        }
        self.outputs.iter().all(|&r| kind[r as usize] <= AFFINE)
    }

    /// Whether every instruction is smooth: no `abs`, `sign`, `min` or
    /// `max`, whose branch a Taylor series cannot see switch.
    pub fn smooth(&self) -> bool {
        !self.ops.iter().any(|op| {
            matches!(
                op,
                Op::Call(Fun::Abs | Fun::Sign, _) | Op::Call2(Fun2::Min | Fun2::Max, _, _)
            )
        })
    }

    /// Whether output `output` reads input `input`, through any instruction.
    pub fn depends_on(&self, output: usize, input: u32) -> bool {
        let mut needed = vec![false; self.ops.len()];
        needed[self.outputs[output] as usize] = true;
        for i in (0..self.ops.len()).rev() {
            if !needed[i] {
                continue;
            }
            if self.ops[i] == Op::Input(input) {
                return true;
            }
            for r in self.ops[i].operands() {
                needed[r as usize] = true;
            }
        }
        false
    }

    /// Whether every output is constant.
    pub fn constant(&self) -> Option<Vec<f64>> {
        self.outputs
            .iter()
            .map(|&r| match self.ops[r as usize] {
                Op::Const(c) => Some(c),
                _ => None,
            })
            .collect()
    }
}

thread_local! {
    /// Registers for evaluations through `&self` (models are shared, read
    /// only, between the threads of a sweep).
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

struct Builder<'s> {
    scope: &'s Scope,
    ops: Vec<Op>,
    /// Each register's value where it is constant (NaN elsewhere).
    folded: Vec<f64>,
    seen: FxHashMap<(u8, u64, u64), Reg>,
}

impl Builder<'_> {
    /// The register of `op`: a folded constant, an instruction already on
    /// the tape, or a new one.
    fn push(&mut self, op: Op) -> Reg {
        let op = self.fold(op);
        let key = op.key();
        if let Some(&r) = self.seen.get(&key) {
            return r;
        }
        let r = self.ops.len() as Reg;
        self.ops.push(op);
        self.folded.push(match op {
            Op::Const(c) => c,
            _ => f64::NAN,
        });
        self.seen.insert(key, r);
        r
    }

    fn constant(&self, r: Reg) -> Option<f64> {
        match self.ops[r as usize] {
            Op::Const(c) => Some(c),
            _ => None,
        }
    }

    /// `op` evaluated now if all it reads is constant.
    fn fold(&self, op: Op) -> Op {
        if matches!(op, Op::Const(_) | Op::Input(_)) {
            return op;
        }
        if op.operands().all(|r| self.constant(r).is_some()) {
            Op::Const(op.value(&self.folded, &[]))
        } else {
            op
        }
    }

    fn node(&mut self, ast: &Ast) -> Result<Reg, CompileError> {
        Ok(match ast {
            Ast::Number(x) => self.push(Op::Const(*x)),
            Ast::Name(name, at) => self.name(name, *at)?,
            Ast::Neg(a) => {
                let a = self.node(a)?;
                self.push(Op::Neg(a))
            }
            Ast::Binary(op, a, b) => {
                let (a, b) = (self.node(a)?, self.node(b)?);
                match op {
                    Binary::Add => self.push(Op::Add(a, b)),
                    Binary::Sub => self.push(Op::Sub(a, b)),
                    Binary::Mul => self.push(Op::Mul(a, b)),
                    Binary::Div => self.push(Op::Div(a, b)),
                    Binary::Pow => self.power(a, b),
                }
            }
            Ast::Call(name, args, at) => self.call(name, args, *at)?,
        })
    }

    /// `a^b`: an integer exponent up to 64 in size as products, by
    /// squaring (`x^4` is `(x x)(x x)`), and `1 / a^n` for a negative one.
    fn power(&mut self, a: Reg, b: Reg) -> Reg {
        match self.constant(b) {
            Some(n) if n == n.round() && n.abs() <= 64.0 => {
                let positive = self.integer_power(a, n.abs() as u32);
                if n < 0.0 {
                    let one = self.push(Op::Const(1.0));
                    self.push(Op::Div(one, positive))
                } else {
                    positive
                }
            }
            _ => self.push(Op::Pow(a, b)),
        }
    }

    /// `a^n` by squaring and multiplying.
    fn integer_power(&mut self, a: Reg, n: u32) -> Reg {
        match n {
            0 => self.push(Op::Const(1.0)),
            1 => a,
            _ => {
                let half = self.integer_power(a, n / 2);
                let square = self.push(Op::Mul(half, half));
                if n % 2 == 1 {
                    self.push(Op::Mul(square, a))
                } else {
                    square
                }
            }
        }
    }

    fn name(&mut self, name: &str, at: usize) -> Result<Reg, CompileError> {
        if let Some(i) = self.scope.inputs.iter().position(|n| n == name) {
            return Ok(self.push(Op::Input(i as u32)));
        }
        if let Some((_, c)) = self.scope.constants.iter().find(|(n, _)| n == name) {
            return Ok(self.push(Op::Const(*c)));
        }
        if name == "pi" {
            return Ok(self.push(Op::Const(std::f64::consts::PI)));
        }
        let mut message = format!("unknown name `{name}`");
        if FUNS.iter().any(|(f, _)| *f == name) || FUNS2.iter().any(|(f, _)| *f == name) {
            message += &format!(" (`{name}` is a function: write `{name}(...)`)");
        } else if let Some(near) = nearest(name, self.scope.names()) {
            message += &format!(" (did you mean `{near}`?)");
        }
        Err(CompileError { at, message })
    }

    fn call(&mut self, name: &str, args: &[Ast], at: usize) -> Result<Reg, CompileError> {
        let arity = |n: usize| {
            if args.len() == n {
                Ok(())
            } else {
                Err(CompileError {
                    at,
                    message: format!("`{name}` takes {n} argument(s), found {}", args.len()),
                })
            }
        };
        if let Some(&(_, f)) = FUNS.iter().find(|(n, _)| *n == name) {
            arity(1)?;
            let a = self.node(&args[0])?;
            return Ok(self.push(Op::Call(f, a)));
        }
        if name == "pow" {
            arity(2)?;
            let (a, b) = (self.node(&args[0])?, self.node(&args[1])?);
            return Ok(self.power(a, b));
        }
        if let Some(&(_, f)) = FUNS2.iter().find(|(n, _)| *n == name) {
            arity(2)?;
            let (a, b) = (self.node(&args[0])?, self.node(&args[1])?);
            return Ok(self.push(Op::Call2(f, a, b)));
        }
        let functions = FUNS
            .iter()
            .map(|(n, _)| *n)
            .chain(["pow"])
            .chain(FUNS2.iter().map(|(n, _)| *n));
        let mut message = format!("unknown function `{name}`");
        if let Some(near) = nearest(name, functions) {
            message += &format!(" (did you mean `{near}`?)");
        }
        Err(CompileError { at, message })
    }
}

/// The known name closest to `name`, if any is close.
fn nearest<'a>(name: &str, known: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    // Ties in edits go to the longer shared start (`sinn` is `sin`, not
    // `sign`).
    known
        .map(|k| (strsim::damerau_levenshtein(name, k), k))
        .filter(|&(d, k)| d <= 2.max(k.len() / 3))
        .min_by(|(d1, k1), (d2, k2)| {
            d1.cmp(d2).then_with(|| {
                strsim::jaro_winkler(name, k2).total_cmp(&strsim::jaro_winkler(name, k1))
            })
        })
        .map(|(_, k)| k)
}

/// Drop the instructions no output reads, renumbering the rest.
fn prune(ops: Vec<Op>, outputs: Vec<Reg>) -> Tape {
    let mut live = vec![false; ops.len()];
    for &r in &outputs {
        live[r as usize] = true;
    }
    for i in (0..ops.len()).rev() {
        if live[i] {
            for r in ops[i].operands() {
                live[r as usize] = true;
            }
        }
    }
    let mut map = vec![0; ops.len()];
    let mut kept = Vec::new();
    for (i, op) in ops.into_iter().enumerate() {
        if live[i] {
            map[i] = kept.len() as Reg;
            kept.push(op.renumbered(&map));
        }
    }
    Tape {
        ops: kept,
        outputs: outputs.iter().map(|&r| map[r as usize]).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::parse::parse;

    fn scope() -> Scope {
        Scope {
            inputs: vec!["x".into(), "v".into(), "t".into()],
            constants: vec![("g".into(), 9.81), ("k".into(), 4.0)],
        }
    }

    fn compile(texts: &[&str]) -> Result<Tape, CompileError> {
        let asts: Vec<Ast> = texts.iter().map(|t| parse(t).unwrap()).collect();
        Tape::compile(&asts.iter().collect::<Vec<_>>(), &scope())
    }

    fn eval(tape: &Tape, inputs: &[f64]) -> Vec<f64> {
        let mut regs = vec![0.0; tape.registers()];
        let mut out = vec![0.0; tape.outputs.len()];
        tape.eval(inputs, &mut regs, &mut out);
        out
    }

    #[test]
    fn values_match_the_formulas_written_in_rust() {
        let tape = compile(&[
            "-x^2 + v/k - g*sin(t)",
            "atan2(x, v) + hypot(x, v) + max(x, v) - min(x, v) + pow(k, 0.5)",
            "exp(-x) * log(k) + sqrt(abs(v)) + cosh(x) - tanh(v) + sinh(t) + tan(x) + asin(0.5) + acos(0.25) + atan(v)",
        ])
        .unwrap();
        let (x, v, t) = (0.3_f64, -1.7_f64, 2.5_f64);
        let want = [
            -(x * x) + v / 4.0 - 9.81 * t.sin(),
            x.atan2(v) + x.hypot(v) + x.max(v) - x.min(v) + 2.0,
            (-x).exp() * 4f64.ln() + v.abs().sqrt() + x.cosh() - v.tanh()
                + t.sinh()
                + x.tan()
                + 0.5f64.asin()
                + 0.25f64.acos()
                + v.atan(),
        ];
        let got = eval(&tape, &[x, v, t]);
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() <= 1e-15 * w.abs().max(1.0), "{g} vs {w}");
        }
    }

    #[test]
    fn constants_fold_and_common_subexpressions_are_shared() {
        let tape = compile(&["2 * g * k + pi"]).unwrap();
        assert_eq!(
            tape.constant(),
            Some(vec![2.0 * 9.81 * 4.0 + std::f64::consts::PI])
        );
        // sin(x) and x*v appear once however often they are written.
        let tape = compile(&["sin(x) * (x*v)", "sin(x) + v*x", "x*v"]).unwrap();
        let sines = tape
            .ops
            .iter()
            .filter(|op| matches!(op, Op::Call(Fun::Sin, _)))
            .count();
        let products = tape
            .ops
            .iter()
            .filter(|op| matches!(op, Op::Mul(..)))
            .count();
        assert_eq!((sines, products), (1, 2), "{:?}", tape.ops);
    }

    #[test]
    fn unused_constants_and_inputs_are_dropped() {
        let tape = compile(&["x * (k - 4) + v"]).unwrap();
        // x * 0 is not simplified (0 * inf is not 0), but no dead constants remain.
        assert!(
            tape.ops
                .iter()
                .all(|op| !matches!(op, Op::Const(c) if *c == 4.0))
        );
        assert!(!tape.reads(2));
        assert!(tape.reads(0) && tape.reads(1));
    }

    #[test]
    fn integer_powers_are_products() {
        // x^2, x^3 = x^2 x, x^-2 = 1 / x^2: two products, one quotient.
        let tape = compile(&["x^3", "x^-2", "x^0.5", "v^0", "v^1"]).unwrap();
        let count = |f: fn(&Op) -> bool| tape.ops.iter().filter(|op| f(op)).count();
        assert_eq!(count(|op| matches!(op, Op::Mul(..))), 2, "{:?}", tape.ops);
        assert_eq!(count(|op| matches!(op, Op::Div(..))), 1);
        assert_eq!(count(|op| matches!(op, Op::Pow(..))), 1);
        let out = eval(&tape, &[1.5, 2.0, 0.0]);
        assert_eq!(
            out,
            vec![1.5 * 1.5 * 1.5, 1.0 / (1.5 * 1.5), 1.5f64.sqrt(), 1.0, 2.0]
        );
    }

    #[test]
    fn affine_outputs_and_dependencies_are_recognised() {
        assert!(
            compile(&["2*x - v/k + 3", "-(x + t)*g", "k^2 * v"])
                .unwrap()
                .affine()
        );
        for text in ["x*v", "sin(x)", "x^2", "1/x", "abs(v)", "g*cos(t)"] {
            assert!(!compile(&[text]).unwrap().affine(), "{text}");
        }
        let tape = compile(&["v", "-k*x + sin(t)"]).unwrap();
        assert!(tape.depends_on(0, 1) && !tape.depends_on(0, 0));
        assert!(tape.depends_on(1, 0) && tape.depends_on(1, 2) && !tape.depends_on(1, 1));
    }

    #[test]
    fn a_linear_flow_driven_by_the_clock_is_affine_beside_it() {
        // The clock is input 2: a function of it alone may be added, and
        // may multiply constants or other functions of it, but not a state.
        let t = Some(2);
        for text in [
            "g*cos(k*t) - 2*v - x",
            "sin(t)*cos(t) + x/k",
            "t/2 - v + exp(-t^2)",
            "(x + sqrt(t + 1)) - k*(v - t)",
        ] {
            assert!(compile(&[text]).unwrap().affine_beside(t), "{text}");
        }
        for text in ["t*x", "x/t", "cos(t + x)", "x*v + t", "sin(t)*v", "x^2"] {
            assert!(!compile(&[text]).unwrap().affine_beside(t), "{text}");
        }
        // Without a forcing, it is `affine`: t is a state like the others.
        for text in ["g*cos(k*t) - x", "2*x - v/k + 3"] {
            let tape = compile(&[text]).unwrap();
            assert_eq!(tape.affine_beside(None), tape.affine(), "{text}");
        }
        assert!(!compile(&["g*cos(k*t) - x"]).unwrap().affine());
    }

    #[test]
    fn unknown_names_say_which_and_the_nearest() {
        let e = compile(&["v + gg"]).unwrap_err();
        assert_eq!(e.at, 4);
        assert!(
            e.message.contains("`gg`") && e.message.contains("`g`"),
            "{e:?}"
        );
        let e = compile(&["sinn(x)"]).unwrap_err();
        assert!(e.message.contains("`sin`"), "{e:?}");
        let e = compile(&["sin"]).unwrap_err();
        assert!(e.message.contains("is a function"), "{e:?}");
        let e = compile(&["atan2(x)"]).unwrap_err();
        assert!(e.message.contains("2 argument"), "{e:?}");
        let e = compile(&["zzzzzz"]).unwrap_err();
        assert!(!e.message.contains("did you mean"), "{e:?}");
    }
}
