//! Basins of attraction (`flicker basins`): a grid of starting values of
//! two states, each run past a transient and named by the attractor it
//! reaches, the attractors gathered across the grid.
//!
//! A point's run goes `transient` (the other states from the scene), then
//! a tenth of that again: a state that moved less than the tolerance over
//! that tenth has settled on an **equilibrium** (or a resting mode).
//! Otherwise, with a section guard, the states just after its next
//! `record` events are read for a repeat: the smallest `k` with every
//! record within the tolerance of the one `k` before is a **periodic**
//! orbit of `k` section events. A run that ends at an accumulation of
//! events is a **Zeno** point; anything else (no repeat within the
//! record, no section, a run that failed) is **unresolved**, said so
//! rather than guessed.
//!
//! Each point is one run of the model by the tightest method the tools
//! run (the closed form, the linear propagator, or DOP853 at
//! the diagram's [`TOLERANCE`](crate::analysis::diagram::TOLERANCE)), the points in parallel. States are compared without a
//! clock the model carries as a state, which never repeats: a forced
//! system's section states carry its phase in its other states.
//!
//! Each periodic orbit found is then refined by the orbit finder from one
//! of its section states ([`crate::analysis::orbit::search`]): its period
//! in time and its multipliers, where the finder converges. A forced
//! model (one that reads the clock) is refined only when told its
//! forcing's period (`--forcing-period`), of which the orbit's is a whole
//! number; without it the orbit keeps its period in section events.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use crate::analysis::lyapunov;
use crate::analysis::orbit::{Orbit, OrbitRequest, Watch};
use crate::analysis::section_records::{SectionRecords, check_section};
use crate::analysis::spacing::evenly_spaced;
use crate::analysis::started_at::StartedAt;
use crate::engine::{Family, Limits, MAX_EVENTS, Mode, Status, Tolerances, simulate};

/// Most points a grid may have.
pub const MAX_POINTS: usize = 10_000_000;

/// Most section events read at a point.
pub const MAX_RECORD: usize = 10_000;

/// One axis of the grid: a state's starting values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// The state, by its name in the scene.
    pub state: String,
    /// Its first value.
    pub from: f64,
    /// Its last value.
    pub to: f64,
    /// How many values, evenly spaced.
    pub count: usize,
}

impl Axis {
    /// The axis written `NAME=A:B:N`.
    pub fn parse(text: &str) -> Result<Axis, String> {
        let bad = || format!("{text:?} is not of the form STATE=A:B:N");
        let (state, range) = text.split_once('=').ok_or_else(bad)?;
        let parts: Vec<&str> = range.split(':').collect();
        let [from, to, count] = parts[..] else {
            return Err(bad());
        };
        let number = |s: &str| s.trim().parse::<f64>().map_err(|_| bad());
        Ok(Axis {
            state: state.trim().to_string(),
            from: number(from)?,
            to: number(to)?,
            count: count.trim().parse().map_err(|_| bad())?,
        })
    }

    /// Its values, from `from` to `to`.
    pub fn values(&self) -> Vec<f64> {
        evenly_spaced(self.from, self.to, self.count)
    }
}

/// Basins as asked.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The two axes: the first varies slowest.
    pub axes: [Axis; 2],
    /// Time run before a point is read.
    pub transient: f64,
    /// The guard whose events are read for a periodic orbit, if any.
    pub section: Option<String>,
    /// Section events read for a repeat.
    pub record: usize,
    /// How close two states must be to count as the same, relative to
    /// the larger of 1 and their size.
    pub tolerance: f64,
    /// The forcing's period, for a model that reads the clock: its
    /// periodic orbits are refined with it.
    pub forcing_period: Option<f64>,
}

/// What an attractor is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The state settles.
    Equilibrium,
    /// The section states repeat.
    Periodic,
    /// The section states do not repeat, and nearby orbits part: a
    /// positive largest Lyapunov exponent.
    Chaotic,
    /// The events accumulate.
    Zeno,
    /// None of these could be told.
    Unresolved,
}

impl Kind {
    /// Its name in `attractors.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Equilibrium => "equilibrium",
            Kind::Periodic => "periodic",
            Kind::Chaotic => "chaotic",
            Kind::Zeno => "zeno",
            Kind::Unresolved => "unresolved",
        }
    }
}

