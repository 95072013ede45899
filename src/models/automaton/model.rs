//! An automaton compiled to tapes, as the engine runs it: a
//! [`HybridModel`] whose modes are ODEs, whose guards and resets are the
//! file's expressions.
//!
//! Each mode's rates are one tape (its subexpressions shared); each guard,
//! each reset and the energy (in each mode) are tapes of their own. When an expression
//! reads the clock `t`, the state gains a last component `t` with rate 1,
//! so that the flows stay autonomous as the engine wants them (the log and
//! the summary show it as a state). What the compiled form reveals is
//! offered to the methods: a mode whose rates are affine is linear (its `A`
//! and `b` read off exactly by forward differentiation), one affine in the
//! state and driven by sines of the clock is that too, with its waves
//! (`expr/waves.rs`), a mode of the
//! shape `[q; v]` with `q' = v` and `v'` free of `v` is second order.

use std::cell::RefCell;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use crate::engine::model::affine_flow::AffineFlow;
use crate::engine::{Flow, Guard, HybridModel, Jump, Mode, Name};
use crate::expr::compiled::{CompiledFlows, CompiledTape};
use crate::expr::derivative::{jacobian, jacobian_into, jacobian_tape};
use crate::expr::recurrences::Series;
use crate::expr::{Ast, Scope, Tape, waves};
use crate::models::automaton::definition::{Definition, Source};
use crate::models::automaton::filippov::{self, Target};
use crate::scene::SceneError;

/// A compiled automaton.
#[derive(Debug, Clone)]
pub struct Automaton {
    states: Vec<Name>,
    /// Whether the last state component is the clock.
    clock: bool,
    modes: Vec<CompiledMode>,
    /// The energy's tape in each mode.
    energy: Option<Vec<Tape>>,
    initial: Vec<f64>,
    initial_mode: Mode,
    /// Where the file's initial mode has switching surfaces, its family:
    /// a start begins in the region (or on the surface) it lies in.
    start_family: Option<usize>,
    /// The modes with switching surfaces (see [`filippov`]).
    families: Vec<Surfaces>,
    /// For each mode, the reason a run entering it stops with, where it
    /// stands for an answer the model does not have.
    stops: Vec<Option<String>>,
    /// For each mode of the file, the modes it became (see
    /// [`filippov::Expanded::origins`]).
    origins: Vec<Vec<Mode>>,
}

#[derive(Debug, Clone)]
struct CompiledMode {
    name: String,
    /// The rate of every state component.
    flow: Tape,
    /// Its tapes as machine code, compiled once warmed up (shared by the
    /// copies of the model a sweep's threads hold).
    code: Arc<ModeCode>,
    /// Its Jacobian's entries, row-major, where compiled (a smooth flow).
    flow_jacobian: Option<Tape>,
    /// The text of each state's rate, for diagnoses.
    rates: Vec<Option<Source>>,
    guards: Vec<Guard>,
    guard_tapes: Vec<Tape>,
    /// Each transition's guard and reset expressions as written, for
    /// diagnoses.
    texts: Vec<(String, Vec<String>)>,
    resets: Vec<Reset>,
    /// Where its barriers' events pile up: the resting mode and state.
    rest: Option<Reset>,
    kind: Flow,
    linear: Option<(DMatrix<f64>, DVector<f64>)>,
    /// The flow as affine in the state and driven by sines of the clock,
    /// where it is that and not plainly linear.
    driven: Option<AffineFlow>,
    /// The flow's Jacobian in the state where it is constant (linear, or
    /// linear and driven by the clock), its clock's column zero.
    constant_jacobian: Option<DMatrix<f64>>,
    second_order: bool,
    /// Where the mode reads `abs`, `min` or `max` (its flow, or a guard by
    /// name), if it does: no Taylor series there. `None`: they hold over
    /// a whole step.
    rough: Option<String>,
}

