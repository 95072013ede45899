//! The error bound a run states, kept as the run goes: the numerical
//! steps' local errors carried along each stretch of flow and across each
//! event ([`ErrorSet`], [`Tangents`]), each event's time error, and the
//! round-off allowance of exact flows.
//!
//! What it promises, and when it stops a run:
//! - `error_bound` bounds every state component at the end, and
//!   `event_time_bound` every event time: an error `d` moves an event by
//!   `d / closing speed`, and the saltation matrix says what that does to
//!   the state after the reset.
//! - An event whose time the error leaves uncertain by half the interval
//!   since the previous event, one at zero closing speed, or an event
//!   within its time error of `t_end`, means the events' order, count or
//!   final state can no longer be told: the run stops and says why.
//! - Events closer than the run can resolve are the Zeno watch's to judge,
//!   not the bound's.
//! - Exact flows add no error: their bound is a round-off allowance of
//!   [`ROUNDOFF_ULPS`] ulps per event of the state's size, or of the
//!   model's rounding scale where larger (a closed form about a centre;
//!   an estimate of how round-off grows, not a bound), and of each event's
//!   time, where a slow crossing turns the state's rounding into a larger
//!   time error (its size over the closing speed); an exact run pays for
//!   nothing else.

use crate::engine::bound::commuting::{Firing, Recent};
use crate::engine::bound::error_set::{CARRIED, ErrorSet, ROUNDOFF_ULPS};
use crate::engine::bound::horizon::{FRACTION, Horizon};
use crate::engine::bound::period_record::{EventFacts, HEADROOM, Op, PeriodRecord};
use crate::engine::bound::tangent::{Rates, Tangents};
use crate::engine::bound::zeno;
use crate::engine::model::{HybridModel, Mode};
use crate::time::{Span, Time};

/// What stands in for an error bound where none is carried: a number
/// that is not a bound, and how it was made.
#[derive(Debug, Clone, PartialEq)]
pub struct ErrorEstimate {
    /// The estimated largest error of any state component at the end.
    pub value: f64,
    /// How the estimate was made, in words (the summary's
    /// `error_estimate_by`).
    pub made_by: String,
}

/// A run's errors so far and the bounds it will state.
#[derive(Debug, Clone)]
pub(crate) struct Bound {
    errors: ErrorSet,
    tangents: Tangents,
    /// Scratch: a tangent or saltation matrix, and a guard's gradient.
    matrix: Vec<f64>,
    gradient: Vec<f64>,
    /// Gradients of a mode's affine guards, computed once per mode.
    affine_gradients: (Option<Mode>, Vec<f64>),
    /// The same, summed in size, where errors are not tracked.
    affine_sums: (Option<Mode>, Vec<f64>),
    /// The largest event-time error so far, the last event's, and when the
    /// last logged event fired.
    event_time_bound: f64,
    last_time_bound: f64,
    last_event: Option<Time>,
    /// The largest state component the bound is about seen (initial state
    /// and events): the round-off allowance's scale.
    state_scale: f64,
    /// How many leading components the bound is about.
    bounded: usize,
    /// The largest such component seen at any step's end or event: the
    /// horizon's scale.
    horizon_scale: f64,
    /// Scratch: the rate of the state at an event.
    rate: Vec<f64>,
    /// The clock component, which carries no error.
    clock: Option<usize>,
    /// The largest time error the rounding of an exact flow's state makes
    /// at an event, over its closing speed (a slow crossing's time is
    /// uncertain by far more ulps than its state).
    crossing_rounding: f64,
    /// The operations of the last period, for a jump over whole periods.
    record: PeriodRecord,
    /// The last events, to tell whether one whose order is in doubt
    /// commutes with them.
    recent: Recent,
    /// Where the run's horizon is, and whether it went past it (then no
    /// error is carried).
    horizon: Horizon,
}