/// An attractor some points of the grid reach.
#[derive(Debug, Clone, PartialEq)]
pub struct Attractor {
    /// Its number, from 0 in the order the grid first meets it.
    pub id: usize,
    /// What it is.
    pub kind: Kind,
    /// A state on it: the equilibrium, the first section state of the
    /// orbit; for the Zeno points and the unresolved (each one class),
    /// where the first point's events accumulated or its run ended.
    pub state: Vec<f64>,
    /// The mode just after the orbit's first section event.
    pub mode: Mode,
    /// The orbit's section states, one per section event of its period.
    pub cycle: Vec<Vec<f64>>,
    /// The orbit as the orbit finder refined it, where it converged.
    pub orbit: Option<Orbit>,
    /// The largest Lyapunov exponent, where one was measured (for an
    /// orbit that does not repeat).
    pub exponent: Option<f64>,
    /// How many points reach it.
    pub points: usize,
    /// Why a point was left unresolved (the first such point's reason).
    pub reason: Option<String>,
}

/// The basins: each point's attractor and the attractors.
#[derive(Debug, Clone, PartialEq)]
pub struct Basins {
    /// The names of the state's components.
    pub names: Vec<String>,
    /// The grid's values on each axis.
    pub values: [Vec<f64>; 2],
    /// Each point's attractor, by id, the first axis varying slowest;
    /// `None` for a point not run (stopped).
    pub attractor: Vec<Option<usize>>,
    /// The attractors.
    pub attractors: Vec<Attractor>,
}

/// Check `request` against `family` before anything runs: the field at
/// fault (`grid`, `transient`, `section`, `record`, `tolerance`) and why.
pub fn check(family: &dyn Family, request: &Request) -> Result<(), (&'static str, String)> {
    let names = family.state_names();
    for axis in &request.axes {
        if !names.contains(&axis.state) {
            return Err((
                "grid",
                format!(
                    "no state is called `{}` (states: {})",
                    axis.state,
                    names.join(", ")
                ),
            ));
        }
        if !(axis.from.is_finite() && axis.to.is_finite()) || axis.count < 2 {
            return Err((
                "grid",
                format!("{}: finite bounds and at least 2 values", axis.state),
            ));
        }
    }
    if request.axes[0].state == request.axes[1].state {
        return Err(("grid", "two different states".into()));
    }
    if request.axes[0].count.saturating_mul(request.axes[1].count) > MAX_POINTS {
        return Err(("grid", format!("at most {MAX_POINTS} points")));
    }
    if !(request.transient.is_finite() && request.transient > 0.0) {
        return Err(("transient", "a finite time > 0".into()));
    }
    if let Some(section) = &request.section {
        check_section(family.model(), family.modes(), section)
            .map_err(|e| ("section", e.reason))?;
    }
    if !(2..=MAX_RECORD).contains(&request.record) {
        return Err(("record", format!("from 2 to {MAX_RECORD} events")));
    }
    if !(request.tolerance.is_finite() && request.tolerance > 0.0) {
        return Err(("tolerance", "a number > 0".into()));
    }
    match (
        request.forcing_period,
        family.model().clock(),
        &request.section,
    ) {
        (None, _, _) => Ok(()),
        (Some(_), None, _) => Err((
            "forcing_period",
            "the model does not read the clock: an autonomous orbit has no forcing period".into(),
        )),
        (Some(_), _, None) => Err((
            "forcing_period",
            "periodic orbits are refined through a section: give --section too".into(),
        )),
        (Some(p), _, _) if !(p.is_finite() && p > 0.0) => {
            Err(("forcing_period", format!("a time > 0 (got {p})")))
        }
        _ => Ok(()),
    }
}

/// What one point's run reached, before the grid's attractors are
/// gathered.
#[derive(Debug, Clone)]
enum Reached {
    Equilibrium(Vec<f64>),
    Periodic(Mode, Vec<Vec<f64>>),
    Zeno(Vec<f64>),
    /// No repeat within the record: where its last section event left it.
    Aperiodic(Mode, Vec<f64>),
    Unresolved(Vec<f64>, String),
    NotRun,
}