/// A mode's tapes compiled (see [`crate::expr::compiled`]),
/// each once a run has asked for it often enough to repay it.
#[derive(Debug, Default)]
struct ModeCode {
    /// The flow's Taylor series, per order.
    series: CompiledFlows,
    /// The flow's rates.
    rates: CompiledTape,
    /// The flow's Jacobian, where it has a tape.
    jacobian: CompiledTape,
    /// Each guard's value.
    guards: Vec<CompiledTape>,
    /// Each transition's reset, and the rest's (an event's new state).
    resets: Vec<CompiledTape>,
    rest: CompiledTape,
    /// The energy, where the file gives one (evaluated at every event).
    energy: CompiledTape,
}

#[derive(Debug, Clone)]
struct Reset {
    /// The new values of `targets`, from the state before the event.
    tape: Tape,
    targets: Vec<usize>,
    /// The rows of the Jacobian for `targets`, where the new values are
    /// affine in the state: the same at every event, so taken once.
    affine_rows: Option<Vec<f64>>,
    to: Mode,
    /// How the mode after is picked: `to`, or by the signs of a family's
    /// switching surfaces at the state after (see [`filippov`]).
    pick: Target,
    terminal: bool,
}

impl Reset {
    /// Set `targets` of an `n`-component state from `tape`'s outputs, into
    /// `to` as `pick` says.
    fn new(
        tape: Tape,
        targets: Vec<usize>,
        n: usize,
        (to, pick): (Mode, Target),
        terminal: bool,
    ) -> Self {
        // The forward pass of an affine tape gives the same derivatives at
        // any state.
        let affine_rows = (!targets.is_empty() && tape.affine()).then(|| {
            let mut rows = vec![0.0; targets.len() * n];
            jacobian_into(&tape, &vec![0.0; n], &mut rows);
            rows
        });
        Reset {
            tape,
            targets,
            affine_rows,
            to,
            pick,
            terminal,
        }
    }

    /// Every new value from the values before the event, all at once, by
    /// `code` (this reset's compiled tape).
    fn apply(&self, code: &CompiledTape, x: &mut [f64]) {
        // On the stack for the few states a reset names: no allocation per
        // event.
        let (mut small, mut large) = ([0.0; 8], Vec::new());
        let new: &mut [f64] = match self.targets.len() {
            n if n <= small.len() => &mut small[..n],
            n => {
                large.resize(n, 0.0);
                &mut large
            }
        };
        code.eval(&self.tape, x, new);
        for (&i, &v) in self.targets.iter().zip(new.iter()) {
            x[i] = v;
        }
    }
}

/// A mode with switching surfaces, compiled (see [`filippov::Family`]).
#[derive(Debug, Clone)]
struct Surfaces {
    /// Each surface `h`.
    surfaces: Vec<Tape>,
    /// The rate of each surface along each region's flow.
    rates: Vec<Vec<Tape>>,
    regions: Vec<Mode>,
    sliding: Vec<Vec<Mode>>,
    repelling: Vec<Mode>,
    double: Mode,
    /// What a slide onto each surface is called in the log.
    slide_names: Vec<Name>,
    /// The state each surface is, up to a constant, where it is one.
    held: Vec<Option<usize>>,
}

impl Surfaces {
    /// The mode of this family the state `x` lies in, with surface `on`
    /// taken as reached (a crossing just located), and what the event that
    /// brought it there is called if it slid: the region of the surfaces'
    /// signs; on one surface, the side both flows carry it to, sliding
    /// where both point into it, the refusal where both point away; on two
    /// at once, see [`Surfaces::on_two`].
    fn pick(&self, x: &[f64], on: Option<usize>) -> (Mode, Option<&Name>) {
        self.pick_on(x, [on, None])
    }

    /// [`Surfaces::pick`] with up to two surfaces taken as reached (a
    /// crossing located while sliding on another).
    fn pick_on(&self, x: &[f64], on: [Option<usize>; 2]) -> (Mode, Option<&Name>) {
        let mut bits = 0;
        let mut zeros = [None, None];
        for (j, h) in self.surfaces.iter().enumerate() {
            let value = if on.contains(&Some(j)) {
                0.0
            } else {
                h.eval1(x)
            };
            if value < 0.0 {
                bits |= 1 << j;
            } else if value == 0.0 {
                match zeros {
                    [None, _] => zeros[0] = Some(j),
                    [Some(_), None] => zeros[1] = Some(j),
                    _ => return (self.double, None),
                }
            }
        }
        match zeros {
            [None, _] => (self.regions[bits], None),
            [Some(j), None] => self.on_one(x, j, bits),
            [Some(a), Some(b)] => self.on_two(x, (a, b), bits),
        }
    }

