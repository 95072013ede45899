//! Bounds that hold whatever the stepper: random impact automata, written as
//! users write them, run by every method that applies, against exact
//! event-driven references computed here in double-double arithmetic.
//!
//! - Balls on a vertical line under gravity, over a floor and under an
//!   optional ceiling, colliding elastically with each other (masses
//!   differ, so a stack of three is chaotic). Between events every ball
//!   falls on its parabola: a gap between two balls is linear in time and a
//!   wall's gap quadratic, so each next event has a closed form.
//! - A point in a circular billiard: chords of closed-form length, each
//!   reflection `v - 2 (v . n) n`.
//!
//! A run that completes must have the reference's events, each at its time
//! within the event-time bound it states, and end within its error bound of
//! the reference's state. A run that stops must say why and have logged only
//! the reference's events, within the same bounds. Chaotic runs are expected
//! to stop once their errors make the order of events uncertain; most runs
//! must complete all the same.

use flicker::engine::bound::ROUNDOFF_ULPS;
use flicker::engine::{Method, Options, Outcome, Status, Tolerances, simulate};
use flicker::models::automaton::{Automaton, AutomatonBuilder, TransitionBuilder};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use twofloat::TwoFloat as D;

use crate::support::{EventLog, Seen};

/// Balls on a line: masses, heights (increasing) and velocities, under
/// gravity 1, over a floor at 0 and under an optional ceiling.
#[derive(Debug, Clone)]
struct Balls {
    masses: Vec<f64>,
    heights: Vec<f64>,
    speeds: Vec<f64>,
    ceiling: Option<f64>,
}

/// An event of the reference: its time and its guard's name.
type Event = (D, String);

fn d(x: f64) -> D {
    D::from(x)
}

fn f(x: D) -> f64 {
    x.hi() + x.lo()
}

impl Balls {
    fn count(&self) -> usize {
        self.masses.len()
    }

    /// The automaton a user would write: states `y1.. v1..` (positions,
    /// then velocities: Stormer-Verlet's `[q; q']`), one mode, a barrier
    /// for each wall and each pair of neighbours.
    fn automaton(&self) -> Automaton {
        let k = self.count();
        let mut builder = AutomatonBuilder::new().parameter("g", 1.0);
        if let Some(h) = self.ceiling {
            builder = builder.parameter("H", h);
        }
        for (i, m) in self.masses.iter().enumerate() {
            builder = builder.parameter(&format!("m{}", i + 1), *m);
        }
        for i in 0..k {
            builder = builder.state(&format!("y{}", i + 1), self.heights[i]);
        }
        for i in 0..k {
            builder = builder.state(&format!("v{}", i + 1), self.speeds[i]);
        }
        let mut transitions = vec![
            TransitionBuilder::new("floor", "y1")
                .falling()
                .barrier()
                .reset("v1", "-v1"),
        ];
        if self.ceiling.is_some() {
            transitions.push(
                TransitionBuilder::new("ceiling", &format!("H - y{k}"))
                    .falling()
                    .barrier()
                    .reset(&format!("v{k}"), &format!("-v{k}")),
            );
        }
        for i in 1..k {
            let (a, b) = (i, i + 1);
            transitions.push(
                TransitionBuilder::new(&format!("c{a}{b}"), &format!("y{b} - y{a}"))
                    .falling()
                    .barrier()
                    .reset(
                        &format!("v{a}"),
                        &format!("((m{a} - m{b}) * v{a} + 2 * m{b} * v{b}) / (m{a} + m{b})"),
                    )
                    .reset(
                        &format!("v{b}"),
                        &format!("((m{b} - m{a}) * v{b} + 2 * m{a} * v{a}) / (m{a} + m{b})"),
                    ),
            );
        }
        let mut flow: Vec<(String, String)> = (1..=k)
            .map(|i| (format!("y{i}"), format!("v{i}")))
            .collect();
        flow.extend((1..=k).map(|i| (format!("v{i}"), "-g".to_string())));
        let flow: Vec<(&str, &str)> = flow.iter().map(|(a, b)| (a.as_str(), b.as_str())).collect();
        builder
            .mode("fall", flow, transitions)
            .build()
            .expect("the balls compile")
    }

