//! A flow's Taylor series compiled to machine code, as heyoka compiles its
//! decomposition: the recurrences of [`Series::flow`] for one tape and one
//! order, unrolled into straight-line x86-64 (every order, every term of
//! every Cauchy sum), each operand at a fixed offset.
//!
//! The interpreter pays about ten instructions of dispatch, indexing and
//! loop control for each floating-point operation; this code pays one or
//! two. It does the same operations on the same operands in the same
//! order (SSE2 scalar arithmetic rounds each one as Rust does, and nothing
//! is fused), so a compiled series is the interpreted one bit for bit: no
//! result moves. Compiling Henon-Heiles' flow at order 20 takes 0.1 ms, a
//! chain of 100 states 3.5 ms (heyoka's LLVM takes 66-146 ms).
//!
//! Tapes of sums, products, quotients, `sin`, `cos`, `sinh`, `cosh` and
//! `exp` compile; a tape with anything else, a very large one, or another
//! processor keeps the interpreter. A function's value at the series'
//! origin is taken by calling Rust's own (the interpreter's), its higher
//! orders by its recurrence.
//!
//! [`Series::flow`]: crate::models::automaton::expr::recurrences::Series::flow

use std::cell::RefCell;
use std::sync::OnceLock;

use crate::engine::taylor_method::MAX_ORDER;
use crate::models::automaton::expr::tape::Tape;

/// A flow's series at each order, compiled the first time it is asked for
/// (a run asks for one order; a sweep over tolerances, for a few).
#[derive(Debug)]
pub struct CompiledFlows {
    by_order: Box<[OnceLock<Option<CompiledFlow>>]>,
}

impl Default for CompiledFlows {
    fn default() -> Self {
        CompiledFlows {
            by_order: (0..=MAX_ORDER).map(|_| OnceLock::new()).collect(),
        }
    }
}

impl CompiledFlows {
    /// The compiled series of `tape` (the flow this cache belongs to) at
    /// `order`, if it compiles.
    #[inline]
    pub fn get(&self, tape: &Tape, order: usize) -> Option<&CompiledFlow> {
        self.by_order
            .get(order)?
            .get_or_init(|| CompiledFlow::new(tape, order))
            .as_ref()
    }
}

thread_local! {
    /// The registers' coefficients (models are shared, read only, between
    /// the threads of a sweep).
    static SCRATCH: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The series of one flow at one order, as machine code.
pub struct CompiledFlow {
    code: machine::Code,
    /// Constants the code reads: each constant register's series (its value,
    /// then zeros), the integers `0..=order + 1` and the signs.
    pool: Box<[f64]>,
    /// Coefficients kept per register and state component (`order + 1`).
    width: usize,
    /// State components (the tape's outputs).
    states: usize,
    /// Scratch the code writes: main and helper series of every register.
    scratch: usize,
}

impl std::fmt::Debug for CompiledFlow {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CompiledFlow")
            .field("order", &(self.width - 1))
            .field("states", &self.states)
            .field("code_bytes", &self.code.len())
            .finish()
    }
}

/// The most terms (coefficient operations) a compiled series may hold:
/// about 25 bytes of code each, so 100 MB at most.
const MAX_TERMS: usize = 4_000_000;

impl CompiledFlow {
    /// Compile the series of the flow `x' = tape(x)` at `order` (see
    /// [`Series::flow`]); `None` where the tape, its size or the processor
    /// is not one this compiles.
    ///
    /// [`Series::flow`]: crate::models::automaton::expr::recurrences::Series::flow
    pub fn new(tape: &Tape, order: usize) -> Option<CompiledFlow> {
        let states = tape.outputs.len();
        let inputs_in_range = tape.ops.iter().all(|op| match op {
            crate::models::automaton::expr::Op::Input(i) => (*i as usize) < states,
            _ => true,
        });
        if order == 0 || order > MAX_ORDER || !inputs_in_range || terms(tape, order) > MAX_TERMS {
            return None;
        }
        let width = order + 1;
        let layout = layout::Layout::new(tape, width);
        let code = machine::compile(tape, &layout, order)?;
        Some(CompiledFlow {
            code,
            pool: layout.pool.into_boxed_slice(),
            width,
            states,
            scratch: 2 * tape.ops.len() * width,
        })
    }

    /// The series from `x0` into `out`, laid out as [`Series::flow`]
    /// writes it (`out[i * (order + 1) + k]`).
    ///
    /// [`Series::flow`]: crate::models::automaton::expr::recurrences::Series::flow
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
        SCRATCH.with_borrow_mut(|scratch| {
            if scratch.len() < self.scratch {
                scratch.resize(self.scratch, 0.0);
            }
            // The code reads and writes `scratch[..self.scratch]`, `out[..
            // states * width]` and `pool`, at offsets fixed when it was
            // compiled from these sizes; the lengths were checked above.
            self.code
                .run(scratch.as_mut_ptr(), out.as_mut_ptr(), self.pool.as_ptr());
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

mod layout;
mod machine;

#[cfg(test)]
mod tests;