    /// On surface `j` alone, the other surfaces' signs `bits`.
    fn on_one(&self, x: &[f64], j: usize, bits: usize) -> (Mode, Option<&Name>) {
        let (plus, minus) = (bits & !(1 << j), bits | (1 << j));
        // Into the surface: h falling on the positive side, rising on the
        // negative (a tangent counts as in: the state stays on it).
        let plus_in = self.rates[plus][j].eval1(x) <= 0.0;
        let minus_in = self.rates[minus][j].eval1(x) >= 0.0;
        match (plus_in, minus_in) {
            (true, true) => (self.sliding[j][bits], Some(&self.slide_names[j])),
            (true, false) => (self.regions[minus], None),
            (false, true) => (self.regions[plus], None),
            (false, false) => (self.repelling[j], None),
        }
    }

    /// On surfaces `a` and `b` at once: where the flows of all four regions
    /// around cross one of them the same way (a block that reverses while
    /// another sticks), the state passes through it to the side they carry
    /// it to, and the other decides alone; otherwise (sliding on both, or
    /// no one answer) the refusal.
    fn on_two(&self, x: &[f64], (a, b): (usize, usize), bits: usize) -> (Mode, Option<&Name>) {
        for (through, other) in [(a, b), (b, a)] {
            let around = [0, 1 << a, 1 << b, (1 << a) | (1 << b)];
            let rates = around.map(|signs| {
                let region = (bits & !(1 << a) & !(1 << b)) | signs;
                self.rates[region][through].eval1(x)
            });
            let side = if rates.iter().all(|&r| r > 0.0) {
                bits & !(1 << through)
            } else if rates.iter().all(|&r| r < 0.0) {
                bits | (1 << through)
            } else {
                continue;
            };
            return self.on_one(x, other, side);
        }
        (self.double, None)
    }
}