    /// The exact events to `t_end` and the state there, event by event in
    /// double-double arithmetic.
    fn reference(&self, t_end: f64) -> (Vec<Event>, Vec<D>) {
        let k = self.count();
        let g = d(1.0);
        let mut y: Vec<D> = self.heights.iter().map(|&x| d(x)).collect();
        let mut v: Vec<D> = self.speeds.iter().map(|&x| d(x)).collect();
        let m: Vec<D> = self.masses.iter().map(|&x| d(x)).collect();
        let (mut t, end) = (d(0.0), d(t_end));
        let mut events = Vec::new();
        loop {
            let mut next: Option<(D, usize)> = None;
            let mut consider = |tau: D, which: usize| {
                if tau > d(0.0) && next.is_none_or(|(best, _)| tau < best) {
                    next = Some((tau, which));
                }
            };
            // Floor: y1 + v1 s - s^2 / 2 = 0 falling.
            consider((v[0] + (v[0] * v[0] + d(2.0) * g * y[0]).sqrt()) / g, 0);
            // Ceiling: y_k + v_k s - s^2 / 2 = H rising.
            if let Some(h) = self.ceiling {
                let disc = v[k - 1] * v[k - 1] + d(2.0) * g * (y[k - 1] - d(h));
                if v[k - 1] > d(0.0) && disc >= d(0.0) {
                    consider((v[k - 1] - disc.sqrt()) / g, 1);
                }
            }
            for i in 0..k - 1 {
                let closing = v[i + 1] - v[i];
                if closing < d(0.0) {
                    consider(-(y[i + 1] - y[i]) / closing, 2 + i);
                }
            }
            let (tau, which) = next.expect("a floor always comes");
            let stop = t + tau > end;
            let s = if stop { end - t } else { tau };
            for i in 0..k {
                y[i] += v[i] * s - g * s * s / d(2.0);
                v[i] -= g * s;
            }
            t += s;
            if stop {
                return (events, y.into_iter().chain(v).collect());
            }
            let name = match which {
                0 => {
                    v[0] = -v[0];
                    "floor".to_string()
                }
                1 => {
                    v[k - 1] = -v[k - 1];
                    "ceiling".to_string()
                }
                c => {
                    let (a, b) = (c - 2, c - 1);
                    let total = m[a] + m[b];
                    let (va, vb) = (v[a], v[b]);
                    v[a] = ((m[a] - m[b]) * va + d(2.0) * m[b] * vb) / total;
                    v[b] = ((m[b] - m[a]) * vb + d(2.0) * m[a] * va) / total;
                    format!("c{}{}", a + 1, b + 1)
                }
            };
            events.push((t, name));
        }
    }
}

/// A point in the unit circle, moving at constant speed between
/// reflections.
#[derive(Debug, Clone)]
struct Billiard {
    position: [f64; 2],
    velocity: [f64; 2],
}

impl Billiard {
    fn automaton(&self) -> Automaton {
        let reflect = |v: &str, x: &str| format!("{v} - 2 * (vx * x + vy * y) * {x} / (x^2 + y^2)");
        AutomatonBuilder::new()
            .state("x", self.position[0])
            .state("y", self.position[1])
            .state("vx", self.velocity[0])
            .state("vy", self.velocity[1])
            .mode(
                "fly",
                [("x", "vx"), ("y", "vy")],
                [TransitionBuilder::new("wall", "1 - x^2 - y^2")
                    .falling()
                    .barrier()
                    .reset("vx", &reflect("vx", "x"))
                    .reset("vy", &reflect("vy", "y"))],
            )
            .build()
            .expect("the billiard compiles")
    }

