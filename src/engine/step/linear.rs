//! The exact propagator of a linear flow `x' = A x + b` (and of one driven
//! by sines of the clock as well, their values carried as more components
//! of `y`: see [`AffineMode`]).
//!
//! With the augmented matrix `M = [[A, b], [0, 0]]`, the flow from `y` is
//! `exp(M tau) y = sum_k M^k y tau^k / k!`. Steps are bounded so that
//! `|M| h <= 1.5` ([`REACH`]); over a step the series is then summed to
//! round-off by its first [`ORDER`] + 1 terms (the rest is below 7e-21 of
//! the state).
//!
//! [`REACH`]: crate::engine::step::affine_mode::REACH
//!
//! A small mode is solved once ([`AffineMode`]): a whole step is one
//! product with its propagator `exp(M h)`, and an affine guard's series
//! along the step are products of its cached rows with the state, and so
//! is the state's own series. That series (a large mode's: `ORDER`
//! matrix-vector products) is summed only where the run asks for a state
//! inside the step (an event, the error bound) or for a step cut short, by
//! compensated Horner, its first terms (see [`FIRST`]) in double-double: the
//! state and what its rounding left out, with no matrix exponential.
//!
//! A step keeps what rounding its end left out, and the next step, if it
//! starts there, starts from the end unrounded (its guards' series, its
//! states and its own end): an exactly periodic orbit otherwise rounds the
//! same way at the same step of every period, and its phase drifts by a
//! fraction of an ulp per period (the paper's mechanism as an automaton,
//! 43,468 impacts: 8e-13 off at the end instead of 8e-14). For the same
//! reason an affine guard's crossing is moved to its zero in double-double
//! ([`Linear::sharpen`]): a reset at the double nearest the crossing is
//! up to an ulp of the time off the guard, the same at every period (the
//! mechanism, each event fired: 8e-14 off at the end before, 6e-17 now; a
//! rotation bounced 10,000 times: up to 4e-13 before, 6e-17 now).
//!
//! Events are found on the guards' polynomials: where the model gives its
//! guards' Taylor series along a flow ([`HybridModel::guard_series`]), by
//! the certified root search Taylor's method uses (no root in the step
//! missed); elsewhere (a chain's ODE) by the engine's scan of the state
//! along the step ([`locate`](crate::engine::step::locate)), each bracket refined
//! on the propagator itself.

use std::cell::{Cell, RefCell};

use nalgebra::{DMatrix, DVector};

use crate::engine::model::{HybridModel, Mode};
use crate::engine::step::adaptive::StepFailure;
pub use crate::engine::step::affine_mode::ORDER;
use crate::engine::step::affine_mode::{
    AffineMode, FIRST, guard_series, mat_vec, state_series, state_series_in_two,
};
use crate::engine::step::crossing::Crossing;
use crate::engine::step::locate::{Start, StepScan};
use crate::numerics::double_double::{dot, two_prod, two_sum};
use crate::numerics::polynomial::{eval, eval_compensated_rows_plus};