impl Automaton {
    /// Compile `definition`; an expression naming what its scope does not
    /// know fails with its field, the character and the nearest name.
    pub fn compile(file: &Definition) -> Result<Automaton, SceneError> {
        let expanded = filippov::expand(file)?;
        let definition = &expanded.definition;
        let clock = definition.reads_clock();
        let mut inputs = definition.states.clone();
        if clock {
            inputs.push("t".into());
        }
        let n = inputs.len();
        let scope = Scope {
            inputs: inputs.clone(),
            constants: definition.parameters.clone(),
        };
        let compile = |sources: &[&Source]| -> Result<Tape, SceneError> {
            let asts: Vec<&Ast> = sources.iter().map(|s| &s.ast).collect();
            Tape::compile(&asts, &scope).map_err(|e| {
                // Which of the sources the error is in: the first that fails alone.
                let culprit = sources
                    .iter()
                    .find(|s| Tape::compile(&[&s.ast], &scope).is_err())
                    .unwrap_or(&sources[0]);
                culprit.error(e.at, &e.message)
            })
        };
        // A reset's new values, one tape (none for a reset of nothing).
        let new_values = |reset: &[(usize, Source)]| -> Result<Tape, SceneError> {
            let sources: Vec<&Source> = reset.iter().map(|(_, s)| s).collect();
            if sources.is_empty() {
                Ok(Tape {
                    ops: Vec::new(),
                    outputs: Vec::new(),
                })
            } else {
                compile(&sources)
            }
        };
        let zero = Source {
            text: "0".into(),
            path: String::new(),
            ast: Ast::Number(0.0),
        };
        let one = Source {
            text: "1".into(),
            path: String::new(),
            ast: Ast::Number(1.0),
        };
        let mut modes = Vec::new();
        for (index, mode) in definition.modes.iter().enumerate() {
            let mut rates: Vec<&Source> = mode
                .flow
                .iter()
                .map(|r| r.as_ref().unwrap_or(&zero))
                .collect();
            if clock {
                rates.push(&one);
            }
            let flow = compile(&rates)?;
            // Within a few times the flow's own forward pass (a register
            // and `n` gradient entries each).
            let budget = 4 * (n + 1) * flow.ops.len();
            let asts: Vec<&Ast> = rates.iter().map(|s| &s.ast).collect();
            let flow_jacobian = flow
                .smooth()
                .then(|| jacobian_tape(&asts, &scope, budget))
                .flatten();
            let mut guards = Vec::new();
            let mut guard_tapes = Vec::new();
            let mut resets = Vec::new();
            let texts = mode
                .transitions
                .iter()
                .map(|t| {
                    let resets = t.reset.iter().map(|(_, s)| s.text.clone()).collect();
                    (t.guard.text.clone(), resets)
                })
                .collect();
            for (t, &pick) in mode.transitions.iter().zip(&expanded.targets[index]) {
                let tape = compile(&[&t.guard])?;
                guards.push(Guard {
                    name: Name::from(t.name.as_str()),
                    direction: t.direction,
                    affine: tape.affine(),
                    internal: false,
                    barrier: t.barrier,
                });
                guard_tapes.push(tape);
                resets.push(Reset::new(
                    new_values(&t.reset)?,
                    t.reset.iter().map(|(i, _)| *i).collect(),
                    n,
                    (t.to, pick),
                    t.terminal,
                ));
            }
            let rest = match &mode.rest {
                Some(r) => Some(Reset::new(
                    new_values(&r.reset)?,
                    r.reset.iter().map(|(i, _)| *i).collect(),
                    n,
                    (r.to, Target::Fixed),
                    false,
                )),
                None => None,
            };
            let still = flow.constant().is_some_and(|c| c.iter().all(|&r| r == 0.0));
            let linear = flow.affine().then(|| {
                let a = jacobian(&flow, &vec![0.0; n]);
                let mut b = vec![0.0; n];
                flow.eval_scratch(&vec![0.0; n], &mut b);
                (a, DVector::from_vec(b))
            });
            let clock_input = clock.then(|| (n - 1) as u32);
            let constant_jacobian = match &linear {
                Some((a, _)) => Some(a.clone()),
                None if clock && flow.affine_beside(clock_input) => {
                    // The same at every state: read at the origin, at
                    // t = 1 (a forcing may be singular at t = 0, and its
                    // infinite slope would turn the state's zero
                    // derivatives into NaN).
                    let mut at = vec![0.0; n];
                    at[n - 1] = 1.0;
                    let mut a = jacobian(&flow, &at);
                    a.column_mut(n - 1).fill(0.0);
                    a.iter().all(|v| v.is_finite()).then_some(a)
                }
                None => None,
            };
            let driven = match (&linear, clock_input) {
                (None, Some(t)) => waves::driven(&flow, n, t as usize),
                _ => None,
            };
            let half = n / 2;
            let second_order = !clock
                && n % 2 == 0
                && (0..half).all(|i| {
                    flow.ops[flow.outputs[i] as usize] == crate::expr::Op::Input((half + i) as u32)
                })
                && (half..n).all(|i| (half..n).all(|j| !flow.depends_on(i, j as u32)));
            let rough = if flow.smooth() {
                (guards.iter().zip(&guard_tapes))
                    .find(|(_, tape)| !tape.smooth())
                    .map(|(g, _)| format!("the guard `{}` of mode `{}`", g.name, mode.name))
            } else {
                Some(format!("the flow of mode `{}`", mode.name))
            };
            modes.push(CompiledMode {
                rough,
                name: mode.name.clone(),
                flow,
                code: Arc::new(ModeCode {
                    guards: guard_tapes
                        .iter()
                        .map(|_| CompiledTape::default())
                        .collect(),
                    resets: resets.iter().map(|_| CompiledTape::default()).collect(),
                    ..ModeCode::default()
                }),
                flow_jacobian,
                rates: mode.flow.clone(),
                guards,
                guard_tapes,
                texts,
                resets,
                rest,
                kind: if still { Flow::Frozen } else { Flow::Ode },
                linear,
                driven,
                constant_jacobian,
                second_order,
            });
        }
        let energy = definition
            .energy
            .as_ref()
            .map(|per_mode| per_mode.iter().map(|e| compile(&[e])).collect())
            .transpose()?;
        let mut initial = definition.initial.clone();
        if clock {
            initial.push(0.0);
        }
        let families = expanded
            .families
            .iter()
            .map(|f| {
                let one = |s: &Source| compile(&[s]);
                Ok(Surfaces {
                    surfaces: f
                        .surfaces
                        .iter()
                        .map(one)
                        .collect::<Result<_, SceneError>>()?,
                    rates: f
                        .rates
                        .iter()
                        .map(|r| r.iter().map(one).collect::<Result<Vec<_>, SceneError>>())
                        .collect::<Result<_, SceneError>>()?,
                    regions: f.regions.clone(),
                    sliding: f.sliding.clone(),
                    repelling: f.repelling.clone(),
                    double: f.double,
                    slide_names: f
                        .surfaces
                        .iter()
                        .map(|h| Name::from(filippov::event_name("slide", h)))
                        .collect(),
                    held: f.held.clone(),
                })
            })
            .collect::<Result<Vec<_>, SceneError>>()?;
        // The start: a mode with surfaces begins in the region (or on the
        // surface) the initial state lies in.
        let start_family = match expanded.start {
            Target::Enter(f) => Some(f),
            _ => None,
        };
        let initial_mode = match start_family {
            Some(f) => families[f].pick(&initial, None).0,
            None => definition.initial_mode,
        };
        Ok(Automaton {
            states: inputs.into_iter().map(Name::from).collect(),
            clock,
            modes,
            energy,
            initial,
            initial_mode,
            start_family,
            families,
            stops: expanded.stops,
            origins: expanded.origins,
        })
    }

