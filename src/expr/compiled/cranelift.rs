//! The portable back end: the lowerings' operations (see `emit.rs`)
//! recorded as they come, then written as one Cranelift function of the
//! three buffers and compiled for the processor the run is on. aarch64's
//! compiled code is this; on x86-64 the tests run it beside the hand
//! assembly (`machine.rs`) and the interpreter.
//!
//! Cranelift keeps IEEE arithmetic as written (it neither fuses a
//! multiply and an add nor reorders a sum: WebAssembly, its main user,
//! forbids both), so the code gives the interpreter's bits. The
//! registers of `emit.rs` become variables, which Cranelift puts in
//! registers; every store is kept, and every load made, in order.

use cranelift_codegen::ir::{
    AbiParam, Function, InstBuilder, MemFlagsData, Signature, UserFuncName, Value, types,
};
use cranelift_codegen::isa::CallConv;
use cranelift_codegen::settings::{self, Configurable};
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext, Variable};
use cranelift_jit::{JITBuilder, JITModule};
use cranelift_module::{Linkage, Module, default_libcall_names};

use crate::expr::compiled::callbacks;
use crate::expr::compiled::emit::{Emit, Helper};
use crate::expr::compiled::layout::{Base, Place};

/// The registers `emit.rs` numbers: 0 to 3 scratch, the rest fresh.
const REGISTERS: u8 = 16;

/// One operation, as recorded (see [`Emit`]).
#[derive(Debug, Clone, Copy)]
enum Recorded {
    Load(u8, Place),
    Add(u8, Place),
    Sub(u8, Place),
    Mul(u8, Place),
    Div(u8, Place),
    Store(Place, u8),
    Zero(u8),
    AddRegisters(u8, u8),
    SubRegisters(u8, u8),
    MulRegisters(u8, u8),
    Copy(u8, u8),
    Negate(u8),
    Call(Helper, u32, Place, Place),
}

/// The function being recorded.
pub struct Emitter {
    recorded: Vec<Recorded>,
    next: u8,
}

/// The compiled function's type: that of the x86-64 back end's on
/// x86-64 (System V), the C convention elsewhere.
#[cfg(target_arch = "x86_64")]
type Entry = unsafe extern "sysv64" fn(*mut f64, *mut f64, *const f64);
#[cfg(not(target_arch = "x86_64"))]
type Entry = unsafe extern "C" fn(*mut f64, *mut f64, *const f64);

/// The calling convention of [`Entry`] and of the callbacks.
fn convention(isa: &dyn cranelift_codegen::isa::TargetIsa) -> CallConv {
    if cfg!(target_arch = "x86_64") {
        CallConv::SystemV
    } else {
        isa.default_call_conv()
    }
}

/// Compiled code: the module that holds its memory, and its entry.
pub struct Code {
    module: Option<Owned>,
    function: Entry,
}

/// The JIT module, kept only to free its memory when the code goes.
struct Owned(JITModule);

// SAFETY: the module is not used again after its code is finalized, but
// to free its memory when the `Code` drops, which takes it by value:
// sharing the `Code` between threads shares only the entry, whose code
// is read only.
unsafe impl Send for Owned {}
// SAFETY: as above; `&Code` reaches the module by no method.
unsafe impl Sync for Owned {}

impl std::fmt::Debug for Code {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Code(cranelift)")
    }
}

impl Drop for Code {
    fn drop(&mut self) {
        if let Some(Owned(module)) = self.module.take() {
            // SAFETY: the entry, the one pointer into this memory, goes
            // with `self`.
            unsafe { module.free_memory() };
        }
    }
}

impl Code {
    /// Run the code on the three buffers.
    ///
    /// # Safety
    ///
    /// Each buffer must be valid, for as many `f64`s as the layout the
    /// code was compiled for says (`work` and `state` for reads and
    /// writes, `pool` for reads), and none may overlap another: the code
    /// reads and writes them at fixed places, unchecked.
    pub unsafe fn run(&self, work: *mut f64, state: *mut f64, pool: *const f64) {
        // SAFETY: the buffers are as the caller promised; the function is
        // one `finish` compiled whole.
        unsafe { (self.function)(work, state, pool) }
    }
}

