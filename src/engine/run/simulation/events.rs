//! Events: placing a crossing (sharpened on a re-taken step), the record
//! of one, settling at a Zeno point, sliding after a mode change, a step
//! that goes on past a marker, and predicting each guard's next crossing.

use super::{Run, guard_rate, size_of};
use crate::engine::bound::tangent::guard_gradient;
use crate::engine::model::labels::Labels;
use crate::engine::model::{Direction, HybridModel, Jump, Mode};
use crate::engine::run::ledger::End;
use crate::engine::run::ledger::Ledger;
use crate::engine::run::observer::{EventRecord, Observer, SETTLE};
use crate::engine::run::run_loop::end_window;
use crate::engine::step::crossing::{Crossing, Sharpened};
use crate::engine::step::integrator::Motion;
use crate::engine::step::locate::Start;
use crate::time::Time;

impl<M: HybridModel + ?Sized> Run<'_, '_, M> {
    /// The crossing of guard `slot` at `t` (state `x`, from the dense
    /// output) sharpened where the integrator can (see
    /// [`Integrator::sharpen`]); the correction stays within a thousandth of
    /// the step and before the next queued event, so the order of events
    /// is kept. A re-fire at the segment's start is left alone: its state
    /// is the segment's own.
    #[inline]
    pub(super) fn sharpen(&mut self, slot: usize, t: Time, x: &mut [f64]) -> Time {
        let tau = t.since(self.origin);
        // An event due at t_end is fired there (see run_loop.rs).
        if !(self.motion == Motion::Stepped && self.stepped)
            || tau == 0.0
            || t.value() >= self.options.t_end
        {
            return t;
        }
        let (model, mode) = (self.model, self.mode);
        let h = self.integrator.h();
        let next = self
            .queue
            .peek()
            .map_or(h - self.step_offset, |(_, later)| later.since(self.origin));
        let reach = (1e-3 * h).min(next - tau);
        let guard = |y: &[f64]| model.guard(mode, slot, y);
        let direction = model.guards(mode)[slot].direction;
        // For a guard of either direction, the side it came from: a little
        // before the crossing on the dense output.
        let before = if direction == Direction::Either {
            let mut y = std::mem::take(&mut self.after);
            self.integrator
                .eval(self.step_offset + (tau - 1e-4 * h).max(0.0), &mut y);
            let g = guard(&y);
            self.after = y;
            if g == 0.0 {
                return t;
            }
            g
        } else {
            0.0
        };
        let crossed = |v: f64| match direction {
            Direction::Falling => v <= 0.0,
            Direction::Rising => v >= 0.0,
            Direction::Either => v == 0.0 || v.signum() != before.signum(),
        };
        let mut sharp = std::mem::take(&mut self.after);
        let crossing = Crossing {
            tau: self.step_offset + tau,
            reach,
            room: next - tau,
            guard: &guard,
            crossed: &crossed,
            slot,
        };
        let correction = self
            .integrator
            .sharpen(model, mode, &self.state, &crossing, &mut sharp);
        let t = match correction {
            Sharpened::Moved(s) => {
                x.copy_from_slice(&sharp);
                t.after(s)
            }
            // A re-step that blew up where the accepted step did not says
            // nothing of the dense output.
            Sharpened::Kept(off) => {
                self.dense_gap = if off.is_finite() { off } else { 0.0 };
                t
            }
        };
        self.after = sharp;
        t
    }

