//! The Rust that compiled code calls for what is not arithmetic: a
//! function's value (the interpreter's own call, so the bits are its),
//! with the platform's calling convention for the back end that calls it
//! (System V on x86-64, whatever the OS, as the x86-64 code calls; the
//! C convention elsewhere, as Cranelift's code calls).

use crate::expr::compiled::emit::Helper;
use crate::expr::tape::{FUNS, FUNS2};

/// The functions whose value [`origin`] takes at a series' origin.
#[derive(Clone, Copy)]
#[repr(u32)]
pub enum Origin {
    Sin,
    Cos,
    Sinh,
    Cosh,
    Exp,
}

/// One callback, its calling convention chosen for the processor.
macro_rules! callback {
    ($(#[$doc:meta])* fn $name:ident($($arg:tt: $ty:ty),*) $(-> $ret:ty)? $body:block) => {
        $(#[$doc])*
        #[cfg(target_arch = "x86_64")]
        unsafe extern "sysv64" fn $name($($arg: $ty),*) $(-> $ret)? $body
        $(#[$doc])*
        #[cfg(not(target_arch = "x86_64"))]
        unsafe extern "C" fn $name($($arg: $ty),*) $(-> $ret)? $body
    };
}

callback! {
    /// A function's value at the origin (and its partner's: the `cos` of a
    /// `sin`), by the same calls as the interpreter's.
    ///
    /// # Safety
    ///
    /// `value` and `partner` must be valid for writes: the compiled code
    /// passes two places of its work buffer.
    fn origin(kind: u32, a: f64, value: *mut f64, partner: *mut f64) {
        let (v, p) = match kind {
            k if k == Origin::Sin as u32 => a.sin_cos(),
            k if k == Origin::Cos as u32 => {
                let (s, c) = a.sin_cos();
                (c, s)
            }
            k if k == Origin::Sinh as u32 => (a.sinh(), a.cosh()),
            k if k == Origin::Cosh as u32 => (a.cosh(), a.sinh()),
            _ => (a.exp(), 0.0),
        };
        // SAFETY: as the caller promised.
        unsafe {
            *value = v;
            *partner = p;
        }
    }
}

callback! {
    /// `f(a)`, `f` the `kind`-th of the tape's functions of one argument.
    ///
    /// # Safety
    ///
    /// None needed: its pointers are not read.
    fn value(kind: u32, a: f64, _: *mut f64, _: *mut f64) -> f64 {
        FUNS[kind as usize].1.apply(a)
    }
}

callback! {
    /// `f(a, b)`, `f` the `kind`-th of the tape's functions of two.
    ///
    /// # Safety
    ///
    /// None needed: its pointers are not read.
    fn value2(kind: u32, a: f64, b: f64, _: *mut f64, _: *mut f64) -> f64 {
        FUNS2[kind as usize].1.apply(a, b)
    }
}

callback! {
    /// `a^b`.
    ///
    /// # Safety
    ///
    /// None needed: its pointers are not read.
    fn pow(_: u32, a: f64, b: f64, _: *mut f64, _: *mut f64) -> f64 {
        a.powf(b)
    }
}

/// The address of `helper`'s function.
pub fn address(helper: Helper) -> *const () {
    match helper {
        Helper::Origin => origin as *const (),
        Helper::Value => value as *const (),
        Helper::Value2 => value2 as *const (),
        Helper::Pow => pow as *const (),
    }
}