/// Run the points of `request` (checked by [`check`]) whose places are in
/// `indices` (row-major, the first axis slowest) on `family`, in
/// parallel, under `limits` (its stop flag and deadline end the work: the
/// points not begun are not run), `done` told of each point.
pub fn run(
    family: &dyn Family,
    request: &Request,
    indices: &[usize],
    limits: &Limits,
    done: &(dyn Fn() + Sync),
) -> Basins {
    let names = family.state_names();
    let values = [request.axes[0].values(), request.axes[1].values()];
    let slots = [0, 1].map(|k| {
        names
            .iter()
            .position(|n| *n == request.axes[k].state)
            .unwrap_or(0)
    });
    let model = family.model();
    let method = crate::analysis::diagram::method(model, family.modes());
    let (_, start) = family.start();
    let width = values[1].len();
    let kept: Vec<usize> = (0..names.len())
        .filter(|&i| Some(i) != model.clock())
        .collect();
    let reached: Vec<(usize, Reached)> = indices
        .par_iter()
        .map(|&index| {
            if limits.stopped() {
                return (index, Reached::NotRun);
            }
            let mut x0 = start.clone();
            x0[slots[0]] = values[0][index / width];
            x0[slots[1]] = values[1][index % width];
            let point = Point {
                family,
                request,
                limits,
                method,
                kept: &kept,
            };
            let (mode, x0) = family.start_from(&x0);
            let reached = point.reach(mode, &x0);
            done();
            (index, reached)
        })
        .collect();
    let mut basins = Basins {
        names,
        values,
        attractor: vec![None; request.axes[0].count * request.axes[1].count],
        attractors: Vec::new(),
    };
    for (index, reached) in reached {
        basins.attractor[index] = gather(&mut basins.attractors, reached, &kept, request.tolerance);
    }
    for attractor in &mut basins.attractors {
        match (attractor.kind, &request.section) {
            // A forced orbit's clock is an unknown of its own, pinned by
            // the forcing's period: without it there is nothing to refine.
            (Kind::Periodic, Some(section))
                if request.forcing_period.is_some() || family.model().clock().is_none() =>
            {
                attractor.orbit = refine(family, attractor, section, request, limits);
            }
            (Kind::Chaotic, _) => judge(family, attractor, request, limits),
            _ => {}
        }
    }
    basins
}

/// An `attractor` whose section states did not repeat: chaotic where its
/// largest Lyapunov exponent, over a transient's time from where its
/// first point's record ended, is positive beyond what the measurement's
/// length can tell from zero; unresolved otherwise, the exponent said.
fn judge(family: &dyn Family, attractor: &mut Attractor, request: &Request, limits: &Limits) {
    let started = StartedAt {
        family,
        mode: attractor.mode,
        state: attractor.state.clone(),
    };
    let span = request.transient;
    let asked = lyapunov::Request {
        exponents: 1,
        transient: 0.0,
        span,
        interval: span / 100.0,
        stop: limits.stop.clone(),
        deadline: limits.deadline,
    };
    let spectrum = lyapunov::spectrum(&started, &asked, &mut |_, _| {});
    let exponent = spectrum.exponents[0];
    attractor.exponent = exponent.is_finite().then_some(exponent);
    // A bounded orbit's exponent that does not part converges to zero as
    // 1 / span: ten times that is a parting, not a remainder.
    if !(spectrum.status == "completed" && exponent > 10.0 / span) {
        attractor.kind = Kind::Unresolved;
        attractor.reason = Some(format!(
            "no repeat within {} section events, and no positive exponent ({exponent:e}: {})",
            request.record, spectrum.status
        ));
    }
}

/// The periodic `attractor` refined by the orbit finder from its first
/// section state, each return within the transient, if the finder
/// converges.
fn refine(
    family: &dyn Family,
    attractor: &Attractor,
    section: &str,
    request: &Request,
    limits: &Limits,
) -> Option<Orbit> {
    let started = StartedAt {
        family,
        mode: attractor.mode,
        state: attractor.cycle[0].clone(),
    };
    let asked = OrbitRequest {
        guard: section.to_string(),
        events: attractor.cycle.len(),
        settle: 0.0,
        forcing_period: request.forcing_period,
        stop: limits.stop.clone(),
        deadline: limits.deadline,
    };
    crate::analysis::orbit::search(&started, &asked, request.transient, Watch::default())
        .ok()
        .filter(|orbit| orbit.converged)
}