    /// The event of guard `name` at `t`, from `before` in the current mode
    /// to `self.after` in `mode_after`, with the model's energies.
    #[inline]
    pub(super) fn event<'a>(
        &'a self,
        name: &'a str,
        t: Time,
        mode_after: Mode,
        before: &'a [f64],
        labels: &'a Labels,
    ) -> EventRecord<'a> {
        let (model, mode) = (self.model, self.mode);
        EventRecord {
            seq: 0,
            t: t.value(),
            guard: name,
            mode_before: model.mode_name(mode),
            mode_after: model.mode_name(mode_after),
            from: mode,
            to: mode_after,
            energy_before: model.energy(mode, before),
            energy_after: model.energy(mode_after, &self.after),
            names_before: model.state_names(mode),
            before,
            names_after: model.state_names(mode_after),
            after: &self.after,
            labels,
            shadow: self.bound.past_horizon(),
        }
    }

    /// Events came faster than the run can resolve (`what`): let the model
    /// settle into resting contact, or stop.
    #[inline]
    pub(super) fn settle<O: Observer + ?Sized>(
        &mut self,
        what: String,
        t: Time,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End> {
        self.after.copy_from_slice(&self.state);
        self.returns.forget();
        let Some(rest) = self.model.settle(self.mode, &mut self.after) else {
            return Err(Ledger::unsettled(&what));
        };
        let before = std::mem::take(&mut self.state);
        // The resting state stands in for an orbit it is not exactly on:
        // the jump to it is an error the run carries on.
        let jump = before
            .iter()
            .zip(&self.after)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        self.bound.widen(jump);
        let into = format!("`{}`", self.model.mode_name(rest));
        let event = self.event(SETTLE, t, rest, &before, &Labels::NONE);
        let recorded = ledger.settled(what, &into, event, observer);
        self.logged = ledger.events();
        self.state = before;
        recorded?;
        std::mem::swap(&mut self.state, &mut self.after);
        self.mode = rest;
        self.integrator.restart();
        self.arm(None);
        self.start_segment()
    }

    /// After guard `slot` of mode `from` took the run across its surface
    /// into the current mode at `t` (the state before in `self.before`,
    /// after in `self.state`): why the run cannot go on if the new mode's
    /// flow points straight back through that surface and one of its own
    /// guards, on the surface, fires at once. Both sides then point into
    /// the surface: the solution slides along it (Filippov), which no
    /// sequence of mode changes follows; going on would chatter between
    /// the modes or, where the located crossings leave the state a
    /// rounding to the other side, drift off the surface quietly. (Modes
    /// of a hysteresis, whose guards lie apart, are not caught: the new
    /// mode's guards are off the surface.)
    #[inline]
    pub(super) fn slides(&mut self, from: Mode, slot: usize, t: Time) -> Result<(), String> {
        let (model, to) = (self.model, self.mode);
        if !(model.has_rhs(from) && model.has_rhs(to)) {
            return Ok(());
        }
        let clock = self.clock.map(|(c, _)| c);
        let (mut f_from, mut f_to) = std::mem::take(&mut self.rates);
        let mut probe = std::mem::take(&mut self.probe);
        model.rhs(from, &self.before, &mut f_from);
        model.rhs(to, &self.state, &mut f_to);
        let surface = |x: &[f64]| model.guard(from, slot, x);
        let came = guard_rate(surface, &self.before, &f_from, clock, &mut probe);
        let back = guard_rate(surface, &self.state, &f_to, clock, &mut probe);
        let size = size_of(&self.state, clock);
        let at_once = (came * back < 0.0 && back.abs() > 1e-8 * came.abs())
            .then(|| {
                model.guards(to).iter().enumerate().find(|(h, guard)| {
                    let value = model.guard(to, *h, &self.state);
                    let rate = guard_rate(
                        |x| model.guard(to, *h, x),
                        &self.state,
                        &f_to,
                        clock,
                        &mut probe,
                    );
                    // On the surface: as near zero as the crossing was
                    // located, or within rounding of the state (a guard
                    // scaled otherwise).
                    let near =
                        value.abs() <= surface(&self.before).abs().max(64.0 * f64::EPSILON * size);
                    near && match guard.direction {
                        Direction::Falling => rate < 0.0,
                        Direction::Rising => rate > 0.0,
                        Direction::Either => rate != 0.0,
                    }
                })
            })
            .flatten();
        self.rates = (f_from, f_to);
        self.probe = probe;
        match at_once {
            None => Ok(()),
            Some((_, guard)) => Err(format!(
                "sliding at t = {}: the `{}` event took mode `{}` into `{}`, whose flow points straight \
                 back through the same surface, where its guard `{}` fires at once: both sides point \
                 into the surface, so the solution slides along it (Filippov) and no sequence of mode \
                 changes follows it. Model the sliding: a mode whose flow keeps the surface (the \
                 convex combination of the two flows tangent to it), left where one side's flow turns \
                 away",
                t.value(),
                model.guards(from)[slot].name,
                model.mode_name(from),
                model.mode_name(to),
                guard.name
            )),
        }
    }

    /// After marker `slot` fired at `t`, `into_step` into the current step,
    /// let the step go on instead of starting a new one, where that changes
    /// nothing but the cost: a marker of a stepped flow that left the state
    /// and mode as they were, with no other guard due at its instant, well
    /// inside the step, on a method that can search the rest of the step
    /// (Taylor's: the guard's series re-expanded there). The other guards'
    /// predictions on the step stand; the marker's own is searched anew
    /// from where it fired. Whether it went on; where its search comes
    /// within the errors of a graze, it does not (a new step decides).
    #[inline]
    pub(super) fn go_on(
        &mut self,
        mode: Mode,
        slot: usize,
        jump: &Jump,
        t: Time,
        into_step: f64,
    ) -> Result<bool, End> {
        let model = self.model;
        let guard = &model.guards(mode)[slot];
        let h = self.integrator.h();
        let unchanged =
            (self.state.iter().zip(&self.before)).all(|(a, b)| a.to_bits() == b.to_bits());
        let inside = self.step_end.is_some_and(|end| t < end)
            && h - into_step > 64.0 * f64::EPSILON * t.value().abs().max(h)
            && t.value() < self.options.t_end;
        if !(self.motion == Motion::Stepped
            && self.stepped
            && self.integrator.locates_inside()
            && jump.mode == mode
            && jump.leaves.is_none()
            && !guard.barrier
            && !guard.internal
            && unchanged
            && inside)
        {
            return Ok(false);
        }
        let instant = t.after(end_window(t.value()));
        self.queue.due_by(instant, &mut self.simultaneous);
        if !self.simultaneous.is_empty() {
            return Ok(false);
        }
        let local = self.local_error();
        let uncertainty = self
            .bound
            .guard_uncertainty(model, mode, slot, &self.state, local);
        let scan =
            match self
                .integrator
                .locate(model, mode, slot, Start::Spent, uncertainty, into_step)
            {
                Some(Ok(scan)) if scan.margin > uncertainty => scan,
                _ => return Ok(false),
            };
        self.step_offset = into_step;
        if let Some(s) = scan.crossing {
            self.queue.schedule(slot, t.after(s * (h - into_step)));
            if let Some(depth) = self.depths.get_mut(slot) {
                *depth = scan.margin;
            }
        }
        Ok(true)
    }

    /// Decide how every guard of the current mode starts from the origin
    /// (see [`Start`]), after the event of guard `slot` of mode `from`
    /// (`fired`; `None` at `t = 0` and after settling). A crossing fires
    /// once, and whatever is due at this instant fires now:
    /// - the guard that fired, staying in its mode: a barrier is checked
    ///   for firing at once (a reset that did not turn the motion round is
    ///   resting contact); a marker the reset left on the surface is spent;
    /// - the other guards of that mode predicted at the same instant
    ///   (simultaneous events) fire at once if they move their way;
    /// - any other guard on its surface (within rounding of zero): at the
    ///   start, or a barrier, it fires at once if it moves its way; a
    ///   marker after an event is spent (the surface it sits on is the one
    ///   just crossed: a copy of the same guard in the new mode does not
    ///   count the crossing twice);
    /// - the rest start armed, as their values say.
    #[inline]
    pub(super) fn arm(&mut self, fired: Option<(Mode, usize)>) {
        let (model, mode) = (self.model, self.mode);
        let mut starts = std::mem::take(&mut self.starts);
        starts.clear();
        let same = fired.filter(|(from, _)| *from == mode).map(|(_, s)| s);
        for (g, guard) in model.guards(mode).iter().enumerate() {
            if same == Some(g) && guard.barrier {
                starts.push(Start::OnZero);
                continue;
            }
            let value = model.guard(mode, g, &self.state);
            let start = if same == Some(g) {
                let located = model.guard(mode, g, &self.before).abs();
                if value.abs() <= located || self.on_surface(g, value) {
                    Start::Spent
                } else {
                    Start::Armed
                }
            } else if same.is_some() && self.simultaneous.contains(&g) {
                Start::OnZero
            } else if !self.on_surface(g, value) {
                Start::Armed
            } else if fired.is_none()
                || guard.barrier
                || fired.is_some_and(|fired| !self.same_surface(fired, g))
            {
                Start::OnZero
            } else {
                Start::Spent
            };
            starts.push(start);
        }
        self.starts = starts;
        self.fresh = true;
    }

    /// Whether guard `g` of the current mode, on its surface, lies along
    /// the surface of guard `slot` of mode `from` just crossed (their
    /// gradients parallel, at the states after and before the event): a
    /// copy of the same transition, not another surface through the same
    /// point (a corner), which fires on its own.
    #[inline]
    pub(super) fn same_surface(&mut self, (from, slot): (Mode, usize), g: usize) -> bool {
        let model = self.model;
        let (mut a, mut b) = std::mem::take(&mut self.rates);
        let mut probe = std::mem::take(&mut self.probe);
        guard_gradient(model, from, slot, &self.before, &mut a, &mut probe);
        guard_gradient(model, self.mode, g, &self.state, &mut b, &mut probe);
        let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
        let norms = a.iter().map(|x| x * x).sum::<f64>() * b.iter().map(|y| y * y).sum::<f64>();
        (self.rates, self.probe) = ((a, b), probe);
        dot * dot >= (1.0 - 1e-6) * norms && norms > 0.0
    }

    /// Whether guard `g` of the current mode, `value` at the state, is on
    /// its surface to rounding: within 64 ulps of the sizes of the terms
    /// its gradient sums (`sum |dg/dx_i x_i|`), and as far as its rate
    /// moves it over the rounding of the time (an event due at `t_end` is
    /// fired there, up to that much before its crossing).
    #[inline]
    pub(super) fn on_surface(&mut self, g: usize, value: f64) -> bool {
        if value == 0.0 {
            return true;
        }
        let (model, mode) = (self.model, self.mode);
        let clock = self.clock.map(|(c, _)| c);
        let x = &self.state;
        // Most guards are far from zero after an event: within a millionth
        // of the state's size they are worth a closer look, beyond it not.
        if value.abs() > 1e-6 * size_of(x, clock) {
            return false;
        }
        let mut probe = std::mem::take(&mut self.probe);
        let drift = if model.has_rhs(mode) {
            let mut rate = std::mem::take(&mut self.rates.0);
            model.rhs(mode, x, &mut rate);
            let drift = guard_rate(|y| model.guard(mode, g, y), x, &rate, clock, &mut probe).abs()
                * end_window(self.origin.value());
            self.rates.0 = rate;
            drift
        } else {
            0.0
        };
        let mut gradient = std::mem::take(&mut self.gradient);
        guard_gradient(model, mode, g, x, &mut gradient, &mut probe);
        self.probe = probe;
        let scale: f64 = gradient.iter().zip(x).map(|(d, v)| (d * v).abs()).sum();
        self.gradient = gradient;
        value.abs() <= 64.0 * f64::EPSILON * scale + drift
    }

    /// Where guards may be undefined, stop at one that is not finite at
    /// `(origin, state)`: a crossing cannot be looked for in it.
    #[inline]
    pub(super) fn check_guards(&self) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        if !model.may_be_undefined() {
            return Ok(());
        }
        for (g, guard) in model.guards(mode).iter().enumerate() {
            let value = model.guard(mode, g, &self.state);
            if !value.is_finite() {
                let why = model
                    .diagnose_guard(mode, g, &self.state, false)
                    .map_or_else(String::new, |why| format!(": {why}"));
                return Err(End::failed(format!(
                    "guard `{}` is {value} at t = {} in mode `{}` (state {:?}){why}",
                    guard.name,
                    self.origin.value(),
                    model.mode_name(mode),
                    self.state
                )));
            }
        }
        Ok(())
    }

    /// The earliest guard that a stepped flow would cross just after
    /// `t_end` (which its last step does not look past), by each guard's
    /// value and rate there: `(guard, time after t_end, rate)`, the time
    /// negative for one a few ulps before it, where no step was taken. The
    /// state it was judged from is left in `self.before`. A guard that
    /// fired at the origin counts as its start says: a spent marker is not
    /// due again.
    #[inline]
    pub(super) fn crossing_after(&mut self, t_end: Time) -> Option<(usize, f64, f64)> {
        let (model, mode) = (self.model, self.mode);
        if self.motion != Motion::Stepped || !model.has_rhs(mode) {
            return None;
        }
        // The state at t_end, from the last step; or, where no step was
        // taken (what was left of the run was below a step), at the
        // origin, a few ulps before t_end, which the extrapolation covers.
        let (reach, from) = if self.stepped {
            (t_end.since(self.origin).max(0.0), t_end)
        } else {
            (0.0, self.origin)
        };
        let gap = t_end.since(from);
        let clock = self.clock.map(|(c, _)| c);
        let mut x = std::mem::take(&mut self.before);
        let mut rate = std::mem::take(&mut self.rates.0);
        let mut probe = std::mem::take(&mut self.probe);
        self.state_at(reach, &mut x);
        self.set_clock(from, &mut x);
        model.rhs(mode, &x, &mut rate);
        let fresh = !self.stepped && self.fresh;
        let mut first: Option<(usize, f64, f64)> = None;
        for (g, guard) in model.guards(mode).iter().enumerate() {
            if fresh && self.starts[g] != Start::Armed {
                continue;
            }
            let value = model.guard(mode, g, &x);
            let slope = guard_rate(|y| model.guard(mode, g, y), &x, &rate, clock, &mut probe);
            let tau = -value / slope - gap;
            if value != 0.0
                && -value / slope > 0.0
                && guard.direction.accepts(value, -value)
                && first.is_none_or(|(_, earliest, _)| tau < earliest)
            {
                first = Some((g, tau, slope));
            }
        }
        (self.before, self.rates.0, self.probe) = (x, rate, probe);
        first
    }

    /// A graze or near miss at `t` closer than the integration error can
    /// resolve, in words (the run stops where the step that finds it
    /// starts).
    #[inline]
    pub(super) fn undecidable(&self, g: usize, t: Time, margin: f64, uncertainty: f64) -> String {
        format!(
            "guard `{}` grazes zero at t = {:e}: its dip or near miss is {margin:.2e} deep, within the \
             integration error so far ({uncertainty:.2e}), so {} cannot tell whether it fires; \
             tighten the method or use an exact one",
            self.model.guards(self.mode)[g].name,
            t.value(),
            self.integrator.name()
        )
    }

    #[inline]
    pub(super) fn predict_exact(&mut self, g: usize) -> Result<(), End> {
        self.exact_evaluations += 1;
        match self.model.next_crossing(self.mode, g, &self.state) {
            None => {
                self.queue.cancel(g);
                Ok(())
            }
            Some(tau) => self.schedule_exact(g, tau),
        }
    }

    /// Predict spent guard `g` (a marker the state has just passed) on an
    /// exact flow: the model, asked from a state on the surface, names the
    /// crossing just passed (at zero); the next is asked from a little
    /// further along, far enough that the guard has visibly left.
    #[inline]
    pub(super) fn predict_past(&mut self, g: usize) -> Result<(), End> {
        let (model, mode) = (self.model, self.mode);
        self.exact_evaluations += 1;
        match model.next_crossing(mode, g, &self.state) {
            Some(tau) if tau > end_window(self.origin.value().abs().max(1.0)) => {
                return self.schedule_exact(g, tau);
            }
            None => {
                self.queue.cancel(g);
                return Ok(());
            }
            Some(_) => {}
        }
        let mut ahead = std::mem::take(&mut self.probe);
        let mut skip = 1e-12 * self.origin.value().abs().max(1.0);
        let mut predicted = None;
        for _ in 0..40 {
            model.advance(mode, &self.state, skip, &mut ahead);
            self.exact_evaluations += 2;
            match model.next_crossing(mode, g, &ahead) {
                Some(tau) if tau > 0.0 => {
                    predicted = Some(Some(skip + tau));
                    break;
                }
                Some(_) => skip *= 4.0,
                None => {
                    predicted = Some(None);
                    break;
                }
            }
        }
        self.probe = ahead;
        match predicted {
            Some(Some(tau)) => self.schedule_exact(g, tau),
            Some(None) => {
                self.queue.cancel(g);
                Ok(())
            }
            None => Err(End::failed(format!(
                "guard `{}` stays on zero at t = {}: the model predicts its crossing at once from \
                 every state up to {skip:.1e} further along the flow, so the next crossing cannot \
                 be told from the one just fired",
                model.guards(mode)[g].name,
                self.origin.value()
            ))),
        }
    }

    /// Queue guard `g` `tau` after the origin, as an exact flow predicted it.
    #[inline]
    pub(super) fn schedule_exact(&mut self, g: usize, tau: f64) -> Result<(), End> {
        if tau >= 0.0 && self.queue.schedule(g, self.origin.after(tau)) {
            return Ok(());
        }
        Err(End::failed(format!(
            "the model predicted guard `{}` at an invalid elapsed time {tau} from state {:?} at t = {}",
            self.model.guards(self.mode)[g].name,
            self.state,
            self.origin.value()
        )))
    }
}
