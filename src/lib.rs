//! flicker: an event-driven engine for hybrid automata.
//!
//! A hybrid automaton is smooth flows plus guards and resets: between events
//! the state follows an ODE or a closed form; when a guard function crosses
//! zero an event fires and a reset map jumps the state. flicker keeps the
//! predicted next events in a priority queue, pops the earliest, advances
//! the flow exactly to it, applies the reset, re-predicts what the reset can
//! affect, and records the event.
//!
//! - [`prelude`]: what most programs need, in one import.
//! - [`engine`]: the generic engine ([`engine::HybridModel`],
//!   [`engine::simulate`]).
//! - [`models`]: models built on it (the bistable mechanism).
//! - [`scene`], [`runner`], [`log`]: JSON scenes, running them, and the
//!   event log and summary they write; [`cli`]: the command line over
//!   them, for the scene models of a [`scene::Registry`].
//!
//! A model of your own: a sawtooth, `x' = 1`, reset to zero at `x = 1`.
//!
//! ```
//! use flicker::prelude::*;
//!
//! struct Sawtooth;
//! const WRAP: &[Guard] = &[Guard::affine("wrap", Direction::Rising)];
//!
//! impl HybridModel for Sawtooth {
//!     fn dimension(&self) -> usize { 1 }
//!     fn state_names(&self, _: Mode) -> &[Name] { names!["x"] }
//!     fn mode_name(&self, _: Mode) -> &str { "ramp" }
//!     fn guards(&self, _: Mode) -> &[Guard] { WRAP }
//!     fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 { x[0] - 1.0 }
//!     fn flow(&self, _: Mode) -> Flow { Flow::Exact }
//!     fn advance(&self, _: Mode, x0: &[f64], tau: f64, x: &mut [f64]) { x[0] = x0[0] + tau }
//!     fn next_crossing(&self, _: Mode, _: usize, x0: &[f64]) -> Option<f64> {
//!         Some((1.0 - x0[0]).max(0.0))
//!     }
//!     fn reset(&self, mode: Mode, _: usize, x: &mut [f64]) -> Jump {
//!         x[0] = 0.0;
//!         Jump::to(mode)
//!     }
//! }
//!
//! let problem = Problem::new(&Sawtooth, 0, &[0.25], 10.0);
//! let outcome = problem.solve(Method::Exact, &Limits::default(), &mut ());
//! assert_eq!(outcome.events, 10); // at t = 0.75, 1.75, ..., 9.75
//! assert!((outcome.final_state[0] - 0.25).abs() < 1e-12);
//! ```
//!
//! The mechanism of the paper, run against its closed form:
//!
//! ```
//! use flicker::engine::{Options, simulate};
//! use flicker::models::mechanism::{ExactOrbit, Mechanism, StrainMechanism, strain::FLIGHT};
//!
//! let m = Mechanism { eta: 1.2, omega: 1.0 };
//! let outcome = simulate(&StrainMechanism { mechanism: m }, FLIGHT, &[0.5, 0.0], &Options::until(1000.0), &mut ());
//! let exact = ExactOrbit::new(m, 0.5, 0.0);
//! assert_eq!(outcome.events, exact.impacts_until(1000.0));
//! let (eps, _) = exact.state_at(1000.0);
//! assert!((outcome.final_state[0] - eps).abs() < 1e-12);
//! ```

#![deny(missing_docs)]
// Raw memory is touched in one place: the JIT (`expr::compiled`).
#![deny(unsafe_code)]

pub mod analysis;
pub mod cli;
pub mod engine;
pub mod expr;
pub mod log;
pub mod models;
pub mod numerics;
pub mod plot;
pub mod prelude;
pub mod runner;
pub mod scene;
pub mod session;
pub mod time;
