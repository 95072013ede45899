//! Hybrid automata defined in a JSON file: any model, no Rust.
//!
//! ```json
//! {"model": "automaton",
//!  "description": "a ball on the floor, losing a fifth of its speed at each bounce",
//!  "parameters": {"g": 9.81, "e": 0.8},
//!  "states": ["y", "v"],
//!  "initial": {"y": 1.0, "v": 0.0},
//!  "modes": {
//!    "flight": {
//!      "flow": {"y": "v", "v": "-g"},
//!      "transitions": [
//!        {"name": "bounce", "guard": "y", "direction": "falling",
//!         "reset": {"v": "-e * v"}}]}},
//!  "energy": "v^2 / 2 + g * y",
//!  "t_end": 10.0}
//! ```
//!
//! - `states`: the ordered state names. `initial`: a value for each, a
//!   number or an expression of the parameters. `parameters`: names to
//!   numbers.
//! - `modes`: each with a `flow` (one rate per state; a state left out has
//!   rate zero) and `transitions`. `initial_mode` is required when there is
//!   more than one mode.
//! - A transition: `name` (the `guard` of its events in the log), `guard`
//!   (an expression; the event fires when it crosses zero), `direction`
//!   (`falling`, `rising` or `either`, the default), `reset` (state to
//!   expression; states it does not name keep their values; every
//!   expression is evaluated on the values before the event, all at once),
//!   `to` (the mode after; default the same), `priority` (larger first
//!   among simultaneous events; default 0, ties in file order), `terminal`
//!   (the run ends there, `completed`), `barrier` (the state must stay on
//!   the side the guard comes from, as at an impact: a reset that leaves it
//!   on zero and still moving through fires again at once, and the Zeno
//!   watch recognises resting contact).
//! - `energy`: an expression the run monitors, reported as the built-in
//!   models' energy is (across every reset in the log, largest relative
//!   error in the summary); or an object giving every mode its own
//!   expression, for modes that are charts in different coordinates.
//! - The keys every scene has: `t_end`, `solver`, `max_events`,
//!   `description`.
//! - Expressions: numbers, names (states, parameters, `t` for time, `pi`),
//!   `+ - * / ^`, unary minus (`-x^2` is `-(x^2)`), parentheses, and
//!   `sin cos tan asin acos atan atan2 sinh cosh tanh exp log sqrt abs min
//!   max pow hypot`; in a flow also `sign`, whose arguments are switching
//!   surfaces run as Filippov defined them ([`filippov`]). Time may appear anywhere (forced systems): the state
//!   then carries the clock `t` as its last component, which the engine
//!   keeps equal to the run's time.
//!
//! What fires and when (markers once per crossing, barriers, simultaneous
//! events, an event at `t_end`, sliding) is the engine's, the same for
//! every method: `docs/automata.md`, "Events".
//!
//! The file is read into a [`Definition`] (names
//! checked, expressions parsed, errors with a caret under the character),
//! compiled to tapes ([`Automaton`], a
//! [`HybridModel`](crate::engine::HybridModel)), and run as any scene
//! ([`scene`]). Without a `solver`, a run takes the exact linear propagator
//! where every flow is affine, Taylor's method at machine precision
//! otherwise (Dormand-Prince where a flow or guard uses `abs`, `min` or
//! `max`, across which series do not hold), and says which.
//! The same model is built in Rust, without JSON, by
//! [`AutomatonBuilder`]. `docs/automata.md` explains each bundled
//! automaton.

pub mod builder;
pub mod definition;
pub mod ensemble;
mod family;
pub mod filippov;
pub mod model;
pub mod scene;
mod scene_model;

pub use builder::{AutomatonBuilder, TransitionBuilder};
pub use definition::Definition;
pub use model::Automaton;
pub use scene::AutomatonScene;