    /// The state the file starts from (the clock at 0 where there is one).
    pub fn initial(&self) -> &[f64] {
        &self.initial
    }

    /// The mode the file starts in.
    pub fn initial_mode(&self) -> Mode {
        self.initial_mode
    }

    /// The mode a run from `state` begins in: the file's initial mode, or,
    /// where that mode switches its flow by `sign()`, the region (or the
    /// surface) `state` lies in, as the file's own start is decided.
    pub fn initial_mode_at(&self, state: &[f64]) -> Mode {
        match self.start_family {
            Some(f) => self.families[f].pick(state, None).0,
            None => self.initial_mode,
        }
    }

    /// The modes mode `file_mode` of the file became: itself, or the
    /// regions and sliding modes of a flow that reads `sign()`.
    pub fn modes_of(&self, file_mode: usize) -> &[Mode] {
        &self.origins[file_mode]
    }

    /// Every mode.
    pub fn modes(&self) -> Vec<Mode> {
        (0..self.modes.len()).collect()
    }

    /// Whether the state carries the clock as its last component.
    pub fn has_clock(&self) -> bool {
        self.clock
    }

    /// The first flow or guard that reads `abs`, `min` or `max`, where
    /// Taylor series do not hold, if any: "the guard `wall` of mode `m`".
    pub fn rough(&self) -> Option<&str> {
        self.modes.iter().find_map(|m| m.rough.as_deref())
    }

    /// Whether every mode's flow is affine, or affine and driven by sines
    /// of the clock (the linear propagator runs it).
    pub fn all_linear(&self) -> bool {
        (0..self.modes.len()).all(|m| self.has_affine_flow(m) || self.modes[m].kind == Flow::Frozen)
    }

    /// Whether the run ends at the event of `guard` in `mode`.
    pub fn is_terminal(&self, mode: Mode, guard: usize) -> bool {
        self.modes[mode].resets[guard].terminal
    }
}

impl HybridModel for Automaton {
    fn dimension(&self) -> usize {
        self.states.len()
    }

    fn state_names(&self, _: Mode) -> &[Name] {
        &self.states
    }

    fn mode_name(&self, mode: Mode) -> &str {
        &self.modes[mode].name
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        &self.modes[mode].guards
    }

    #[inline]
    fn guard(&self, mode: Mode, guard: usize, x: &[f64]) -> f64 {
        let m = &self.modes[mode];
        let mut value = [0.0];
        m.code.guards[guard].eval(&m.guard_tapes[guard], x, &mut value);
        value[0]
    }

