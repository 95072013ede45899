//! Lyapunov spectra through impacts (`flicker lyapunov`), on any model
//! that gives a [`Family`]: Benettin's method with QR re-orthonormalisation.
//!
//! `K` tangent vectors ride with the state as the model's derivatives
//! ([`Variational`]): along each flow the variational equations, and at
//! each event its saltation matrix, which is what makes the spectrum right
//! through impacts (a plain variational run would miss the jump of the
//! tangent at every impact). Every `interval` the vectors are
//! re-orthonormalised, `S = Q R`; the logarithms of `|R_ii|` summed over
//! the run, divided by its span, are the exponents, largest first. A
//! forced system's clock is a direction like any other: its exponent is 0,
//! and it is reported, not hidden.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use nalgebra::DMatrix;
use serde_json::{Value, json};

use crate::engine::bound::variational::Variational;
use crate::engine::step::method::{Method, tightest};
use crate::engine::{Family, Options, Status, simulate};

/// Tolerance of the runs where the flows (with their derivatives) are not
/// all linear.
const TOLERANCE: f64 = 1e-12;

/// Rows of the convergence history kept at most (the last is always the
/// end).
const HISTORY: usize = 400;

/// What a spectrum asks for.
#[derive(Debug, Clone)]
pub struct Request {
    /// How many exponents, the largest first (at most the dimension).
    pub exponents: usize,
    /// Time run first, without tangents, for a transient to die out.
    pub transient: f64,
    /// Time over which the exponents are averaged, after the transient.
    pub span: f64,
    /// Time between re-orthonormalisations.
    pub interval: f64,
    /// Set from outside (Ctrl-C) to end the spectrum at the next interval.
    pub stop: Option<Arc<AtomicBool>>,
    /// When the spectrum must end (`--wall`): it stops there, saying so,
    /// keeping what it measured.
    pub deadline: Option<Instant>,
}

/// A spectrum, as far as it got.
#[derive(Debug, Clone, PartialEq)]
pub struct Spectrum {
    /// The exponents, largest first.
    pub exponents: Vec<f64>,
    /// The time they are averaged over.
    pub t_span: f64,
    /// Events over that time.
    pub events: u64,
    /// The exponents after each interval (at most 400 rows,
    /// evenly spread): `(t, exponents)`.
    pub history: Vec<(f64, Vec<f64>)>,
    /// The method the tangents were carried by.
    pub method: Method,
    /// `completed`, or why the spectrum stopped short.
    pub status: String,
}

impl Spectrum {
    /// The contents of `lyapunov.json`: the spectrum of `scene` as
    /// `request` asked.
    pub fn to_json(&self, request: &Request, scene: &Path) -> Value {
        let history: Vec<Value> = self
            .history
            .iter()
            .map(|(t, exponents)| json!({"t": t, "exponents": exponents}))
            .collect();
        json!({
            "scene": scene.display().to_string(),
            "status": self.status,
            "exponents": self.exponents,
            "sum": self.exponents.iter().sum::<f64>(),
            "t_span": self.t_span,
            "events": self.events,
            "transient": request.transient,
            "interval": request.interval,
            "method": self.method.name(),
            "history": history,
        })
    }

    /// Whether it ran its whole span.
    pub fn completed(&self) -> bool {
        self.status == "completed"
    }
}

/// Check `request` against `family` before anything runs; the error says
/// which field is wrong and why.
pub fn check(family: &dyn Family, request: &Request) -> Result<(), (&'static str, String)> {
    let n = family.model().dimension();
    if request.exponents == 0 || request.exponents > n {
        return Err((
            "exponents",
            format!(
                "between 1 and the state's dimension, {n} (got {})",
                request.exponents
            ),
        ));
    }
    let positive = |field: &'static str, x: f64| {
        if x.is_finite() && x > 0.0 {
            Ok(())
        } else {
            Err((field, format!("a time > 0 (got {x})")))
        }
    };
    positive("t_end", request.span)?;
    positive("interval", request.interval)?;
    if !(request.transient.is_finite() && request.transient >= 0.0) {
        return Err((
            "transient",
            format!("a time >= 0 (got {})", request.transient),
        ));
    }
    if request.interval > request.span {
        return Err((
            "interval",
            format!(
                "longer than the span {} (got {})",
                request.span, request.interval
            ),
        ));
    }
    Ok(())
}

