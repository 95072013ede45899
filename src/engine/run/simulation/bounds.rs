//! The errors a run states as it goes: a step's local error (and a
//! forcing's rounding), a sample's bound beside an event, and the errors
//! carried across each event.

use super::Run;
use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::integrator::Motion;
use crate::numerics::central_difference::CBRT_EPSILON;
use crate::time::Time;

/// Rounding a step makes, in ulps of the state's size: a few roundings of
/// each stage's or term's sum.
const STEP_ROUNDING_ULPS: f64 = 4.0;

impl<M: HybridModel + ?Sized> Run<'_, '_, M> {
    /// The bound on the state `tau` past the origin (`x`), after
    /// `events` events, NaN where none is carried.
    #[inline]
    pub(super) fn sample_bound(&mut self, tau: f64, x: &[f64], events: u64) -> f64 {
        self.flow_bound(tau, events) + self.beside_events(self.origin.after(tau), x)
    }

    /// Where a sample at `t` (state `x`) lies within an event's time error
    /// of it, the true state may be on the reset's other side: the reset's
    /// jump. For the last event, where the true one may be later; for the
    /// next, where it may be earlier (its jump from `x`, its time error
    /// from the errors so far along its guard).
    #[inline]
    pub(super) fn beside_events(&mut self, t: Time, x: &[f64]) -> f64 {
        let last = self
            .last_event
            .filter(|last| t.since(last.t) <= last.time_error)
            .map_or(0.0, |last| last.jump);
        let Some((slot, next)) = self.queue.peek() else {
            return last;
        };
        let (model, mode) = (self.model, self.mode);
        let local = if self.motion == Motion::Stepped {
            self.local_error()
        } else {
            0.0
        };
        let time_error = self.bound.crossing_uncertainty(model, mode, slot, x, local);
        if next.since(t) > time_error {
            return last;
        }
        let mut after = std::mem::take(&mut self.probe);
        after.copy_from_slice(x);
        let to = model.reset(mode, slot, &mut after).mode;
        let jump = self.other_side((mode, x), (to, &after), time_error);
        self.probe = after;
        last + jump
    }

    /// How far the state on one side of a reset, from `before` in one mode
    /// to `after` in another, may be from the other side's within
    /// `time_error` of it: the jump, and how far either flow moves in that
    /// time (the jump itself moves with the state it is taken at; largest
    /// bounded component, the clock's aside).
    #[inline]
    pub(super) fn other_side(
        &mut self,
        before: (Mode, &[f64]),
        after: (Mode, &[f64]),
        time_error: f64,
    ) -> f64 {
        let model = self.model;
        let bounded = model.bounded_dimension().min(before.1.len());
        let clock = self.clock.map(|(c, _)| c);
        let mut rates = std::mem::take(&mut self.rates);
        let parting = if model.has_rhs(before.0) && model.has_rhs(after.0) {
            model.rhs(before.0, before.1, &mut rates.0);
            model.rhs(after.0, after.1, &mut rates.1);
            time_error
        } else {
            rates.0.fill(0.0);
            rates.1.fill(0.0);
            0.0
        };
        let side = (0..bounded)
            .filter(|&i| Some(i) != clock)
            .map(|i| {
                (after.1[i] - before.1[i]).abs() + parting * (rates.1[i].abs() + rates.0[i].abs())
            })
            .fold(0.0, f64::max);
        self.rates = rates;
        side
    }

    /// [`Run::sample_bound`] without the events beside it: the errors
    /// carried to the origin, and a stepped flow's local error, or its
    /// dense output's where that is larger (see
    /// [`Integrator::dense_error`]). Both are errors over the whole step:
    /// the carried errors' growth over part of it is within them.
    #[inline]
    pub(super) fn flow_bound(&mut self, tau: f64, events: u64) -> f64 {
        let Some(carried) = self.bound.state_bound(events) else {
            return f64::NAN;
        };
        if self.motion != Motion::Stepped {
            return carried;
        }
        let mut local = self.local_error();
        if self.stepped && tau > 0.0 {
            let (model, mode) = (self.model, self.mode);
            let mut x = std::mem::take(&mut self.after);
            let at = (self.state.as_slice(), self.step_offset + tau);
            let spare = &mut self.spare;
            if let Some(dense) = self.integrator.dense_error(spare, model, mode, at, &mut x) {
                local = local.max(dense + self.forcing_error);
            }
            self.after = x;
        }
        carried + local
    }