    fn flow(&self, mode: Mode) -> Flow {
        self.modes[mode].kind
    }

    #[inline]
    fn rhs(&self, mode: Mode, x: &[f64], dx: &mut [f64]) {
        let m = &self.modes[mode];
        m.code.rates.eval(&m.flow, x, dx);
    }

    fn has_rhs(&self, _: Mode) -> bool {
        true
    }

    /// Exact, by forward differentiation along the mode's tape.
    fn jacobian(&self, mode: Mode, x: &[f64], jac: &mut [f64]) -> bool {
        let m = &self.modes[mode];
        match &m.flow_jacobian {
            Some(tape) => m.code.jacobian.eval(tape, x, jac),
            None => jacobian_into(&m.flow, x, jac),
        }
        true
    }

    /// Exact, by forward differentiation along the guard's tape.
    fn guard_gradient(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        jacobian_into(&self.modes[mode].guard_tapes[guard], x, out);
        true
    }

    /// Exact: the identity on the states the reset leaves alone, its
    /// tape's derivatives on the others.
    fn reset_jacobian(&self, mode: Mode, guard: usize, x: &[f64], out: &mut [f64]) -> bool {
        let n = x.len();
        let reset = &self.modes[mode].resets[guard];
        out.fill(0.0);
        for i in 0..n {
            out[i * n + i] = 1.0;
        }
        if reset.targets.is_empty() {
            return true;
        }
        if let Some(rows) = &reset.affine_rows {
            for (k, &i) in reset.targets.iter().enumerate() {
                out[i * n..(i + 1) * n].copy_from_slice(&rows[k * n..(k + 1) * n]);
            }
            return true;
        }
        // The rows of the states it sets, on the stack where they fit (an
        // event's saltation asks at every event).
        let size = reset.targets.len() * n;
        let mut small = [0.0; 64];
        let mut large = Vec::new();
        let rows = if size <= small.len() {
            &mut small[..size]
        } else {
            large.resize(size, 0.0);
            &mut large[..]
        };
        jacobian_into(&reset.tape, x, rows);
        for (k, &i) in reset.targets.iter().enumerate() {
            out[i * n..(i + 1) * n].copy_from_slice(&rows[k * n..(k + 1) * n]);
        }
        true
    }

    fn second_order(&self, mode: Mode) -> bool {
        self.modes[mode].second_order
    }

    fn has_series(&self, mode: Mode) -> bool {
        self.modes[mode].rough.is_none()
    }

    fn flow_series(&self, mode: Mode, x: &[f64], order: usize, series: &mut [f64]) {
        let m = &self.modes[mode];
        match m.code.series.get(&m.flow, order) {
            Some(code) => code.flow(x, series),
            None => SERIES.with_borrow_mut(|s| s.flow(&m.flow, x, order, series)),
        }
    }

    fn guard_series(
        &self,
        mode: Mode,
        guard: usize,
        series: &[f64],
        order: usize,
        out: &mut [f64],
    ) {
        let tape = &self.modes[mode].guard_tapes[guard];
        SERIES.with_borrow_mut(|s| s.compose(tape, series, order, out));
    }

    fn linear(&self, mode: Mode) -> Option<(DMatrix<f64>, DVector<f64>)> {
        self.modes[mode].linear.clone()
    }

    fn is_linear(&self, mode: Mode) -> bool {
        self.modes[mode].linear.is_some()
    }

    fn constant_jacobian(&self, mode: Mode) -> Option<DMatrix<f64>> {
        self.modes[mode].constant_jacobian.clone()
    }

    fn affine_flow(&self, mode: Mode) -> Option<AffineFlow> {
        let m = &self.modes[mode];
        m.driven
            .clone()
            .or_else(|| m.linear.clone().map(AffineFlow::linear))
    }

    fn has_affine_flow(&self, mode: Mode) -> bool {
        let m = &self.modes[mode];
        m.linear.is_some() || m.driven.is_some()
    }