/// The exact propagator's working state: each mode met so far solved once,
/// and the current step.
#[derive(Debug, Clone)]
pub struct Linear {
    /// Per mode index, once met.
    modes: Vec<Option<AffineMode>>,
    /// The mode of the current step.
    mode: Mode,
    h: f64,
    /// `[x0, 1]` of the current step (and its waves: see
    /// [`AffineMode::augment`]).
    y0: Vec<f64>,
    /// The step's state series, summed on first need.
    series: RefCell<Vec<f64>>,
    /// Whether `series` is the current step's.
    series_ready: Cell<bool>,
    /// Scratch for the series: one term of the augmented series and the
    /// next.
    terms: RefCell<(Vec<f64>, Vec<f64>)>,
    /// Each guard's series along the step, one after another (where the
    /// model gives them).
    guards: Vec<f64>,
    /// A guard's series, scratch for its search.
    guard: Vec<f64>,
    y1: Vec<f64>,
    /// What rounding `y1` to double left out (zero where the step ended
    /// beyond its series, by an exponential of its own).
    carry: Vec<f64>,
    /// The same for `y0`, where the step continues from the last one's
    /// end; and (lazily, with the series) `M` and `M^2` times it, which
    /// carry it along the step to well below an ulp.
    y0_lo: Vec<f64>,
    lo_terms: RefCell<(Vec<f64>, Vec<f64>)>,
    /// What rounding the series' first terms left out, `FIRST + 1` per
    /// component (empty where the mode has no double-double rows).
    first_lo: RefCell<Vec<f64>>,
    /// The last state summed inside the step, and what its rounding left
    /// out, at the time into the step it was taken (NaN for none): an
    /// event's state, which [`Linear::sharpen`] then moves.
    evaluated: RefCell<(f64, Vec<f64>, Vec<f64>)>,
    /// The clock's component and what rounding the run's time to its
    /// reading left out, for the next step (see [`Linear::clock_at`]).
    clock: Option<(usize, f64)>,
    /// Propagator evaluations; a `Cell` because evaluation reads `&self`.
    evaluations: Cell<u64>,
}

impl Linear {
    /// A propagator for states of `dimension` components.
    pub fn new(dimension: usize) -> Self {
        Linear {
            modes: Vec::new(),
            mode: 0,
            h: 0.0,
            y0: vec![0.0; dimension + 1],
            series: RefCell::new(vec![0.0; dimension * (ORDER + 1)]),
            series_ready: Cell::new(false),
            terms: RefCell::new((vec![0.0; dimension + 1], vec![0.0; dimension + 1])),
            guards: Vec::new(),
            guard: vec![0.0; ORDER + 1],
            y1: vec![0.0; dimension],
            carry: vec![0.0; dimension],
            y0_lo: vec![0.0; dimension + 1],
            lo_terms: RefCell::new((vec![0.0; dimension + 1], vec![0.0; dimension + 1])),
            first_lo: RefCell::new(Vec::new()),
            evaluated: RefCell::new((f64::NAN, vec![0.0; dimension], vec![0.0; dimension])),
            clock: None,
            evaluations: Cell::new(0),
        }
    }

    /// The next step starts at a time whose clock reading (component
    /// `clock`) left out `rounding`: every step starts from the exact
    /// time, whether it continues a step (whose carry holds the same) or
    /// starts at an event. A flow driven by sines of the clock otherwise sees its
    /// forcing shifted against the state by up to half an ulp of `t` at
    /// each such step, which adds up where nothing damps it (`x' = cos(w
    /// t)` with a marker: 4e-10 after 2000 passages to `t = 1e4`, 2e-16
    /// now).
    pub fn clock_at(&mut self, clock: usize, rounding: f64) {
        self.clock = Some((clock, rounding));
    }

    /// Forget the last step's rounding residual: after an event the run
    /// goes on from the event's state.
    pub fn restart(&mut self) {
        self.carry.fill(0.0);
    }