/// The spectrum of `family`'s model from its start, as `request` asks;
/// `progress` hears the time and the events reached after each interval.
pub fn spectrum(
    family: &dyn Family,
    request: &Request,
    progress: &mut dyn FnMut(f64, u64),
) -> Spectrum {
    let model = family.model();
    let modes = family.modes();
    let n = model.dimension();
    let k = request.exponents;
    let directions: Vec<String> = (0..k).map(|j| format!("v{j}")).collect();
    let variational = Variational::new(model, modes, &directions);
    // Tangents are never a closed form: the propagator or DOP853.
    let method = tightest(&variational, modes, TOLERANCE);
    let mut spectrum = Spectrum {
        exponents: vec![f64::NAN; k],
        t_span: 0.0,
        events: 0,
        history: Vec::new(),
        method,
        status: "completed".into(),
    };
    let (mut mode, mut x) = family.start();
    if request.transient > 0.0 {
        // The transient carries no tangents: a closed form runs it exactly.
        let options = Options {
            method: tightest(model, modes, TOLERANCE),
            stop: request.stop.clone(),
            max_wall_seconds: request
                .deadline
                .map(|d| d.saturating_duration_since(Instant::now()).as_secs_f64()),
            ..Options::until(request.transient)
        };
        let outcome = simulate(model, mode, &x, &options, &mut ());
        if outcome.status != Status::Completed {
            spectrum.status = format!(
                "the transient {} at t = {}: {}",
                outcome.status.as_str(),
                outcome.t_reached,
                outcome.reason.unwrap_or_default()
            );
            return spectrum;
        }
        (mode, x) = (outcome.final_mode, outcome.final_state);
    }
    let mut basis: Vec<Vec<f64>> = (0..k)
        .map(|j| (0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    let mut sums = vec![0.0; k];
    let intervals = (request.span / request.interval).ceil().max(1.0) as usize;
    let keep_every = intervals.div_ceil(HISTORY).max(1);
    let mut t = 0.0;
    for step in 0..intervals {
        if request
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            spectrum.status = format!("interrupted at t = {t}");
            break;
        }
        if request.deadline.is_some_and(|d| Instant::now() >= d) {
            spectrum.status = format!(
                "stopped at t = {t} of {}: past the wall-clock budget (--wall)",
                request.span
            );
            break;
        }
        // The interval's end from its count, so no rounding accumulates.
        let end = if step + 1 == intervals {
            request.span
        } else {
            request.interval * (step + 1) as f64
        };
        let h = end - t;
        let options = Options {
            method,
            stop: request.stop.clone(),
            max_wall_seconds: request
                .deadline
                .map(|d| d.saturating_duration_since(Instant::now()).as_secs_f64()),
            ..Options::until(h)
        };
        let start = variational.initial(&x, &basis);
        let outcome = simulate(&variational, mode, &start, &options, &mut ());
        if outcome.status != Status::Completed {
            spectrum.status = if request.deadline.is_some_and(|d| Instant::now() >= d) {
                format!(
                    "stopped at t = {t} of {}: past the wall-clock budget (--wall)",
                    request.span
                )
            } else {
                format!(
                    "the run {} at t = {}: {}",
                    outcome.status.as_str(),
                    t + outcome.t_reached,
                    outcome.reason.unwrap_or_default()
                )
            };
            break;
        }
        spectrum.events += outcome.events;
        let tangents = DMatrix::from_fn(n, k, |i, j| {
            variational.sensitivity(&outcome.final_state, j)[i]
        });
        if !tangents.iter().all(|v| v.is_finite()) {
            spectrum.status = format!("the tangents left the finite numbers at t = {}", t + h);
            break;
        }
        let qr = tangents.qr();
        let (q, r) = (qr.q(), qr.r());
        for j in 0..k {
            sums[j] += r[(j, j)].abs().ln();
            basis[j] = q.column(j).iter().copied().collect();
        }
        t = end;
        mode = outcome.final_mode;
        x = outcome.final_state[..n].to_vec();
        spectrum.t_span = t;
        spectrum.exponents = largest_first(sums.iter().map(|s| s / t).collect());
        if (step + 1) % keep_every == 0 {
            spectrum.history.push((t, spectrum.exponents.clone()));
        }
        progress(t, spectrum.events);
    }
    // The last row is where the spectrum ended, whole or stopped short.
    if t > 0.0 && spectrum.history.last().is_none_or(|(last, _)| *last < t) {
        spectrum.history.push((t, spectrum.exponents.clone()));
    }
    spectrum
}

/// QR keeps the order the vectors grow in only on average (and not at all
/// among exponents that tend to the same value): the exponents are
/// reported sorted.
fn largest_first(mut exponents: Vec<f64>) -> Vec<f64> {
    exponents.sort_by(|a, b| b.total_cmp(a));
    exponents
}