impl Emitter {
    /// A function to record (the buffers' sizes do not matter here: each
    /// place is addressed from its buffer's start).
    pub fn new(_extents: [usize; 3]) -> Option<Emitter> {
        Some(Emitter {
            recorded: Vec::new(),
            next: 4,
        })
    }
}

impl Emit for Emitter {
    type Code = Code;

    fn load(&mut self, x: u8, place: Place) {
        self.recorded.push(Recorded::Load(x, place));
    }
    fn add(&mut self, x: u8, place: Place) {
        self.recorded.push(Recorded::Add(x, place));
    }
    fn sub(&mut self, x: u8, place: Place) {
        self.recorded.push(Recorded::Sub(x, place));
    }
    fn mul(&mut self, x: u8, place: Place) {
        self.recorded.push(Recorded::Mul(x, place));
    }
    fn div(&mut self, x: u8, place: Place) {
        self.recorded.push(Recorded::Div(x, place));
    }
    fn fresh(&mut self) -> u8 {
        let x = self.next;
        self.next = if x + 1 == REGISTERS { 4 } else { x + 1 };
        x
    }
    fn store(&mut self, place: Place, x: u8) {
        self.recorded.push(Recorded::Store(place, x));
    }
    fn zero(&mut self, x: u8) {
        self.recorded.push(Recorded::Zero(x));
    }
    fn add_registers(&mut self, x: u8, y: u8) {
        self.recorded.push(Recorded::AddRegisters(x, y));
    }
    fn sub_registers(&mut self, x: u8, y: u8) {
        self.recorded.push(Recorded::SubRegisters(x, y));
    }
    fn mul_registers(&mut self, x: u8, y: u8) {
        self.recorded.push(Recorded::MulRegisters(x, y));
    }
    fn copy(&mut self, x: u8, y: u8) {
        self.recorded.push(Recorded::Copy(x, y));
    }
    fn negate(&mut self, x: u8) {
        self.recorded.push(Recorded::Negate(x));
    }
    fn call(&mut self, helper: Helper, kind: u32, first: Place, second: Place) {
        self.recorded
            .push(Recorded::Call(helper, kind, first, second));
    }

    fn finish(self) -> Option<Code> {
        let mut flags = settings::builder();
        flags.set("opt_level", "speed").ok()?;
        let isa = cranelift_native::builder()
            .ok()?
            .finish(settings::Flags::new(flags))
            .ok()?;
        let mut signature = Signature::new(convention(&*isa));
        signature.params = vec![AbiParam::new(isa.pointer_type()); 3];
        let mut module = JITModule::new(JITBuilder::with_isa(isa.clone(), default_libcall_names()));
        let id = module
            .declare_function("tape", Linkage::Local, &signature)
            .ok()?;
        let mut context = module.make_context();
        context.func = Function::with_name_signature(UserFuncName::default(), signature);
        let mut builder_context = FunctionBuilderContext::new();
        write(
            &self.recorded,
            &mut context.func,
            &mut builder_context,
            &*isa,
        );
        module.define_function(id, &mut context).ok()?;
        module.clear_context(&mut context);
        module.finalize_definitions().ok()?;
        let address = module.get_finalized_function(id);
        // SAFETY: the function at `address` was compiled from a signature
        // of three pointers in `Entry`'s convention, returning nothing,
        // and stays mapped until `module` frees it (see `Drop`).
        let function: Entry = unsafe { std::mem::transmute::<*const u8, Entry>(address) };
        Some(Code {
            module: Some(Owned(module)),
            function,
        })
    }
}

/// Whether `helper` takes a second float (register 1) and returns a float.
fn shape(helper: Helper) -> (bool, bool) {
    match helper {
        Helper::Origin => (false, false),
        Helper::Value => (false, true),
        Helper::Value2 | Helper::Pow => (true, true),
    }
}

