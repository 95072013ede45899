//! Tapes compiled to machine code, as heyoka compiles its decomposition:
//! a flow's Taylor series at one order ([`CompiledFlow`], `series.rs`) and
//! a tape's plain evaluation ([`CompiledTape`], `evaluation.rs`), both
//! straight-line x86-64 (`machine.rs`) with each operand at a fixed place
//! (`layout.rs`).
//!
//! The interpreter pays about ten instructions of dispatch, indexing and
//! loop control for each floating-point operation; this code pays one or
//! two. It does the same operations on the same operands in the same
//! order (SSE2 scalar arithmetic rounds each one as Rust does, nothing is
//! fused, functions are Rust's own), so its results are the interpreter's
//! bit for bit: no result moves. Compiling Henon-Heiles' series at order
//! 20 takes 0.1 ms, a chain of 100 states 3.5 ms (heyoka's LLVM takes
//! 66-146 ms). A tape is compiled once it has been asked for 64
//! times (`tiered.rs`): a short run never pays for it. Other
//! processors, a build without the `jit` feature (on by default), and
//! what does not compile keep the interpreter.

mod evaluation;
// Where is no machine code, the layout is built and never read.
#[cfg_attr(not(all(feature = "jit", target_arch = "x86_64")), allow(dead_code))]
mod layout;
mod machine;
mod series;
mod tiered;

pub use evaluation::CompiledTape;
pub use series::{CompiledFlow, CompiledFlows};

/// Whether this build compiles tapes to machine code (x86-64 with the
/// `jit` feature), rather than interpreting every one.
pub const MACHINE_CODE: bool = cfg!(all(feature = "jit", target_arch = "x86_64"));

#[cfg(test)]
mod tests;
