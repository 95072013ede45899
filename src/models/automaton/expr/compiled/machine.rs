//! x86-64 code for compiled tapes, assembled with dynasm: scalar SSE2
//! loads, stores and arithmetic on places in three buffers, and calls
//! into Rust for what is not arithmetic (a function's value). Other
//! processors assemble nothing, and keep the interpreter.
//!
//! The code is one function, `extern "sysv64" fn(work, state, pool)`: it
//! keeps the three buffers' addresses in callee-saved registers (rbx,
//! r12, r13) and works in xmm0-xmm3.
//!
//! Every result is stored, and the last ones stored are also kept in
//! xmm4-xmm15 (see `Kept`): an operand read soon after it was written
//! comes from its register, not back through memory, where each store
//! and load would add the processor's store-to-load latency to the
//! series' chain of dependent terms (a Henon-Heiles series at order 20,
//! called in a loop: 215 -> 137 ns). The arithmetic, and so every bit, is
//! the same. A call clobbers those registers and may write any place, so
//! it forgets them; memory holds every value, so nothing is saved.

#[cfg(target_arch = "x86_64")]
pub use x64::{Code, Emitter};

#[cfg(not(target_arch = "x86_64"))]
pub use other::Code;

#[cfg(target_arch = "x86_64")]
// dynasm's expansion converts each dynamic register's number by `.into()`.
#[allow(clippy::useless_conversion)]
mod x64 {
    use dynasmrt::x64::Assembler;
    use dynasmrt::{AssemblyOffset, DynasmApi, ExecutableBuffer, dynasm};

    use crate::models::automaton::expr::compiled::layout::{Base, Place};

    /// Compiled code: one function of three buffers.
    pub struct Code {
        /// The mapped code, kept for as long as `function` is called.
        buffer: ExecutableBuffer,
        /// Its entry, taken once (the buffer's mapping does not move with
        /// `Code`): a run is then one indirect call.
        function: Entry,
    }

    type Entry = extern "sysv64" fn(*mut f64, *mut f64, *const f64);