/// The recorded operations as the body of `function`.
fn write(
    recorded: &[Recorded],
    function: &mut Function,
    context: &mut FunctionBuilderContext,
    isa: &dyn cranelift_codegen::isa::TargetIsa,
) {
    let (pointer, call_conv) = (isa.pointer_type(), convention(isa));
    let mut b = FunctionBuilder::new(function, context);
    let block = b.create_block();
    b.append_block_params_for_function_params(block);
    b.switch_to_block(block);
    b.seal_block(block);
    let params = b.block_params(block).to_vec();
    let base = |buffer: Base| match buffer {
        Base::Work => params[0],
        Base::State => params[1],
        Base::Pool => params[2],
    };
    // The buffers are `f64` arrays: aligned, and never a trap.
    let flags = MemFlagsData::trusted();
    let registers: Vec<Variable> = (0..REGISTERS).map(|_| b.declare_var(types::F64)).collect();
    let zero = b.ins().f64const(0.0);
    for &r in &registers {
        b.def_var(r, zero);
    }
    let reg = |x: u8| registers[x as usize];
    // A callback's signature: kind, one or two floats, two pointers, and
    // a float back or none.
    let callee = |b: &mut FunctionBuilder, helper: Helper| {
        let (two, returns) = shape(helper);
        let mut s = Signature::new(call_conv);
        s.params.push(AbiParam::new(types::I32));
        s.params.push(AbiParam::new(types::F64));
        if two {
            s.params.push(AbiParam::new(types::F64));
        }
        s.params.push(AbiParam::new(pointer));
        s.params.push(AbiParam::new(pointer));
        if returns {
            s.returns.push(AbiParam::new(types::F64));
        }
        (b.import_signature(s), two, returns)
    };
    for op in recorded {
        let load = |b: &mut FunctionBuilder, (buffer, offset): Place| -> Value {
            b.ins().load(types::F64, flags, base(buffer), offset)
        };
        match *op {
            Recorded::Load(x, place) => {
                let v = load(&mut b, place);
                b.def_var(reg(x), v);
            }
            Recorded::Add(x, place)
            | Recorded::Sub(x, place)
            | Recorded::Mul(x, place)
            | Recorded::Div(x, place) => {
                let (left, right) = (b.use_var(reg(x)), load(&mut b, place));
                let v = match op {
                    Recorded::Add(..) => b.ins().fadd(left, right),
                    Recorded::Sub(..) => b.ins().fsub(left, right),
                    Recorded::Mul(..) => b.ins().fmul(left, right),
                    _ => b.ins().fdiv(left, right),
                };
                b.def_var(reg(x), v);
            }
            Recorded::Store((buffer, offset), x) => {
                let v = b.use_var(reg(x));
                b.ins().store(flags, v, base(buffer), offset);
            }
            Recorded::Zero(x) => {
                let v = b.ins().f64const(0.0);
                b.def_var(reg(x), v);
            }
            Recorded::AddRegisters(x, y)
            | Recorded::SubRegisters(x, y)
            | Recorded::MulRegisters(x, y) => {
                let (left, right) = (b.use_var(reg(x)), b.use_var(reg(y)));
                let v = match op {
                    Recorded::AddRegisters(..) => b.ins().fadd(left, right),
                    Recorded::SubRegisters(..) => b.ins().fsub(left, right),
                    _ => b.ins().fmul(left, right),
                };
                b.def_var(reg(x), v);
            }
            Recorded::Copy(x, y) => {
                let v = b.use_var(reg(y));
                b.def_var(reg(x), v);
            }
            Recorded::Negate(x) => {
                let v = b.use_var(reg(x));
                let v = b.ins().fneg(v);
                b.def_var(reg(x), v);
            }
            Recorded::Call(helper, kind, first, second) => {
                let (signature, two, returns) = callee(&mut b, helper);
                let address = callbacks::address(helper) as i64;
                let target = b.ins().iconst(pointer, address);
                let kind = b.ins().iconst(types::I32, i64::from(kind));
                let mut arguments = vec![kind, b.use_var(reg(0))];
                if two {
                    arguments.push(b.use_var(reg(1)));
                }
                for (buffer, offset) in [first, second] {
                    let at = b.ins().iadd_imm_s(base(buffer), i64::from(offset));
                    arguments.push(at);
                }
                let call = b.ins().call_indirect(signature, target, &arguments);
                if returns {
                    let v = b.inst_results(call)[0];
                    b.def_var(reg(0), v);
                }
            }
        }
    }
    b.ins().return_(&[]);
    b.finalize(isa.frontend_config());
}
