//! Exactly periodic orbits jumped over whole periods (`engine::periodic`),
//! against the written-out reference of [`crate::oscillator`]: the impact
//! count to the impact, the final state and the samples within the run's
//! stated bound, budgets kept, and runs that look at every event (an event
//! log) firing every event. Stepped runs (the linear propagator, Taylor's
//! method) jump with the bounds and the stops that firing each event gives.

use flicker::engine::{Options, Outcome, Recorder, Status, simulate, simulate_sampled};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{Mechanism, StrainMechanism};

use crate::oscillator::Unit;
use crate::support::{flicker, models, read_json};

/// The issue's chattering case: below the critical load, strain 1e-14 at
/// rest, impacts 4e-7 apart, 2.5e8 of them by t = 100.
const CHATTER: Unit = Unit {
    eta: 0.5,
    omega: 1.0,
};
const CHATTER_START: (f64, f64) = (1e-14, 0.0);

fn model(u: Unit) -> StrainMechanism {
    StrainMechanism {
        mechanism: Mechanism {
            eta: u.eta,
            omega: u.omega,
        },
    }
}

fn run_quietly(u: Unit, x0: (f64, f64), options: &Options) -> Outcome {
    simulate(&model(u), FLIGHT, &[x0.0, x0.1], options, &mut ())
}

fn assert_within_bound(outcome: &Outcome, want: (f64, f64)) {
    let got = (outcome.final_state[0], outcome.final_state[1]);
    let err = (got.0 - want.0).abs().max((got.1 - want.1).abs());
    assert!(
        err <= outcome.error_bound.unwrap(),
        "final state {got:?}, reference {want:?}: error {err:.2e} above the stated bound {:.2e}",
        outcome.error_bound.unwrap()
    );
}

#[test]
fn the_chattering_mechanism_counts_every_impact_and_lands_on_the_arc() {
    let t_end = 100.0;
    let outcome = run_quietly(CHATTER, CHATTER_START, &Options::until(t_end));
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    let impacts = CHATTER.impacts_until(CHATTER_START, t_end);
    assert!(impacts > 249_000_000, "{impacts}");
    assert_eq!(outcome.events, impacts);
    assert_eq!(outcome.events_by_guard["impact"], impacts);
    assert_within_bound(&outcome, CHATTER.state_at(CHATTER_START, t_end));
    let jumped = outcome
        .fast_forward
        .expect("the orbit repeats: it should be jumped over");
    // All but the first impacts (the orbit is proven on the second) and
    // the margin before the end.
    assert!(jumped.periods + 5 >= impacts, "{jumped:?} of {impacts}");
    let period = CHATTER.period_atan2(CHATTER.energy(CHATTER_START.0, CHATTER_START.1));
    assert!(
        (jumped.period - period).abs() <= 1e-12 * period,
        "{jumped:?}"
    );
    // Microseconds, not the 40 s of firing each impact: a budget that
    // per-impact firing could not meet holds it to the jump.
    let mut options = Options::until(t_end);
    options.max_wall_seconds = Some(5.0);
    assert_eq!(
        run_quietly(CHATTER, CHATTER_START, &options).status,
        Status::Completed
    );
}

#[test]
fn jumping_and_firing_each_event_agree_where_both_run() {
    // Firing each impact, the post-impact rate gains about an ulp per
    // impact (a bias of the closed form's rounding about its centre), so
    // the phase drifts quadratically: 8e-13 in the rate after the
    // chattering case's 2.5e5 impacts. The round-off allowance, scaled by
    // the centre (`HybridModel::exact_flow_scale`), covers it; the jump stays
    // on the state the orbit returned to.
    for (u, x0, t_end) in [
        (CHATTER, CHATTER_START, 0.1),
        (
            Unit {
                eta: 1.3,
                omega: 2.0,
            },
            (0.0, 0.7),
            3000.0,
        ),
    ] {
        let options = Options::until(t_end);
        let mut every = Recorder::default();
        let fired = simulate(&model(u), FLIGHT, &[x0.0, x0.1], &options, &mut every);
        assert!(
            fired.fast_forward.is_none(),
            "an observer of events sees each one"
        );
        assert_eq!(every.events.len() as u64, fired.events);
        let jumped = run_quietly(u, x0, &options);
        assert!(jumped.fast_forward.is_some());
        assert_eq!(jumped.events, fired.events);
        assert_eq!(jumped.events, u.impacts_until(x0, t_end));
        assert_within_bound(&jumped, u.state_at(x0, t_end));
        assert_within_bound(&fired, u.state_at(x0, t_end));
    }
}

