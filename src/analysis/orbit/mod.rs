//! Periodic orbits of any model that gives a [`Family`]: found by Newton
//! shooting through a
//! Poincare section ([`shooting`]), from the section map and its Jacobian
//! ([`section`]: saltation matrices included), and followed in a parameter
//! ([`continuation`]), drawn over the brute-force diagram ([`diagram`]).
//!
//! The section is the events of one guard (an impact); `K` of them make a
//! period. For an automaton that reads the clock (a forced system), the
//! period must be a whole number of the forcing's period, which the search
//! is told. `flicker orbit` and `flicker continue` write what these
//! find.

pub mod continuation;
pub mod diagram;
pub mod grazing;
mod json;
pub mod section;
pub mod shooting;

use crate::engine::{Family, HybridModel, Mode, Name, Observer, Options, Status, simulate};
use crate::scene::SceneError;
pub use section::Section;
pub use shooting::{Orbit, OrbitRequest, Unknowns};

/// Check `request` against `model` over `modes` modes (the guard exists,
/// at least one event per period, a forcing period exactly where the clock
/// is read).
pub fn check(
    model: &dyn HybridModel,
    modes: usize,
    request: &OrbitRequest,
) -> Result<(), SceneError> {
    crate::analysis::section_records::check_section(model, modes, &request.guard)?;
    if request.events == 0 {
        return Err(SceneError::field(
            "events",
            "at least one section event per period".into(),
        ));
    }
    if !(request.settle.is_finite() && request.settle >= 0.0) {
        return Err(SceneError::field("settle", "a time >= 0".into()));
    }
    match (model.clock().is_some(), request.forcing_period) {
        (true, None) => Err(SceneError::field(
            "forcing_period",
            "the model reads the clock t: give the forcing's period (--forcing-period), of which the orbit's is a whole number".into(),
        )),
        (false, Some(_)) => Err(SceneError::field(
            "forcing_period",
            "the model does not read the clock: an autonomous orbit has no forcing period".into(),
        )),
        (_, Some(p)) if !(p.is_finite() && p > 0.0) => Err(SceneError::field(
            "forcing_period",
            format!("a time > 0 (got {p})"),
        )),
        _ => Ok(()),
    }
}

/// Where the search starts: the state just after the first section event
/// from `x0` in `mode`, once `settle` has passed.
pub fn start(
    section: &Section,
    mode: Mode,
    x0: &[f64],
    settle: f64,
    observer: &mut dyn Observer,
) -> Result<(Mode, Vec<f64>), String> {
    let (mut mode, mut x) = (mode, x0.to_vec());
    if settle > 0.0 {
        let options = Options {
            stop: section.stop.cloned(),
            method: section.method(section.model),
            max_wall_seconds: section.deadline.map(|d| {
                d.saturating_duration_since(std::time::Instant::now())
                    .as_secs_f64()
            }),
            ..Options::until(settle)
        };
        let outcome = simulate(section.model, mode, &x, &options, observer);
        if outcome.status != Status::Completed {
            return Err(format!(
                "the transient stopped at t = {}: {}",
                outcome.t_reached,
                outcome.reason.unwrap_or_default()
            ));
        }
        (mode, x) = (outcome.final_mode, outcome.final_state);
    }
    let first = Section {
        events: 1,
        ..*section
    };
    let (_, mode, x) = first.plain(mode, &x)?;
    Ok((mode, x))
}

/// Who hears how a search goes (nobody by default): the transient's run,
/// as any run's observer (its progress), and each Newton iteration's
/// residual.
#[derive(Default)]
pub struct Watch<'a> {
    /// The observer of the transient's run.
    pub transient: Option<&'a mut dyn Observer>,
    /// Told each Newton iteration and its residual.
    pub newton: Option<&'a mut dyn FnMut(usize, f64)>,
}

