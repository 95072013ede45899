//! Closed forms of the bundled automata that have one, which the stress
//! suite measures every method against. An automaton's own reference is
//! its tightest run (the linear propagator, or Taylor's method at machine
//! precision), which shares whatever the engine gets wrong: these do not.
//!
//! - `bouncing_ball`: flights of `2 e^k v1 / g` after the first landing at
//!   `(v0 + v1) / g`, `v1 = sqrt(v0^2 + 2 g y0)`; the bounces pile up at
//!   the Zeno point.
//! - `mechanism`: the strain form's exact orbit (impacts every `T_imp`),
//!   the built-in model's closed form.
//! - `rocking_block_linear`: `theta = c + (theta0 - c) cosh(p s) + (omega0
//!   / p) sinh(p s)` about the centre `c = +-alpha` of each side; from the
//!   ground the next impact comes after `(2 / p) atanh(|omega| / (p
//!   alpha))`, and each impact keeps `1 - 1.5 sin^2 alpha` of the rate.
//! - `impact_oscillator`: the damped, forced oscillator's particular plus
//!   free solution from each impact, the next impact its first rise to the
//!   stop, bracketed on a fine grid and bisected to the last bit.
//!
//! Each is evaluated in `f64` from the scene's own parameters and initial
//! values (so an edited file is measured against its own closed form); the
//! reference states its own rounding, which the suite adds to each run's
//! bounds.

use std::sync::Arc;

use crate::models::automaton::{AutomatonScene, Definition};
use crate::models::mechanism::{ExactOrbit, Mechanism};
use crate::scene::Reference;
use crate::scene::{Scene, SceneError};

/// The closed form of the bundled automaton `case`, if it has one.
pub fn reference(case: &str, scene: &Scene) -> Option<Result<Reference, SceneError>> {
    let automaton = scene.downcast_ref::<AutomatonScene>()?;
    let (d, t_end) = (&automaton.definition, automaton.t_end);
    let closed = match case {
        "bouncing_ball" => bouncing_ball,
        "mechanism" => mechanism,
        "rocking_block_linear" => rocking_block_linear,
        "impact_oscillator" => impact_oscillator,
        _ => return None,
    };
    Some(closed(d, t_end))
}

/// The value of parameter or initial state `name`.
fn value(d: &Definition, name: &str) -> Result<f64, SceneError> {
    d.parameters
        .iter()
        .find(|(p, _)| p == name)
        .map(|(_, v)| *v)
        .or_else(|| {
            d.states
                .iter()
                .position(|s| s == name)
                .map(|i| d.initial[i])
        })
        .ok_or_else(|| {
            SceneError::field(
                "parameters",
                format!("the closed form needs `{name}`, which the file no longer has"),
            )
        })
}

/// A reference from a list of event times and the state at the end (empty
/// where the run ends at a Zeno point: judged by its events only).
fn from_events(times: Vec<f64>, events: u64, final_state: Vec<f64>, rounding: f64) -> Reference {
    let scale = final_state.iter().fold(1.0_f64, |m, x| m.max(x.abs()));
    let last = times.last().copied().unwrap_or(1.0).abs().max(1.0);
    let times = Arc::new(times);
    Reference::new("closed form", final_state, events, move |k| {
        usize::try_from(k)
            .ok()
            .and_then(|k| times.get(k).copied())
            .unwrap_or(f64::NAN)
    })
    .with_bounds(rounding * scale, rounding * last)
}

fn bouncing_ball(d: &Definition, t_end: f64) -> Result<Reference, SceneError> {
    let (g, e) = (value(d, "g")?, value(d, "e")?);
    let (y0, v0) = (value(d, "y")?, value(d, "v")?);
    let v1 = (v0 * v0 + 2.0 * g * y0).sqrt();
    let t1 = (v0 + v1) / g;
    // Bounce k (from 0) at t1 + (2 v1 / g)(e + ... + e^k).
    let time = move |k: u64| {
        let sum = if e == 1.0 {
            k as f64
        } else {
            e * (1.0 - e.powi(k as i32)) / (1.0 - e)
        };
        t1 + 2.0 * v1 / g * sum
    };
    let zeno = if e < 1.0 {
        t1 + 2.0 * v1 * e / (g * (1.0 - e))
    } else {
        f64::INFINITY
    };
    if t_end >= zeno {
        return Ok(Reference::new("closed form", Vec::new(), u64::MAX, time)
            .with_bounds(0.0, 64.0 * f64::EPSILON * zeno));
    }
    let times: Vec<f64> = (0..).map(time).take_while(|&t| t <= t_end).collect();
    let state = match times.last() {
        None => (y0 + v0 * t_end - 0.5 * g * t_end * t_end, v0 - g * t_end),
        Some(&last) => {
            let up = e.powi(times.len() as i32) * v1;
            let s = t_end - last;
            (up * s - 0.5 * g * s * s, up - g * s)
        }
    };
    let events = times.len() as u64;
    Ok(from_events(
        times,
        events,
        vec![state.0, state.1],
        64.0 * f64::EPSILON,
    ))
}

