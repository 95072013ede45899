//! Brute-force bifurcation diagrams (`flicker diagram`): at each value of
//! a parameter, run past a transient and record the state just after each
//! of the next few events of a section guard. Where the attractor is a
//! period-k orbit the records take k values; where it is chaotic they
//! fill a band.
//!
//! Each value is one run of the model with the parameter held as a state
//! that never changes ([`Family::promoted`]), by the tightest method the
//! tools run (the closed form, the linear propagator, or DOP853 at
//! [`TOLERANCE`]). Without following, every value starts from the scene
//! and the values run in parallel; following, each starts from the state
//! the one before ended in, its clock continuing, so an attractor is
//! followed and a sweep up and a sweep down show hysteresis.
//!
//! A value whose run ends at a Zeno point, fails or stops keeps what it
//! recorded and says why; the diagram goes on.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use rayon::prelude::*;

use crate::analysis::section_records::{SectionRecords, check_section};
use crate::engine::step::method::tightest;
use crate::engine::{
    Family, HybridModel, Limits, MAX_EVENTS, Method, Mode, Promoted, Status, Tolerances, simulate,
};

/// The tolerance of the runs where the model needs a numerical method.
pub const TOLERANCE: f64 = 1e-12;

/// Most records a value may keep.
pub const MAX_RECORD: usize = 100_000;

/// Most values a diagram may have.
pub const MAX_POINTS: usize = 1_000_000;

/// The tightest method the brute-force tools run `model` (of `modes`
/// modes) by, at [`TOLERANCE`] where it has tolerances.
pub fn method(model: &dyn HybridModel, modes: usize) -> (Method, Tolerances) {
    let tolerances = Tolerances {
        rtol: TOLERANCE,
        atol: TOLERANCE,
    };
    (tightest(model, modes, TOLERANCE), tolerances)
}

/// A diagram as asked.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// The parameter varied, by its name in the scene.
    pub parameter: String,
    /// Its values, in the order they run (following, the order matters).
    pub values: Vec<f64>,
    /// The guard whose events are recorded.
    pub section: String,
    /// Time run at each value before recording.
    pub transient: f64,
    /// Section events recorded at each value.
    pub record: usize,
    /// The longest a value runs after its transient.
    pub span: f64,
    /// Start each value from the state the one before ended in.
    pub follow: bool,
}

/// What one value recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct DiagramPoint {
    /// Its place in the request's values.
    pub index: usize,
    /// The parameter's value.
    pub parameter: f64,
    /// `(t, state just after)` of each section event recorded; `t` runs
    /// on across values when following.
    pub records: Vec<(f64, Vec<f64>)>,
    /// How the value's run ended: `completed` once its records are in or
    /// its span is run, else `zeno`, `failed` or `interrupted`.
    pub status: Status,
    /// Why it ended short, where it did.
    pub reason: Option<String>,
}

/// A diagram: the names of the recorded states, and each value's records.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagram {
    /// The names of the states recorded, the parameter's aside.
    pub names: Vec<String>,
    /// Each value run, in the request's order.
    pub points: Vec<DiagramPoint>,
}

/// Check `request` against `family` before anything runs: the field at
/// fault (`param`, `section`, `points`, `transient`, `record`, `span`) and
/// why.
pub fn check(family: &dyn Family, request: &Request) -> Result<(), (&'static str, String)> {
    if !family.parameters().contains(&request.parameter) {
        return Err((
            "param",
            format!(
                "no parameter is called `{}` (parameters: {})",
                request.parameter,
                family.parameters().join(", ")
            ),
        ));
    }
    check_section(family.model(), family.modes(), &request.section)
        .map_err(|e| ("section", e.reason))?;
    if request.values.is_empty() || request.values.len() > MAX_POINTS {
        return Err(("points", format!("from 1 to {MAX_POINTS} values")));
    }
    if request.values.iter().any(|v| !v.is_finite()) {
        return Err(("points", "every value must be a finite number".into()));
    }
    if !(request.transient.is_finite() && request.transient >= 0.0) {
        return Err(("transient", "a finite time >= 0".into()));
    }
    if !(1..=MAX_RECORD).contains(&request.record) {
        return Err(("record", format!("from 1 to {MAX_RECORD} events")));
    }
    if !(request.span.is_finite() && request.span > 0.0) {
        return Err(("span", "a finite time > 0".into()));
    }
    Ok(())
}

