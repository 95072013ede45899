//! Segments of flow: starting one (an exact flow's future, or one
//! integrator step with its crossings located), closing it (its errors
//! carried), and why a step failed.

use super::Run;
use crate::engine::model::HybridModel;
use crate::engine::run::ledger::End;
use crate::engine::step::adaptive::StepFailure;
use crate::engine::step::integrator::Motion;
use crate::engine::step::locate::{Start, scan_step};
use crate::engine::step::method::Method;

impl<M: HybridModel + ?Sized> Run<'_, '_, M> {
    /// Predict every guard of the current mode from `(origin, state)`; for an
    /// ODE mode this takes the next integration step.
    #[inline]
    pub(super) fn start_segment(&mut self) -> Result<(), End> {
        let mut state = std::mem::take(&mut self.state);
        self.set_clock(self.origin, &mut state);
        self.state = state;
        self.depths.clear();
        self.check_guards()?;
        self.queue.clear();
        self.step_end = None;
        self.step_offset = 0.0;
        let (model, mode) = (self.model, self.mode);
        let guards = model.guards(mode);
        self.motion = self.motion_of(mode)?;
        match self.motion {
            Motion::Frozen => Ok(()),
            Motion::Exact => {
                let fresh = std::mem::replace(&mut self.fresh, false);
                (0..guards.len()).try_for_each(|g| {
                    if fresh && self.starts[g] == Start::Spent {
                        self.predict_past(g)
                    } else {
                        self.predict_exact(g)
                    }
                })
            }
            Motion::Stepped => {
                let t_end = self.options.t_end;
                let remaining = self.origin.until(t_end);
                let h_min = self.min_step();
                // What is left of the run is below what a step can resolve
                // (the guards keep how they start, for `due_at_end`).
                self.stepped = remaining > h_min;
                if !self.stepped {
                    return Ok(());
                }
                let fresh = std::mem::replace(&mut self.fresh, false);
                let mut graze: Option<(usize, f64, f64, f64)> = None;
                let mut earliest = f64::INFINITY;
                self.depths.resize(guards.len(), f64::INFINITY);
                if let Some((c, c0)) = self.clock {
                    self.integrator
                        .clock_at(c, self.origin.after(c0).rounding());
                }
                if let Err(failure) =
                    self.integrator
                        .step(model, mode, &self.state, remaining, h_min)
                {
                    return Err(self.step_failed(failure));
                }
                let h = self.integrator.h();
                // A step the run's end cut short depends on more than its
                // start: its period does not repeat.
                if h >= remaining {
                    self.bound.unrepeatable();
                }
                self.forcing_error = self.forcing_rounding(h);
                let local = self.local_error();
                let interpolant = self.integrator.interpolant();
                let n = self.state.len();
                for (g, guard) in guards.iter().enumerate() {
                    let start = if fresh { self.starts[g] } else { Start::Armed };
                    // What the errors so far, and this step's, may shift the
                    // guard by.
                    let uncertainty = if guard.internal {
                        0.0
                    } else {
                        self.bound
                            .guard_uncertainty(model, mode, g, &self.state, local)
                    };
                    // A recording run proves guards clear of more (see
                    // `period_record`).
                    let searched = self.bound.scan_uncertainty(uncertainty);
                    let scan = match self.integrator.locate(model, mode, g, start, searched, 0.0) {
                        Some(Ok(scan)) => {
                            if !guard.internal {
                                let proven = scan.margin.is_finite() || searched > uncertainty;
                                self.bound
                                    .margin_found(proven.then(|| scan.margin.min(searched)));
                            }
                            scan
                        }
                        Some(Err(why)) => {
                            return Err(End::failed(format!(
                                "{} at t = {}: {why}",
                                self.integrator.name(),
                                self.origin.value()
                            )));
                        }
                        None => {
                            self.bound.margin_found(None);
                            let (step, x) = (&self.integrator, &mut self.before[..n]);
                            scan_step(guard, start, interpolant, uncertainty, |s| {
                                step.eval(s * h, x);
                                model.guard(mode, g, x)
                            })
                        }
                    };
                    if scan.margin <= uncertainty
                        && graze.is_none_or(|(_, _, _, at)| scan.margin_at < at)
                    {
                        graze = Some((g, scan.margin, uncertainty, scan.margin_at));
                    }
                    if let Some(s) = scan.crossing {
                        self.queue.schedule(g, self.origin.after(s * h));
                        self.depths[g] = scan.margin;
                        earliest = earliest.min(s);
                    }
                }
                // A graze the errors cannot decide stops the run, unless an
                // event comes first: the step is taken again after it.
                if let Some((g, margin, uncertainty, at)) =
                    graze.filter(|&(_, _, _, at)| at <= earliest)
                {
                    let why = self.undecidable(g, self.origin.after(at * h), margin, uncertainty);
                    if let Err(why) = self.bound.undecided(self.origin, why) {
                        self.undecided_graze = Some(g);
                        return Err(End::failed(why));
                    }
                }
                self.step_end = Some(self.origin.after(h));
                Ok(())
            }
        }
    }

