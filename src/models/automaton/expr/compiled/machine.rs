//! The x86-64 code of a compiled series (see [`super`]), assembled with
//! dynasm: scalar SSE2 loads, stores and arithmetic on the coefficients'
//! places, and a call into Rust for a function's value at the origin.
//! Other processors compile nothing, and keep the interpreter.
//!
//! The code is one function, `extern "sysv64" fn(scratch, out, pool)`:
//! it keeps the three buffers' addresses in callee-saved registers (rbx,
//! r12, r13) and works in xmm0-xmm3, so a call needs nothing saved.

#[cfg(target_arch = "x86_64")]
pub use x64::{Code, compile};

#[cfg(not(target_arch = "x86_64"))]
pub use other::{Code, compile};

#[cfg(target_arch = "x86_64")]
mod x64 {
    use dynasmrt::x64::Assembler;
    use dynasmrt::{AssemblyOffset, DynasmApi, ExecutableBuffer, dynasm};

    use crate::models::automaton::expr::compiled::layout::{Base, Layout, Place};
    use crate::models::automaton::expr::tape::{Fun, Op, Tape};

    /// A compiled series' machine code.
    pub struct Code {
        buffer: ExecutableBuffer,
        entry: AssemblyOffset,
    }

    type Entry = extern "sysv64" fn(*mut f64, *mut f64, *const f64);

    impl Code {
        pub fn len(&self) -> usize {
            self.buffer.len()
        }

        /// Run the series on the three buffers, which must be as long as
        /// the layout it was compiled for says (see `CompiledFlow::flow`).
        pub fn run(&self, scratch: *mut f64, out: *mut f64, pool: *const f64) {
            // SAFETY: the buffer holds a complete function with this
            // signature, emitted by `compile` below, and stays mapped
            // executable for as long as `self` lives.
            let entry: Entry = unsafe { std::mem::transmute(self.buffer.ptr(self.entry)) };
            entry(scratch, out, pool);
        }
    }

    /// The base register of each buffer (callee-saved: they survive the
    /// calls into Rust).
    fn base(base: Base) -> u8 {
        match base {
            Base::Scratch => 3, // rbx
            Base::Out => 12,    // r12
            Base::Pool => 13,   // r13
        }
    }

    /// The functions the code calls for at a series' origin.
    #[derive(Clone, Copy)]
    #[repr(u64)]
    enum Origin {
        Sin,
        Cos,
        Sinh,
        Cosh,
        Exp,
    }

    /// A function's value at the origin (and its partner's: the `cos` of a
    /// `sin`), by the same calls as the interpreter's.
    extern "sysv64" fn origin(kind: u64, a: f64, value: *mut f64, partner: *mut f64) {
        let (v, p) = match kind {
            k if k == Origin::Sin as u64 => a.sin_cos(),
            k if k == Origin::Cos as u64 => {
                let (s, c) = a.sin_cos();
                (c, s)
            }
            k if k == Origin::Sinh as u64 => (a.sinh(), a.cosh()),
            k if k == Origin::Cosh as u64 => (a.cosh(), a.sinh()),
            _ => (a.exp(), 0.0),
        };
        // SAFETY: the code passes two places of its scratch, which the
        // caller of `Code::run` sized for every register's series.
        unsafe {
            *value = v;
            *partner = p;
        }
    }

    struct Emitter {
        asm: Assembler,
    }

    macro_rules! at {
        ($e:ident, $op:ident, $x:expr, $place:expr) => {{
            let (b, d) = $place;
            let (b, x): (u8, u8) = (base(b), $x);
            dynasm!($e.asm ; .arch x64 ; $op Rx(x), QWORD [Rq(b) + d]);
        }};
    }