/// One point's run and what it needs.
struct Point<'a> {
    family: &'a dyn Family,
    request: &'a Request,
    limits: &'a Limits,
    method: (crate::engine::Method, Tolerances),
    /// The components compared: all but an automaton's clock.
    kept: &'a [usize],
}

impl Point<'_> {
    /// Run from `x0` in `mode` and say what it reached.
    fn reach(&self, mode: Mode, x0: &[f64]) -> Reached {
        let model = self.family.model();
        let (method, tolerances) = self.method;
        let transient = self.request.transient;
        let options = self
            .limits
            .options(transient, MAX_EVENTS, method, tolerances);
        let first = simulate(model, mode, x0, &options, &mut ());
        match first.status {
            Status::Completed => {}
            Status::Zeno => return Reached::Zeno(first.final_state),
            Status::Interrupted => return Reached::NotRun,
            Status::Failed => {
                return Reached::Unresolved(first.final_state, reason(first.reason));
            }
        }
        let (mode, a) = (first.final_mode, first.final_state);
        let compared = |x: &[f64]| -> Vec<f64> { self.kept.iter().map(|&i| x[i]).collect() };
        // Settled: moved less than the tolerance over a tenth more.
        let options = self
            .limits
            .options(transient / 10.0, MAX_EVENTS, method, tolerances);
        let second = simulate(model, mode, &a, &options, &mut ());
        match second.status {
            Status::Completed
                if near(
                    &compared(&a),
                    &compared(&second.final_state),
                    self.request.tolerance,
                ) =>
            {
                return Reached::Equilibrium(second.final_state);
            }
            Status::Zeno => return Reached::Zeno(second.final_state),
            Status::Interrupted => return Reached::NotRun,
            _ => {}
        }
        let Some(section) = &self.request.section else {
            return Reached::Unresolved(a, "it had not settled, and no section was given".into());
        };
        // The section states, over at most the transient's length again.
        let own_stop = Arc::new(AtomicBool::new(false));
        let mut options = self
            .limits
            .options(transient, MAX_EVENTS, method, tolerances);
        options.stop = Some(own_stop.clone());
        let mut records = SectionRecords::new(
            section,
            (0.0, self.request.record),
            &own_stop,
            self.limits.stop.as_deref(),
        );
        let third = simulate(model, mode, &a, &options, &mut records);
        let full = records.full();
        match third.status {
            Status::Zeno => return Reached::Zeno(third.final_state),
            Status::Interrupted if !full => return Reached::NotRun,
            Status::Failed => return Reached::Unresolved(a, reason(third.reason)),
            _ => {}
        }
        let states: Vec<Vec<f64>> = records.kept.iter().map(|c| compared(&c.state)).collect();
        let modes: Vec<Mode> = records.kept.iter().map(|c| c.mode).collect();
        let raw: Vec<Vec<f64>> = records.kept.into_iter().map(|c| c.state).collect();
        if !full {
            return Reached::Unresolved(
                a,
                format!(
                    "{} section events in a transient's time, {} asked for",
                    states.len(),
                    self.request.record
                ),
            );
        }
        match period(&states, self.request.tolerance) {
            Some(k) => Reached::Periodic(modes[raw.len() - k], raw[raw.len() - k..].to_vec()),
            None => Reached::Aperiodic(modes[modes.len() - 1], raw[raw.len() - 1].clone()),
        }
    }
}

fn reason(why: Option<String>) -> String {
    why.unwrap_or_else(|| "no reason given".into())
}

/// Whether `a` and `b` agree to `tolerance` relative to the larger of 1
/// and their size, in every component.
fn near(a: &[f64], b: &[f64], tolerance: f64) -> bool {
    a.iter()
        .zip(b)
        .all(|(x, y)| (x - y).abs() <= tolerance * x.abs().max(y.abs()).max(1.0))
}

/// The smallest `k` (at most half the records) with every record within
/// the tolerance of the one `k` before.
fn period(states: &[Vec<f64>], tolerance: f64) -> Option<usize> {
    (1..=states.len() / 2)
        .find(|&k| (k..states.len()).all(|i| near(&states[i], &states[i - k], tolerance)))
}