    fn reference(&self, t_end: f64) -> (Vec<Event>, Vec<D>) {
        let (mut x, mut y) = (d(self.position[0]), d(self.position[1]));
        let (mut u, mut w) = (d(self.velocity[0]), d(self.velocity[1]));
        let (mut t, end) = (d(0.0), d(t_end));
        let mut events = Vec::new();
        loop {
            // |p + v s| = 1: s = (-p.v + sqrt((p.v)^2 + |v|^2 (1 - |p|^2))) / |v|^2.
            let pv = x * u + y * w;
            let vv = u * u + w * w;
            let tau = (-pv + (pv * pv + vv * (d(1.0) - x * x - y * y)).sqrt()) / vv;
            let stop = t + tau > end;
            let s = if stop { end - t } else { tau };
            x += u * s;
            y += w * s;
            t += s;
            if stop {
                return (events, vec![x, y, u, w]);
            }
            // On the circle the normal is the position itself.
            let r2 = x * x + y * y;
            let dot = (u * x + w * y) / r2;
            u -= d(2.0) * dot * x;
            w -= d(2.0) * dot * y;
            events.push((t, "wall".to_string()));
        }
    }
}

const METHODS: [(&str, Method); 5] = [
    ("linear", Method::Linear),
    (
        "taylor",
        Method::Taylor(Tolerances {
            rtol: f64::EPSILON,
            atol: f64::EPSILON,
        }),
    ),
    (
        "dopri5",
        Method::Dopri5(Tolerances {
            rtol: 1e-10,
            atol: 1e-10,
        }),
    ),
    (
        "dop853",
        Method::Dop853(Tolerances {
            rtol: 1e-12,
            atol: 1e-12,
        }),
    ),
    ("verlet", Method::Verlet { step: 1e-2 }),
];

/// Run `model` by `method` to `t_end`.
fn run(model: &Automaton, method: Method, t_end: f64) -> (Outcome, Vec<Seen>) {
    let mut options = Options::until(t_end);
    options.method = method;
    let mut log = EventLog::default();
    let outcome = simulate(
        model,
        model.initial_mode(),
        model.initial(),
        &options,
        &mut log,
    );
    (outcome, log.0)
}

/// How many times its errors a completed run's stated bounds are: the
/// final state's, and the event times' (each error taken as at least one
/// event's round-off allowance, [`ROUNDOFF_ULPS`] ulps of the scale).
#[derive(Debug, Clone, Copy)]
struct Looseness {
    state: f64,
    time: f64,
}

/// Whether a run keeps its word against the reference: `Ok(Some(how
/// loose))` where it completed, `Ok(None)` where it stopped saying why,
/// or what is wrong.
fn keeps_its_word(
    (outcome, seen): &(Outcome, Vec<Seen>),
    (events, state): &(Vec<Event>, Vec<D>),
) -> Result<Option<Looseness>, String> {
    // A few balls' errors are carried: a missing bound is a defect.
    let Some(time_bound) = outcome.event_time_bound else {
        return Err(format!("no event-time bound stated: {:?}", outcome.reason));
    };
    let completed = outcome.status == Status::Completed;
    if !completed && outcome.reason.as_deref().unwrap_or("").is_empty() {
        return Err(format!("{:?} without a reason", outcome.status));
    }
    if seen.len() > events.len() || completed && seen.len() != events.len() {
        return Err(format!(
            "{} events where the reference has {} ({:?})",
            seen.len(),
            events.len(),
            outcome.reason
        ));
    }
    let mut time_error = 0.0_f64;
    for (k, (e, (t, name))) in seen.iter().zip(events).enumerate() {
        let off = (d(e.t) - *t).abs();
        time_error = time_error.max(f(off));
        if e.guard != *name || f(off) > time_bound + 8.0 * f64::EPSILON * e.t.abs().max(1.0) {
            return Err(format!(
                "event {k}: `{}` at {} where the reference has `{name}` at {} ({:.2e} off, bound {time_bound:.2e})",
                e.guard,
                e.t,
                f(*t),
                f(off)
            ));
        }
    }
    if !completed {
        return Ok(None);
    }
    let scale = state.iter().fold(1.0_f64, |s, x| s.max(f(*x).abs()));
    let error = outcome
        .final_state
        .iter()
        .zip(state)
        .map(|(x, r)| f((d(*x) - *r).abs()))
        .fold(0.0, f64::max);
    if error > outcome.error_bound.unwrap() + 8.0 * f64::EPSILON * scale {
        return Err(format!(
            "final state {error:.2e} off the reference, beyond its stated bound {:.2e}",
            outcome.error_bound.unwrap()
        ));
    }
    let floor = ROUNDOFF_ULPS * f64::EPSILON * scale;
    Ok(Some(Looseness {
        state: outcome.error_bound.unwrap() / error.max(floor),
        time: time_bound / time_error.max(floor),
    }))
}

