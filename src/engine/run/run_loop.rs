//! The one event loop every run goes through, and its rules.
//!
//! A run is driven by a *source of segments* ([`Segments`]): the whole-state
//! path ([`simulate`]) holds the model's state and advances it along an
//! exact flow or one integration step at a time; the event-local path
//! ([`simulate_local`]) leaves the state with a large model and asks it for
//! each guard's next crossing. A source answers what happens next (the
//! earliest predicted event, or the end of its current segment), fires
//! events, starts segments and reports sample states. Everything else is
//! the loop's and the [`Ledger`]'s, written here once:
//!
//! - **Order.** Events happen in strict time order, ties by guard index; an
//!   event at the very end of a segment happens before the segment ends.
//!   Nothing past `t_end` happens: the source is asked to reach `t_end` and
//!   say whether it can vouch for the state there.
//! - **An event at `t_end`** is the run's: it is applied, and the final
//!   state is the state after its reset (the log has the state before it).
//!   "At `t_end`" means within [`end_window`] of it, the rounding of times
//!   there: an event that lands on `t_end` by construction (a clock that
//!   ticks every unit, `t_end` a whole number of ticks) is found a few
//!   ulps to either side, and is fired whichever (at its own time, or at
//!   `t_end` where a step that ends there finds it just beyond). Past the
//!   window nothing happens; an event the run cannot place on one side of
//!   the window (its time error reaches across) stops the run there.
//! - **Samples.** Sample times (increasing, up to `t_end`) due before what
//!   happens next are reported from the flow as it is: a sample at an
//!   event's time sees the state before the reset, and sampling changes
//!   neither steps nor events.
//! - **Looking outside.** The stop flag is read at every turn; every
//!   `CLOCK_EVERY` turns the wall clock is read, for the wall-time budget
//!   and for a progress report every `PROGRESS_SECONDS`.
//! - **Event budget.** A run fails when event `max_events + 1` is logged;
//!   every `BUDGET_CHECK` events it projects the events still needed to
//!   reach `t_end` at the recent rate, and fails early if they exceed the
//!   budget.
//! - **Zeno.** Every firing, internal guards included, is shown to the
//!   [`ZenoWatch`](crate::engine::bound::zeno::ZenoWatch); when one guard's
//!   events become unresolvable the model may settle into resting contact
//!   (logged as [`SETTLE`](crate::engine::run::observer::SETTLE), the run goes on
//!   and ends `zeno`) or the run stops there, `zeno`.
//! - **Energy.** The model's energy is audited against its initial value
//!   wherever the source computes it (at each event for the whole-state
//!   path; at logged events and samples for the event-local one, whose
//!   energy is a sum over the whole model) and at the end; the largest
//!   relative error is the outcome's `max_energy_error`. Where the model's
//!   resets may change the energy (`HybridModel::resets_keep_energy`), each
//!   logged reset's change moves what the energy is held to, so the audit
//!   measures the flows.
//! - **Periods.** Where the source proves that its orbit repeats after an
//!   event ([`periodic`]) and the observer does not look at events, whole
//!   periods are jumped over (short of the end, the next sample, the event
//!   budget and its next projection, so the budget's rules hold as if
//!   every event fired) and their events counted as fired.
//! - **Counts.** Non-internal events are counted per guard, settlings
//!   apart; the outcome reports them by guard name.
//!
//! [`simulate`]: crate::engine::simulate
//! [`simulate_local`]: crate::engine::simulate_local

use crate::engine::bound::ROUNDOFF_ULPS;
use crate::engine::bound::zeno;
use crate::engine::run::ledger::{End, Ledger};
use crate::engine::run::observer::Observer;
use crate::engine::run::periodic;
use crate::time::{Span, Time};

/// A source of segments: what a run advances, the loop's rules aside.
pub(crate) trait Segments {
    /// The time of the last event or segment boundary.
    fn origin(&self) -> Time;

    /// Predict what happens first from the initial state.
    fn begin(&mut self, ledger: &mut Ledger) -> Result<(), End>;

    /// What happens next: `(Some(guard), t)`, the earliest predicted
    /// event; `(None, t)`, the end of the current segment; `t` infinite if
    /// nothing is ahead.
    fn next(&self) -> (Option<usize>, Time);