    /// Carry the state errors over the `tau` of the current segment that
    /// has passed: along the flow's tangent, with a numerical step's local
    /// error added. Nothing to do while the run has made no error.
    #[inline(always)]
    pub(super) fn close_segment(&mut self, tau: f64) {
        if self.motion != Motion::Stepped && self.bound.idle() {
            return;
        }
        self.close_stretch(tau);
    }

    /// [`Run::close_segment`] once there is something to carry.
    #[inline(never)]
    pub(super) fn close_stretch(&mut self, tau: f64) {
        let (model, mode) = (self.model, self.mode);
        match self.motion {
            Motion::Stepped if self.stepped => {
                // The part of the step passed leaves its share of the local
                // error (none for an event at the step's start).
                let h = self.integrator.h();
                let local =
                    self.local_error() * (tau / h).min(1.0) + std::mem::take(&mut self.dense_gap);
                let (step, offset) = (&self.integrator, self.step_offset);
                let rates = step.rates(offset, tau);
                self.bound.after_step(
                    model,
                    mode,
                    (tau, local),
                    |s, x| step.sample(offset + s, x),
                    rates,
                );
            }
            Motion::Exact => self.bound.after_exact(model, mode, &self.state, tau),
            _ => {}
        }
    }

    #[inline]
    pub(super) fn step_failed(&self, failure: StepFailure) -> End {
        let t = self.origin.value();
        let what = match failure {
            StepFailure::Collapsed { h } => {
                let what = format!(
                    "the step size of {} collapsed to {h:.3e} at t = {t} in mode `{}` (state {:?})",
                    self.integrator.name(),
                    self.model.mode_name(self.mode),
                    self.state
                );
                // Neither cause below is the flow's: no diagnosis of it.
                if let Some(why) = self.collapse_not_the_flows(h) {
                    return End::failed(format!("{what}: {why}"));
                }
                what
            }
            StepFailure::GuardCollapsed { h, guard } => {
                let why = self
                    .model
                    .diagnose_guard(self.mode, guard, &self.state, false)
                    .map_or_else(String::new, |why| format!(": {why}"));
                return End::failed(format!(
                    "the step size of {} collapsed to {h:.3e} at t = {t} in mode `{}` (state {:?}): \
                     guard `{}` turns steep there{why}",
                    self.integrator.name(),
                    self.model.mode_name(self.mode),
                    self.state,
                    self.model.guards(self.mode)[guard].name
                ));
            }
            StepFailure::NotApplicable(why) => {
                format!(
                    "method `{}` cannot run this model: {why}",
                    self.options.method.name()
                )
            }
            StepFailure::NonFinite => {
                format!(
                    "the right-hand side is not finite at t = {t} in mode `{}` (state {:?})",
                    self.model.mode_name(self.mode),
                    self.state
                )
            }
        };
        match self.model.diagnose(self.mode, &self.state) {
            Some(why) => End::failed(format!("{what}: {why}")),
            None => End::failed(what),
        }
    }

    /// The shortest step the run takes: 64 ulps of the latest time it
    /// reaches, below which a step's end cannot be told from its start.
    #[inline]
    pub(super) fn min_step(&self) -> f64 {
        64.0 * f64::EPSILON * self.origin.value().abs().max(self.options.t_end)
    }

    /// Where a step collapsed to `h` for a reason of the run's settings
    /// rather than its flow, that reason: tolerances below the rounding of
    /// a step, or a `t_end` so far that times are resolved more coarsely
    /// than the flow needs.
    #[inline]
    pub(super) fn collapse_not_the_flows(&self, h: f64) -> Option<String> {
        // Taylor's method runs to machine precision (its default); a
        // Runge-Kutta pair's estimate drowns in rounding well above it.
        let (tolerances, floor) = match self.options.method {
            Method::Taylor(tol) => (Some(tol), f64::EPSILON),
            Method::Dopri5(tol) | Method::Dop853(tol) => (Some(tol), 100.0 * f64::EPSILON),
            _ => (None, 0.0),
        };
        let size = self.state.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        if let Some(tol) = tolerances
            && tol.rtol < floor
            && tol.atol < floor * size.max(1.0)
        {
            return Some(format!(
                "rtol = {:e} and atol = {:e} ask for less error than a step's rounding leaves (about \
                 {:.1e} of the state): loosen them to 1e-14 or more",
                tol.rtol,
                tol.atol,
                f64::EPSILON,
            ));
        }
        // A step far longer than the time's own rounding here (a collapse
        // into a singularity shrinks to that) was cut by t_end's.
        let h_min = self.min_step();
        let resolved = 64.0 * f64::EPSILON * self.origin.value().abs().max(1.0);
        (h >= 1e6 * resolved && h_min > h).then(|| {
            format!(
                "t_end = {:e} resolves times only to {h_min:.3e} (a step is at least 64 ulps of it), \
                 coarser than the {h:.3e} this flow needs: shorten t_end, or rescale time",
                self.options.t_end
            )
        })
    }
}