    /// The length of the last step taken.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// `mode` solved once, on first meeting it.
    fn solved<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
    ) -> Result<&AffineMode, StepFailure> {
        if self.modes.len() <= mode {
            self.modes.resize(mode + 1, None);
        }
        if self.modes[mode].is_none() {
            let n = self.y1.len();
            self.modes[mode] = Some(AffineMode::new(model, mode, n)?);
        }
        Ok(self.modes[mode].as_ref().expect("solved above"))
    }

    /// One step from `y0` in `mode`, as long as `h_max` and the bound
    /// `|M| h <= REACH` allow; fails if the mode's flow is not linear or the
    /// state stops being finite.
    pub fn step<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        y0: &[f64],
        h_max: f64,
        h_min: f64,
    ) -> Result<(), StepFailure> {
        let solved = self.solved(model, mode)?;
        let (h_bound, m) = (solved.h_bound, solved.augmented_len());
        self.mode = mode;
        // Sized for this mode's augmented state (its waves' components).
        for v in [&mut self.y0, &mut self.y0_lo] {
            v.resize(m, 0.0);
        }
        for (a, b) in [self.terms.get_mut(), self.lo_terms.get_mut()] {
            a.resize(m, 0.0);
            b.resize(m, 0.0);
        }
        // A step that continues from the last one's end starts from the
        // end unrounded: the state of an exactly periodic orbit otherwise
        // rounds the same way at the same step of every period, and its
        // phase drifts with the number of periods.
        let continues = y0 == &self.y1[..];
        for (l, c) in self.y0_lo.iter_mut().zip(&self.carry) {
            *l = if continues { *c } else { 0.0 };
        }
        // The clock's residual is the engine's, whatever the step before
        // left.
        if let Some((clock, rounding)) = self.clock {
            self.y0_lo[clock] = rounding;
        }
        self.modes[mode]
            .as_ref()
            .expect("solved above")
            .augment(y0, &self.y0_lo, &mut self.y0);
        self.h = h_bound.min(h_max);
        self.series_ready.set(false);
        self.evaluated.get_mut().0 = f64::NAN;
        self.evaluations.set(self.evaluations.get() + 1);
        if model.has_series(mode) {
            let shortened_by = self.fit_guards(model, mode);
            if self.h < h_min {
                return Err(match shortened_by {
                    Some(guard) => StepFailure::GuardCollapsed { h: self.h, guard },
                    None => StepFailure::Collapsed { h: self.h },
                });
            }
        }
        let mut y1 = std::mem::take(&mut self.y1);
        let whole = self.h == h_bound;
        match self.modes[mode]
            .as_mut()
            .filter(|_| whole)
            .and_then(AffineMode::whole_step)
        {
            Some(p) => {
                // y1 = the first n rows of exp(M h) y0, each rounded once,
                // and what the rounding left out.
                let ends = y1.iter_mut().zip(self.carry.iter_mut());
                for ((o, c), row) in ends.zip(p.chunks_exact(m)) {
                    let end = dot(row, &self.y0, &self.y0_lo);
                    (*o, *c) = (end.hi, end.lo);
                }
            }
            None => {
                let mut carry = std::mem::take(&mut self.carry);
                self.eval_split(self.h, &mut y1, &mut carry);
                self.carry = carry;
            }
        }
        self.y1 = y1;
        if self.y1.iter().any(|x| !x.is_finite()) {
            return Err(StepFailure::NonFinite);
        }
        Ok(())
    }

    /// The step's state series, summed now if the step has not yet needed
    /// it.
    fn ensure_series(&self) {
        if self.series_ready.get() {
            return;
        }
        let solved = self.modes[self.mode]
            .as_ref()
            .expect("a step solved its mode");
        let mut series = self.series.borrow_mut();
        let mut first_lo = self.first_lo.borrow_mut();
        first_lo.clear();
        match (&solved.state_rows, &solved.first_rows) {
            (Some(rows), Some(first)) => state_series_in_two(
                rows,
                first,
                &self.y0,
                &self.y0_lo,
                &mut series,
                &mut first_lo,
            ),
            _ => {
                let (term, next) = &mut *self.terms.borrow_mut();
                state_series(&solved.rows, &self.y0, &mut series, term, next);
            }
        }
        if first_lo.is_empty() {
            let (once, twice) = &mut *self.lo_terms.borrow_mut();
            mat_vec(&solved.rows, &self.y0_lo, once);
            mat_vec(&solved.rows, once, twice);
        }
        self.series_ready.set(true);
    }

    /// Each guard's series along the step (kept for [`Linear::locate`]),
    /// and the step shortened until every one of them is summed to
    /// round-off by its terms: the state's series converge over `|M| h <=
    /// REACH`, but a guard may read the clock through a sine of any frequency.
    /// Returns the guard that shortened the step last, if one did: the one
    /// to blame where the step collapses (`sqrt(x)` near `x = 0`).
    fn fit_guards<M: HybridModel + ?Sized>(&mut self, model: &M, mode: Mode) -> Option<usize> {
        let w = ORDER + 1;
        let guards = model.guards(mode).len();
        self.guards.resize(guards * w, 0.0);
        // Measured as the state's own series are: against the state's size
        // (a guard's own coefficients, which a fast sine makes large, would
        // excuse any step).
        let clock = self.clock.map(|(c, _)| c);
        let scale = (self.y0[..self.y1.len()].iter().enumerate())
            .filter(|&(i, _)| Some(i) != clock)
            .fold(1.0_f64, |m, (_, v)| m.max(v.abs()));
        let mut shortened_by = None;
        let mut series = std::mem::take(&mut self.guards);
        for g in 0..guards {
            let c = &mut series[g * w..(g + 1) * w];
            let rows = self.modes[mode]
                .as_ref()
                .and_then(|s| s.guard_rows[g].as_ref());
            match rows {
                Some(rows) => guard_series(rows, &self.y0, &self.y0_lo, c),
                None => {
                    self.ensure_series();
                    model.guard_series(mode, g, &self.series.borrow(), ORDER, c);
                }
            }
            // The last two terms at the step's length far below round-off
            // (1e-18 of the state's size: as far as the state's own, whose
            // last two are at most `REACH^23 / 23! + REACH^24 / 24!`, 5e-19,
            // of it).
            while self.h > 0.0
                && (c[ORDER - 1].abs() * self.h.powi(ORDER as i32 - 1)
                    + c[ORDER].abs() * self.h.powi(ORDER as i32))
                    > 1e-18 * scale
            {
                self.h *= 0.5;
                shortened_by = Some(g);
            }
        }
        self.guards = series;
        shortened_by
    }

    /// The exact state `tau` after the step's start: the step's series
    /// inside it, an exponential of its own beyond.
    pub fn eval(&self, tau: f64, x: &mut [f64]) {
        self.eval_with(tau, x, None);
    }

    /// [`Linear::eval`], and what rounding the state left out into `lo`
    /// (zero beyond the step).
    fn eval_split(&self, tau: f64, x: &mut [f64], lo: &mut [f64]) {
        lo.fill(0.0);
        self.eval_with(tau, x, Some(lo));
    }

    /// Whether `tau` into the step is inside it, where its series holds.
    fn inside(&self, tau: f64) -> bool {
        tau <= self.h * (1.0 + 4.0 * f64::EPSILON)
    }

    fn eval_with(&self, tau: f64, x: &mut [f64], lo: Option<&mut [f64]>) {
        if self.inside(tau) {
            self.ensure_series();
            let series = self.series.borrow();
            let (once, twice) = &*self.lo_terms.borrow();
            let first_lo = self.first_lo.borrow();
            let n = x
                .len()
                .min(self.y0_lo.len())
                .min(once.len())
                .min(twice.len());
            // What rounding left out, added before the one rounding: the
            // first terms' residuals where they were summed in
            // double-double (the start's among them); else the start's
            // residual along the step to its second order (the third is
            // below 1 / 6 of the residual, itself below half an ulp).
            let extra = |i: usize| match first_lo.get(i * (FIRST + 1)..(i + 1) * (FIRST + 1)) {
                Some(terms) => terms.iter().rev().fold(0.0, |sum, c| sum * tau + c),
                None => self.y0_lo[i] + tau * (once[i] + 0.5 * tau * twice[i]),
            };
            let (at, hi, kept) = &mut *self.evaluated.borrow_mut();
            eval_compensated_rows_plus(
                &series,
                ORDER + 1,
                tau,
                extra,
                &mut x[..n],
                Some(&mut kept[..n]),
            );
            *at = tau;
            hi[..n].copy_from_slice(&x[..n]);
            if let Some(lo) = lo {
                lo[..n].copy_from_slice(&kept[..n]);
            }
            return;
        }
        self.evaluated.borrow_mut().0 = f64::NAN;
        let m = self.y0.len();
        let rows = &self.modes[self.mode]
            .as_ref()
            .expect("a step solved its mode")
            .rows;
        let propagator = (DMatrix::from_row_slice(m, m, rows) * tau).exp();
        // The start's residual (a carry, the clock's) through the same
        // exponential: an ulp of the start that this path would drop.
        let y = &propagator * DVector::from_column_slice(&self.y0)
            + &propagator * DVector::from_column_slice(&self.y0_lo);
        x.copy_from_slice(&y.as_slice()[..x.len()]);
        self.evaluations.set(self.evaluations.get() + 1);
    }

    /// The crossing of an affine guard at `tau` into the step, moved to
    /// where the guard at the state carried with its residual is zero to
    /// double-double accuracy: one Newton step, `-g / g'` (below an ulp of
    /// `tau`: the search found the double nearest the crossing), the time
    /// kept exact by the engine's double-double clock. A reset at a state
    /// off the guard by the rounding of `tau` turns the motion round from
    /// there, a little early or late, and a periodic impact orbit repeats
    /// that every period: a rotation bounced 10,000 times drifted by 4e-13
    /// with the double nearest each crossing, and by 1e-17 to 6e-17 (its
    /// final state's rounding) from this one.
    /// `None` for a guard that is not affine, or a crossing past the step.
    pub fn sharpen(&mut self, crossing: &Crossing, x: &mut [f64]) -> Option<f64> {
        let n = x.len();
        if !self.inside(crossing.tau) || self.evaluated.borrow().1.len() != n {
            return None;
        }
        // The engine has just asked for the state there, as a rule.
        if self.evaluated.borrow().0 != crossing.tau {
            self.eval(crossing.tau, x);
        }
        let (_, hi, lo) = &*self.evaluated.borrow();
        let row = self.modes[self.mode]
            .as_ref()?
            .guard_rows
            .get(crossing.slot)?
            .as_deref()?;
        // The guard `c . x + d`, its products and sums carried exactly.
        let (c, d) = (&row[..n], row[n]);
        let (mut sum, mut error) = (d, 0.0);
        for ((c, x), lo) in c.iter().zip(hi).zip(lo) {
            let (product, product_error) = two_prod(*c, *x);
            let (next, sum_error) = two_sum(sum, product);
            sum = next;
            error += product_error + sum_error + c * lo;
        }
        // The flow there, from the step's series.
        let (w, tau) = (ORDER + 1, crossing.tau);
        let series = self.series.borrow();
        let rate = |i: usize| {
            let terms = &series[i * w..(i + 1) * w];
            (1..w)
                .rev()
                .fold(0.0, |sum, k| sum * tau + k as f64 * terms[k])
        };
        let slope: f64 = c.iter().enumerate().map(|(i, c)| c * rate(i)).sum();
        let shift = -(sum + error) / slope;
        // The search found the double nearest the crossing: a shift beyond
        // a few of its ulps is no refinement (and the state moves to first
        // order only, its second order below 1e-20 of the step's swing
        // here); nor may it go before the step's start.
        let polish = (8.0 * f64::EPSILON * tau.abs().max(self.h * 1e-8)).min(crossing.reach);
        if !shift.is_finite() || shift.abs() > polish || tau + shift < 0.0 {
            return None;
        }
        for (i, x) in x.iter_mut().enumerate() {
            *x = hi[i] + (lo[i] + rate(i) * shift);
        }
        Some(shift)
    }

    /// Where the model gives its guards' series: the first crossing of
    /// `guard` in the step on its series, as Taylor's method finds it (see
    /// [`crate::engine::step::taylor_method`]); `None` where the step is to be scanned.
    pub fn locate<M: HybridModel + ?Sized>(
        &mut self,
        model: &M,
        mode: Mode,
        guard: usize,
        start: Start,
        uncertainty: f64,
    ) -> Option<Result<StepScan, String>> {
        if !model.has_series(mode) {
            return None;
        }
        let w = ORDER + 1;
        self.guard
            .copy_from_slice(&self.guards[guard * w..(guard + 1) * w]);
        let scan = crate::engine::step::taylor_method::locate_on_series(
            model,
            mode,
            guard,
            &mut self.guard,
            self.h,
            start,
            uncertainty,
        );
        Some(scan.map(|scan| self.crossed_by_the_end(model, mode, guard, start, scan)))
    }

    /// `scan`, or a crossing at the step's end where the series found none
    /// but the step going on from the end starts past the surface: the
    /// series, its terms rounded to double, and the end with what its
    /// rounding left out may disagree about a crossing within an ulp of
    /// the end, and the next step, starting past it, would never see it (a
    /// crossing at `t_end` was lost so).
    fn crossed_by_the_end<M: HybridModel + ?Sized>(
        &self,
        model: &M,
        mode: Mode,
        guard: usize,
        start: Start,
        scan: StepScan,
    ) -> StepScan {
        let row = self.modes[self.mode]
            .as_ref()
            .and_then(|solved| solved.guard_rows.get(guard)?.as_deref());
        let (Some(row), None, Start::Armed) = (row, scan.crossing, start) else {
            return scan;
        };
        // The guard's first term in the step that goes on from here, as
        // that step will sum it (see `guard_series`): what decides whether
        // that step starts before the surface or past it.
        let n = self.y1.len();
        let (c, d) = (&row[..n], row[n]);
        let mut at_end = c.iter().zip(&self.y1).fold(0.0, |sum, (c, x)| sum + c * x) + d;
        if self.carry.iter().any(|lo| *lo != 0.0) {
            at_end += c
                .iter()
                .zip(&self.carry)
                .fold(0.0, |sum, (c, lo)| sum + c * lo);
        }
        let size = c
            .iter()
            .zip(&self.y1)
            .fold(d.abs(), |size, (c, x)| size + (c * x).abs());
        // Only an end within rounding of the surface can disagree.
        if at_end.abs() > 64.0 * f64::EPSILON * size {
            return scan;
        }
        let w = ORDER + 1;
        let series_end = eval(&self.guards[guard * w..(guard + 1) * w], self.h);
        if model.guards(mode)[guard]
            .direction
            .accepts(series_end, at_end)
        {
            StepScan {
                crossing: Some(1.0),
                ..scan
            }
        } else {
            scan
        }
    }

    /// Propagator evaluations so far: the steps and exponentials taken.
    pub fn evaluations(&self) -> u64 {
        self.evaluations.get()
    }

    /// The truncation of one propagation's series: below 7e-21 of the
    /// state, nothing beside the step's rounding (which the engine adds:
    /// see `STEP_ROUNDING_ULPS` in `src/engine/run/simulation/bounds.rs`) and, where
    /// sines of the clock drive the flow, what their values' rounding at
    /// the step's start leaves ([`Linear::forcing_error`], which the engine
    /// adds to it).
    pub fn local_error(&self) -> f64 {
        0.0
    }

    /// What the step of `h` errs by for reading the clock: the step starts
    /// from the exact time ([`Linear::clock_at`]), so only its waves' own
    /// rounding ([`AffineMode::wave_error`]; zero where none drives the
    /// mode).
    pub fn forcing_error(&self, h: f64) -> f64 {
        self.modes
            .get(self.mode)
            .and_then(Option::as_ref)
            .map_or(0.0, |solved| solved.wave_error(h))
    }

    /// The state at the end of the step.
    pub fn end(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.y1);
    }
}