    fn reset(&self, mode: Mode, guard: usize, x: &mut [f64]) -> Jump {
        let m = &self.modes[mode];
        let reset = &m.resets[guard];
        reset.apply(&m.code.resets[guard], x);
        let (to, named) = match reset.pick {
            Target::Fixed => (reset.to, None),
            Target::Leave(guard) => return Jump::to(reset.to).leaving(guard),
            Target::Enter(f) => self.families[f].pick(x, None),
            Target::Across { family, surface }
            | Target::AcrossSliding {
                family, surface, ..
            } => {
                let surfaces = &self.families[family];
                let sliding = match reset.pick {
                    Target::AcrossSliding { sliding, .. } => Some(sliding),
                    _ => None,
                };
                let mut picked = surfaces.pick_on(x, [Some(surface), sliding]);
                // Still sliding where it slid: the crossing is the event.
                if sliding.is_some_and(|j| surfaces.sliding[j].contains(&picked.0)) {
                    picked.1 = None;
                }
                // Onto the surface exactly, where it is one state (the
                // crossing was located a rounding off it): the sliding flow
                // then holds it there.
                if let (Some(_), Some(c)) = (picked.1, surfaces.held[surface]) {
                    x[c] -= surfaces.surfaces[surface].eval1(x);
                }
                picked
            }
        };
        match named {
            Some(name) => Jump::to(to).named(name.clone()),
            None => Jump::to(to),
        }
    }

    /// The mode's `rest`, where its barriers' events pile up.
    fn settle(&self, mode: Mode, x: &mut [f64]) -> Option<Mode> {
        let m = &self.modes[mode];
        let rest = m.rest.as_ref()?;
        rest.apply(&m.code.rest, x);
        Some(rest.to)
    }

    fn stop_reason(&self, mode: Mode) -> Option<String> {
        self.stops.get(mode).cloned().flatten()
    }

    fn terminal(&self, mode: Mode, guard: usize) -> bool {
        self.is_terminal(mode, guard)
    }

    fn marks_only(&self, mode: Mode, guard: usize) -> bool {
        let reset = &self.modes[mode].resets[guard];
        reset.targets.is_empty() && matches!(reset.pick, Target::Fixed) && reset.to == mode
    }

    fn clock(&self) -> Option<usize> {
        self.clock.then(|| self.states.len() - 1)
    }

    fn energy(&self, mode: Mode, x: &[f64]) -> Option<f64> {
        self.energy.as_ref().map(|e| {
            let mut value = [0.0];
            self.modes[mode].code.energy.eval(&e[mode], x, &mut value);
            value[0]
        })
    }

    /// A file's resets may take energy away (a restitution) or rewrite
    /// it in other coordinates: its energy is audited along the flows.
    fn resets_keep_energy(&self) -> bool {
        false
    }

    fn energy_scale(&self, initial_energy: f64) -> f64 {
        initial_energy.abs().max(f64::MIN_POSITIVE)
    }

    /// Which rate is not finite at `x`, and its expression; where all are
    /// (a step size that collapsed), the steepest.
    fn diagnose(&self, mode: Mode, x: &[f64]) -> Option<String> {
        let m = &self.modes[mode];
        let mut rates = vec![0.0; self.states.len()];
        m.flow.eval_scratch(x, &mut rates);
        let text = |i: usize| {
            m.rates
                .get(i)
                .and_then(|r| r.as_ref())
                .map_or("0", |s| s.text.as_str())
        };
        if let Some(i) = rates.iter().position(|r| !r.is_finite()) {
            return Some(format!(
                "the rate of `{}`, `{}`, is {} there",
                self.states[i],
                text(i),
                rates[i]
            ));
        }
        // All finite: the step collapsed where a rate turns steep (a
        // square root at zero, a pole): name the steepest.
        let jac = jacobian(&m.flow, x);
        let (i, j) = (0..jac.nrows())
            .flat_map(|i| (0..jac.ncols()).map(move |j| (i, j)))
            .max_by(|a, b| jac[*a].abs().total_cmp(&jac[*b].abs()))?;
        Some(format!(
            "the rate of `{}`, `{}`, changes by {:e} per unit of `{}` there",
            self.states[i],
            text(i),
            jac[(i, j)],
            self.states[j]
        ))
    }

