//! An automaton as its file defines it: names checked, modes and states
//! resolved to indices, every expression parsed (and kept with its text and
//! field path, for errors that put a caret under the offending character).
//! Compiling it to something that runs is [`model`](super::model)'s.

use serde_json::{Map, Value};

use crate::engine::Direction;
use crate::expr::symbolic::{constant, never_zero, same};
use crate::expr::{Ast, Scope, Tape, parse};
use crate::scene::SceneError;
use crate::scene::fields::{Fields, kind};

/// Names an expression may not give a state or a parameter: the clock, the
/// constant `pi` and the functions.
const RESERVED: [&str; 21] = [
    "t", "pi", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "exp",
    "log", "sqrt", "abs", "min", "max", "pow", "hypot", "sign",
];

/// The most states, modes, or transitions of one mode a file may define.
pub const MAX_ITEMS: usize = 10_000;

/// One expression of the file: its text, where it is, and its tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    /// The expression as written.
    pub text: String,
    /// Dotted path of its field (`modes.flight.flow.v`).
    pub path: String,
    /// The parsed expression.
    pub ast: Ast,
}

impl Source {
    /// Parse `value` (a string, or a number) found at `path`.
    pub fn read(value: &Value, path: &str) -> Result<Source, SceneError> {
        let text = match value {
            Value::String(s) => s.clone(),
            Value::Number(n) => n.to_string(),
            other => {
                return Err(SceneError::field(
                    path,
                    format!(
                        "must be an expression (a string) or a number, found {}",
                        kind(other)
                    ),
                ));
            }
        };
        let ast = parse(&text).map_err(|e| located(path, &text, e.at, &e.message))?;
        Ok(Source {
            text,
            path: path.to_string(),
            ast,
        })
    }

    /// An error about the character `at` of this expression.
    pub fn error(&self, at: usize, message: &str) -> SceneError {
        located(&self.path, &self.text, at, message)
    }
}

/// An error at character `at` of the expression `text` in field `path`, with
/// the expression shown and a caret under the character.
fn located(path: &str, text: &str, at: usize, message: &str) -> SceneError {
    SceneError::field(
        path,
        format!(
            "{message} (character {}):\n    {text}\n    {}^",
            at + 1,
            " ".repeat(at)
        ),
    )
}

/// One transition of a mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    /// Its name: the `guard` of its events in the log.
    pub name: String,
    /// Fires when this crosses zero.
    pub guard: Source,
    /// Which way it must cross.
    pub direction: Direction,
    /// The new value of some states, each from the values before the event.
    pub reset: Vec<(usize, Source)>,
    /// The mode after.
    pub to: usize,
    /// Larger first among simultaneous events.
    pub priority: f64,
    /// The run ends at this event.
    pub terminal: bool,
    /// The state must stay on the side the guard comes from (an impact).
    pub barrier: bool,
}

/// Where the events of a mode's barriers pile up (a Zeno point, such as
/// a ball's bounces): the mode the run goes on in, resting, and the state
/// there.
#[derive(Debug, Clone, PartialEq)]
pub struct Rest {
    /// The mode the run goes on in.
    pub to: usize,
    /// The new value of some states, each from the values at the Zeno
    /// point.
    pub reset: Vec<(usize, Source)>,
}

/// One mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeDef {
    /// Its name.
    pub name: String,
    /// The rate of each state (`None`: zero).
    pub flow: Vec<Option<Source>>,
    /// Its transitions, highest priority first (ties in file order).
    pub transitions: Vec<Transition>,
    /// Where its events pile up, the resting mode and state, if it has one.
    pub rest: Option<Rest>,
}

/// An automaton file's definition of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct Definition {
    /// Parameter names and values.
    pub parameters: Vec<(String, f64)>,
    /// State names, in order.
    pub states: Vec<String>,
    /// The initial value of each state.
    pub initial: Vec<f64>,
    /// The expression each initial value came from.
    pub initial_sources: Vec<Source>,
    /// The modes.
    pub modes: Vec<ModeDef>,
    /// The mode the run starts in.
    pub initial_mode: usize,
    /// The monitored energy, if any: one expression per mode, in the order
    /// of `modes` (the same one for all where the file gives one).
    pub energy: Option<Vec<Source>>,
}