/// The names of the states a diagram of `family` in `parameter` records.
pub fn names(family: &dyn Family, parameter: &str) -> Result<Vec<String>, String> {
    let promoted = family.promoted(&[parameter.to_string()])?;
    Ok(recorded(&promoted).1)
}

/// Which of `promoted`'s components a diagram records, and their names:
/// the model's own states, without the parameter held as one or a clock
/// the model carries as a state: the diagram's `t` says it.
fn recorded(promoted: &Promoted) -> (Vec<usize>, Vec<String>) {
    let p = promoted.parameters[0];
    let names = promoted.model.state_names(promoted.mode);
    names
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != p && Some(*i) != promoted.model.clock())
        .map(|(i, n)| (i, n.to_string()))
        .unzip()
}

/// Run the values of `request` (checked by [`check`]) whose places are in
/// `indices` on `family`, under `limits` (its stop flag and deadline end
/// the diagram: the values under way stop, those not begun say so), `done`
/// told of each value as it ends. Following, the values run one after
/// another in the order of `indices`.
pub fn run(
    family: &dyn Family,
    request: &Request,
    indices: &[usize],
    limits: &Limits,
    done: &(dyn Fn() + Sync),
) -> Result<Diagram, String> {
    let promoted = family.promoted(std::slice::from_ref(&request.parameter))?;
    let p = promoted.parameters[0];
    let model = &*promoted.model;
    let (kept, names) = recorded(&promoted);
    let (method, tolerances) = method(model, family.modes());
    let fresh = |value: f64| promoted.start_at(family, &request.parameter, value);
    let one = |index: usize, (mode, x0): (Mode, Vec<f64>), offset: f64| {
        let value = request.values[index];
        if limits.stopped() {
            return (not_begun(index, value, limits), (mode, x0), offset);
        }
        let own_stop = Arc::new(AtomicBool::new(false));
        let mut options = limits.options(
            request.transient + request.span,
            MAX_EVENTS,
            method,
            tolerances,
        );
        options.stop = Some(own_stop.clone());
        let mut recorder = SectionRecords::new(
            &request.section,
            (request.transient, request.record),
            &own_stop,
            limits.stop.as_deref(),
        );
        let outcome = simulate(model, mode, &x0, &options, &mut recorder);
        let full = recorder.full();
        let (status, reason) = match outcome.status {
            Status::Interrupted if full => (Status::Completed, None),
            status => (status, outcome.reason.clone()),
        };
        done();
        let point = DiagramPoint {
            index,
            parameter: value,
            records: recorder
                .kept
                .into_iter()
                .map(|c| (offset + c.t, kept.iter().map(|&i| c.state[i]).collect()))
                .collect(),
            status,
            reason,
        };
        let end = (outcome.final_mode, outcome.final_state);
        (point, end, offset + outcome.t_reached)
    };
    let points = if request.follow {
        let mut points = Vec::with_capacity(indices.len());
        let (mut from, mut offset): (Option<(Mode, Vec<f64>)>, f64) = (None, 0.0);
        for &index in indices {
            let value = request.values[index];
            let start = match from.take() {
                // Where the last one ended, at this value.
                Some((mode, mut x)) => {
                    x[p] = value;
                    (mode, x)
                }
                None => fresh(value),
            };
            let (point, end, reached) = one(index, start, offset);
            // A failed run's end is no state to follow from.
            if point.status != Status::Failed {
                from = Some(end);
            }
            offset = reached;
            points.push(point);
        }
        points
    } else {
        indices
            .par_iter()
            .map(|&index| one(index, fresh(request.values[index]), 0.0).0)
            .collect()
    };
    Ok(Diagram { names, points })
}

fn not_begun(index: usize, value: f64, limits: &Limits) -> DiagramPoint {
    DiagramPoint {
        index,
        parameter: value,
        records: Vec::new(),
        status: Status::Interrupted,
        reason: Some(format!("not begun: {}", limits.stop_reason())),
    }
}