/// How far errors `along` a guard's gradient move its event in time, at
/// closing speed `closing`: a guard that curves back after crossing (its dip
/// `depth` deep) moves by more than `along / closing` towards its turning
/// point: on the parabola through the crossing, by up to twice that as the
/// error nears the depth (beyond it the crossing may vanish, which the graze
/// check refuses).
fn time_shift(along: f64, closing: f64, depth: f64) -> f64 {
    let ratio = (along / depth).min(1.0);
    along / closing.abs() * 2.0 / (1.0 + (1.0 - ratio).sqrt())
}

/// A step's `local` error along `gradient`: the graze check's uncertainty
/// beside the carried errors'.
fn spread(gradient: &[f64], local: f64) -> f64 {
    gradient.iter().map(|d| d.abs()).sum::<f64>() * local
}

/// One recorded period's operations on `errors`, moving `times` (the
/// largest event-time error, the last event's); false where a check fails.
fn replay_period(ops: &[Op<'_>], errors: &mut ErrorSet, (largest, last): &mut (f64, f64)) -> bool {
    ops.iter().all(|&op| match op {
        Op::Step { matrix, local } => {
            errors.map(matrix, local);
            true
        }
        Op::Margin {
            gradient,
            local,
            limit,
        } => errors.within(gradient, spread(gradient, local), limit),
        Op::Event {
            gradient,
            saltation,
            facts:
                EventFacts {
                    closing,
                    depth,
                    widen,
                    since,
                    timed,
                },
        } => {
            let shift = time_shift(errors.along(gradient), closing, depth);
            if timed {
                *last = shift;
                *largest = largest.max(shift);
            }
            if !shift.is_finite() || (timed && shift > 0.5 * since) {
                return false;
            }
            // As the event itself did (see `Bound::across`).
            if widen != 0.0 || !is_identity(saltation, gradient.len()) {
                errors.map(saltation, widen);
            }
            true
        }
    })
}

/// Whether the graze checks that open a recorded period (its first step's,
/// taken before a jump) hold with `errors`.
fn opening_checks_hold(ops: &[Op<'_>], errors: &ErrorSet) -> bool {
    ops.iter()
        .map_while(|&op| match op {
            Op::Margin {
                gradient,
                local,
                limit,
            } => Some(errors.within(gradient, spread(gradient, local), limit)),
            _ => None,
        })
        .all(|holds| holds)
}

impl Bound {
    /// No error yet, for a run of dimension `n` from `x0` whose bound is
    /// about its first `bounded` components
    /// ([`HybridModel::bounded_dimension`]), whose component `clock` (if
    /// any) is the run's time, which carries no error, and whose flows
    /// round to ulps of `rounding` at least
    /// ([`HybridModel::exact_flow_scale`]); `past_horizon`: a run that goes
    /// on past its horizon (see [`Horizon`]).
    pub fn new(
        (n, bounded): (usize, usize),
        x0: &[f64],
        clock: Option<usize>,
        rounding: f64,
        past_horizon: bool,
    ) -> Self {
        let bounded = bounded.min(n);
        Bound {
            errors: ErrorSet::new(n).holding(bounded, clock),
            tangents: Tangents::new(n),
            matrix: vec![0.0; if n <= CARRIED { n * n } else { 0 }],
            gradient: vec![0.0; n],
            affine_gradients: (None, Vec::new()),
            affine_sums: (None, Vec::new()),
            event_time_bound: 0.0,
            last_time_bound: 0.0,
            last_event: None,
            state_scale: x0[..bounded]
                .iter()
                .enumerate()
                .filter(|(i, _)| Some(*i) != clock)
                .fold(rounding.abs(), |m: f64, (_, v)| m.max(v.abs())),
            clock,
            bounded,
            horizon_scale: 0.0,
            rate: vec![0.0; n],
            crossing_rounding: 0.0,
            record: PeriodRecord::default(),
            recent: Recent::default(),
            horizon: Horizon::new(past_horizon),
        }
    }

    /// Whether there is no error to carry (an exact run's stays so, and a
    /// run's past its horizon).
    #[inline(always)]
    pub fn idle(&self) -> bool {
        self.errors.is_empty() || self.horizon.shadow()
    }

    /// Carry the errors over a stretch `tau` of an ODE flow in `mode` whose
    /// states `at(s)` the step's dense output gives, adding `local`; the
    /// flow at the stretch's two ends where the step knows it.
    pub fn after_step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        (tau, local): (f64, f64),
        at: impl FnMut(f64, &mut [f64]),
        rates: Rates<'_>,
    ) {
        if self.horizon.shadow() {
            return;
        }
        if self.errors.tracked() {
            self.tangents
                .ode(model, mode, (tau, rates), at, &mut self.matrix);
            self.record.step(&self.matrix, local);
        } else {
            self.record.broken();
        }
        self.errors.map(&self.matrix, local);
    }

    /// Carry the errors over `tau` of `mode`'s exact flow from `state`.
    pub fn after_exact<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        state: &[f64],
        tau: f64,
    ) {
        if self.errors.tracked() && !self.idle() {
            self.tangents
                .exact(model, mode, state, tau, &mut self.matrix);
            self.errors.map(&self.matrix, 0.0);
            self.record.broken();
        }
    }

    /// Add an error of half-width `jump` where the state stands: a resting
    /// state stands in for an orbit it is not exactly on.
    pub fn widen(&mut self, jump: f64) {
        if self.horizon.shadow() {
            return;
        }
        self.errors.widen(jump);
        self.record.broken();
    }

    /// How far guard `g` of `mode` may be off at `state`: the errors so far
    /// and a step's `local` error, along the guard's gradient (the graze
    /// check's margin).
    pub fn guard_uncertainty<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        g: usize,
        state: &[f64],
        local: f64,
    ) -> f64 {
        // Past its horizon a run goes as it computes.
        if self.horizon.shadow() {
            return 0.0;
        }
        if !self.errors.tracked() && model.guards(mode)[g].affine {
            // An untracked set has one scale for every direction: what an
            // affine guard needs of its gradient is the sum of its sizes,
            // kept per guard (a long chain's gradients would cost O(N) per
            // guard per step).
            let sum = self.affine_sum(model, mode, g, state);
            let unit = [1.0];
            self.record.broken();
            return sum * (self.errors.along(&unit) + local);
        }
        self.gradient_of(model, mode, g, state);
        self.record.margin(&self.gradient, local);
        self.errors.along(&self.gradient) + spread(&self.gradient, local)
    }

    /// How far in time the crossing of guard `g` of `mode` near `state`
    /// may be off: the errors so far and a step's `local` error along its
    /// gradient, over its rate there (for a sample beside the event; the
    /// period record is not touched). Zero where no error is carried.
    pub fn crossing_uncertainty<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        g: usize,
        state: &[f64],
        local: f64,
    ) -> f64 {
        if self.idle() || !self.errors.tracked() {
            return 0.0;
        }
        self.gradient_of(model, mode, g, state);
        let along = self.errors.along(&self.gradient) + spread(&self.gradient, local);
        if along == 0.0 {
            return 0.0;
        }
        self.tangents.rate(model, mode, state, &mut self.rate);
        let closing: f64 = (self.gradient.iter().zip(&self.rate))
            .map(|(g, f)| g * f)
            .sum();
        along / closing.abs()
    }

    /// `sum |d g / d x_i|` of affine guard `g` of `mode`, once per mode.
    fn affine_sum<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        g: usize,
        state: &[f64],
    ) -> f64 {
        if self.affine_sums.0 != Some(mode) {
            let sums = (0..model.guards(mode).len())
                .map(|g| {
                    self.tangents
                        .gradient(model, mode, g, state, &mut self.gradient);
                    self.gradient.iter().map(|d| d.abs()).sum()
                })
                .collect();
            self.affine_sums = (Some(mode), sums);
        }
        self.affine_sums.1[g]
    }

    /// The gradient of guard `g` of `mode` at `state`, into
    /// `self.gradient`: once per mode for affine guards.
    #[inline]
    fn gradient_of<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        g: usize,
        state: &[f64],
    ) {
        let n = state.len();
        if !model.guards(mode)[g].affine {
            self.tangents
                .gradient(model, mode, g, state, &mut self.gradient);
            return;
        }
        if self.affine_gradients.0 != Some(mode) {
            let guards = model.guards(mode).len();
            let mut all = vec![0.0; guards * n];
            for (g, row) in all.chunks_mut(n).enumerate() {
                self.tangents.gradient(model, mode, g, state, row);
            }
            self.affine_gradients = (Some(mode), all);
        }
        self.gradient
            .copy_from_slice(&self.affine_gradients.1[g * n..(g + 1) * n]);
    }

    /// Note an event's state before its reset, for the round-off
    /// allowance's scale (a plain loop: this runs at every event of an
    /// exact run too).
    #[inline(always)]
    pub fn note_state(&mut self, before: &[f64]) {
        for (i, x) in before[..self.bounded].iter().enumerate() {
            let size = x.abs();
            if size > self.state_scale && Some(i) != self.clock {
                self.state_scale = size;
            }
        }
    }

    /// Note how far rounding moves the time of an exact flow's event of
    /// guard `slot` at `before`: [`ROUNDOFF_ULPS`] ulps of the sizes its
    /// guard sums, over its closing speed.
    #[inline]
    pub fn note_crossing<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        slot: usize,
        before: &[f64],
    ) {
        if model.guards(mode)[slot].internal || !self.errors.tracked() {
            return;
        }
        self.gradient_of(model, mode, slot, before);
        let sizes: f64 = self
            .gradient
            .iter()
            .zip(before)
            .map(|(g, x)| (g * x).abs())
            .sum();
        // A guard whose terms all vanish there (a gap closing to zero)
        // rounds to nothing, whatever its speed.
        if sizes == 0.0 {
            return;
        }
        self.tangents.rate(model, mode, before, &mut self.rate);
        let closing: f64 = self
            .gradient
            .iter()
            .zip(&self.rate)
            .map(|(g, f)| g * f)
            .sum();
        let shift = ROUNDOFF_ULPS * f64::EPSILON * sizes / closing.abs();
        if shift.is_finite() && shift > self.crossing_rounding {
            self.crossing_rounding = shift;
        }
    }

    /// Carry the errors across the event of guard `slot` of `mode` at `t`,
    /// from `before` to `after` in `mode_after`, by its saltation matrix,
    /// and bound the event's time (the crossing's dip is `depth` deep,
    /// infinite for a guard that does not curve back); why the run cannot
    /// go on, if it cannot (`method` names the method in the reason).
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    pub fn across<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        slot: usize,
        t: Time,
        (before, after): (&[f64], &[f64]),
        mode_after: Mode,
        (t_end, depth): (f64, f64),
        method: &str,
    ) -> Result<(), String> {
        if self.idle() || !self.errors.tracked() {
            self.record.broken();
            return Ok(());
        }
        let guard = &model.guards(mode)[slot];
        self.gradient_of(model, mode, slot, before);
        let along = self.errors.along(&self.gradient);
        let (closing, jump) = self.tangents.saltation(
            model,
            mode,
            slot,
            before,
            &self.gradient,
            mode_after,
            after,
            &mut self.matrix,
        );
        let shift = time_shift(along, closing, depth);
        let since = self.last_event.map(|last| t.since(last));
        // Events closer than the run can resolve are the Zeno watch's to
        // judge (it settles them or stops), not the error bound's: their
        // order and any state at them are equally unresolvable.
        if since.is_some_and(|since| since <= zeno::resolution(t.value(), t_end)) {
            if self.matrix.iter().all(|m| m.is_finite()) {
                self.errors.map(&self.matrix, 0.0);
            }
            self.record.broken();
            return Ok(());
        }
        if !guard.internal {
            self.last_event = Some(t);
            self.last_time_bound = shift;
            self.event_time_bound = self.event_time_bound.max(shift);
        }
        let firing = Firing {
            t,
            mode,
            guard: slot,
            before,
            mode_after,
        };
        // An order in doubt matters only where the events do not commute:
        // the time that counts is the time since the last one that may not.
        let doubt = |since: f64| shift > 0.5 * since;
        let since = match since {
            Some(since) if !guard.internal && doubt(since) => {
                Some(
                    self.recent
                        .since_conflict(model, &mut self.tangents, &firing, doubt),
                )
            }
            since => since,
        };
        if !shift.is_finite() {
            self.record.broken();
            return self.horizon.undecided(t, format!(
                "the `{}` event at t = {} comes at zero closing speed (a graze) with an integration \
                 error of {along:.2e} in its guard: whether and when it fires cannot be told, so {method} \
                 cannot be trusted past here; tighten the method or use an exact one",
                guard.name,
                t.value(),
            ));
        }
        if let Some(since) = since.filter(|&since| !guard.internal && doubt(since)) {
            self.record.broken();
            // The event fires all the same where its pile-up is a Zeno
            // point the run settles: its saltation is carried.
            if self.matrix.iter().all(|m| m.is_finite()) {
                self.errors.map(&self.matrix, 0.0);
            }
            return self.horizon.undecided(t, format!(
                "the `{}` event at t = {} may be off by {shift:.2e} in time (its guard by {along:.2e}, \
                 closing at {:.2e}), more than half the {since:.3e} since an earlier event whose \
                 order with it matters: the integration error so far ({:.2e} in the state) leaves the \
                 events' order and count uncertain, so {method} cannot be trusted past here; tighten \
                 the method or use an exact one",
                guard.name,
                t.value(),
                closing.abs(),
                self.errors.state_bound().unwrap_or(f64::NAN),
            ));
        }
        // Where the event was located, the guard is not exactly zero: the
        // reset came that residual's time early or late (rounding at
        // least), which leaves `f+ - R f-` times it in the state.
        let widen = if jump == 0.0 {
            0.0
        } else {
            let residual = model.guard(mode, slot, before).abs()
                + f64::EPSILON
                    * (self.gradient.iter().zip(before))
                        .map(|(g, x)| (g * x).abs())
                        .sum::<f64>();
            jump * residual / closing.abs()
        };
        // An identity saltation (a passage's; a reset that changes nothing
        // there) maps nothing.
        if widen != 0.0 || !is_identity(&self.matrix, self.gradient.len()) {
            self.errors.map(&self.matrix, widen);
        }
        if !guard.internal {
            self.recent.push(&firing);
        }
        let facts = EventFacts {
            closing,
            depth,
            widen,
            since: since.unwrap_or(f64::INFINITY),
            timed: !guard.internal,
        };
        self.record.event((&self.gradient, &self.matrix), facts);
        Ok(())
    }

    /// Record each period's operations from now on, for
    /// [`Bound::replay`]; false where the errors are not tracked (nothing
    /// to replay them on).
    pub fn record_periods(&mut self) -> bool {
        let tracked = self.errors.tracked();
        if tracked {
            self.record.start(self.gradient.len());
        }
        tracked
    }

    /// Something in the stretch since the last event depends on more than
    /// the state the stretch started from: no replay may repeat it.
    pub fn unrepeatable(&mut self) {
        self.record.broken();
    }

    /// The uncertainty a step's scan is to prove a guard clear of, for the
    /// graze check's `uncertainty`: more while periods are recorded (see
    /// [`HEADROOM`]).
    pub fn scan_uncertainty(&self, uncertainty: f64) -> f64 {
        if self.record.on() {
            uncertainty * HEADROOM
        } else {
            uncertainty
        }
    }

    /// The scan of the last graze check found no margin below `margin`
    /// (see [`Bound::scan_uncertainty`]), or could not say.
    pub fn margin_found(&mut self, margin: Option<f64>) {
        match margin {
            Some(margin) => self.record.margin_limit(margin),
            None => self.record.broken(),
        }
    }

    /// Carry the errors over up to `periods` more periods of `events`
    /// events each, as the last recorded period did, checks included (see
    /// [`crate::engine::bound::period_record`]); stop short of the first period
    /// whose checks would fail, or after which the next one's first graze
    /// checks would. How many periods were carried.
    pub fn replay(&mut self, periods: u64, events: usize) -> u64 {
        let done = self.replayed(periods, events);
        if done > 0 {
            // The period under way was checked against the errors before
            // the jump.
            self.record.broken();
        }
        done
    }

    /// [`Bound::replay`] without its closing note.
    fn replayed(&mut self, periods: u64, events: usize) -> u64 {
        let Some(ops) = self.record.last(events) else {
            return 0;
        };
        let ops: Vec<Op> = ops.collect();
        let mut done = 0;
        while done < periods {
            let saved = (
                self.errors.clone(),
                self.event_time_bound,
                self.last_time_bound,
            );
            let mut times = (saved.1, saved.2);
            if !replay_period(&ops, &mut self.errors, &mut times)
                || !opening_checks_hold(&ops, &self.errors)
            {
                (self.errors, self.event_time_bound, self.last_time_bound) = saved;
                break;
            }
            (self.event_time_bound, self.last_time_bound) = times;
            done += 1;
        }
        done
    }

    /// The run jumped over `periods` periods of `tau` (see
    /// [`periodic`](crate::engine::run::periodic)): its last event moves with it.
    pub fn postpone(&mut self, periods: u64, tau: Span) {
        self.last_event = self.last_event.map(|t| t.after_multiple(periods, tau));
        // The events kept to check commuting against are a jump behind:
        // none may excuse an order in doubt past it.
        if let Some(last) = self.last_event {
            self.recent.restart(last);
        }
    }

    /// The time error of the last event.
    pub fn last_time_bound(&self) -> f64 {
        self.last_time_bound
    }

    /// Whether the run may end at `t`, with its next event predicted at
    /// `next`, whose time is uncertain by the second number: an event within
    /// its time error of the end may or may not belong to the run, and then
    /// its count and final state are uncertain. One within `window` of the
    /// end (the rounding of times there) is at the end by the run's
    /// convention (applied), not uncertain.
    pub fn at_end(
        &mut self,
        t: Time,
        next: Option<(Time, f64)>,
        window: f64,
    ) -> Result<(), String> {
        if self.horizon.shadow() {
            return Ok(());
        }
        let around = [
            self.last_event
                .map(|last| (t.since(last), self.last_time_bound)),
            next.map(|(next, error)| (next.since(t), error)),
        ];
        match around
            .into_iter()
            .flatten()
            .find(|&(gap, error)| error > 0.0 && gap > window && gap <= error)
        {
            Some((gap, error)) => self.horizon.undecided(
                t,
                format!(
                    "an event lies {gap:.2e} from t_end = {}, within the time error of the events \
                 ({error:.2e}): whether it happens before the end is uncertain, so the final state \
                 cannot be trusted; tighten the method or move t_end",
                    t.value(),
                ),
            ),
            None => Ok(()),
        }
    }

    /// The bound on every state component after `events` events; `None`
    /// where the errors are not carried (see [`Bound::uncarried_estimate`]).
    pub fn state_bound(&self, events: u64) -> Option<f64> {
        if self.horizon.shadow() {
            return None;
        }
        (self.errors.state_bound()).map(|carried| carried + self.roundoff(events))
    }

    /// Note the state at `t`, after `events` events (a step's end, an
    /// event's reset): the horizon is where the error first reaches
    /// [`FRACTION`] of the largest state component seen. Asked at every
    /// step: the cheap questions first.
    #[inline]
    pub fn watch(&mut self, t: Time, state: &[f64], events: u64) {
        if self.horizon.at().is_some() || !self.beyond(events) {
            return;
        }
        // Near it: the scale is the largest state seen (a larger one only
        // moves the limit up), this one's included.
        for (i, x) in state[..self.bounded].iter().enumerate() {
            if x.abs() > self.horizon_scale && Some(i) != self.clock {
                self.horizon_scale = x.abs();
            }
        }
        if self.beyond(events) && self.horizon_scale.max(self.state_scale) > 0.0 {
            self.horizon.reached(t);
        }
    }

    /// Whether the errors after `events` events may exceed [`FRACTION`] of
    /// the largest state seen so far.
    #[inline(always)]
    fn beyond(&self, events: u64) -> bool {
        let limit = FRACTION * self.horizon_scale.max(self.state_scale) - self.roundoff(events);
        if self.errors.is_empty() {
            // Round-off alone: after about 10^11 events.
            limit <= 0.0
        } else {
            self.errors.exceeds(limit)
        }
    }

    /// Where the run's horizon is, if it reached it.
    pub fn horizon(&self) -> Option<f64> {
        self.horizon.at().map(Time::value)
    }

    /// Whether the run has gone past its horizon (its events are shadows).
    pub fn past_horizon(&self) -> bool {
        self.horizon.shadow()
    }

    /// A graze the bound cannot decide at `t`, for the reason `why`: the
    /// run's horizon (see [`Horizon::undecided`]).
    pub fn undecided(&mut self, t: Time, why: String) -> Result<(), String> {
        self.record.broken();
        self.horizon.undecided(t, why)
    }

    /// What stands in for the bound where the errors are not carried: the
    /// local errors summed, not amplified by the flow or the events;
    /// `None` where a bound is.
    pub fn uncarried_estimate(&self, events: u64) -> Option<ErrorEstimate> {
        (!self.errors.tracked() && !self.horizon.shadow()).then(|| ErrorEstimate {
            value: self.errors.estimate() + self.roundoff(events),
            made_by: format!(
                "the steps' local errors summed, not carried through the flow or across events \
                 (errors are carried up to {CARRIED} state components)"
            ),
        })
    }

    /// The round-off allowance after `events` events.
    fn roundoff(&self, events: u64) -> f64 {
        ROUNDOFF_ULPS * f64::EPSILON * self.state_scale * (1 + events) as f64
    }

    /// The bound on every event time of a run that reached `t`; `None`
    /// where the errors are not tracked.
    pub fn event_time_bound(&self, t: Time) -> Option<f64> {
        (self.errors.tracked() && !self.horizon.shadow()).then(|| {
            self.event_time_bound
                + self.crossing_rounding
                + ROUNDOFF_ULPS * f64::EPSILON * t.value().abs()
        })
    }
}

/// Whether the row-major `n x n` matrix `m` is exactly the identity.
fn is_identity(m: &[f64], n: usize) -> bool {
    n > 0
        && m.len() == n * n
        && (m.chunks_exact(n).enumerate())
            .all(|(i, row)| (row.iter().enumerate()).all(|(j, &x)| x == f64::from(i == j)))
}

#[cfg(test)]
mod tests {
    use super::is_identity;

    #[test]
    fn only_the_identity_is_the_identity() {
        assert!(is_identity(&[1.0, 0.0, -0.0, 1.0], 2));
        assert!(is_identity(&[1.0], 1));
        // A saltation that moves anything at all is mapped.
        assert!(!is_identity(&[1.0, 1e-300, 0.0, 1.0], 2));
        assert!(!is_identity(&[1.0, 0.0, 0.0, -1.0], 2));
        assert!(!is_identity(&[1.0, 0.0, 0.0, f64::NAN], 2));
        // No matrix, or one of the wrong size, is not the identity.
        assert!(!is_identity(&[], 0));
        assert!(!is_identity(&[1.0, 0.0, 0.0], 2));
    }
}