    /// The last step's local error: the method's estimate, and never less
    /// than the step's rounding ([`STEP_ROUNDING_ULPS`] ulps of the state),
    /// which a step exact in its arithmetic (a Taylor series that ends, on
    /// a polynomial flow; Stormer-Verlet under a constant force) still
    /// makes, and which a chaotic run amplifies like any other error; plus
    /// the rounding of a forcing (see [`Run::forcing_rounding`]).
    #[inline]
    pub(super) fn local_error(&self) -> f64 {
        let bounded = self.model.bounded_dimension().min(self.state.len());
        let clock = self.clock.map(|(c, _)| c);
        let size = self.state[..bounded]
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != clock)
            .fold(0.0_f64, |m, (_, x)| m.max(x.abs()));
        self.integrator
            .local_error()
            .max(STEP_ROUNDING_ULPS * f64::EPSILON * size)
            + self.forcing_error
    }

    /// What a forced flow's step of length `h` from the origin errs by
    /// because it reads the clock: `sin(w t)` at `t = 1e4` is computed from
    /// a product rounded by an ulp of `w t`, a shift of the time by `eps
    /// |t|`, so the rate errs by `|df/dt| eps |t|` and the step by `h` times
    /// that (`df/dt` by a central difference of the right-hand side).
    #[inline]
    pub(super) fn forcing_rounding(&mut self, h: f64) -> f64 {
        let (model, mode) = (self.model, self.mode);
        let Some((c, _)) = self.clock.filter(|_| model.has_rhs(mode)) else {
            return 0.0;
        };
        // The linear propagator steps from the exact time.
        if let Some(error) = self.integrator.exact_clock_error(h) {
            return error;
        }
        let t = self.state[c];
        // A difference over a small part of the step (which resolves the
        // forcing), and far above the ulps of t.
        let dt = (CBRT_EPSILON * h).max(1e3 * f64::EPSILON * t.abs());
        let (mut up, mut down) = std::mem::take(&mut self.rates);
        let mut x = std::mem::take(&mut self.probe);
        x.copy_from_slice(&self.state);
        x[c] = t + dt;
        model.rhs(mode, &x, &mut up);
        x[c] = t - dt;
        model.rhs(mode, &x, &mut down);
        let bounded = model.bounded_dimension().min(x.len());
        let slope = up[..bounded]
            .iter()
            .zip(&down[..bounded])
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs() / (2.0 * dt)));
        (self.rates, self.probe) = ((up, down), x);
        h * slope * f64::EPSILON * t.abs()
    }

    /// Carry the errors across the event of guard `slot` at `t` (state
    /// `before`, `self.after` after the reset, in `mode_after`): see
    /// [`Bound::across`]; why the run cannot go on, if it cannot.
    #[inline(always)]
    pub(super) fn carry_errors(
        &mut self,
        slot: usize,
        t: Time,
        before: &[f64],
        mode_after: Mode,
    ) -> Result<(), String> {
        self.bound.note_state(before);
        if self.bound.idle() {
            self.bound
                .note_crossing(self.model, self.mode, slot, before);
            return Ok(());
        }
        let depth = match self.motion {
            Motion::Stepped => self.depths.get(slot).copied().unwrap_or(f64::INFINITY),
            _ => f64::INFINITY,
        };
        self.bound.across(
            self.model,
            self.mode,
            slot,
            t,
            (before, &self.after),
            mode_after,
            (self.options.t_end, depth),
            self.integrator.name(),
        )
    }
}
