//! x86-64 code for compiled tapes: scalar SSE2 loads, stores and
//! arithmetic on places in three buffers, and calls into Rust for what is
//! not arithmetic (a function's value). aarch64 has Cranelift's
//! (`cranelift.rs`); other processors assemble nothing, and keep the
//! interpreter.
//!
//! The code is one function, `extern "sysv64" fn(work, state, pool)`,
//! straight-line and run once a step: kilobytes of it (11 KB for
//! Henon-Heiles at order 20), fetched anew at each step beside the rest of
//! the step's code, so that in a run its size sets its pace more than its
//! arithmetic does. It reaches the buffers through windows (see
//! `Window`): general registers pointing into them, so that most places
//! take a one-byte displacement. The arithmetic is encoded by hand
//! (`Emitter::sse`: dynasm gives a register chosen at run time a SIB byte
//! and a four-byte displacement at every use); the rest (the prologue,
//! calls) by dynasm. That made Henon-Heiles' series 12 KB of code instead
//! of 18 KB, and a bare run of it 9% faster.
//!
//! Every result is stored, and the last ones stored are also kept in
//! xmm4-xmm15 (see `Kept`; arithmetic computes in the register that then
//! keeps its value, `Emitter::fresh`; a function's recurrence works in
//! xmm0-xmm3): an operand read soon after it was written comes from its
//! register, not back through memory, where each store and load would add
//! the processor's store-to-load latency to the series' chain of dependent
//! terms (Henon-Heiles' series in a loop: 222-238 -> 140 ns). The
//! arithmetic, and so every bit, is the same. A call clobbers those
//! registers and may write any place, so it forgets them; memory holds
//! every value, so nothing is saved.

#[cfg(all(feature = "jit", target_arch = "x86_64"))]
pub use x64::{Code, Emitter};

#[cfg(all(feature = "jit", target_arch = "aarch64"))]
pub use super::cranelift::{Code, Emitter};

#[cfg(not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))))]
pub use other::Code;

#[cfg(all(feature = "jit", target_arch = "x86_64"))]
// dynasm's expansion converts each dynamic register's number by `.into()`.
#[allow(clippy::useless_conversion)]
mod x64 {
    use dynasmrt::x64::Assembler;
    use dynasmrt::{AssemblyOffset, DynasmApi, ExecutableBuffer, dynasm};

    use crate::expr::compiled::callbacks;
    use crate::expr::compiled::emit::{Emit, Helper};
    use crate::expr::compiled::layout::{Base, Place};

    /// Compiled code: one function of three buffers.
    pub struct Code {
        /// The mapped code, kept for as long as `function` is called.
        buffer: ExecutableBuffer,
        /// Its entry, taken once (the buffer's mapping does not move with
        /// `Code`): a run is then one indirect call.
        function: Entry,
    }

    /// The compiled function: it reads and writes the three buffers at
    /// places fixed when it was compiled, so calling it is unsafe.
    type Entry = unsafe extern "sysv64" fn(*mut f64, *mut f64, *const f64);