    /// Its size, not its bytes.
    impl std::fmt::Debug for Code {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "Code({} bytes)", self.buffer.len())
        }
    }

    impl Code {
        /// Run the code on the three buffers, which must be as long as the
        /// layout it was compiled for says.
        pub fn run(&self, work: *mut f64, state: *mut f64, pool: *const f64) {
            (self.function)(work, state, pool);
        }
    }

    /// The base register of each buffer (callee-saved: they survive the
    /// calls into Rust).
    fn base(base: Base) -> u8 {
        match base {
            Base::Work => 3,   // rbx
            Base::State => 12, // r12
            Base::Pool => 13,  // r13
        }
    }

    /// A function being assembled, instruction by instruction.
    pub struct Emitter {
        asm: Assembler,
        entry: AssemblyOffset,
        kept: Kept,
    }

    /// The registers that hold copies of the places stored last.
    const KEPT: std::ops::Range<u8> = 4..16;

    /// Which place each of the registers [`KEPT`] holds a copy of, the
    /// oldest copy given up first (round robin). A place stored anew moves
    /// to a new register; a call forgets them all.
    #[derive(Default)]
    struct Kept {
        /// By register number (those below `KEPT` stay `None`).
        places: [Option<Place>; KEPT.end as usize],
        /// The register the next copy goes to.
        next: u8,
    }

    impl Kept {
        /// The register holding `place`, if one does.
        fn find(&self, place: Place) -> Option<u8> {
            KEPT.clone()
                .find(|&r| self.places[r as usize] == Some(place))
        }

        /// A register for a copy of `place` (which no other then holds).
        fn take(&mut self, place: Place) -> u8 {
            if let Some(r) = self.find(place) {
                self.places[r as usize] = None;
            }
            if !KEPT.contains(&self.next) {
                self.next = KEPT.start;
            }
            let r = self.next;
            self.next += 1;
            self.places[r as usize] = Some(place);
            r
        }

        fn forget(&mut self) {
            self.places = [None; KEPT.end as usize];
        }
    }

    /// `op x, operand`, the operand from the register that holds a copy of
    /// the place if one does, else from memory.
    macro_rules! at {
        ($e:ident, $op:ident, $x:expr, $place:expr) => {{
            let place: Place = $place;
            let x: u8 = $x;
            match $e.kept.find(place) {
                Some(r) => dynasm!($e.asm ; .arch x64 ; $op Rx(x), Rx(r)),
                None => {
                    let (b, d) = (base(place.0), place.1);
                    dynasm!($e.asm ; .arch x64 ; $op Rx(x), QWORD [Rq(b) + d]);
                }
            }
        }};
    }

    impl Emitter {
        /// A function's start: the buffers' addresses kept.
        pub fn new() -> Option<Emitter> {
            let mut asm = Assembler::new().ok()?;
            let entry = asm.offset();
            dynasm!(asm
                ; .arch x64
                ; push rbx
                ; push r12
                ; push r13
                ; mov rbx, rdi
                ; mov r12, rsi
                ; mov r13, rdx
            );
            Some(Emitter {
                asm,
                entry,
                kept: Kept::default(),
            })
        }

        /// The function returned from, made executable.
        pub fn finish(mut self) -> Option<Code> {
            dynasm!(self.asm
                ; .arch x64
                ; pop r13
                ; pop r12
                ; pop rbx
                ; ret
            );
            let entry = self.entry;
            let buffer = self.asm.finalize().ok()?;
            // SAFETY: the buffer holds a complete function with this
            // signature, emitted by an `Emitter` from `new` to `finish`,
            // and stays mapped executable for as long as the `Code` that
            // owns it lives.
            let function: Entry = unsafe { std::mem::transmute(buffer.ptr(entry)) };
            Some(Code { buffer, function })
        }

        pub fn load(&mut self, x: u8, place: Place) {
            match self.kept.find(place) {
                // The whole register: a move the processor renames.
                Some(r) => dynasm!(self.asm ; .arch x64 ; movapd Rx(x), Rx(r)),
                None => at!(self, movsd, x, place),
            }
        }
        pub fn add(&mut self, x: u8, place: Place) {
            at!(self, addsd, x, place);
        }
        pub fn sub(&mut self, x: u8, place: Place) {
            at!(self, subsd, x, place);
        }
        pub fn mul(&mut self, x: u8, place: Place) {
            at!(self, mulsd, x, place);
        }
        pub fn div(&mut self, x: u8, place: Place) {
            at!(self, divsd, x, place);
        }
        pub fn store(&mut self, place: Place, x: u8) {
            let (b, d) = place;
            let b = base(b);
            let copy = self.kept.take(place);
            dynasm!(self.asm
                ; .arch x64
                ; movsd QWORD [Rq(b) + d], Rx(x)
                ; movapd Rx(copy), Rx(x)
            );
        }
        pub fn zero(&mut self, x: u8) {
            dynasm!(self.asm ; .arch x64 ; xorpd Rx(x), Rx(x));
        }
        pub fn add_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; addsd Rx(x), Rx(y));
        }
        pub fn sub_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; subsd Rx(x), Rx(y));
        }
        pub fn mul_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; mulsd Rx(x), Rx(y));
        }
        pub fn copy(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; movapd Rx(x), Rx(y));
        }
        /// `x = -x`: its sign bit flipped, as Rust's `-` does.
        pub fn negate(&mut self, x: u8) {
            dynasm!(self.asm
                ; .arch x64
                ; mov rax, QWORD i64::MIN
                ; movq xmm3, rax
                ; xorpd Rx(x), xmm3
            );
        }

        /// Call `helper(kind, xmm0, xmm1, first, second)` (System V: the
        /// integer and pointer arguments in rdi, rsi, rdx, the floats in
        /// xmm0 and xmm1, a float result in xmm0), the two places passed
        /// by address.
        pub fn call(&mut self, helper: *const (), kind: u32, first: Place, second: Place) {
            let (fb, fd) = (base(first.0), first.1);
            let (sb, sd) = (base(second.0), second.1);
            let (kind, helper) = (kind as i32, helper as i64);
            self.kept.forget();
            dynasm!(self.asm
                ; .arch x64
                ; mov edi, kind
                ; lea rsi, [Rq(fb) + fd]
                ; lea rdx, [Rq(sb) + sd]
                ; mov rax, QWORD helper
                ; call rax
            );
        }

        /// `sum_{j in terms} a_j b_{k - j}` into `x`, from zero upwards (the
        /// terms of `lo..=k` that are not known zeros).
        pub fn product(
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
}

#[cfg(not(target_arch = "x86_64"))]
mod other {
    /// No code: nothing compiles on this processor.
    #[derive(Debug)]
    pub enum Code {}

    impl Code {
        pub fn run(&self, _: *mut f64, _: *mut f64, _: *const f64) {
            match *self {}
        }
    }
}
