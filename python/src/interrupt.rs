//! Ctrl-C for the long tools (`compare`, `sweep`, `orbit`, `continuation`):
//! the work goes on in a thread of its own, the GIL released, while the
//! calling thread looks for a signal every [`POLL`]; a Ctrl-C sets the
//! work's stop flag, waits for it to wind down (the run under way ends
//! `interrupted`, the next is not begun) and raises `KeyboardInterrupt`.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use pyo3::prelude::*;

use crate::POLL;

/// Do `work` with a stop flag that Ctrl-C sets; the signal's exception
/// (KeyboardInterrupt) is raised once the work has returned.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&Arc<AtomicBool>) -> T + Send,
) -> PyResult<T> {
    let stop = Arc::new(AtomicBool::new(false));
    let done = AtomicBool::new(false);
    let mut signal = None;
    let result = py.detach(|| {
        std::thread::scope(|s| {
            let caller = std::thread::current();
            let (stop_flag, finished) = (&stop, &done);
            let worker = s.spawn(move || {
                let result = work(stop_flag);
                finished.store(true, Ordering::Release);
                caller.unpark();
                result
            });
            while !done.load(Ordering::Acquire) && !worker.is_finished() {
                std::thread::park_timeout(POLL);
                if signal.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    stop.store(true, Ordering::Relaxed);
                    signal = Some(e);
                }
            }
            worker.join()
        })
    });
    match (result, signal) {
        (_, Some(e)) => Err(e),
        (Ok(result), None) => Ok(result),
        (Err(_), None) => Err(pyo3::exceptions::PyRuntimeError::new_err(
            "flicker: the tool panicked (a bug: please report the scene)",
        )),
    }
}