#[test]
fn samples_are_taken_on_the_arc_between_jumps() {
    let t_end = 100.0;
    let times = [1e-3, 12.5, 50.0, 99.99];
    let mut samples = Vec::new();
    // Firing each impact would take 40 s: the budget holds the test to
    // the jumps.
    let mut options = Options::until(t_end);
    options.max_wall_seconds = Some(5.0);
    let outcome = simulate_sampled(
        &model(CHATTER),
        FLIGHT,
        &[CHATTER_START.0, CHATTER_START.1],
        &options,
        &times,
        &mut |s| samples.push((s.t, s.state.to_vec(), s.events, s.bound)),
        &mut (),
    );
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert!(outcome.fast_forward.is_some());
    assert_eq!(samples.len(), times.len());
    for (t, state, events, bound) in samples {
        let (eps, rate) = CHATTER.state_at(CHATTER_START, t);
        let err = (state[0] - eps).abs().max((state[1] - rate).abs());
        assert!(
            err <= bound,
            "at t = {t}: {state:?} against ({eps}, {rate}), bound {bound:.2e}"
        );
        assert_eq!(
            events,
            CHATTER.impacts_until(CHATTER_START, t),
            "at t = {t}"
        );
    }
}

#[test]
fn the_event_budget_stops_a_jumping_run_at_the_same_event() {
    // As if every event fired: the event past the budget fails the run.
    let mut options = Options::until(100.0);
    options.max_events = 1_000_000;
    let outcome = run_quietly(CHATTER, CHATTER_START, &options);
    assert_eq!(outcome.status, Status::Failed);
    let reason = outcome.reason.as_deref().unwrap_or("");
    assert!(reason.contains("max_events"), "{reason}");
    assert_eq!(outcome.events, 1_000_001);
    // A budget the projection (which counts the fraction of a period to
    // the end too) finds enough lets it finish.
    options.max_events = CHATTER.impacts_until(CHATTER_START, 100.0) + 1;
    options.max_wall_seconds = Some(5.0);
    let outcome = run_quietly(CHATTER, CHATTER_START, &options);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert!(outcome.fast_forward.is_some());
    // The budget is projected every 2^20 events, jumped or fired: a run
    // that would need far more says so there.
    options.max_events = 10_000_000;
    let outcome = run_quietly(CHATTER, CHATTER_START, &options);
    let reason = outcome.reason.as_deref().unwrap_or("");
    assert!(reason.contains("at the recent rate"), "{reason}");
    assert!(outcome.events <= 1 << 21, "{}", outcome.events);
}

#[test]
fn the_summary_says_a_run_without_a_log_was_fast_forwarded() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("chatter.json");
    std::fs::write(
        &scene,
        r#"{"model": "mechanism", "formulation": "strain", "eta": 0.5, "omega": 1.0,
            "initial": {"strain": 1e-14, "strain_rate": 0.0}, "t_end": 0.01}"#,
    )
    .unwrap();
    let summary = |extra: &[&str], out: &str| {
        let out = dir.path().join(out);
        let mut args = vec!["run", scene.to_str().unwrap(), "--quiet", "--out"];
        args.push(out.to_str().unwrap());
        args.extend(extra);
        let run = flicker(&args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        (
            read_json(&out.join("summary.json")),
            String::from_utf8_lossy(&run.stdout).into_owned(),
        )
    };
    let (logged, _) = summary(&[], "logged");
    let (quiet, said) = summary(&["--no-events"], "quiet");
    assert!(logged.get("fast_forward").is_none(), "{logged}");
    assert_eq!(logged["events"], quiet["events"]);
    let periods = quiet["fast_forward"]["periods"].as_u64().unwrap();
    assert!(periods + 5 >= quiet["events"].as_u64().unwrap(), "{quiet}");
    assert!(said.contains("fast-forwarded"), "{said}");
}

/// An oscillator `x'' = -x` bouncing elastically off a wall at `x = 0`,
/// from the wall at unit speed: `x = |sin t|`, an impact every `pi`, with
/// `guards` added to its transitions.
fn bouncing_oscillator(guards: &str, t_end: f64) -> String {
    format!(
        r#"{{"model": "automaton", "states": ["x", "v"], "initial": {{"x": 0.0, "v": 1.0}},
            "modes": {{"m": {{"flow": {{"x": "v", "v": "-x"}},
              "transitions": [
                {{"name": "impact", "guard": "x", "direction": "falling", "barrier": true,
                  "reset": {{"x": "0", "v": "-v"}}}}{guards}]}}}},
            "t_end": {t_end}}}"#
    )
}