/// The attractor `reached` is, found among `attractors` or added to them:
/// its id (`None` for a point not run).
fn gather(
    attractors: &mut Vec<Attractor>,
    reached: Reached,
    kept: &[usize],
    tolerance: f64,
) -> Option<usize> {
    // States gathered by the same attractor agree less tightly than a
    // run's repeat: the transient's remains differ from point to point.
    let loose = tolerance.sqrt().max(tolerance);
    let (kind, (mode, state), cycle, why) = match reached {
        Reached::NotRun => return None,
        Reached::Equilibrium(x) => (Kind::Equilibrium, (0, x), Vec::new(), None),
        Reached::Periodic(mode, cycle) => (Kind::Periodic, (mode, cycle[0].clone()), cycle, None),
        Reached::Zeno(x) => (Kind::Zeno, (0, x), Vec::new(), None),
        // Told chaotic or not once gathered, by its largest exponent.
        Reached::Aperiodic(mode, x) => (Kind::Chaotic, (mode, x), Vec::new(), None),
        Reached::Unresolved(x, why) => (Kind::Unresolved, (0, x), Vec::new(), Some(why)),
    };
    let same = |a: &Attractor| {
        a.kind == kind
            && match kind {
                Kind::Equilibrium => kept
                    .iter()
                    .all(|&i| near(&[a.state[i]], &[state[i]], loose)),
                // Every state of the one cycle is on the other.
                Kind::Periodic => {
                    a.cycle.len() == cycle.len()
                        && cycle.iter().all(|x| {
                            a.cycle
                                .iter()
                                .any(|y| kept.iter().all(|&i| near(&[x[i]], &[y[i]], loose)))
                        })
                }
                // One class for all the accumulations (a forced system's
                // each at its own phase), one for all that could not be
                // told.
                Kind::Zeno | Kind::Chaotic | Kind::Unresolved => true,
            }
    };
    if let Some(found) = attractors.iter_mut().find(|a| same(a)) {
        found.points += 1;
        return Some(found.id);
    }
    let id = attractors.len();
    attractors.push(Attractor {
        id,
        kind,
        mode,
        state,
        cycle,
        orbit: None,
        exponent: None,
        points: 1,
        reason: why,
    });
    Some(id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cycle_is_its_smallest_repeat_and_none_without_one() {
        let s = |x: f64| vec![x];
        let two = [s(1.0), s(2.0), s(1.0), s(2.0), s(1.0), s(2.0)];
        assert_eq!(period(&two, 1e-9), Some(2));
        let fixed = vec![s(1.0); 4];
        assert_eq!(period(&fixed, 1e-9), Some(1));
        let drift = [s(1.0), s(2.0), s(3.0), s(4.0)];
        assert_eq!(period(&drift, 1e-9), None);
        assert_eq!(Axis::parse("x=-1:2:31").unwrap().values().len(), 31);
        assert!(Axis::parse("x=-1:2").is_err());
    }

    #[test]
    fn the_same_attractor_is_gathered_once() {
        let mut found = Vec::new();
        let a = gather(
            &mut found,
            Reached::Equilibrium(vec![1.0, 0.0]),
            &[0, 1],
            1e-8,
        );
        let b = gather(
            &mut found,
            Reached::Equilibrium(vec![1.0 + 1e-6, 0.0]),
            &[0, 1],
            1e-8,
        );
        let c = gather(
            &mut found,
            Reached::Equilibrium(vec![-1.0, 0.0]),
            &[0, 1],
            1e-8,
        );
        assert_eq!((a, b, c), (Some(0), Some(0), Some(1)));
        assert_eq!(found[0].points, 2);
        let p = gather(
            &mut found,
            Reached::Periodic(0, vec![vec![1.0], vec![2.0]]),
            &[0],
            1e-8,
        );
        let q = gather(
            &mut found,
            Reached::Periodic(0, vec![vec![2.0], vec![1.0]]),
            &[0],
            1e-8,
        );
        assert_eq!((p, q), (Some(2), Some(2)));
        assert_eq!(gather(&mut found, Reached::NotRun, &[0], 1e-8), None);
    }
}
