//! The integrators and event location: the methods a mode may be stepped
//! by ([`method`] decides which, in one place), behind one interface
//! ([`integrator`]): the Runge-Kutta pairs and their step control, Taylor's
//! method, Stormer-Verlet and the exact linear propagator; and how each
//! finds a guard's first crossing inside its step ([`locate`], and
//! `sharpen.rs` for a pair's crossing placed on a step re-taken to it).

pub mod adaptive;
pub mod affine_mode;
pub mod crossing;
pub mod dop853;
pub mod dopri5;
pub mod integrator;
pub mod linear;
pub mod locate;
pub mod method;
mod sharpen;
pub mod taylor_method;
pub mod verlet;