    impl Emitter {
        fn load(&mut self, x: u8, place: Place) {
            at!(self, movsd, x, place);
        }
        fn add(&mut self, x: u8, place: Place) {
            at!(self, addsd, x, place);
        }
        fn sub(&mut self, x: u8, place: Place) {
            at!(self, subsd, x, place);
        }
        fn mul(&mut self, x: u8, place: Place) {
            at!(self, mulsd, x, place);
        }
        fn div(&mut self, x: u8, place: Place) {
            at!(self, divsd, x, place);
        }
        fn store(&mut self, place: Place, x: u8) {
            let (b, d) = place;
            let b = base(b);
            dynasm!(self.asm ; .arch x64 ; movsd QWORD [Rq(b) + d], Rx(x));
        }
        fn zero(&mut self, x: u8) {
            dynasm!(self.asm ; .arch x64 ; xorpd Rx(x), Rx(x));
        }
        fn add_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; addsd Rx(x), Rx(y));
        }
        fn sub_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; subsd Rx(x), Rx(y));
        }
        fn mul_registers(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; mulsd Rx(x), Rx(y));
        }
        fn copy(&mut self, x: u8, y: u8) {
            dynasm!(self.asm ; .arch x64 ; movapd Rx(x), Rx(y));
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
        /// `value, partner = f(a)` at the origin.
        fn call(&mut self, f: Origin, a: Place, value: Place, partner: Place) {
            self.load(0, a);
            let (vb, vd) = (base(value.0), value.1);
            let (pb, pd) = (base(partner.0), partner.1);
            dynasm!(self.asm
                ; .arch x64
                ; mov edi, f as i32
                ; lea rsi, [Rq(vb) + vd]
                ; lea rdx, [Rq(pb) + pd]
                ; mov rax, QWORD origin as *const () as i64
                ; call rax
            );
        }

        /// `x = sum_{j = lo..=k} a_j b_{k - j}`, from zero upwards.
        fn product(
            &mut self,
            x: u8,
            a: impl Fn(usize) -> Place,
            b: impl Fn(usize) -> Place,
            k: usize,
            lo: usize,
        ) {
            self.zero(x);
            for j in lo..=k {
                self.load(1, a(j));
                self.mul(1, b(k - j));
                self.add_registers(x, 1);
            }
        }
    }

    /// The series of `tape` at `order`, `None` for an instruction this
    /// does not compile.
    pub fn compile(tape: &Tape, layout: &Layout, order: usize) -> Option<Code> {
        let asm = Assembler::new().ok()?;
        let mut e = Emitter { asm };
        let entry = e.asm.offset();
        dynasm!(e.asm
            ; .arch x64
            ; push rbx
            ; push r12
            ; push r13
            ; mov rbx, rdi
            ; mov r12, rsi
            ; mov r13, rdx
        );
        let constant = |r: u32| matches!(tape.ops[r as usize], Op::Const(_));
        let width = order + 1;
        for k in 0..order {
            for (r, &op) in tape.ops.iter().enumerate() {
                let r = r as u32;
                let out = layout.at(r, k);
                match op {
                    Op::Const(_) | Op::Input(_) => continue,
                    Op::Add(a, b) => {
                        e.load(0, layout.at(a, k));
                        e.add(0, layout.at(b, k));
                    }
                    Op::Sub(a, b) => {
                        e.load(0, layout.at(a, k));
                        e.sub(0, layout.at(b, k));
                    }
                    Op::Neg(a) => {
                        e.load(0, layout.at(a, k));
                        e.negate(0);
                    }
                    Op::Mul(a, b) if constant(a) => {
                        e.load(0, layout.at(a, 0));
                        e.mul(0, layout.at(b, k));
                    }
                    Op::Mul(a, b) if constant(b) => {
                        e.load(0, layout.at(a, k));
                        e.mul(0, layout.at(b, 0));
                    }
                    Op::Mul(a, b) => e.product(0, |j| layout.at(a, j), |j| layout.at(b, j), k, 0),
                    Op::Div(a, b) if constant(b) => {
                        e.load(0, layout.at(a, k));
                        e.div(0, layout.at(b, 0));
                    }
                    Op::Div(a, b) => {
                        // a = q b: q_k = (a_k - sum_{j=1..k} b_j q_{k-j}) / b_0.
                        e.product(2, |j| layout.at(b, j), |j| layout.at(r, j), k, 1);
                        e.load(0, layout.at(a, k));
                        e.sub_registers(0, 2);
                        e.div(0, layout.at(b, 0));
                    }
                    Op::Call(f @ (Fun::Sin | Fun::Cos | Fun::Sinh | Fun::Cosh), a) => {
                        let hyperbolic = matches!(f, Fun::Sinh | Fun::Cosh);
                        let is_sin = matches!(f, Fun::Sin | Fun::Sinh);
                        if k == 0 {
                            let kind = match f {
                                Fun::Sin => Origin::Sin,
                                Fun::Cos => Origin::Cos,
                                Fun::Sinh => Origin::Sinh,
                                _ => Origin::Cosh,
                            };
                            e.call(kind, layout.at(a, 0), out, layout.helper(r, 0));
                            continue;
                        }
                        // s' = a' c, c' = -+ a' s: the rates j a_j times
                        // the partner's (into xmm0) and the value's (xmm1).
                        e.zero(0);
                        e.zero(1);
                        for j in 1..=k {
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
                        // sign times the one that changes sign.
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
                    }
                    Op::Call(Fun::Exp, a) => {
                        if k == 0 {
                            e.call(Origin::Exp, layout.at(a, 0), out, layout.helper(r, 0));
                            continue;
                        }
                        // e' = a' e.
                        e.zero(0);
                        for j in 1..=k {
                            e.load(2, layout.integer(j));
                            e.mul(2, layout.at(a, j));
                            e.mul(2, layout.at(r, k - j));
                            e.add_registers(0, 2);
                        }
                        e.div(0, layout.integer(k));
                    }
                    Op::Pow(..) | Op::Call(..) | Op::Call2(..) => return None,
                }
                e.store(out, 0);
            }
            // The state's order k + 1 is the rate's order k over k + 1.
            for (i, &o) in tape.outputs.iter().enumerate() {
                e.load(0, layout.at(o, k));
                e.div(0, layout.integer(k + 1));
                let to = i32::try_from((i * width + k + 1) * size_of::<f64>()).ok()?;
                e.store((Base::Out, to), 0);
            }
        }
        dynasm!(e.asm
            ; .arch x64
            ; pop r13
            ; pop r12
            ; pop rbx
            ; ret
        );
        let buffer = e.asm.finalize().ok()?;
        Some(Code { buffer, entry })
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod other {
    use crate::models::automaton::expr::compiled::layout::Layout;
    use crate::models::automaton::expr::tape::Tape;

    /// No code: nothing compiles on this processor.
    pub enum Code {}

    impl Code {
        pub fn len(&self) -> usize {
            match *self {}
        }
        pub fn run(&self, _: *mut f64, _: *mut f64, _: *const f64) {
            match *self {}
        }
    }

    pub fn compile(_: &Tape, _: &Layout, _: usize) -> Option<Code> {
        None
    }
}
