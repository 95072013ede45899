//! The expressions of an automaton file: parsed to a syntax tree
//! ([`mod@parse`]), compiled to a register tape ([`tape`]) that is evaluated,
//! differentiated and expanded in Taylor series without walking text.

// The one module that runs machine code it wrote, over raw buffers.
#[allow(unsafe_code)]
pub mod compiled;
pub mod derivative;
pub mod parse;
pub mod recurrences;
pub mod symbolic;
pub mod tape;
pub mod waves;

pub use parse::{Ast, ParseError, parse};
pub use tape::{CompileError, Op, Scope, Tape};