    /// Its size, not its bytes.
    impl std::fmt::Debug for Code {
        fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            write!(f, "Code({} bytes)", self.buffer.len())
        }
    }

    impl Code {
        /// Run the code on the three buffers.
        ///
        /// # Safety
        ///
        /// Each buffer must be valid, for as many `f64`s as the layout the
        /// code was compiled for says (`work` and `state` for reads and
        /// writes, `pool` for reads), and none may overlap another: the
        /// code reads and writes them at fixed places, unchecked.
        pub unsafe fn run(&self, work: *mut f64, state: *mut f64, pool: *const f64) {
            // SAFETY: the buffers are as the caller promised; the function
            // is one `finish` emitted whole (see there).
            unsafe { (self.function)(work, state, pool) }
        }
    }

    /// The register holding each buffer's base window (its address plus
    /// `REACH`), from which its other windows are set: one a call keeps.
    fn base(buffer: Base) -> u8 {
        match buffer {
            Base::Work => 3,  // rbx
            Base::State => 5, // rbp
            Base::Pool => 13, // r13
        }
    }

    /// General registers for the windows past the bases: first those a
    /// call keeps, then those it clobbers, set again after each call. rsp
    /// and r12 would take a SIB byte at each use; rax, rdi, rsi and rdx
    /// carry a call's arguments.
    const KEPT_BY_CALLS: [u8; 2] = [14, 15]; // r14 r15
    const CLOBBERED_BY_CALLS: [u8; 5] = [1, 8, 9, 10, 11]; // rcx r8 r9 r10 r11

    /// A general register holding a buffer's address plus `center` bytes:
    /// a place within -128..=127 bytes of it is addressed by a one-byte
    /// displacement, not a four-byte one (a series of order 20 spans 168
    /// bytes, so most of its terms take five or six bytes of code, not
    /// nine or ten).
    #[derive(Clone, Copy)]
    struct Window {
        buffer: Base,
        center: i32,
        register: u8,
    }

    /// The bytes a window reaches on either side of its center.
    const REACH: i32 = 128;

    /// A function being assembled, instruction by instruction.
    pub struct Emitter {
        asm: Assembler,
        entry: AssemblyOffset,
        kept: Kept,
        /// The windows past the buffers' bases.
        windows: Vec<Window>,
    }

    /// The registers that keep the values of the places stored last.
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

        /// The next register in turn, holding nothing now.
        fn fresh(&mut self) -> u8 {
            if !KEPT.contains(&self.next) {
                self.next = KEPT.start;
            }
            let r = self.next;
            self.next += 1;
            self.places[r as usize] = None;
            r
        }

        /// Register `r` holds `place` (which no other then does).
        fn hold(&mut self, place: Place, r: u8) {
            if let Some(old) = self.find(place) {
                self.places[old as usize] = None;
            }
            self.places[r as usize] = Some(place);
        }

        fn forget(&mut self) {
            self.places = [None; KEPT.end as usize];
        }
    }

    /// An SSE instruction's operand other than its destination.
    enum Operand {
        Register(u8),
        /// A general register and a displacement from it.
        Memory(u8, i32),
    }

    /// Scalar double precision opcodes (after `0F`), each with its
    /// mandatory prefix.
    const MOVSD_LOAD: (u8, u8) = (0xF2, 0x10);
    const MOVSD_STORE: (u8, u8) = (0xF2, 0x11);
    const ADDSD: (u8, u8) = (0xF2, 0x58);
    const MULSD: (u8, u8) = (0xF2, 0x59);
    const SUBSD: (u8, u8) = (0xF2, 0x5C);
    const DIVSD: (u8, u8) = (0xF2, 0x5E);
    const MOVAPD: (u8, u8) = (0x66, 0x28);
    const XORPD: (u8, u8) = (0x66, 0x57);

    impl Emitter {
        /// A function's start: the buffers' addresses kept, and windows
        /// set into buffers of `extents` bytes (work, state, pool).
        pub fn new(extents: [usize; 3]) -> Option<Emitter> {
            let mut asm = Assembler::new().ok()?;
            let entry = asm.offset();
            // Five pushes and the return address keep rsp 16-aligned for
            // the calls.
            dynasm!(asm
                ; .arch x64
                ; push rbx
                ; push rbp
                ; push r13
                ; push r14
                ; push r15
                ; lea rbx, [rdi + REACH]
                ; lea rbp, [rsi + REACH]
                ; lea r13, [rdx + REACH]
            );
            // The state's first (its series are the products' factors),
            // while registers last.
            let mut windows = Vec::new();
            let mut free = KEPT_BY_CALLS.iter().chain(&CLOBBERED_BY_CALLS);
            'buffers: for (buffer, extent) in [
                (Base::State, extents[1]),
                (Base::Work, extents[0]),
                (Base::Pool, extents[2]),
            ] {
                let extent = i32::try_from(extent).ok()?;
                for center in (3 * REACH..extent + REACH).step_by(2 * REACH as usize) {
                    let Some(&register) = free.next() else {
                        break 'buffers;
                    };
                    windows.push(Window {
                        buffer,
                        center,
                        register,
                    });
                }
            }
            let mut e = Emitter {
                asm,
                entry,
                kept: Kept::default(),
                windows,
            };
            e.set_windows(|_| true);
            Some(e)
        }

        /// Set the windows whose registers `which` names, from the bases.
        fn set_windows(&mut self, which: impl Fn(u8) -> bool) {
            for w in self.windows.iter().copied() {
                if which(w.register) {
                    let (b, d) = (base(w.buffer), w.center - REACH);
                    dynasm!(self.asm ; .arch x64 ; lea Rq(w.register), [Rq(b) + d]);
                }
            }
        }

        /// The register and displacement that address `place`: through a
        /// window that reaches it, else from its buffer's base.
        fn address(&self, (buffer, offset): Place) -> (u8, i32) {
            let reaches =
                |w: &&Window| w.buffer == buffer && (-REACH..REACH).contains(&(offset - w.center));
            match self.windows.iter().find(reaches) {
                Some(w) => (w.register, offset - w.center),
                None => (base(buffer), offset - REACH),
            }
        }

        /// Emit `prefix [REX] 0F opcode ModRM [SIB] [displacement]`: `op
        /// xmm(reg), operand` (or the store, its operand the destination).
        fn sse(&mut self, (prefix, opcode): (u8, u8), reg: u8, operand: Operand) {
            let (rm, mode, displacement) = match operand {
                Operand::Register(r) => (r, 0b11, None),
                Operand::Memory(base, d) => match i8::try_from(d) {
                    Ok(d) => (base, 0b01, Some((d as i32, 1))),
                    Err(_) => (base, 0b10, Some((d, 4))),
                },
            };
            self.asm.push(prefix);
            let rex = ((reg >> 3) << 2) | (rm >> 3);
            if rex != 0 {
                self.asm.push(0x40 | rex);
            }
            self.asm.push(0x0F);
            self.asm.push(opcode);
            self.asm.push((mode << 6) | ((reg & 7) << 3) | (rm & 7));
            if let Some((d, size)) = displacement {
                // rsp or r12 as the base takes a SIB byte (no index).
                if rm & 7 == 4 {
                    self.asm.push(0x24);
                }
                for &byte in &d.to_le_bytes()[..size] {
                    self.asm.push(byte);
                }
            }
        }

        /// `op x, place`, the place read from the register that holds a
        /// copy of it if one does.
        fn at(&mut self, op: (u8, u8), x: u8, place: Place) {
            let operand = match self.kept.find(place) {
                Some(r) => Operand::Register(r),
                None => {
                    let (b, d) = self.address(place);
                    Operand::Memory(b, d)
                }
            };
            self.sse(op, x, operand);
        }
    }

    impl Emit for Emitter {
        type Code = Code;

        /// The function returned from, made executable.
        fn finish(mut self) -> Option<Code> {
            dynasm!(self.asm
                ; .arch x64
                ; pop r15
                ; pop r14
                ; pop r13
                ; pop rbp
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

        fn load(&mut self, x: u8, place: Place) {
            match self.kept.find(place) {
                // The whole register: a move the processor renames.
                Some(r) => self.sse(MOVAPD, x, Operand::Register(r)),
                None => self.at(MOVSD_LOAD, x, place),
            }
        }
        fn add(&mut self, x: u8, place: Place) {
            self.at(ADDSD, x, place);
        }
        fn sub(&mut self, x: u8, place: Place) {
            self.at(SUBSD, x, place);
        }
        fn mul(&mut self, x: u8, place: Place) {
            self.at(MULSD, x, place);
        }
        fn div(&mut self, x: u8, place: Place) {
            self.at(DIVSD, x, place);
        }
        /// A register to compute a value in that is then stored: it keeps
        /// the value with no copy (see [`Emitter::store`]).
        fn fresh(&mut self) -> u8 {
            self.kept.fresh()
        }

        /// Store `x` at `place`, and keep it in a register: `x` itself
        /// where it came from [`Emitter::fresh`], else a copy.
        fn store(&mut self, place: Place, x: u8) {
            let (b, d) = self.address(place);
            self.sse(MOVSD_STORE, x, Operand::Memory(b, d));
            if KEPT.contains(&x) {
                self.kept.hold(place, x);
            } else {
                let copy = self.kept.fresh();
                self.kept.hold(place, copy);
                self.sse(MOVAPD, copy, Operand::Register(x));
            }
        }
        fn zero(&mut self, x: u8) {
            self.sse(XORPD, x, Operand::Register(x));
        }
        fn add_registers(&mut self, x: u8, y: u8) {
            self.sse(ADDSD, x, Operand::Register(y));
        }
        fn sub_registers(&mut self, x: u8, y: u8) {
            self.sse(SUBSD, x, Operand::Register(y));
        }
        fn mul_registers(&mut self, x: u8, y: u8) {
            self.sse(MULSD, x, Operand::Register(y));
        }
        fn copy(&mut self, x: u8, y: u8) {
            self.sse(MOVAPD, x, Operand::Register(y));
        }
        /// `x = -x`: its sign bit flipped, as Rust's `-` does.
        fn negate(&mut self, x: u8) {
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
        fn call(&mut self, helper: Helper, kind: u32, first: Place, second: Place) {
            let (fb, fd) = self.address(first);
            let (sb, sd) = self.address(second);
            let (kind, helper) = (kind as i32, callbacks::address(helper) as i64);
            self.kept.forget();
            dynasm!(self.asm
                ; .arch x64
                ; mov edi, kind
                ; lea rsi, [Rq(fb) + fd]
                ; lea rdx, [Rq(sb) + sd]
                ; mov rax, QWORD helper
                ; call rax
            );
            self.set_windows(|r| CLOBBERED_BY_CALLS.contains(&r));
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        /// What `emit` writes by hand.
        fn by_hand(emit: impl FnOnce(&mut Emitter)) -> Vec<u8> {
            let asm = Assembler::new().unwrap();
            let mut e = Emitter {
                entry: asm.offset(),
                asm,
                kept: Kept::default(),
                windows: Vec::new(),
            };
            emit(&mut e);
            e.asm.finalize().unwrap().to_vec()
        }

        /// What dynasm writes for the same instruction, its registers and
        /// displacement known when it is assembled (so that it picks the
        /// shortest form, as the hand encoding does).
        fn dynasm_s(emit: impl FnOnce(&mut Assembler)) -> Vec<u8> {
            let mut asm = Assembler::new().unwrap();
            emit(&mut asm);
            asm.finalize().unwrap().to_vec()
        }

        #[test]
        fn hand_encoded_instructions_are_dynasm_s() {
            use Operand::{Memory, Register};
            let cases: Vec<(Vec<u8>, Vec<u8>)> = vec![
                (
                    by_hand(|e| e.sse(MULSD, 1, Memory(3, 8))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; mulsd xmm1, QWORD [rbx + 8])),
                ),
                (
                    by_hand(|e| e.sse(ADDSD, 0, Memory(3, -128))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; addsd xmm0, QWORD [rbx - 128])),
                ),
                (
                    by_hand(|e| e.sse(DIVSD, 2, Memory(5, 127))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; divsd xmm2, QWORD [rbp + 127])),
                ),
                (
                    by_hand(|e| e.sse(SUBSD, 9, Memory(13, -100))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; subsd xmm9, QWORD [r13 - 100])),
                ),
                (
                    by_hand(|e| e.sse(MOVSD_LOAD, 3, Memory(11, 4096))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; movsd xmm3, QWORD [r11 + 4096])),
                ),
                (
                    by_hand(|e| e.sse(MOVSD_STORE, 3, Memory(12, 4096))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; movsd QWORD [r12 + 4096], xmm3)),
                ),
                (
                    by_hand(|e| e.sse(MOVSD_STORE, 14, Memory(1, -129))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; movsd QWORD [rcx - 129], xmm14)),
                ),
                (
                    by_hand(|e| e.sse(MOVAPD, 12, Register(3))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; movapd xmm12, xmm3)),
                ),
                (
                    by_hand(|e| e.sse(XORPD, 0, Register(0))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; xorpd xmm0, xmm0)),
                ),
                (
                    by_hand(|e| e.sse(SUBSD, 15, Register(8))),
                    dynasm_s(|a| dynasm!(a ; .arch x64 ; subsd xmm15, xmm8)),
                ),
            ];
            for (k, (hand, reference)) in cases.iter().enumerate() {
                assert_eq!(
                    hand, reference,
                    "case {k}: {hand:02x?} by hand, {reference:02x?} by dynasm"
                );
            }
        }

        /// A place is addressed through the window that reaches it, by one
        /// byte, else from its buffer's base by four.
        #[test]
        fn places_are_addressed_through_their_windows() {
            let mut e = Emitter::new([2000, 600, 100]).unwrap();
            // Work's base (rbx, center 128), state's (rbp), pool's (r13).
            assert_eq!(e.address((Base::Work, 0)), (3, -128));
            assert_eq!(e.address((Base::State, 255)), (5, 127));
            assert_eq!(e.address((Base::Pool, 8)), (13, -120));
            // The state's second window (r14, center 384), then the
            // third (r15, 640), then work's (rcx, r8, ...).
            assert_eq!(e.address((Base::State, 256)), (14, -128));
            assert_eq!(e.address((Base::State, 600)), (15, -40));
            assert_eq!(e.address((Base::Work, 300)), (1, -84));
            // Past every window: from the base, by four bytes.
            assert_eq!(e.address((Base::Pool, 800)), (13, 672));
            e.store((Base::State, 600), 0);
            assert!(e.finish().is_some());
        }
    }
}

#[cfg(not(all(feature = "jit", any(target_arch = "x86_64", target_arch = "aarch64"))))]
mod other {
    /// No code: nothing compiles on this processor.
    #[derive(Debug)]
    pub enum Code {}

    impl Code {
        /// Never called: no `Code` exists here.
        ///
        /// # Safety
        ///
        /// As the machine code's (see the x86-64 `Code::run`).
        pub unsafe fn run(&self, _: *mut f64, _: *mut f64, _: *const f64) {
            match *self {}
        }
    }
}