/// A run's summary and its samples `(t, x, v, bound)`.
type Run = (serde_json::Value, Vec<[f64; 4]>);

/// `scene` run with `args` (`--method M`, or none), with its event log and
/// without one (`--no-events`, which may jump), each sampled at 7 times.
fn logged_and_quiet(scene: &str, args: &[&str]) -> (Run, Run) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene).unwrap();
    let run = |extra: &[&str], out: &str| {
        let out = dir.path().join(out);
        let mut all = vec!["run", path.to_str().unwrap(), "--quiet"];
        all.extend(args);
        all.extend(["--samples", "7", "--out", out.to_str().unwrap()]);
        all.extend(extra);
        flicker(&all);
        let samples = std::fs::read_to_string(out.join("samples.csv")).unwrap_or_default();
        let rows = samples
            .lines()
            .skip(1)
            .map(|line| {
                let mut row = line.split(',').map(|x| x.parse::<f64>().unwrap());
                std::array::from_fn(|_| row.next().unwrap())
            })
            .collect();
        (read_json(&out.join("summary.json")), rows)
    };
    (run(&[], "logged"), run(&["--no-events"], "quiet"))
}

fn number(summary: &serde_json::Value, field: &str) -> f64 {
    summary[field]
        .as_f64()
        .unwrap_or_else(|| panic!("no `{field}` in {summary}"))
}

/// `summary` is of a completed run with `events` events, whose final
/// `(x, v)` is within its stated bound of `want`.
fn assert_completed_at(summary: &serde_json::Value, events: u64, want: (f64, f64), what: &str) {
    assert_eq!(summary["status"], "completed", "{what}: {summary}");
    assert_eq!(
        summary["events"].as_u64(),
        Some(events),
        "{what}: {summary}"
    );
    let fs = &summary["final_state"];
    let err = (number(fs, "x") - want.0)
        .abs()
        .max((number(fs, "v") - want.1).abs());
    assert!(
        err <= number(summary, "error_bound"),
        "{what}: error {err:e}, {summary}"
    );
}

/// The summaries of bundled scene `name` run to `t_end` by its own method,
/// with its event log and without one.
fn bundled_logged_and_quiet(name: &str, t_end: f64) -> (serde_json::Value, serde_json::Value) {
    let mut json = read_json(std::path::Path::new(&models(name)));
    json["t_end"] = t_end.into();
    let ((logged, _), (quiet, _)) = logged_and_quiet(&json.to_string(), &[]);
    (logged, quiet)
}

/// The bounds a jumping run states are those of firing each event: the
/// same operations on states equal to round-off, so the same to 1e-6.
fn assert_same_bounds(logged: &serde_json::Value, quiet: &serde_json::Value, what: &str) {
    for field in ["error_bound", "event_time_bound"] {
        let (a, b) = (number(logged, field), number(quiet, field));
        assert!(
            (a - b).abs() <= 1e-6 * a && a > 0.0,
            "{what}: {field} {b:e} jumping, {a:e} firing each"
        );
    }
}

#[test]
fn stepped_runs_jump_with_the_bound_firing_each_event_would_state() {
    let t_end = 3000.0;
    let scene = bouncing_oscillator("", t_end);
    let impacts = (t_end / std::f64::consts::PI).floor() as u64;
    let phase = t_end % std::f64::consts::PI;
    for method in ["linear", "taylor"] {
        let ((logged, _), (quiet, samples)) = logged_and_quiet(&scene, &["--method", method]);
        for s in [&logged, &quiet] {
            assert_completed_at(s, impacts, (phase.sin(), phase.cos()), method);
        }
        assert!(logged.get("fast_forward").is_none(), "{logged}");
        // All but a few periods after the start and each sample.
        let periods = quiet["fast_forward"]["periods"].as_u64().unwrap_or(0);
        assert!(periods + 40 >= impacts, "{method}: {quiet}");
        assert_eq!(samples.len(), 7);
        for [t, x, v, bound] in samples {
            let phase = t % std::f64::consts::PI;
            let err = (x - phase.sin()).abs().max((v - phase.cos()).abs());
            assert!(
                err <= bound,
                "{method}: at t = {t}, error {err:e}, bound {bound:e}"
            );
        }
        assert_same_bounds(&logged, &quiet, method);
    }
}

