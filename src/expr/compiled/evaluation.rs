//! A tape's evaluation compiled: each instruction's value in turn, as
//! [`Op::value`] takes it, arithmetic in place and every function,
//! power and two-argument function by a call to the same Rust the
//! interpreter calls. Every tape compiles (where a back end is); the values are the
//! interpreter's bit for bit.

use std::cell::RefCell;

use crate::expr::compiled::emit::{Emit, Helper};
use crate::expr::compiled::layout::Layout;
use crate::expr::compiled::machine::Code;
use crate::expr::compiled::tiered::Tiered;
use crate::expr::tape::{Op, Tape};

/// A tape's evaluation, compiled once warmed up (see `tiered.rs`). It
/// belongs to one tape: the one each [`CompiledTape::eval`] is given.
#[derive(Debug, Default)]
pub struct CompiledTape {
    code: Tiered<Evaluation>,
}

thread_local! {
    /// The registers' values (models are shared, read only, between the
    /// threads of a sweep).
    static WORK: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

impl CompiledTape {
    /// The outputs of `tape` (always this cache's) at `inputs`, into
    /// `out`: compiled where it can be, else by the interpreter.
    #[inline]
    pub fn eval(&self, tape: &Tape, inputs: &[f64], out: &mut [f64]) {
        match self.code.get(|| Evaluation::new(tape)) {
            Some(code) => code.eval(inputs, out),
            None => tape.eval_scratch(inputs, out),
        }
    }

    /// Whether the tape was compiled (not left to the interpreter).
    #[cfg(test)]
    pub fn compiled(&self) -> bool {
        self.code.compiled()
    }
}

/// The most instructions a compiled evaluation holds.
const MAX_INSTRUCTIONS: usize = 1_000_000;

#[derive(Debug)]
struct Evaluation {
    code: Code,
    pool: Box<[f64]>,
    /// How many inputs the tape reads (one past the largest read).
    inputs: usize,
    outputs: usize,
    /// The work buffer's length, its outputs at the end.
    work: usize,
}

impl Evaluation {
    fn new(tape: &Tape) -> Option<Evaluation> {
        if tape.ops.len() > MAX_INSTRUCTIONS {
            return None;
        }
        let layout = Layout::new(tape, 1);
        let code = compile(tape, &layout)?;
        let inputs = tape
            .ops
            .iter()
            .filter_map(|op| match op {
                Op::Input(i) => Some(*i as usize + 1),
                _ => None,
            })
            .max()
            .unwrap_or(0);
        Some(Evaluation {
            code,
            inputs,
            outputs: tape.outputs.len(),
            work: layout.work(tape.outputs.len()),
            pool: layout.pool.into_boxed_slice(),
        })
    }

    // Inlined into each caller as it was before event location called the
    // flow from more places: out of line, its copy of the results became a
    // call to memmove, 13% of a Runge-Kutta run's time.
    #[inline]
    fn eval(&self, inputs: &[f64], out: &mut [f64]) {
        assert!(
            inputs.len() >= self.inputs,
            "a compiled tape reading {} inputs was given {}",
            self.inputs,
            inputs.len()
        );
        WORK.with_borrow_mut(|work| {
            if work.len() < self.work {
                work.resize(self.work, 0.0);
            }
            // SAFETY: the code reads `inputs[..self.inputs]` and `pool`,
            // and writes `work[..self.work]`, at places fixed when it was
            // compiled; the lengths were checked above, and the three are
            // distinct buffers. It writes no input, so the shared slice's
            // pointer is never written through.
            unsafe {
                self.code.run(
                    work.as_mut_ptr(),
                    inputs.as_ptr().cast_mut(),
                    self.pool.as_ptr(),
                );
            }
            let results = &work[self.work - self.outputs..self.work];
            match (out, results) {
                // A guard's or the energy's one value: no call to copy it.
                ([o], [r, ..]) => *o = *r,
                (out, results) => {
                    for (o, r) in out.iter_mut().zip(results) {
                        *o = *r;
                    }
                }
            }
        });
    }
}

/// The evaluation of `tape` in this processor's code, `None` where
/// nothing compiles.
fn compile(tape: &Tape, layout: &Layout) -> Option<Code> {
    #[cfg(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        let e = crate::expr::compiled::machine::Emitter::new(layout.extents(tape.outputs.len()))?;
        lower(e, tape, layout)
    }
    #[cfg(not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))))]
    {
        let _ = (tape, layout);
        None
    }
}

/// The evaluation of `tape` written by `e`.
#[cfg_attr(
    not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))),
    allow(dead_code)
)]
pub(super) fn lower<E: Emit>(mut e: E, tape: &Tape, layout: &Layout) -> Option<E::Code> {
    use crate::expr::compiled::layout::Place;
    use crate::expr::tape::{FUNS, FUNS2};

    let anywhere = layout.output(0);
    for (r, &op) in tape.ops.iter().enumerate() {
        let r = r as u32;
        match op {
            Op::Const(_) | Op::Input(_) => continue,
            Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) => {
                let apply: fn(&mut E, u8, Place) = match op {
                    Op::Add(..) => E::add,
                    Op::Sub(..) => E::sub,
                    Op::Mul(..) => E::mul,
                    _ => E::div,
                };
                e.load(0, layout.at(a, 0));
                apply(&mut e, 0, layout.at(b, 0));
            }
            Op::Neg(a) => {
                e.load(0, layout.at(a, 0));
                e.negate(0);
            }
            Op::Pow(a, b) => {
                e.load(0, layout.at(a, 0));
                e.load(1, layout.at(b, 0));
                e.call(Helper::Pow, 0, anywhere, anywhere);
            }
            Op::Call(f, a) => {
                let kind = FUNS.iter().position(|&(_, g)| g == f)?;
                e.load(0, layout.at(a, 0));
                e.call(Helper::Value, kind as u32, anywhere, anywhere);
            }
            Op::Call2(f, a, b) => {
                let kind = FUNS2.iter().position(|&(_, g)| g == f)?;
                e.load(0, layout.at(a, 0));
                e.load(1, layout.at(b, 0));
                e.call(Helper::Value2, kind as u32, anywhere, anywhere);
            }
        }
        e.store(layout.at(r, 0), 0);
    }
    for (i, &o) in tape.outputs.iter().enumerate() {
        e.load(0, layout.at(o, 0));
        e.store(layout.output(i), 0);
    }
    e.finish()
}