fn mechanism(d: &Definition, t_end: f64) -> Result<Reference, SceneError> {
    let m = Mechanism {
        eta: value(d, "eta")?,
        omega: value(d, "omega")?,
    };
    let orbit = ExactOrbit::new(m, value(d, "strain")?, value(d, "strain_rate")?);
    let events = orbit.impacts_until(t_end);
    let (eps, rate) = orbit.state_at(t_end);
    Ok(
        Reference::new("closed form", vec![eps, rate], events, move |k| {
            orbit.impact_time(k)
        })
        .with_bounds(
            64.0 * f64::EPSILON * (events as f64).max(1.0),
            64.0 * f64::EPSILON * t_end,
        ),
    )
}

fn rocking_block_linear(d: &Definition, t_end: f64) -> Result<Reference, SceneError> {
    let (g, b, h) = (value(d, "g")?, value(d, "b")?, value(d, "h")?);
    let alpha = (b / h).atan();
    let p = (3.0 * g / (4.0 * b.hypot(h))).sqrt();
    let keep = 1.0 - 1.5 * alpha.sin().powi(2);
    let (mut theta, mut rate) = (value(d, "theta")?, value(d, "theta_rate")?);
    // The side it starts on: its mode's name, `right` (theta > 0) or `left`.
    let right = d.modes[d.initial_mode].name == "right";
    let mut centre = if right { alpha } else { -alpha };
    let along = |theta: f64, rate: f64, centre: f64, s: f64| {
        let (sh, ch) = ((p * s).sinh(), (p * s).cosh());
        (
            centre + (theta - centre) * ch + rate / p * sh,
            p * (theta - centre) * sh + rate * ch,
        )
    };
    let (mut t, mut times) = (0.0, Vec::new());
    loop {
        // The next return to theta = 0 from (theta, rate) about `centre`.
        let flight = if theta == 0.0 {
            let ratio = rate / (p * centre);
            (ratio > 0.0 && ratio < 1.0).then(|| 2.0 / p * ratio.atanh())
        } else {
            // From rest away from the ground: cosh(p s) = c / (c - theta).
            let ratio = centre / (centre - theta);
            (rate == 0.0 && ratio >= 1.0).then(|| ratio.acosh() / p)
        };
        match flight {
            Some(s) if t + s <= t_end => {
                let (_, at) = along(theta, rate, centre, s);
                t += s;
                times.push(t);
                (theta, rate, centre) = (0.0, keep * at, -centre);
            }
            _ => {
                let (x, v) = along(theta, rate, centre, t_end - t);
                let events = times.len() as u64;
                return Ok(from_events(times, events, vec![x, v], 256.0 * f64::EPSILON));
            }
        }
    }
}

fn impact_oscillator(d: &Definition, t_end: f64) -> Result<Reference, SceneError> {
    let (zeta, w) = (value(d, "zeta")?, value(d, "w")?);
    let (stop, keep) = (value(d, "s")?, value(d, "r")?);
    let (mut x, mut v) = (value(d, "x")?, value(d, "v")?);
    // x = X cos(w t) + Y sin(w t) + exp(-zeta s) (C1 cos(wd s) + C2 sin(wd s)).
    let denominator = (1.0 - w * w).powi(2) + (2.0 * zeta * w).powi(2);
    let (px, py) = ((1.0 - w * w) / denominator, 2.0 * zeta * w / denominator);
    let wd = (1.0 - zeta * zeta).sqrt();
    let forced = |t: f64| {
        let (s, c) = (w * t).sin_cos();
        (px * c + py * s, w * (py * c - px * s))
    };
    // The state at t from (x0, v0) at t0, no stop.
    let free = |t0: f64, (x0, v0): (f64, f64), t: f64| {
        let (fx, fv) = forced(t0);
        let c1 = x0 - fx;
        let c2 = (v0 - fv + zeta * c1) / wd;
        let s = t - t0;
        let (sn, cs) = (wd * s).sin_cos();
        let decay = (-zeta * s).exp();
        let (gx, gv) = forced(t);
        (
            gx + decay * (c1 * cs + c2 * sn),
            gv + decay * ((wd * c2 - zeta * c1) * cs - (wd * c1 + zeta * c2) * sn),
        )
    };
    let (mut t0, mut times) = (0.0, Vec::new());
    let grid = 1e-3;
    loop {
        let gap = |t: f64| free(t0, (x, v), t).0 - stop;
        // The first rise to the stop after t0 (bracketed, then bisected).
        let mut a = t0;
        let next = loop {
            let b = (a + grid).min(t_end);
            if gap(a) < 0.0 && gap(b) >= 0.0 {
                let (mut lo, mut hi) = (a, b);
                while hi - lo > 2.0 * f64::EPSILON * hi {
                    let mid = 0.5 * (lo + hi);
                    if gap(mid) < 0.0 { lo = mid } else { hi = mid }
                }
                break Some(hi);
            }
            if b >= t_end {
                break None;
            }
            a = b;
        };
        match next {
            Some(t) => {
                let (_, vt) = free(t0, (x, v), t);
                times.push(t);
                (t0, x, v) = (t, stop, -keep * vt);
            }
            None => {
                let (xe, ve) = free(t0, (x, v), t_end);
                let events = times.len() as u64;
                return Ok(from_events(
                    times,
                    events,
                    vec![xe, ve, t_end],
                    1e3 * f64::EPSILON,
                ));
            }
        }
    }
}
