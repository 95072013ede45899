//! A flow's Taylor series compiled, as heyoka compiles its decomposition:
//! the recurrences of [`Series::flow`] for one tape and one order,
//! unrolled (every order, every term of every Cauchy sum), each operand at
//! a fixed place.
//!
//! Each instruction follows the recurrence the interpreter gives it
//! ([`recurrence`]: one classification for both). Tapes of sums,
//! products, quotients, `sin`, `cos`, `sinh`, `cosh` and `exp` compile; a tape with anything else, or a very large one, keeps
//! the interpreter. A function's value at the series' origin is taken by
//! calling Rust's own (the interpreter's), its higher orders by its
//! recurrence.
//!
//! [`Series::flow`]: crate::expr::recurrences::Series::flow

use std::cell::RefCell;

use crate::engine::step::taylor_method::MAX_ORDER;
use crate::expr::compiled::callbacks::Origin;
use crate::expr::compiled::emit::{Emit, Helper};
use crate::expr::compiled::layout::Layout;
use crate::expr::compiled::machine::Code;
use crate::expr::compiled::tiered::Tiered;
use crate::expr::recurrences::{Recurrence, recurrence};
use crate::expr::tape::{Op, Reg, Tape};

/// A flow's series at each order, compiled once warmed up (see
/// `tiered.rs`; a run asks for one order, a sweep over tolerances for a
/// few).
#[derive(Debug)]
pub struct CompiledFlows {
    by_order: Box<[Tiered<CompiledFlow>]>,
}

impl Default for CompiledFlows {
    fn default() -> Self {
        CompiledFlows {
            by_order: (0..=MAX_ORDER).map(|_| Tiered::default()).collect(),
        }
    }
}

impl CompiledFlows {
    /// The compiled series of `tape` (the flow this cache belongs to) at
    /// `order`, if it is warmed up and compiles.
    #[inline]
    pub fn get(&self, tape: &Tape, order: usize) -> Option<&CompiledFlow> {
        self.by_order
            .get(order)?
            .get(|| CompiledFlow::new(tape, order))
    }
}