    /// Fire `guard` at `t`: reset, log through the ledger, re-predict.
    fn fire<O: Observer + ?Sized>(
        &mut self,
        guard: usize,
        t: Time,
        ledger: &mut Ledger,
        observer: &mut O,
    ) -> Result<(), End>;

    /// The current segment ends at `t`: start the next one there.
    fn renew(&mut self, t: Time) -> Result<(), End>;

    /// Report the state at sample time `s` (not past what happens next).
    fn sample(&mut self, s: f64, ledger: &mut Ledger);

    /// The guard, if any, that crosses in `(t_end, t_end + window]`
    /// beyond what the source has predicted (a step that ends at `t_end`
    /// does not look past it): it is due at `t_end`.
    fn due_at_end(&mut self, t_end: Time, window: f64) -> Option<usize> {
        let _ = (t_end, window);
        None
    }

    /// The period of the orbit the last event showed to repeat, and the
    /// events each period holds, where the source can prove it does (see
    /// [`periodic`]): from the current origin, the next period's events
    /// repeat the last period's.
    ///
    /// [`periodic`]: crate::engine::run::periodic
    fn period(&self) -> Option<(Span, u64)> {
        None
    }

    /// Jump `periods` whole periods of `tau` ahead (the state repeats),
    /// counting their events in `ledger`.
    fn jump(&mut self, periods: u64, tau: Span, ledger: &mut Ledger) {
        let _ = (periods, tau, ledger);
    }

    /// Reach `t_end` with nothing more to happen before it, or say why the
    /// state there cannot be vouched for. An event due at `t_end` may have
    /// fired a rounding past it: the state after it is the final state.
    fn finish(&mut self, t_end: Time) -> Result<(), End>;
}

/// Run `source` to `t_end` under the loop's rules, reporting events to
/// `observer` and the state at each of `samples` to the source.
pub(crate) fn drive<S: Segments + ?Sized, O: Observer + ?Sized>(
    source: &mut S,
    ledger: &mut Ledger,
    samples: &[f64],
    observer: &mut O,
) -> End {
    match turns(source, ledger, samples, observer) {
        Ok(()) => ledger.completed(),
        Err(end) => end,
    }
}

fn turns<S: Segments + ?Sized, O: Observer + ?Sized>(
    source: &mut S,
    ledger: &mut Ledger,
    samples: &[f64],
    observer: &mut O,
) -> Result<(), End> {
    let t_end = ledger.t_end();
    source.begin(ledger)?;
    let mut samples = samples.iter().copied().peekable();
    loop {
        ledger.look_outside(source.origin(), observer)?;
        let (guard, t) = source.next();
        let due = t.value().min(t_end);
        while let Some(s) = samples.next_if(|&s| s <= due) {
            source.sample(s, ledger);
        }
        if t.value() > t_end {
            let end = Time::new(t_end);
            let window = end_window(t_end);
            // A predicted event fires at its own time, a state that has
            // just crossed; one the source finds past its last step at
            // the end.
            let due = match guard {
                Some(guard) if t.since(end) <= window => Some((guard, t)),
                _ => source.due_at_end(end, window).map(|guard| (guard, end)),
            };
            match due {
                Some((guard, at)) => source.fire(guard, at, ledger, observer)?,
                None => return source.finish(end),
            }
            ledger.check_events(source.origin())?;
            continue;
        }
        match guard {
            Some(guard) => {
                source.fire(guard, t, ledger, observer)?;
                // An observer that looks at events sees every one fired.
                if !observer.wants_details()
                    && let Some((span, events)) = source.period()
                    // Events closer than the run resolves are the Zeno
                    // watch's, not a period's.
                    && span.value() / events as f64 > zeno::resolution(t.value(), t_end)
                {
                    let (tau, limit) = (
                        span.value(),
                        samples.peek().map_or(t_end, |&s| s.min(t_end)),
                    );
                    let periods = periodic::periods_to_skip(source.origin(), tau, limit)
                        .min(ledger.jump_allowance((tau, events), source.origin()));
                    if periods > 0 {
                        source.jump(periods, span, ledger);
                    }
                }
            }
            None => source.renew(t)?,
        }
        ledger.check_events(source.origin())?;
    }
}

/// How far past `t_end` an event still counts as at `t_end`: the rounding
/// of times there, [`ROUNDOFF_ULPS`] ulps of `t_end`.
pub fn end_window(t_end: f64) -> f64 {
    ROUNDOFF_ULPS * f64::EPSILON * t_end.abs()
}
