//! What a back end does for the lowerings (`series.rs`, `evaluation.rs`):
//! scalar loads, stores and arithmetic on places in the three buffers
//! (see `layout.rs`), in a few numbered registers, and calls into Rust.
//! The lowerings are written once against [`Emit`]; each processor's back
//! end (`machine.rs` for x86-64, `cranelift.rs` elsewhere) turns the same
//! operations, in the same order, into its code, so every back end gives
//! the interpreter's bits.
//!
//! Registers: 0 to 3 are scratch (a call takes its arguments in 0 and 1
//! and leaves its value in 0; any call may change all of them);
//! [`Emit::fresh`] hands out others, to compute a value in that is then
//! stored.

use crate::expr::compiled::layout::Place;

/// The Rust function a call runs (see `callbacks.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Helper {
    /// A function's value at a series' origin and its partner's, written
    /// to the call's two places: `(kind, register 0)`.
    Origin,
    /// One of the tape's functions of one argument, of register 0.
    Value,
    /// One of the tape's functions of two arguments, of registers 0 and 1.
    Value2,
    /// Register 0 to the power register 1.
    Pow,
}

/// One back end's code being written.
pub trait Emit: Sized {
    /// The finished code.
    type Code;

    /// `x = place`.
    fn load(&mut self, x: u8, place: Place);
    /// `x = x + place`.
    fn add(&mut self, x: u8, place: Place);
    /// `x = x - place`.
    fn sub(&mut self, x: u8, place: Place);
    /// `x = x * place`.
    fn mul(&mut self, x: u8, place: Place);
    /// `x = x / place`.
    fn div(&mut self, x: u8, place: Place);
    /// A register to compute a value in that is then stored.
    fn fresh(&mut self) -> u8;
    /// `place = x`.
    fn store(&mut self, place: Place, x: u8);
    /// `x = +0`.
    fn zero(&mut self, x: u8);
    /// `x = x + y`.
    fn add_registers(&mut self, x: u8, y: u8);
    /// `x = x - y`.
    fn sub_registers(&mut self, x: u8, y: u8);
    /// `x = x * y`.
    fn mul_registers(&mut self, x: u8, y: u8);
    /// `x = y`.
    fn copy(&mut self, x: u8, y: u8);
    /// `x = -x`: its sign bit flipped, as Rust's `-` does.
    fn negate(&mut self, x: u8);
    /// Call `helper` on `kind`, registers 0 and 1 and the addresses of
    /// `first` and `second`; a value it returns is left in register 0.
    fn call(&mut self, helper: Helper, kind: u32, first: Place, second: Place);
    /// The code, ready to run; `None` where it could not be made.
    fn finish(self) -> Option<Self::Code>;

    /// `sum_{j in terms} a_j b_{k - j}` into `x`, from zero upwards (the
    /// terms of `lo..=k` that are not known zeros), as the interpreter's
    /// Cauchy sums add them. Register 1 is spent.
    fn product(
        &mut self,
        x: u8,
        a: impl Fn(usize) -> Place,
        b: impl Fn(usize) -> Place,
        k: usize,
        terms: std::ops::RangeInclusive<usize>,
    ) {
        self.zero(x);
        for j in terms {
            self.load(1, a(j));
            self.mul(1, b(k - j));
            self.add_registers(x, 1);
        }
    }
}