thread_local! {
    /// The registers' coefficients (models are shared, read only, between
    /// the threads of a sweep).
    static WORK: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The series of one flow at one order, as machine code.
#[derive(Debug)]
pub struct CompiledFlow {
    code: Code,
    /// Constants the code reads (see [`Layout`]).
    pool: Box<[f64]>,
    /// Coefficients kept per register and state component (`order + 1`).
    width: usize,
    /// State components (the tape's outputs).
    states: usize,
    /// The work buffer's length.
    work: usize,
}

/// The most terms (coefficient operations) a compiled series may hold:
/// 15 to 25 bytes of code each, so 100 MB at most.
const MAX_TERMS: usize = 4_000_000;

impl CompiledFlow {
    /// Compile the series of the flow `x' = tape(x)` at `order` (see
    /// [`Series::flow`]); `None` where the tape, its size or the processor
    /// is not one this compiles.
    ///
    /// [`Series::flow`]: crate::expr::recurrences::Series::flow
    pub fn new(tape: &Tape, order: usize) -> Option<CompiledFlow> {
        let states = tape.outputs.len();
        let inputs_in_range = tape.ops.iter().all(|op| match op {
            Op::Input(i) => (*i as usize) < states,
            _ => true,
        });
        if order == 0 || order > MAX_ORDER || !inputs_in_range || terms(tape, order) > MAX_TERMS {
            return None;
        }
        let width = order + 1;
        let layout = Layout::new(tape, width);
        let code = compile(tape, &layout, order)?;
        Some(CompiledFlow {
            code,
            work: layout.work(0),
            pool: layout.pool.into_boxed_slice(),
            width,
            states,
        })
    }

    /// The series from `x0` into `out`, laid out as [`Series::flow`]
    /// writes it (`out[i * (order + 1) + k]`).
    ///
    /// [`Series::flow`]: crate::expr::recurrences::Series::flow
    pub fn flow(&self, x0: &[f64], out: &mut [f64]) {
        let w = self.width;
        assert!(
            x0.len() == self.states && out.len() >= self.states * w,
            "a compiled series of {} components was given {} initial values and room for {}",
            self.states,
            x0.len(),
            out.len() / w
        );
        for (i, &x) in x0.iter().enumerate() {
            out[i * w] = x;
        }
        WORK.with_borrow_mut(|work| {
            if work.len() < self.work {
                work.resize(self.work, 0.0);
            }
            // SAFETY: the code reads and writes `work[..self.work]`,
            // `out[..states * width]` and `pool`, at places fixed when it
            // was compiled from these sizes; the lengths were checked
            // above, and the three are distinct buffers.
            unsafe {
                self.code
                    .run(work.as_mut_ptr(), out.as_mut_ptr(), self.pool.as_ptr());
            }
        });
    }
}

/// How many coefficient operations the series of `tape` at `order` takes
/// (a product's order `k` is `k + 1`).
fn terms(tape: &Tape, order: usize) -> usize {
    tape.ops
        .len()
        .saturating_mul(order)
        .saturating_mul(order + 1)
}

/// The degree of each register's series where it is a polynomial in the
/// step (a constant's is 0, the clock's 1, a product's the sum), else
/// `usize::MAX`. A state is a polynomial of one degree more than its rate
/// where that is one. Coefficients past a register's degree are exact
/// zeros, so the Cauchy sums leave out the terms they would multiply: a
/// forcing `cos(w t)` then costs one term an order, not `k`. Leaving out
/// an exact zero moves no sum (one that starts at `+0` never becomes
/// `-0`), so the code still gives the interpreter's bits.
pub(super) fn degrees(tape: &Tape) -> Vec<usize> {
    const ANY: usize = usize::MAX;
    let mut states = vec![ANY; tape.outputs.len()];
    let mut degree = vec![ANY; tape.ops.len()];
    // Each pass settles at least one more state of a chain of polynomials
    // (t, then t^2 / 2, ...), or none at all.
    for _ in 0..=states.len() {
        for (i, op) in tape.ops.iter().enumerate() {
            let d = |r: Reg| degree[r as usize];
            degree[i] = match *op {
                Op::Const(_) => 0,
                Op::Input(j) => states[j as usize],
                Op::Add(a, b) | Op::Sub(a, b) => d(a).max(d(b)),
                Op::Neg(a) => d(a),
                Op::Mul(a, b) => d(a).saturating_add(d(b)),
                Op::Div(a, b) if d(b) == 0 => d(a),
                _ if op.operands().all(|r| d(r) == 0) => 0,
                _ => ANY,
            };
        }
        let next: Vec<usize> = tape
            .outputs
            .iter()
            .map(|&o| degree[o as usize].saturating_add(1))
            .collect();
        if next == states {
            break;
        }
        states = next;
    }
    degree
}

/// The series of `tape` at `order` in this processor's code, `None` for
/// an instruction that does not compile, or where nothing does.
fn compile(tape: &Tape, layout: &Layout, order: usize) -> Option<Code> {
    #[cfg(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        let e = crate::expr::compiled::machine::Emitter::new(layout.extents(0))?;
        lower(e, tape, layout, order)
    }
    #[cfg(not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))))]
    {
        let _ = (tape, layout, order);
        None
    }
}