/// The methods that completed (with how loose their bounds were), the
/// earliest time a run stopped at, and the methods that stopped at their
/// horizon.
type Verdicts = (Vec<(&'static str, Looseness)>, f64, Vec<&'static str>);

/// Every method on one model, or what was wrong.
fn every_method(
    model: &Automaton,
    reference: &(Vec<Event>, Vec<D>),
    t_end: f64,
) -> Result<Verdicts, String> {
    let (mut completed, mut reached, mut horizons) = (Vec::new(), t_end, Vec::new());
    for (name, method) in METHODS {
        let run = run(model, method, t_end);
        match keeps_its_word(&run, reference) {
            Ok(Some(looseness)) => completed.push((name, looseness)),
            Ok(None) if run.0.horizon.is_some() => horizons.push(name),
            Ok(None) => {}
            Err(why) => return Err(format!("{name}: {why}")),
        }
        reached = reached.min(run.0.t_reached);
    }
    Ok((completed, reached, horizons))
}

fn balls() -> impl Strategy<Value = (Balls, f64)> {
    (1usize..=3)
        .prop_flat_map(|k| {
            (
                prop::collection::vec(0.5f64..2.0, k),
                0.1f64..1.0,
                prop::collection::vec(0.1f64..1.0, k - 1),
                prop::collection::vec(-1.0f64..1.0, k),
                prop::option::of(0.5f64..2.0),
                5.0f64..30.0,
            )
        })
        .prop_map(|(masses, floor, gaps, speeds, above, t_end)| {
            let mut heights = vec![floor];
            for g in gaps {
                heights.push(heights.last().unwrap() + g);
            }
            let ceiling = above.map(|a| heights.last().unwrap() + a);
            (
                Balls {
                    masses,
                    heights,
                    speeds,
                    ceiling,
                },
                t_end,
            )
        })
}

fn billiards() -> impl Strategy<Value = (Billiard, f64)> {
    (
        0.0f64..0.9,
        0.0f64..std::f64::consts::TAU,
        0.0f64..std::f64::consts::TAU,
        0.5f64..2.0,
        10.0f64..300.0,
    )
        .prop_map(|(r, a, b, speed, t_end)| {
            (
                Billiard {
                    position: [r * a.cos(), r * a.sin()],
                    velocity: [speed * b.cos(), speed * b.sin()],
                },
                t_end,
            )
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    /// Every method on random balls keeps its word. One ball never stops a
    /// method that computes well; two or three are chaotic (two already,
    /// where the lower is the heavier: Wojtkowski's falling balls), and runs
    /// then stop where their errors make the order of events uncertain, but
    /// not within the first ten time units, where the errors are still far
    /// below the intervals between events; an exact method completes.
    #[test]
    fn balls_under_gravity_are_within_their_bounds_or_stop((balls, t_end) in balls()) {
        let reference = balls.reference(t_end);
        let (completed, reached, horizons) = every_method(&balls.automaton(), &reference, t_end)
            .map_err(|why| TestCaseError::fail(format!("{balls:?} to {t_end}: {why}")))?;
        if balls.count() == 1 {
            prop_assert!(completed.len() >= 4, "{balls:?} to {t_end}: only {completed:?} completed");
        }
        // A method exact to round-off completes, or stops at its horizon:
        // where its own errors, ulps grown by the chaos, reach 1e-3 of the
        // state or can no longer order the events.
        let completed: Vec<_> = completed.iter().map(|(name, _)| *name).collect();
        for exact in ["linear", "taylor"] {
            prop_assert!(
                completed.contains(&exact) || horizons.contains(&exact),
                "{balls:?} to {t_end}: {exact} stopped short of its horizon"
            );
        }
        prop_assert!(reached >= t_end.min(10.0), "{balls:?} to {t_end}: a run stopped at {reached}");
    }

    /// Every method on a random circular billiard keeps its word, and the
    /// exact methods complete (the motion is integrable: errors grow
    /// linearly).
    #[test]
    fn billiards_in_a_circle_are_within_their_bounds_or_stop((billiard, t_end) in billiards()) {
        let reference = billiard.reference(t_end);
        let (completed, _, _) = every_method(&billiard.automaton(), &reference, t_end)
            .map_err(|why| TestCaseError::fail(format!("{billiard:?} to {t_end}: {why}")))?;
        let completed: Vec<_> = completed.iter().map(|(name, _)| *name).collect();
        for exact in ["linear", "taylor"] {
            prop_assert!(completed.contains(&exact), "{billiard:?} to {t_end}: only {completed:?} completed");
        }
    }
}

/// The bounds are not far above the errors either. Every flow here is a
/// polynomial each method integrates exactly, so the errors are round-off
/// alone: the bound allows each step and event its worst rounding, added
/// up, where the roundings a run makes mostly cancel, and the largest
/// component's error at the end is one draw that may fall far below its
/// typical size. A single run's ratio therefore has a long tail (2000
/// cases: up to 5e4 for the exact methods, 7e6 for DOP853, 2e6 for
/// Stormer-Verlet), and it is the median over a fixed set of 60 balls and
/// 60 billiards that is held, by method: 1e3 for the exact propagator and
/// Taylor's method (about 300 and 150 measured, for state and times
/// alike), 1e4 for the Runge-Kutta pairs, which round at many more steps
/// (about 2e3), and 3e4 for Stormer-Verlet, whose steps are shorter still
/// (about 7e3 on the 4-state scenes; in a billiard its velocities do not
/// change between walls, yet each step allows them a rounding). A bound
/// inflated 100 times fails every method.
#[test]
fn the_bounds_are_within_a_few_thousand_times_the_errors_on_the_median() {
    let mut runner = TestRunner::new(Config {
        rng_seed: RngSeed::Fixed(20261129),
        failure_persistence: None,
        ..Config::default()
    });
    let mut ratios: Vec<(&str, Looseness)> = Vec::new();
    for _ in 0..60 {
        let (balls, t_end) = balls().new_tree(&mut runner).unwrap().current();
        let verdicts = every_method(&balls.automaton(), &balls.reference(t_end), t_end);
        ratios.extend(verdicts.unwrap_or_else(|why| panic!("{balls:?}: {why}")).0);
        let (billiard, t_end) = billiards().new_tree(&mut runner).unwrap().current();
        let verdicts = every_method(&billiard.automaton(), &billiard.reference(t_end), t_end);
        ratios.extend(
            verdicts
                .unwrap_or_else(|why| panic!("{billiard:?}: {why}"))
                .0,
        );
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    for (method, cap) in [
        ("linear", 1e3),
        ("taylor", 1e3),
        ("dopri5", 1e4),
        ("dop853", 1e4),
        ("verlet", 3e4),
    ] {
        let runs: Vec<Looseness> = ratios
            .iter()
            .filter(|(name, _)| *name == method)
            .map(|(_, l)| *l)
            .collect();
        assert!(runs.len() >= 60, "{method}: {} runs completed", runs.len());
        let state = median(runs.iter().map(|l| l.state).collect());
        let time = median(runs.iter().map(|l| l.time).collect());
        eprintln!("{method}: median looseness {state:.1e} (state), {time:.1e} (times)");
        assert!(
            state <= cap && time <= cap,
            "{method}: bounds {state:.1e} (state) and {time:.1e} (times) the errors on the median"
        );
        // Not below the errors either, which every run asserts of itself.
        assert!(state >= 1.0 && time >= 1.0);
    }
}
