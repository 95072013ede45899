//! The whole-state source of segments: the engine holds the model's state
//! and advances it, for models small enough to copy at every event.
//!
//! It never asks which integrator a mode uses. A mode's flow gives a
//! *segment*: for an exact flow, the whole future (guards predicted by the
//! model's exact crossing times); for an ODE, one accepted step with dense
//! output (guards located on it, see [`locate`]). The queue holds one
//! prediction per guard; whichever comes first, the earliest prediction or
//! the end of the current step, happens next. Along the way it carries the
//! run's error bound ([`bound`]) and stops where an event cannot be decided
//! (a graze within the integration error, a non-finite state, a step size
//! collapse). Order, samples, budgets, Zeno, the energy audit and counts
//! are the one run loop's (`src/engine/run/run_loop.rs`).
//!
//! [`locate`]: crate::engine::step::locate
//! [`bound`]: crate::engine::bound

use crate::engine::bound::Bound;
use crate::engine::model::{HybridModel, Mode};
use crate::engine::run::ledger::End;
use crate::engine::run::ledger::{Final, Ledger};
use crate::engine::run::observer::Observer;
use crate::engine::run::periodic::Returns;
use crate::engine::run::queue::EventQueue;
use crate::engine::run::run_loop::drive;
use crate::engine::run::{Options, Outcome};
use crate::engine::step::integrator::{Integrator, Motion, motion};
use crate::engine::step::locate::Start;
use crate::engine::step::method::Method;
use crate::numerics::central_difference::CBRT_EPSILON;
use crate::time::Time;

mod bounds;
mod events;
mod segments;
mod steps;

/// The state at one of the sample times a run was asked for.
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    /// The sample time.
    pub t: f64,
    /// The mode then.
    pub mode: Mode,
    /// The state then (before an event at the same time).
    pub state: &'a [f64],
    /// Events logged before it.
    pub events: u64,
    /// The bound on every state component's error there: the bound the
    /// run carried to the start of the step the sample falls in, plus
    /// that step's own local error, or its dense output's error there
    /// where larger (a Runge-Kutta interpolant's, measured by re-taking
    /// the step to the sample); and, within an event's time error of it,
    /// that event's jump (the true state may be on the reset's other
    /// side).
    pub bound: f64,
}

/// Run `model` from state `x0` in `mode` at `t = 0`, reporting events to
/// `observer`.
pub fn simulate<M: HybridModel + ?Sized, O: Observer + ?Sized>(
    model: &M,
    mode: Mode,
    x0: &[f64],
    options: &Options,
    observer: &mut O,
) -> Outcome {
    simulate_sampled(model, mode, x0, options, &[], &mut |_| {}, observer)
}

/// [`simulate`], also calling `on_sample` with the state at each of
/// `samples` (times in increasing order, up to `t_end`), taken from the
/// flow as it goes: the run is not restarted there, so sampling changes
/// neither its steps nor its events.
pub fn simulate_sampled<M: HybridModel + ?Sized, O: Observer + ?Sized>(
    model: &M,
    mode: Mode,
    x0: &[f64],
    options: &Options,
    samples: &[f64],
    on_sample: &mut dyn FnMut(&Sample),
    observer: &mut O,
) -> Outcome {
    // The model is asked nothing about a state it cannot hold.
    let refused = if x0.len() != model.dimension() {
        Some(format!(
            "the initial state has {} components, the model {}",
            x0.len(),
            model.dimension()
        ))
    } else if !all_finite(x0) {
        Some(format!("the initial state {x0:?} is not finite"))
    } else {
        None
    };
    let x0 = if refused.is_some() {
        vec![0.0; model.dimension()]
    } else {
        x0.to_vec()
    };
    let energy_initial = model.energy(mode, &x0);
    let energy_scale = energy_initial.map_or(1.0, |e| model.energy_scale(e));
    let mut ledger = Ledger::new(options, energy_initial, energy_scale);
    if !model.resets_keep_energy() {
        ledger = ledger.rebase_at_resets();
    }
    let mut run = Run::new(model, mode, &x0, options, on_sample);
    run.sampled = !samples.is_empty();
    let end = match refused {
        Some(reason) => End::failed(reason),
        None => drive(&mut run, &mut ledger, samples, observer),
    };
    run.outcome(end, ledger)
}