/// The series of `tape` at `order` written by `e`, `None` for an
/// instruction this does not compile.
#[cfg_attr(
    not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))),
    allow(dead_code)
)]
pub(super) fn lower<E: Emit>(
    mut e: E,
    tape: &Tape,
    layout: &Layout,
    order: usize,
) -> Option<E::Code> {
    use crate::expr::compiled::layout::Base;
    use crate::expr::tape::Fun;

    let degree = degrees(tape);
    // The terms `j` of a Cauchy sum `sum_j a_j b_(k - j)` (from `lo`) whose
    // factors are not past their degrees.
    let terms = |a: u32, b: u32, k: usize, lo: usize| {
        lo.max(k.saturating_sub(degree[b as usize]))..=k.min(degree[a as usize])
    };
    let width = order + 1;
    for k in 0..order {
        for r in 0..tape.ops.len() {
            let out = layout.at(r as u32, k);
            // Arithmetic computes in a fresh register, which keeps the value
            // it stores; a function's recurrence works in xmm0-xmm3.
            let result = match recurrence(tape, r) {
                Recurrence::Const(_) | Recurrence::Input(_) => continue,
                Recurrence::Add(a, b) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, k));
                    e.add(x, layout.at(b, k));
                    x
                }
                Recurrence::Sub(a, b) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, k));
                    e.sub(x, layout.at(b, k));
                    x
                }
                Recurrence::Neg(a) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, k));
                    e.negate(x);
                    x
                }
                Recurrence::ScaledRight(a, b) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, 0));
                    e.mul(x, layout.at(b, k));
                    x
                }
                Recurrence::ScaledLeft(a, b) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, k));
                    e.mul(x, layout.at(b, 0));
                    x
                }
                // A square as the interpreter's (`recurrences::square`):
                // each pair once, doubled, then the middle term; the terms
                // past its degree are exact zeros and left out.
                Recurrence::Square(a) if k >= 1 => {
                    let x = e.fresh();
                    let terms = terms(a, a, k, 0);
                    let pairs = *terms.start()..=(*terms.end()).min((k - 1) / 2);
                    e.product(x, |j| layout.at(a, j), |j| layout.at(a, j), k, pairs);
                    e.add_registers(x, x);
                    if k.is_multiple_of(2) && terms.contains(&(k / 2)) {
                        e.load(1, layout.at(a, k / 2));
                        e.mul(1, layout.at(a, k / 2));
                        e.add_registers(x, 1);
                    }
                    x
                }
                // Order 0 of a square is its one product.
                Recurrence::Mul(a, b) | Recurrence::Square(a @ b) => {
                    let x = e.fresh();
                    e.product(
                        x,
                        |j| layout.at(a, j),
                        |j| layout.at(b, j),
                        k,
                        terms(a, b, k, 0),
                    );
                    x
                }
                Recurrence::DivConst(a, b) => {
                    let x = e.fresh();
                    e.load(x, layout.at(a, k));
                    e.div(x, layout.at(b, 0));
                    x
                }
                Recurrence::Div(a, b) => {
                    let x = e.fresh();
                    let r = r as u32;
                    // a = q b: q_k = (a_k - sum_{j=1..k} b_j q_{k-j}) / b_0.
                    e.product(
                        2,
                        |j| layout.at(b, j),
                        |j| layout.at(r, j),
                        k,
                        terms(b, r, k, 1),
                    );
                    e.load(x, layout.at(a, k));
                    e.sub_registers(x, 2);
                    e.div(x, layout.at(b, 0));
                    x
                }
                Recurrence::Call(f @ (Fun::Sin | Fun::Cos | Fun::Sinh | Fun::Cosh), a) => {
                    let r = r as u32;
                    let hyperbolic = matches!(f, Fun::Sinh | Fun::Cosh);
                    let is_sin = matches!(f, Fun::Sin | Fun::Sinh);
                    if k == 0 {
                        let kind = match f {
                            Fun::Sin => Origin::Sin,
                            Fun::Cos => Origin::Cos,
                            Fun::Sinh => Origin::Sinh,
                            _ => Origin::Cosh,
                        };
                        e.load(0, layout.at(a, 0));
                        e.call(Helper::Origin, kind as u32, out, layout.helper(r, 0));
                        continue;
                    }
                    // s' = a' c, c' = -+ a' s: the rates j a_j times the
                    // partner's (into xmm0) and the value's (xmm1).
                    e.zero(0);
                    e.zero(1);
                    for j in 1..=k.min(degree[a as usize]) {
                        e.load(2, layout.integer(j));
                        e.mul(2, layout.at(a, j));
                        e.copy(3, 2);
                        e.mul(3, layout.helper(r, k - j));
                        e.add_registers(0, 3);
                        e.mul(2, layout.at(r, k - j));
                        e.add_registers(1, 2);
                    }
                    e.div(0, layout.integer(k));
                    e.div(1, layout.integer(k));
                    // The sign times the one that changes sign.
                    let sign = if hyperbolic {
                        layout.integer(1)
                    } else {
                        layout.minus_one()
                    };
                    let signed = if is_sin { 1 } else { 0 };
                    e.load(2, sign);
                    e.mul_registers(2, signed);
                    e.copy(signed, 2);
                    e.store(layout.helper(r, k), 1);
                    0
                }
                Recurrence::Call(Fun::Exp, a) => {
                    let r = r as u32;
                    if k == 0 {
                        e.load(0, layout.at(a, 0));
                        e.call(Helper::Origin, Origin::Exp as u32, out, layout.helper(r, 0));
                        continue;
                    }
                    // e' = a' e.
                    e.zero(0);
                    for j in 1..=k.min(degree[a as usize]) {
                        e.load(2, layout.integer(j));
                        e.mul(2, layout.at(a, j));
                        e.mul(2, layout.at(r, k - j));
                        e.add_registers(0, 2);
                    }
                    e.div(0, layout.integer(k));
                    0
                }
                Recurrence::PowConst(..)
                | Recurrence::Pow(..)
                | Recurrence::Call(..)
                | Recurrence::Call2(..) => return None,
            };
            e.store(out, result);
        }
        // The state's order k + 1 is the rate's order k over k + 1.
        for (i, &o) in tape.outputs.iter().enumerate() {
            let x = e.fresh();
            e.load(x, layout.at(o, k));
            e.div(x, layout.integer(k + 1));
            let to = i32::try_from((i * width + k + 1) * size_of::<f64>()).ok()?;
            e.store((Base::State, to), x);
        }
    }
    e.finish()
}
