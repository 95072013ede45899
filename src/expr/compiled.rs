//! Tapes compiled to machine code, as heyoka compiles its decomposition:
//! a flow's Taylor series at one order ([`CompiledFlow`], `series.rs`) and
//! a tape's plain evaluation ([`CompiledTape`], `evaluation.rs`), both
//! straight-line code with each operand at a fixed place (`layout.rs`),
//! lowered once against a back end's interface (`emit.rs`): x86-64 by
//! hand (`machine.rs`), aarch64 by Cranelift (`cranelift.rs`). Both do
//! the same operations in the same order, calling the same Rust for
//! functions (`callbacks.rs`).
//!
//! The interpreter pays about ten instructions of dispatch, indexing and
//! loop control for each floating-point operation; this code pays one or
//! two. It does the same operations on the same operands in the same
//! order (SSE2 scalar arithmetic rounds each one as Rust does, nothing is
//! fused, functions are Rust's own), so its results are the interpreter's
//! bit for bit: no result moves. Compiling Henon-Heiles' series at order
//! 20 takes 0.1 ms, a chain of 100 states 3.5 ms (heyoka's LLVM takes
//! 66-146 ms; Cranelift 5.2 ms for Henon-Heiles, its code 195 ns a
//! series against the hand assembly's 142 and the interpreter's 618, on
//! x86-64). A tape is compiled once it has been asked for 64 times (8192
//! where Cranelift compiles: `tiered.rs`): a short run never pays for it. Other
//! processors, a build without the `jit` feature (on by default), and
//! what does not compile keep the interpreter.

// Where no back end is built, the lowerings' parts are compiled, not used.
#[cfg_attr(
    not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))),
    allow(dead_code)
)]
mod callbacks;
// The portable back end: aarch64's, and tested on x86-64 beside its own.
#[cfg(any(
    all(feature = "jit", target_arch = "aarch64"),
    all(test, target_arch = "x86_64")
))]
mod cranelift;
#[cfg_attr(
    not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))),
    allow(dead_code)
)]
mod emit;
mod evaluation;
#[cfg_attr(
    not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))),
    allow(dead_code)
)]
mod layout;
mod machine;
mod series;
mod tiered;

pub use evaluation::CompiledTape;
pub use series::{CompiledFlow, CompiledFlows};

/// Whether this build compiles tapes to machine code (x86-64 or aarch64,
/// with the `jit` feature), rather than interpreting every one.
pub const MACHINE_CODE: bool = cfg!(all(
    feature = "jit",
    any(target_arch = "x86_64", target_arch = "aarch64")
));

#[cfg(test)]
mod tests;
