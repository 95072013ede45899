//! Compile once a tape has earned it: the interpreter answers the first
//! [`WARM_UP`] calls, and only a tape asked for more is compiled. Both give
//! the same bits, so a run may switch at any call; a short run (a sweep's
//! points, a few steps) never pays the compilation.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicU32, Ordering};

/// Calls answered by the interpreter before compiling: about as many as a
/// compilation is worth. Compiling Henon-Heiles' series at order 20 takes
/// 0.1 ms, what about 75 interpreted series cost beyond compiled ones (an
/// evaluation's break-even is a few hundred calls, its compilation a few
/// tens of microseconds); so a run never pays much more than twice the
/// least it could, however long it is. Cranelift (aarch64's back end)
/// takes fifty times as long to compile (5.2 ms for that series, whose
/// code then saves 0.42 us a call: 195 ns against the interpreter's 618,
/// measured on x86-64), so there a tape waits for 8192 calls.
pub const WARM_UP: u32 = if cfg!(target_arch = "x86_64") {
    64
} else {
    8192
};

/// A tape's code, compiled on the call after its warm-up.
#[derive(Debug)]
pub struct Tiered<T> {
    asked: AtomicU32,
    code: OnceLock<Option<T>>,
}

impl<T> Default for Tiered<T> {
    fn default() -> Self {
        Tiered {
            asked: AtomicU32::new(0),
            code: OnceLock::new(),
        }
    }
}

impl<T> Tiered<T> {
    /// The code, compiled by `compile` once warmed up; `None` while
    /// warming up and where it does not compile.
    #[inline]
    pub fn get(&self, compile: impl FnOnce() -> Option<T>) -> Option<&T> {
        if let Some(code) = self.code.get() {
            return code.as_ref();
        }
        // Counting is all threads' together, and need not be exact.
        if self.asked.fetch_add(1, Ordering::Relaxed) < WARM_UP {
            return None;
        }
        self.code.get_or_init(compile).as_ref()
    }

    /// Whether it was compiled.
    #[cfg(test)]
    pub fn compiled(&self) -> bool {
        matches!(self.code.get(), Some(Some(_)))
    }
}