#[test]
fn a_jump_stops_short_of_the_period_whose_checks_fail() {
    // A second guard comes within 1e-12 of zero at the top of each flight:
    // once the carried errors reach that, the run cannot tell whether it
    // fires, and stops. A jump must not carry it past that period.
    let scene = bouncing_oscillator(
        r#", {"name": "near", "guard": "1 + 1e-12 - x", "direction": "falling"}"#,
        20000.0,
    );
    for method in ["linear", "taylor"] {
        let ((logged, _), (quiet, _)) = logged_and_quiet(&scene, &["--method", method]);
        for s in [&logged, &quiet] {
            assert_eq!(s["status"], "failed", "{method}: {s}");
            let reason = s["reason"].as_str().unwrap_or("");
            assert!(reason.contains("`near` grazes zero"), "{method}: {reason}");
        }
        assert!(quiet["fast_forward"]["periods"].as_u64().unwrap_or(0) > 100);
        assert_eq!(logged["events"], quiet["events"], "{method}");
        let (a, b) = (number(&logged, "t_reached"), number(&quiet, "t_reached"));
        assert!(
            (a - b).abs() <= 1e-12 * a,
            "{method}: {a} firing, {b} jumping"
        );
    }
}

#[test]
fn a_periodic_section_marker_is_jumped_over_too() {
    // x'' = -x from (0.3, 1), a marker where x rises through zero: no
    // reset, the state after each crossing repeats every 2 pi.
    let t_end: f64 = 3000.0;
    let scene = r#"{"model": "automaton", "states": ["x", "v"], "initial": {"x": 0.3, "v": 1.0},
        "modes": {"m": {"flow": {"x": "v", "v": "-x"},
          "transitions": [{"name": "section", "guard": "x", "direction": "rising"}]}},
        "t_end": 3000.0}"#;
    let (x, v) = (
        0.3 * t_end.cos() + t_end.sin(),
        -0.3 * t_end.sin() + t_end.cos(),
    );
    // Rising crossings at 2 pi k - atan(0.3), k >= 1.
    let crossings = ((t_end + 0.3f64.atan()) / std::f64::consts::TAU).floor() as u64;
    for method in ["linear", "taylor"] {
        let ((logged, _), (quiet, _)) = logged_and_quiet(scene, &["--method", method]);
        for s in [&logged, &quiet] {
            assert_completed_at(s, crossings, (x, v), method);
        }
        let periods = quiet["fast_forward"]["periods"].as_u64().unwrap_or(0);
        assert!(periods + 40 >= crossings, "{method}: {quiet}");
        // A passage's identity saltation, replayed as it was fired (by
        // Taylor's method a run with its log lets the step go on past the
        // marker: other steps, other bounds).
        if method == "linear" {
            assert_same_bounds(&logged, &quiet, method);
        }
    }
}

#[test]
fn a_ball_between_two_walls_jumps_over_both_impacts() {
    // x' = v, v' = 0 from (0.5, 0.7) between walls at 0 and 1: a period of
    // two impacts, 2 / 0.7 long; impacts at (0.5 + k) / 0.7.
    let t_end: f64 = 3000.0;
    let scene = r#"{"model": "automaton", "states": ["x", "v"], "initial": {"x": 0.5, "v": 0.7},
        "modes": {"m": {"flow": {"x": "v", "v": "0"},
          "transitions": [
            {"name": "left", "guard": "x", "direction": "falling", "barrier": true,
             "reset": {"x": "0", "v": "-v"}},
            {"name": "right", "guard": "1 - x", "direction": "falling", "barrier": true,
             "reset": {"x": "1", "v": "-v"}}]}},
        "t_end": 3000.0}"#;
    let impacts = (0.7 * t_end - 0.5).floor() as u64 + 1;
    // The triangle wave through x = 0.5 rising at t = 0.
    let phase = (0.5 + 0.7 * t_end) % 2.0;
    let (x, v) = if phase < 1.0 {
        (phase, 0.7)
    } else {
        (2.0 - phase, -0.7)
    };
    for method in ["linear", "taylor"] {
        let ((logged, _), (quiet, _)) = logged_and_quiet(scene, &["--method", method]);
        for s in [&logged, &quiet] {
            assert_completed_at(s, impacts, (x, v), method);
        }
        assert_eq!(logged["events_by_guard"], quiet["events_by_guard"]);
        assert_same_bounds(&logged, &quiet, method);
        // Taylor's series of this flow ends at its first order: each step
        // runs to the end of the run, which its length then depends on, so
        // its periods do not repeat and nothing is jumped.
        let jumped = &quiet["fast_forward"];
        if method == "taylor" {
            assert!(jumped.is_null(), "{quiet}");
            continue;
        }
        assert_eq!(jumped["events_per_period"], 2, "{method}: {quiet}");
        // All but a few periods after the start and each sample.
        assert!(jumped["periods"].as_u64().unwrap() * 2 + 100 >= impacts);
    }
}

