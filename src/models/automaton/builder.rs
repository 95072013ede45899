//! Automata built in Rust: the same model a file defines, assembled by
//! calls instead of written as JSON, checked and compiled by the same code
//! (so an error names the same field a file's would).
//!
//! ```
//! use flicker::models::automaton::{AutomatonBuilder, TransitionBuilder};
//! use flicker::engine::Limits;
//!
//! let scene = AutomatonBuilder::new()
//!     .parameter("g", 9.81)
//!     .parameter("e", 0.8)
//!     .state("y", 1.0)
//!     .state("v", 0.0)
//!     .mode("flight", [("y", "v"), ("v", "-g")], [
//!         TransitionBuilder::new("bounce", "y").falling().barrier().reset("v", "-e * v"),
//!     ])
//!     .energy("v^2 / 2 + g * y")
//!     .scene(10.0)
//!     .unwrap();
//! let report = scene.run(&Limits::default(), &mut ()).unwrap();
//! // Dropped from 1 m, the ball first lands at sqrt(2 h / g).
//! assert_eq!(report.outcome.status.as_str(), "zeno");
//! assert!(report.outcome.events > 30);
//! ```

use serde_json::{Map, Value, json};

use crate::models::automaton::definition::Definition;
use crate::models::automaton::model::Automaton;
use crate::scene::fields::Fields;
use crate::scene::{Registry, Scene, SceneError};

/// An automaton under construction; [`build`](Self::build) checks and
/// compiles it.
#[derive(Debug, Clone, Default)]
pub struct AutomatonBuilder {
    parameters: Map<String, Value>,
    states: Vec<Value>,
    initial: Map<String, Value>,
    modes: Map<String, Value>,
    initial_mode: Option<String>,
    energy: Option<Value>,
}

impl AutomatonBuilder {
    /// An automaton with nothing in it yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// A parameter and its value.
    pub fn parameter(mut self, name: &str, value: f64) -> Self {
        self.parameters.insert(name.into(), json!(value));
        self
    }

    /// The next state, starting at `value`.
    pub fn state(mut self, name: &str, value: f64) -> Self {
        self.states.push(json!(name));
        self.initial.insert(name.into(), json!(value));
        self
    }

    /// The next state, starting at an expression of the parameters.
    pub fn state_from(mut self, name: &str, initial: &str) -> Self {
        self.states.push(json!(name));
        self.initial.insert(name.into(), json!(initial));
        self
    }

    /// A mode: the rate of each state it moves (`(state, expression)`) and
    /// its transitions.
    pub fn mode<'a>(
        mut self,
        name: &str,
        flow: impl IntoIterator<Item = (&'a str, &'a str)>,
        transitions: impl IntoIterator<Item = TransitionBuilder>,
    ) -> Self {
        let flow: Map<String, Value> = flow
            .into_iter()
            .map(|(state, rate)| (state.to_string(), json!(rate)))
            .collect();
        let transitions: Vec<Value> = transitions
            .into_iter()
            .map(|t| Value::Object(t.0))
            .collect();
        self.modes.insert(
            name.into(),
            json!({"flow": flow, "transitions": transitions}),
        );
        self
    }

    /// The mode the run starts in (needed with more than one mode).
    pub fn initial_mode(mut self, name: &str) -> Self {
        self.initial_mode = Some(name.into());
        self
    }

    /// The energy the run monitors.
    pub fn energy(mut self, expression: &str) -> Self {
        self.energy = Some(json!(expression));
        self
    }

    /// The automaton's keys, as a file would hold them.
    fn keys(&self) -> Map<String, Value> {
        let mut keys = Map::new();
        keys.insert("parameters".into(), Value::Object(self.parameters.clone()));
        keys.insert("states".into(), Value::Array(self.states.clone()));
        keys.insert("initial".into(), Value::Object(self.initial.clone()));
        keys.insert("modes".into(), Value::Object(self.modes.clone()));
        if let Some(mode) = &self.initial_mode {
            keys.insert("initial_mode".into(), json!(mode));
        }
        if let Some(energy) = &self.energy {
            keys.insert("energy".into(), energy.clone());
        }
        keys
    }

    /// Check every name and expression and compile the automaton.
    pub fn build(&self) -> Result<Automaton, SceneError> {
        let keys = Value::Object(self.keys());
        let mut fields = Fields::open(&keys, "")?;
        let definition = Definition::read(&mut fields)?;
        fields.finish()?;
        Automaton::compile(&definition)
    }

    /// A scene of this automaton run to `t_end`, with the cheapest exact
    /// method: what `flicker run` would make of the same file.
    pub fn scene(&self, t_end: f64) -> Result<Scene, SceneError> {
        let mut keys = self.keys();
        keys.insert("model".into(), json!("automaton"));
        keys.insert("t_end".into(), json!(t_end));
        Registry::builtin().from_value(&Value::Object(keys))
    }
}

/// A transition under construction: fires when its guard crosses zero.
#[derive(Debug, Clone)]
pub struct TransitionBuilder(Map<String, Value>);

impl TransitionBuilder {
    /// A transition called `name` (the `guard` of its events in the log)
    /// on the guard expression `guard`, in either direction.
    pub fn new(name: &str, guard: &str) -> Self {
        let mut keys = Map::new();
        keys.insert("name".into(), json!(name));
        keys.insert("guard".into(), json!(guard));
        TransitionBuilder(keys)
    }

    fn with(mut self, key: &str, value: Value) -> Self {
        self.0.insert(key.into(), value);
        self
    }

    /// Fire only as the guard falls through zero.
    pub fn falling(self) -> Self {
        self.with("direction", json!("falling"))
    }

    /// Fire only as the guard rises through zero.
    pub fn rising(self) -> Self {
        self.with("direction", json!("rising"))
    }

    /// Set `state` to `expression` (of the values before the event).
    pub fn reset(mut self, state: &str, expression: &str) -> Self {
        let reset = self
            .0
            .entry("reset")
            .or_insert_with(|| Value::Object(Map::new()));
        if let Value::Object(map) = reset {
            map.insert(state.into(), json!(expression));
        }
        self
    }

    /// The mode after the event.
    pub fn to(self, mode: &str) -> Self {
        self.with("to", json!(mode))
    }

    /// Larger first among simultaneous events.
    pub fn priority(self, priority: f64) -> Self {
        self.with("priority", json!(priority))
    }

    /// End the run at this event.
    pub fn terminal(self) -> Self {
        self.with("terminal", json!(true))
    }

    /// The state must stay on the side the guard comes from (an impact).
    pub fn barrier(self) -> Self {
        self.with("barrier", json!(true))
    }
}