/// The periodic orbit of `family`'s model (from its start, after
/// `request.settle`) through the section `request` names; every return
/// within `t_max`.
pub fn search(
    family: &dyn Family,
    request: &OrbitRequest,
    t_max: f64,
    watch: Watch<'_>,
) -> Result<Orbit, SceneError> {
    let model = family.model();
    check(model, family.modes(), request)?;
    let section = Section {
        family,
        model,
        guard: &request.guard,
        events: request.events,
        t_max,
        stop: request.stop.as_ref(),
        deadline: request.deadline,
    };
    let n = model.dimension();
    let unknowns = Unknowns {
        free: (0..n).collect(),
        clock: request
            .forcing_period
            .zip(model.clock())
            .map(|(p, c)| (c, p)),
    };
    let (mode0, x0) = family.start();
    let mut nobody = ();
    let transient: &mut dyn Observer = match watch.transient {
        Some(observer) => observer,
        None => &mut nobody,
    };
    let (mode, x) = match start(&section, mode0, &x0, request.settle, transient) {
        Ok(start) => start,
        Err(why) => {
            return Ok(Orbit {
                converged: false,
                status: format!("no start on the section: {why}"),
                period: f64::NAN,
                events_per_period: request.events,
                mode: model.mode_name(mode0).into(),
                section_state: Vec::new(),
                multipliers: Vec::new(),
                stable: false,
                residual: f64::NAN,
                iterations: 0,
                residuals: Vec::new(),
            });
        }
    };
    let mut quiet = |_: usize, _: f64| {};
    let newton: &mut dyn FnMut(usize, f64) = match watch.newton {
        Some(newton) => newton,
        None => &mut quiet,
    };
    Ok(shooting::shoot(&section, &unknowns, mode, x, newton))
}

/// A followed branch, the names of the state's components, and the
/// parameter's component among them.
pub type ContinuedBranch = (continuation::Branch, Vec<Name>, usize);

/// A branch of orbits of `family`'s model followed in its parameter
/// `parameter` to `to` (at most `points` orbits, the longest step
/// `max_step` of the way), from the orbit found as `request` asks; every
/// return within `t_max`; `on_point` hears of each orbit as it is found.
pub fn follow(
    family: &dyn Family,
    request: &OrbitRequest,
    parameter: &str,
    to: f64,
    (points, max_step): (usize, f64),
    t_max: f64,
    on_point: &mut dyn FnMut(&continuation::Point),
) -> Result<ContinuedBranch, SceneError> {
    if !(max_step.is_finite() && max_step > 0.0 && max_step <= 1.0) {
        return Err(SceneError::field(
            "max_step",
            format!("a fraction in (0, 1] (got {max_step})"),
        ));
    }
    if !to.is_finite() {
        return Err(SceneError::field(
            "to",
            format!("a finite number (got {to})"),
        ));
    }
    if request.forcing_period.is_some() && family.moves_the_forcing(parameter) {
        return Err(SceneError::field(
            "param",
            format!(
                "`{parameter}` enters a function of the clock with it (a forcing's frequency): the \
                 forcing's period would move with it, and --forcing-period holds it fixed; follow \
                 another parameter"
            ),
        ));
    }
    let promoted = family
        .promoted(&[parameter.to_string()])
        .map_err(|why| SceneError::field("param", why))?;
    let model = &*promoted.model;
    check(model, family.modes(), request)?;
    let n = model.dimension();
    let p = promoted.parameters[0];
    let section = Section {
        family,
        model,
        guard: &request.guard,
        events: request.events,
        t_max,
        stop: request.stop.as_ref(),
        deadline: request.deadline,
    };
    let unknowns = Unknowns {
        free: (0..n).filter(|&i| i != p).collect(),
        clock: request
            .forcing_period
            .zip(model.clock())
            .map(|(period, c)| (c, period)),
    };
    // The section state's names, in the mode the section is in.
    let names_in = |mode: Mode| shooting::names(&section, mode, n, Some((p, parameter)));
    let names = names_in(promoted.mode);
    let (mode, x) = match start(
        &section,
        promoted.mode,
        &promoted.start,
        request.settle,
        &mut (),
    ) {
        Ok(start) => start,
        Err(why) => {
            let branch = continuation::Branch {
                points: Vec::new(),
                ended: format!("no start on the section: {why}"),
            };
            return Ok((branch, names, p));
        }
    };
    let names = names_in(mode);
    let orbit = shooting::shoot(&section, &unknowns, mode, x.clone(), &mut |_, _| {});
    if !orbit.converged {
        let branch = continuation::Branch {
            points: Vec::new(),
            ended: format!("no orbit at the start: {}", orbit.status),
        };
        return Ok((branch, names, p));
    }
    let x: Vec<f64> = orbit.section_state.iter().map(|(_, v)| *v).collect();
    let plan = continuation::Plan {
        parameter: p,
        to,
        points,
        step: (0.2 * max_step, max_step),
    };
    Ok((
        continuation::follow(&section, &unknowns, mode, x, &plan, on_point),
        names,
        p,
    ))
}