impl Definition {
    /// Read the automaton keys of a scene (`parameters`, `states`,
    /// `initial`, `modes`, `initial_mode`, `energy`) from `f`.
    pub fn read(f: &mut Fields) -> Result<Definition, SceneError> {
        let parameters = parameters(f)?;
        let states = states(f, &parameters)?;
        let (initial, initial_sources) = initial(f, &states, &parameters)?.into_iter().unzip();
        let modes_value = f.required("modes")?;
        let modes_map = object(modes_value, &f.path("modes"))?;
        if modes_map.is_empty() || modes_map.len() > MAX_ITEMS {
            return Err(SceneError::field(
                &f.path("modes"),
                format!("must name between 1 and {MAX_ITEMS} modes"),
            ));
        }
        let mode_names: Vec<&str> = modes_map.keys().map(String::as_str).collect();
        let initial_mode = match f.optional_string("initial_mode")? {
            Some(name) => index_of(name, &mode_names, "mode", &f.path("initial_mode"))?,
            None if mode_names.len() == 1 => 0,
            None => {
                return Err(SceneError::field(
                    &f.path("initial_mode"),
                    format!(
                        "is missing: with {} modes, say which the run starts in",
                        mode_names.len()
                    ),
                ));
            }
        };
        let modes = modes_map
            .iter()
            .map(|(name, value)| {
                mode(
                    name,
                    value,
                    &format!("{}.{name}", f.path("modes")),
                    &states,
                    &mode_names,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        let energy = match f.optional("energy") {
            None => None,
            Some(value) => Some(energy(value, &f.path("energy"), &mode_names)?),
        };
        Ok(Definition {
            parameters,
            states,
            initial,
            initial_sources,
            modes,
            initial_mode,
            energy,
        })
    }

    /// Every expression of the definition.
    pub fn sources(&self) -> impl Iterator<Item = &Source> {
        self.modes
            .iter()
            .flat_map(|m| {
                m.flow.iter().flatten().chain(
                    m.transitions.iter().flat_map(|t| {
                        std::iter::once(&t.guard).chain(t.reset.iter().map(|(_, s)| s))
                    }),
                )
            })
            .chain(self.energy.iter().flatten())
    }

    /// The same automaton with the parameters `names` turned into states
    /// that never change (appended, in that order, to the states), so that
    /// what depends on them can be differentiated as on any state; and,
    /// for each, the derivative of every initial value with respect to it
    /// (an initial value may be an expression of the parameters). An
    /// unknown name is refused with the nearest, as said of `field`.
    pub fn with_parameters_as_states(
        &self,
        names: &[String],
        field: &str,
    ) -> Result<(Definition, Vec<Vec<f64>>), SceneError> {
        use crate::expr::derivative::jacobian;
        let known: Vec<&str> = self.parameters.iter().map(|(p, _)| p.as_str()).collect();
        let mut promoted = self.clone();
        let mut slopes = Vec::new();
        for name in names {
            let k = index_of(name, &known, "parameter", field)?;
            let (_, value) = self.parameters[k].clone();
            // d x0 / d p: the initial values' expressions with p as their input.
            let tapes = self.initial_of(name)?;
            slopes.push(
                tapes
                    .iter()
                    .map(|t| jacobian(t, &[value])[(0, 0)])
                    .collect(),
            );
            promoted.parameters.retain(|(p, _)| p != name);
            promoted.states.push(name.clone());
            promoted.initial.push(value);
            promoted.initial_sources.push(Source {
                text: value.to_string(),
                path: format!("parameters.{name}"),
                ast: Ast::Number(value),
            });
            for mode in &mut promoted.modes {
                mode.flow.push(None);
            }
        }
        Ok((promoted, slopes))
    }

    /// Whether any expression reads the clock `t` (a forced system).
    pub fn reads_clock(&self) -> bool {
        self.sources().any(|s| mentions(&s.ast, "t"))
    }

    /// Whether `name` enters a function's argument together with the
    /// clock (`sin(w * t)`): the forcing's period then moves with it.
    pub fn sets_the_forcing(&self, name: &str) -> bool {
        fn inside(ast: &Ast, name: &str) -> bool {
            match ast {
                Ast::Number(_) | Ast::Name(..) => false,
                Ast::Neg(a) => inside(a, name),
                Ast::Binary(_, a, b) => inside(a, name) || inside(b, name),
                Ast::Call(_, args, _) => {
                    args.iter().any(|a| mentions(a, name)) && args.iter().any(|a| mentions(a, "t"))
                        || args.iter().any(|a| inside(a, name))
                }
            }
        }
        self.sources().any(|s| inside(&s.ast, name))
    }

    /// The initial values with the parameter `name` at `value` (an initial
    /// value may be an expression of it).
    pub fn initial_with(&self, name: &str, value: f64) -> Result<Vec<f64>, SceneError> {
        Ok(self
            .initial_of(name)?
            .iter()
            .map(|t| t.eval1(&[value]))
            .collect())
    }

    /// Each initial value's expression compiled as a function of the
    /// parameter `name` (the other parameters held at their values).
    fn initial_of(&self, name: &str) -> Result<Vec<Tape>, SceneError> {
        let scope = Scope {
            inputs: vec![name.to_string()],
            constants: self
                .parameters
                .iter()
                .filter(|(p, _)| p != name)
                .cloned()
                .collect(),
        };
        self.initial_sources
            .iter()
            .map(|source| {
                Tape::compile(&[&source.ast], &scope).map_err(|e| source.error(e.at, &e.message))
            })
            .collect()
    }
}

/// Whether `ast` uses the name `name`.
fn mentions(ast: &Ast, name: &str) -> bool {
    match ast {
        Ast::Number(_) => false,
        Ast::Name(n, _) => n == name,
        Ast::Neg(a) => mentions(a, name),
        Ast::Binary(_, a, b) => mentions(a, name) || mentions(b, name),
        Ast::Call(_, args, _) => args.iter().any(|a| mentions(a, name)),
    }
}

/// The energy: one expression for every mode, or an object giving each
/// mode its own (a model whose modes are charts in different coordinates).
fn energy(value: &Value, path: &str, modes: &[&str]) -> Result<Vec<Source>, SceneError> {
    let Value::Object(map) = value else {
        let one = Source::read(value, path)?;
        return Ok(vec![one; modes.len()]);
    };
    for key in map.keys() {
        index_of(key, modes, "mode", &format!("{path}.{key}"))?;
    }
    modes
        .iter()
        .map(|mode| {
            let at = format!("{path}.{mode}");
            let value = map.get(*mode).ok_or_else(|| {
                SceneError::field(
                    &at,
                    "is missing: an energy given per mode needs every mode's".into(),
                )
            })?;
            Source::read(value, &at)
        })
        .collect()
}

fn object<'a>(value: &'a Value, path: &str) -> Result<&'a Map<String, Value>, SceneError> {
    value
        .as_object()
        .ok_or_else(|| SceneError::field(path, format!("must be an object, found {}", kind(value))))
}

/// Check that `name` may name a state or a parameter.
fn check_name(name: &str, path: &str) -> Result<(), SceneError> {
    let mut chars = name.chars();
    let well_formed = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !well_formed {
        return Err(SceneError::field(
            path,
            format!("{name:?} is not a name (letters, digits and _, not starting with a digit)"),
        ));
    }
    if RESERVED.contains(&name) {
        return Err(SceneError::field(
            path,
            format!("`{name}` is reserved (the clock, pi or a function)"),
        ));
    }
    Ok(())
}

/// The position of `name` among `known`, or an error naming the nearest.
fn index_of(name: &str, known: &[&str], what: &str, path: &str) -> Result<usize, SceneError> {
    known.iter().position(|k| *k == name).ok_or_else(|| {
        let nearest = known
            .iter()
            .map(|k| (strsim::damerau_levenshtein(name, k), *k))
            .min()
            .map(|(_, k)| format!("; the nearest is `{k}`"))
            .unwrap_or_default();
        SceneError::field(
            path,
            format!(
                "no {what} is called `{name}` (known: {}{nearest})",
                known.join(", ")
            ),
        )
    })
}

fn parameters(f: &mut Fields) -> Result<Vec<(String, f64)>, SceneError> {
    let path = f.path("parameters");
    let Some(value) = f.optional("parameters") else {
        return Ok(Vec::new());
    };
    object(value, &path)?
        .iter()
        .map(|(name, v)| {
            let at = format!("{path}.{name}");
            check_name(name, &at)?;
            match v.as_f64() {
                Some(x) if x.is_finite() => Ok((name.clone(), x)),
                _ => Err(SceneError::field(
                    &at,
                    format!("must be a finite number, found {}", kind(v)),
                )),
            }
        })
        .collect()
}

fn states(f: &mut Fields, parameters: &[(String, f64)]) -> Result<Vec<String>, SceneError> {
    let path = f.path("states");
    let value = f.required("states")?;
    let list = value
        .as_array()
        .filter(|l| !l.is_empty() && l.len() <= MAX_ITEMS)
        .ok_or_else(|| {
            SceneError::field(
                &path,
                format!(
                    "must be a list of 1 to {MAX_ITEMS} state names, found {}",
                    kind(value)
                ),
            )
        })?;
    let mut states: Vec<String> = Vec::new();
    for (i, v) in list.iter().enumerate() {
        let at = format!("{path}[{i}]");
        let name = v
            .as_str()
            .ok_or_else(|| SceneError::field(&at, format!("must be a name, found {}", kind(v))))?;
        check_name(name, &at)?;
        if states.iter().any(|s| s == name) {
            return Err(SceneError::field(
                &at,
                format!("state `{name}` is listed twice"),
            ));
        }
        if parameters.iter().any(|(p, _)| p == name) {
            return Err(SceneError::field(
                &at,
                format!("`{name}` is both a state and a parameter"),
            ));
        }
        states.push(name.to_string());
    }
    Ok(states)
}

/// The initial value of each state, and its expression: numbers or
/// expressions of the parameters.
fn initial(
    f: &mut Fields,
    states: &[String],
    parameters: &[(String, f64)],
) -> Result<Vec<(f64, Source)>, SceneError> {
    use crate::expr::{Scope, Tape};
    let path = f.path("initial");
    let map = object(f.required("initial")?, &path)?;
    let names: Vec<&str> = states.iter().map(String::as_str).collect();
    for key in map.keys() {
        index_of(key, &names, "state", &format!("{path}.{key}"))?;
    }
    let scope = Scope {
        inputs: Vec::new(),
        constants: parameters.to_vec(),
    };
    states
        .iter()
        .map(|name| {
            let at = format!("{path}.{name}");
            let value = map.get(name).ok_or_else(|| {
                SceneError::field(&at, "is missing: every state needs an initial value".into())
            })?;
            let source = Source::read(value, &at)?;
            let tape = Tape::compile(&[&source.ast], &scope).map_err(|e| {
                // The name the compiler stopped at, if a state: no near
                // miss among the parameters to suggest.
                let word: String = (source.text.get(e.at..).unwrap_or_default().chars())
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let what = if states.contains(&word) {
                    Some("a state")
                } else {
                    (word == "t").then_some("the time")
                };
                let message = match what {
                    Some(what) => {
                        format!("`{word}` is {what}: an initial value may use parameters only")
                    }
                    None => e.message,
                };
                source.error(e.at, &message)
            })?;
            match tape.constant() {
                Some(c) if c[0].is_finite() => Ok((c[0], source)),
                _ => Err(SceneError::field(
                    &at,
                    format!("`{}` is not a finite number", source.text),
                )),
            }
        })
        .collect()
}

fn mode(
    name: &str,
    value: &Value,
    path: &str,
    states: &[String],
    modes: &[&str],
) -> Result<ModeDef, SceneError> {
    let mut f = Fields::open(value, path)?;
    let names: Vec<&str> = states.iter().map(String::as_str).collect();
    let mut flow = vec![None; states.len()];
    if let Some(value) = f.optional("flow") {
        let flow_path = f.path("flow");
        for (state, rate) in object(value, &flow_path)? {
            let at = format!("{flow_path}.{state}");
            let i = index_of(state, &names, "state", &at)?;
            flow[i] = Some(Source::read(rate, &at)?);
        }
    }
    let mut transitions = Vec::new();
    if let Some(value) = f.optional("transitions") {
        let list_path = f.path("transitions");
        let list = value
            .as_array()
            .filter(|l| l.len() <= MAX_ITEMS)
            .ok_or_else(|| {
                SceneError::field(
                    &list_path,
                    format!(
                        "must be a list of at most {MAX_ITEMS} transitions, found {}",
                        kind(value)
                    ),
                )
            })?;
        for (i, t) in list.iter().enumerate() {
            let at = format!("{list_path}[{i}]");
            let transition = transition(t, &at, &names, modes, name)?;
            if transitions
                .iter()
                .any(|u: &Transition| u.name == transition.name)
            {
                return Err(SceneError::field(
                    &format!("{at}.name"),
                    format!(
                        "mode `{name}` has two transitions called `{}`",
                        transition.name
                    ),
                ));
            }
            transitions.push(transition);
        }
    }
    let rest = match f.optional("rest") {
        None => None,
        Some(value) => Some(rest(value, &f.path("rest"), &names, modes, name)?),
    };
    let transitions_path = f.path("transitions");
    f.finish()?;
    // A stable sort keeps file order among equal priorities.
    transitions.sort_by(|a, b| b.priority.total_cmp(&a.priority));
    unreachable_copies(&transitions, modes, name, &transitions_path)?;
    Ok(ModeDef {
        name: name.to_string(),
        flow,
        transitions,
        rest,
    })
}

/// Refuse a transition that can never fire: one with the same guard as a
/// transition that fires before it (by priority, then file order) at every
/// crossing it would take, and leaves the mode or ends the run there.
fn unreachable_copies(
    transitions: &[Transition],
    modes: &[&str],
    mode: &str,
    path: &str,
) -> Result<(), SceneError> {
    let here = modes.iter().position(|m| *m == mode);
    for (k, later) in transitions.iter().enumerate() {
        let covers = |first: &Transition| {
            same(&first.guard.ast, &later.guard.ast)
                && (first.direction == Direction::Either || first.direction == later.direction)
                && (Some(first.to) != here || first.terminal)
        };
        if let Some(first) = transitions[..k].iter().find(|first| covers(first)) {
            return Err(SceneError::field(
                path,
                format!(
                    "transition `{}` can never fire: `{}` has the same guard, fires first at \
                     every crossing `{}` would take (priority, then file order) and {}; give it \
                     another guard or remove it",
                    later.name,
                    first.name,
                    later.name,
                    if first.terminal {
                        "ends the run".to_string()
                    } else {
                        format!("leaves mode `{mode}`")
                    }
                ),
            ));
        }
    }
    Ok(())
}

/// A mode's `rest`: `to` (default the mode itself) and `reset`.
fn rest(
    value: &Value,
    path: &str,
    states: &[&str],
    modes: &[&str],
    mode: &str,
) -> Result<Rest, SceneError> {
    let mut f = Fields::open(value, path)?;
    let to = match f.optional_string("to")? {
        Some(target) => index_of(target, modes, "mode", &f.path("to"))?,
        None => modes.iter().position(|m| *m == mode).unwrap_or(0),
    };
    let reset = match f.optional("reset") {
        None => Vec::new(),
        Some(value) => resets(value, &f.path("reset"), states)?,
    };
    f.finish()?;
    Ok(Rest { to, reset })
}

/// A `reset` object: each state it names, and its new value.
fn resets(value: &Value, path: &str, states: &[&str]) -> Result<Vec<(usize, Source)>, SceneError> {
    let mut reset = Vec::new();
    for (state, expr) in object(value, path)? {
        let at = format!("{path}.{state}");
        let i = index_of(state, states, "state", &at)?;
        reset.push((i, Source::read(expr, &at)?));
    }
    Ok(reset)
}

fn transition(
    value: &Value,
    path: &str,
    states: &[&str],
    modes: &[&str],
    mode: &str,
) -> Result<Transition, SceneError> {
    let mut f = Fields::open(value, path)?;
    let name = f.string("name")?.to_string();
    if name.is_empty() || name.len() > 100 {
        return Err(SceneError::field(
            &f.path("name"),
            "must be 1 to 100 characters".into(),
        ));
    }
    let guard = Source::read(f.required("guard")?, &f.path("guard"))?;
    let variables: Vec<&str> = states.iter().copied().chain(["t"]).collect();
    if constant(&guard.ast, &variables).is_some() || never_zero(&guard.ast) {
        return Err(SceneError::field(
            &f.path("guard"),
            format!(
                "`{}` never crosses zero (it does not change with the state or the time, \
                 or its form keeps one sign), so the transition could never fire",
                guard.text
            ),
        ));
    }
    let direction = match f.optional_string("direction")? {
        None | Some("either") => Direction::Either,
        Some("falling") => Direction::Falling,
        Some("rising") => Direction::Rising,
        Some(other) => {
            return Err(SceneError::field(
                &f.path("direction"),
                format!("must be \"falling\", \"rising\" or \"either\", found {other:?}"),
            ));
        }
    };
    let reset = match f.optional("reset") {
        None => Vec::new(),
        Some(value) => resets(value, &f.path("reset"), states)?,
    };
    let to = match f.optional_string("to")? {
        Some(target) => index_of(target, modes, "mode", &f.path("to"))?,
        None => modes.iter().position(|m| *m == mode).unwrap_or(0),
    };
    let priority = f.optional_number("priority")?.unwrap_or(0.0);
    let flag = |f: &mut Fields, key: &'static str| -> Result<bool, SceneError> {
        let path = f.path(key);
        match f.optional(key) {
            None => Ok(false),
            Some(Value::Bool(b)) => Ok(*b),
            Some(other) => Err(SceneError::field(
                &path,
                format!("must be true or false, found {}", kind(other)),
            )),
        }
    };
    let terminal = flag(&mut f, "terminal")?;
    let barrier = flag(&mut f, "barrier")?;
    f.finish()?;
    Ok(Transition {
        name,
        guard,
        direction,
        reset,
        to,
        priority,
        terminal,
        barrier,
    })
}