/// An event, for the samples beside it: when it fired, how uncertain that
/// time is, and how far its reset moved the state.
#[derive(Debug, Clone, Copy)]
struct Beside {
    t: Time,
    time_error: f64,
    jump: f64,
}

struct Run<'m, 's, M: HybridModel + ?Sized> {
    model: &'m M,
    options: &'m Options,
    on_sample: &'s mut dyn FnMut(&Sample),
    mode: Mode,
    /// Time of the last event (or step end); `state` is the state then.
    origin: Time,
    state: Vec<f64>,
    queue: EventQueue,
    integrator: Integrator,
    /// How the current mode moves under the run's method.
    motion: Motion,
    /// The same for every mode met so far.
    motions: Vec<Option<Motion>>,
    /// Flow maps and crossing times asked of exact flows.
    exact_evaluations: u64,
    /// The errors so far, and the bounds the run will state.
    bound: Bound,
    /// When the integrator's current step ends, for stepped modes.
    step_end: Option<Time>,
    /// How far into the current step the origin is: zero where a step
    /// starts, more after a marker that let the step go on (see
    /// [`Run::go_on`]).
    step_offset: f64,
    /// What the dense output errs by at an event it placed (sharpening
    /// declined), for the segment that closes there.
    dense_gap: f64,
    /// A copy of a Runge-Kutta integrator to re-take steps on (see
    /// [`Run::flow_bound`]), made when first needed.
    spare: Option<Box<Integrator>>,
    /// Whether the run reports samples: then the last logged event is
    /// kept for the samples beside it.
    sampled: bool,
    last_event: Option<Beside>,
    /// Whether the integrator's last step starts at the current origin.
    stepped: bool,
    /// How each guard of the current mode starts the first step from the
    /// origin (see [`Run::arm`]), set at `t = 0`, after each event and
    /// after settling; `fresh` until a step has used it (later steps start
    /// armed).
    starts: Vec<Start>,
    fresh: bool,
    /// The guards predicted at the instant of the event being fired (a
    /// scratch list: simultaneous events).
    simultaneous: Vec<usize>,
    /// Scratch for a guard's gradient.
    gradient: Vec<f64>,
    /// The current step's error from a forcing's rounding (see
    /// [`Run::forcing_rounding`]).
    forcing_error: f64,
    /// Scratch of the state's length: a shifted state, and two rates.
    probe: Vec<f64>,
    rates: (Vec<f64>, Vec<f64>),
    /// How deep the dip of each guard's predicted crossing in the current
    /// step is (infinite where it does not curve back): what its time
    /// error grows by.
    depths: Vec<f64>,
    before: Vec<f64>,
    after: Vec<f64>,
    /// The model's clock component and its value at `t = 0`: the clock
    /// reads the run's time from there.
    clock: Option<(usize, f64)>,
    /// The last events and the states they left, to prove the orbit
    /// periodic.
    returns: Returns,
    /// Events logged so far (the round-off allowance's count, for the
    /// horizon between events).
    logged: u64,
    /// The guard whose graze the bound could not decide, when a segment
    /// failed for it: a pile-up of its events is a Zeno point.
    undecided_graze: Option<usize>,
}

impl<'m, 's, M: HybridModel + ?Sized> Run<'m, 's, M> {
    fn new(
        model: &'m M,
        mode: Mode,
        x0: &[f64],
        options: &'m Options,
        on_sample: &'s mut dyn FnMut(&Sample),
    ) -> Self {
        let n = model.dimension();
        Run {
            model,
            options,
            on_sample,
            mode,
            origin: Time::new(0.0),
            state: x0.to_vec(),
            queue: EventQueue::default(),
            integrator: {
                let mut integrator = Integrator::for_method(options.method, n, options.tolerances);
                integrator.bound_first(model.bounded_dimension());
                integrator
            },
            motion: Motion::Frozen,
            motions: Vec::new(),
            exact_evaluations: 0,
            bound: Bound::new(
                (n, model.bounded_dimension()),
                x0,
                model.clock(),
                // Only the closed forms round about their own scale.
                match options.method {
                    Method::Auto | Method::Exact => model.exact_flow_scale(),
                    _ => 0.0,
                },
                options.past_horizon,
            ),
            logged: 0,
            undecided_graze: None,
            stepped: false,
            step_end: None,
            step_offset: 0.0,
            dense_gap: 0.0,
            spare: None,
            sampled: false,
            last_event: None,
            starts: Vec::new(),
            fresh: false,
            simultaneous: Vec::new(),
            gradient: vec![0.0; n],
            depths: Vec::new(),
            forcing_error: 0.0,
            probe: vec![0.0; n],
            rates: (vec![0.0; n], vec![0.0; n]),
            before: vec![0.0; n],
            after: vec![0.0; n],
            clock: model.clock().map(|c| (c, x0[c])),
            returns: Returns::default(),
        }
    }