    fn may_be_undefined(&self) -> bool {
        true
    }

    /// The guard's expression, or the reset's that is not finite.
    fn diagnose_guard(&self, mode: Mode, guard: usize, x: &[f64], reset: bool) -> Option<String> {
        let m = &self.modes[mode];
        let (guard_text, reset_texts) = &m.texts[guard];
        if !reset {
            return Some(format!("its expression is `{guard_text}`"));
        }
        let r = &m.resets[guard];
        let mut new = vec![0.0; r.targets.len()];
        r.tape.eval_scratch(x, &mut new);
        let k = new.iter().position(|v| !v.is_finite())?;
        Some(format!(
            "the reset of `{}`, `{}`, is {} there",
            self.states[r.targets[k]], reset_texts[k], new[k]
        ))
    }
}

thread_local! {
    /// Scratch for Taylor series (models are shared, read only, between
    /// the threads of a sweep).
    static SERIES: RefCell<Series> = RefCell::new(Series::default());
}

#[cfg(test)]
mod tests {
    use crate::engine::model::HybridModel;
    use crate::models::automaton::{AutomatonBuilder, TransitionBuilder};

    /// A driven linear oscillator's Jacobian in the state is constant
    /// (its clock's column zero); a parametric one's, `x'' = -(1 + cos t)
    /// x`, is not, nor a nonlinear one's.
    #[test]
    fn a_driven_linear_flow_has_a_constant_jacobian() {
        let model = |rate: &str| {
            AutomatonBuilder::new()
                .parameter("z", 0.25)
                .state("x", 1.0)
                .state("v", 0.0)
                .mode("m", [("x", "v"), ("v", rate)], [])
                .build()
                .unwrap()
        };
        let driven = model("cos(0.8 * t) - 2 * z * v - 4 * x");
        assert_eq!(driven.clock(), Some(2));
        let a = driven.constant_jacobian(0).expect("constant");
        #[rustfmt::skip]
        let want = [
            0.0, 1.0, 0.0,
            -4.0, -0.5, 0.0,
            0.0, 0.0, 0.0,
        ];
        assert_eq!(a.transpose().as_slice(), want);
        // A model's own linear flow: its A.
        let free = model("-2 * z * v - 4 * x");
        assert_eq!(free.constant_jacobian(0), free.linear(0).map(|(a, _)| a));
        assert!(free.constant_jacobian(0).is_some());
        for rate in ["-(1 + cos(t)) * x", "-sin(x)", "-t * v"] {
            assert_eq!(model(rate).constant_jacobian(0), None, "{rate}");
        }
    }

    /// The energy and each transition's reset are compiled once warmed up
    /// (64 calls): past that, each still reads its own expression, at
    /// every state, the two transitions' resets not swapped.
    #[test]
    fn energy_and_resets_keep_their_expressions_once_compiled() {
        let model = AutomatonBuilder::new()
            .parameter("k", 3.0)
            .state("x", 1.0)
            .state("v", 0.0)
            .mode(
                "flight",
                [("x", "v"), ("v", "-k * x")],
                [
                    TransitionBuilder::new("low", "x + 1")
                        .falling()
                        .reset("v", "-0.5 * v"),
                    TransitionBuilder::new("high", "2 - x")
                        .falling()
                        .reset("v", "x * v - 1"),
                ],
            )
            .energy("v^2 / 2 + k * x^2 / 2 + sin(x)")
            .build()
            .unwrap();
        for i in 0..200 {
            let (x, v) = (0.37 * i as f64 - 20.0, 1.5 - 0.011 * i as f64);
            let energy = model.energy(0, &[x, v]).unwrap();
            assert_eq!(
                energy,
                v.powi(2) / 2.0 + 3.0 * x.powi(2) / 2.0 + x.sin(),
                "{i}"
            );
            let mut low = [x, v];
            model.reset(0, 0, &mut low);
            assert_eq!(low, [x, -0.5 * v], "{i}");
            let mut high = [x, v];
            model.reset(0, 1, &mut high);
            assert_eq!(high, [x, x * v - 1.0], "{i}");
        }
    }
}