#[test]
fn periods_of_several_events_and_modes_are_jumped_as_firing_each_would_end() {
    // The mechanism's angle as two charts: six events a period, among them
    // the switches between the charts (modes).
    let (logged, quiet) = bundled_logged_and_quiet("automata/mechanism_charts.json", 2000.0);
    for s in [&logged, &quiet] {
        assert_eq!(s["status"], "completed", "{s}");
    }
    assert_eq!(logged["events_by_guard"], quiet["events_by_guard"]);
    let jumped = &quiet["fast_forward"];
    assert_eq!(jumped["events_per_period"], 6, "{quiet}");
    assert!(jumped["periods"].as_u64() > Some(100), "{quiet}");
    assert_same_bounds(&logged, &quiet, "charts");
    // Within round-off of firing each: the jump stays on the state it
    // returned to, where firing walks away from it by an ulp or so.
    let bound = number(&logged, "error_bound");
    let (a, b) = (&logged["final_state"], &quiet["final_state"]);
    for (name, value) in a.as_object().unwrap() {
        let gap = (value.as_f64().unwrap() - number(b, name)).abs();
        assert!(
            gap <= 2.0 * bound,
            "{name} differs by {gap:e}, bound {bound:e}"
        );
    }
}

#[test]
fn a_period_whose_steps_run_to_the_end_is_not_jumped() {
    // Stick-slip on a belt: while the block sticks its flow is a constant
    // velocity, whose Taylor series ends at its first order, so each such
    // step runs to the end of the run and depends on it. The periods do
    // not repeat their steps, and the run fires every event, to the same
    // bytes as with its log.
    let (logged, quiet) = bundled_logged_and_quiet("automata/stick_slip_belt.json", 400.0);
    assert!(quiet["fast_forward"].is_null(), "{quiet}");
    for field in [
        "events_by_guard",
        "final_state",
        "error_bound",
        "event_time_bound",
    ] {
        assert_eq!(logged[field], quiet[field], "{field}");
    }
}

/// A stepped orbit jumped over tens of thousands of periods lands where
/// firing each event does, to the last ulps: the period, measured between
/// two events' double-double times, is jumped as a double-double too.
/// Rounded to a double, the mechanism's period (as an automaton, by the
/// linear propagator) missed by 2e-18 each time: 8e-14 after 43,372
/// periods, where firing each impact was 6e-17 off the closed form.
#[test]
fn a_jumped_stepped_orbit_lands_where_firing_each_event_does() {
    use flicker::engine::Method;
    use flicker::models::automaton::{AutomatonBuilder, TransitionBuilder};
    let model = AutomatonBuilder::new()
        .parameter("eta", 0.8)
        .state("strain", 0.0)
        .state("strain_rate", (2.0f64 * 0.1).sqrt())
        .mode(
            "flight",
            [
                ("strain", "strain_rate"),
                ("strain_rate", "-(strain - (eta - 1))"),
            ],
            [TransitionBuilder::new("impact", "strain")
                .falling()
                .barrier()
                .reset("strain", "0")
                .reset("strain_rate", "-strain_rate")],
        )
        .build()
        .expect("the model compiles");
    let x0 = [0.0, (2.0f64 * 0.1).sqrt()];
    let mut options = Options::until(1e5);
    options.method = Method::Linear;
    let mut every = Recorder::default();
    let fired = simulate(&model, 0, &x0, &options, &mut every);
    let jumped = simulate(&model, 0, &x0, &options, &mut ());
    assert!(fired.fast_forward.is_none());
    let periods = jumped.fast_forward.as_ref().expect("jumped").periods;
    assert!(periods > 43_000, "{periods}");
    assert_eq!(jumped.events, fired.events);
    for (a, b) in jumped.final_state.iter().zip(&fired.final_state) {
        assert!((a - b).abs() <= 4.0 * f64::EPSILON, "{a} jumped, {b} fired");
    }
}