    /// Write the clock's reading at time `t` into `x`, where the model has
    /// a clock: its initial value plus `t`, rounded once from the run's
    /// double-double time.
    #[inline]
    fn set_clock(&self, t: Time, x: &mut [f64]) {
        if let Some((c, c0)) = self.clock {
            x[c] = t.after(c0).value();
        }
    }

    /// How `mode` moves under the run's method, decided once per mode.
    #[inline]
    fn motion_of(&mut self, mode: Mode) -> Result<Motion, End> {
        if let Some(Some(known)) = self.motions.get(mode) {
            return Ok(*known);
        }
        let decided = motion(self.model, mode, self.options.method).map_err(|why| {
            End::failed(format!(
                "method `{}` cannot run this model: {why}",
                self.options.method.name()
            ))
        })?;
        if self.motions.len() <= mode {
            self.motions.resize(mode + 1, None);
        }
        self.motions[mode] = Some(decided);
        Ok(decided)
    }

    /// The state `tau` after `origin`, by the current segment's flow.
    #[inline]
    fn state_at(&mut self, tau: f64, x: &mut [f64]) {
        match self.motion {
            Motion::Exact => {
                self.exact_evaluations += 1;
                self.model.advance(self.mode, &self.state, tau, x)
            }
            Motion::Stepped if self.stepped => self.integrator.eval(self.step_offset + tau, x),
            Motion::Stepped | Motion::Frozen => x.copy_from_slice(&self.state),
        }
    }

    fn outcome(self, end: End, ledger: Ledger) -> Outcome {
        let model = self.model;
        let last = Final {
            t_reached: self.origin,
            mode: self.mode,
            mode_name: model.mode_name(self.mode),
            state_names: model.state_names(self.mode),
            energy: model.energy(self.mode, &self.state),
            flow_evaluations: self.integrator.evaluations() + self.exact_evaluations,
            error_bound: self.bound.state_bound(ledger.events()),
            error_estimate: self.bound.uncarried_estimate(ledger.events()),
            event_time_bound: self.bound.event_time_bound(self.origin),
            horizon: self.bound.horizon(),
            state: self.state,
        };
        ledger.outcome(end, last, |mode, slot| {
            model.guards(mode)[slot].name.clone()
        })
    }
}

/// The largest component of `x` but the clock, and at least one: the
/// scale differences and rounding are measured against.
#[inline]
fn size_of(x: &[f64], clock: Option<usize>) -> f64 {
    x.iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != clock)
        .fold(1.0_f64, |m, (_, v)| m.max(v.abs()))
}

/// The rate of `guard` along the flow `rate` at `x`, by a central
/// difference along the flow (errors about 1e-10 relative), its step a
/// cube root of eps of the state's size (the clock's aside) over the
/// speed; `probe` is scratch of the state's length.
fn guard_rate(
    guard: impl Fn(&[f64]) -> f64,
    x: &[f64],
    rate: &[f64],
    clock: Option<usize>,
    probe: &mut [f64],
) -> f64 {
    let speed = rate.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    if speed == 0.0 || !speed.is_finite() {
        return 0.0;
    }
    let h = CBRT_EPSILON * size_of(x, clock) / speed;
    let mut at = |sign: f64| {
        for ((p, a), r) in probe.iter_mut().zip(x).zip(rate) {
            *p = a + sign * h * r;
        }
        guard(probe)
    };
    (at(1.0) - at(-1.0)) / (2.0 * h)
}

#[inline]
fn all_finite(x: &[f64]) -> bool {
    x.iter().all(|v| v.is_finite())
}
