//! Event location on numerical flows must not miss a crossing, even one that
//! enters and leaves inside a single step.

use flicker::engine::Name;
use flicker::engine::{
    Direction, Flow, Guard, HybridModel, Jump, Method, Mode, Options, Outcome, Recorder, Status,
    Tolerances, simulate,
};
use flicker::names;

/// A harmonic oscillator `x'' = -x` whose guard `x = level` is reached only
/// briefly near each crest: with a loose tolerance the integrator takes a
/// few steps per period, so both ends of the step that holds a crest sit
/// below the level. A sign check at step ends misses every crossing.
struct Crest {
    level: f64,
}

const CREST_GUARDS: &[Guard] = &[Guard::affine("crest", Direction::Rising).as_crossing()];

impl HybridModel for Crest {
    fn dimension(&self) -> usize {
        2
    }
    fn state_names(&self, _: Mode) -> &[Name] {
        names!["x", "v"]
    }
    fn mode_name(&self, _: Mode) -> &str {
        "free"
    }
    fn guards(&self, _: Mode) -> &[Guard] {
        CREST_GUARDS
    }
    fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
        x[0] - self.level
    }
    fn flow(&self, _: Mode) -> Flow {
        Flow::Ode
    }
    fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -x[0];
    }
    fn reset(&self, mode: Mode, _: usize, _: &mut [f64]) -> Jump {
        Jump::to(mode)
    }
}

/// The exact rising crossings of `x = level` by `x = cos(t + phase)` in
/// `(0, t_end]`: `t + phase = 2 pi k - acos(level)`.
fn crest_times(level: f64, phase: f64, t_end: f64) -> Vec<f64> {
    let (tau, dip) = (std::f64::consts::TAU, level.acos());
    (0..)
        .map(|k| k as f64 * tau - dip - phase)
        .skip_while(|t| *t <= 0.0)
        .take_while(|t| *t <= t_end)
        .collect()
}

/// Run the crest model from phase `phase` with `method`; the outcome and
/// the event times.
fn run_crest(level: f64, phase: f64, method: Method, periods: f64) -> (Outcome, Vec<f64>) {
    let model = Crest { level };
    let mut options = Options::until(periods * std::f64::consts::TAU);
    options.method = method;
    let mut log = Recorder::default();
    let outcome = simulate(&model, 0, &[phase.cos(), -phase.sin()], &options, &mut log);
    (outcome, log.events.iter().map(|e| e.t).collect())
}

/// A completed run found exactly the crossings of the exact solution, each
/// within the event-time bound the run stated.
fn assert_exact_crossings(outcome: &Outcome, times: &[f64], exact: &[f64]) {
    assert_eq!(times.len(), exact.len(), "times {times:?}, exact {exact:?}");
    if let Err(why) = exact_prefix(outcome, times, exact) {
        panic!("{why}");
    }
}

/// Whether the crossings a run found (all of them, or those before it
/// stopped) are the exact solution's, in order, each within the
/// event-time bound the run stated.
fn exact_prefix(outcome: &Outcome, times: &[f64], exact: &[f64]) -> Result<(), String> {
    if times.len() > exact.len() {
        return Err(format!("times {times:?}, exact {exact:?}"));
    }
    // Every run here is of a few states, whose errors are carried: a
    // missing bound is a defect, not a licence.
    let Some(bound) = outcome.event_time_bound else {
        return Err(format!("no event-time bound stated: {:?}", outcome.reason));
    };
    for (k, (t, want)) in times.iter().zip(exact).enumerate() {
        if (t - want).abs() > bound {
            return Err(format!(
                "crossing {k} at {t}, exact {want}: off by {:.2e}, stated bound {bound:.2e}",
                (t - want).abs()
            ));
        }
    }
    Ok(())
}

#[test]
fn a_crossing_in_and_out_within_one_step_is_found() {
    let level = 0.998;
    let tol = Tolerances {
        rtol: 1e-6,
        atol: 1e-6,
    };
    let (outcome, times) = run_crest(level, 0.0, Method::Dopri5(tol), 20.0);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    assert_exact_crossings(&outcome, &times, &crest_times(level, 0.0, outcome.t_end));
    assert_eq!(times.len(), 20);
    // The test is only meaningful if steps straddle the crests: the time
    // above the level, 2 acos(0.998) = 0.126 per period, must be well below
    // a typical step (at most 26 steps per period: 0.24).
    let steps_per_period = outcome.flow_evaluations as f64 / 6.0 / 20.0;
    assert!(
        steps_per_period < 26.0,
        "{steps_per_period} steps per period"
    );
}

/// Over crest heights down to a near graze (1e-7 above the level),
/// tolerances from 1e-11 to 1e-5 and phases, each embedded pair either
/// finds exactly the exact solution's crossings, each within its stated
/// time bound, and ends within its bound, or says that it cannot tell,
/// having found only exact crossings before it stopped. Where the crest
/// rises 1e5 times the tolerance above the level (the errors of some hundred
/// steps, each estimated pessimistically), nothing is in doubt and
/// every run completes; over the whole grid, most do.
#[test]
fn no_crossing_is_missed_or_misplaced_without_a_word() {
    let (mut runs, mut completed) = (0, 0);
    for depth in (0..=10).map(|k| -7.0 + 0.5 * k as f64) {
        for log_tol in (-11..=-5).map(f64::from) {
            for phase in [0.3, 2.1, 4.4] {
                for pair in 0..2 {
                    let level = 1.0 - 10f64.powf(depth);
                    let tol = Tolerances {
                        rtol: 10f64.powf(log_tol),
                        atol: 10f64.powf(log_tol),
                    };
                    let method = [Method::Dopri5(tol), Method::Dop853(tol)][pair];
                    let (outcome, times) = run_crest(level, phase, method, 10.0);
                    let case =
                        format!("depth 1e{depth}, tol 1e{log_tol}, phase {phase}, {method:?}");
                    runs += 1;
                    match outcome.status {
                        Status::Completed => {
                            completed += 1;
                            let exact = crest_times(level, phase, outcome.t_end);
                            assert_eq!(
                                times.len(),
                                exact.len(),
                                "{case}: times {times:?}, exact {exact:?}"
                            );
                            if let Err(why) = exact_prefix(&outcome, &times, &exact) {
                                panic!("{case}: {why}");
                            }
                            let t = outcome.t_end + phase;
                            let exact = [t.cos(), -t.sin()];
                            for (x, want) in outcome.final_state.iter().zip(exact) {
                                assert!(
                                    (x - want).abs() <= outcome.error_bound.unwrap(),
                                    "{case}: {x} vs {want}, bound {}",
                                    outcome.error_bound.unwrap()
                                );
                            }
                        }
                        Status::Failed => {
                            let reason = outcome.reason.clone().unwrap_or_default();
                            assert!(reason.contains("cannot"), "{case}: {reason}");
                            assert!(
                                depth < log_tol + 5.0,
                                "{case}: a crest far above the errors stopped the run: {reason}"
                            );
                            if let Err(why) = exact_prefix(
                                &outcome,
                                &times,
                                &crest_times(level, phase, outcome.t_end),
                            ) {
                                panic!("{case}: {why}");
                            }
                        }
                        other => panic!("{case}: {other:?}: {:?}", outcome.reason),
                    }
                }
            }
        }
    }
    assert!(
        completed * 2 >= runs,
        "only {completed} of {runs} runs completed"
    );
}

/// The linear propagator finds an affine guard's crossings on rows cached
/// once per mode (`src/engine/step/affine_mode.rs`), not on the state's series:
/// a guard that mixes the states and has a constant, `x - v / 2 - 0.3`
/// on `x = cos t`, `v = -sin t`, i.e. `R cos(t - phi) - 0.3` with `R =
/// sqrt(5) / 2` and `tan(phi) = 1 / 2`, must fire at exactly its closed
/// form's crossings, both ways, each within the stated bound. A row built
/// from the wrong component, a lost constant or a wrong power of `M` moves
/// every crossing by far more than the bound.
#[test]
fn a_mixed_affine_guard_fires_at_its_closed_form_under_the_linear_propagator() {
    use flicker::models::automaton::{AutomatonBuilder, TransitionBuilder};
    let model = AutomatonBuilder::new()
        .state("x", 1.0)
        .state("v", 0.0)
        .mode(
            "free",
            [("x", "v"), ("v", "-x")],
            [TransitionBuilder::new("mark", "x - v / 2 - 0.3")],
        )
        .build()
        .expect("the model compiles");
    let t_end = 60.0;
    let mut options = Options::until(t_end);
    options.method = Method::Linear;
    let mut log = Recorder::default();
    let outcome = simulate(&model, 0, &[1.0, 0.0], &options, &mut log);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    let times: Vec<f64> = log.events.iter().map(|e| e.t).collect();
    let (r, phi) = (1.25_f64.sqrt(), 0.5_f64.atan2(1.0));
    let half = (0.3 / r).acos();
    let tau = std::f64::consts::TAU;
    let mut exact: Vec<f64> = (-1..12)
        .flat_map(|k| [phi + half + k as f64 * tau, phi - half + k as f64 * tau])
        .filter(|t| *t > 0.0 && *t <= t_end)
        .collect();
    exact.sort_by(f64::total_cmp);
    assert_exact_crossings(&outcome, &times, &exact);
    let bound = outcome.event_time_bound.expect("a stated event-time bound");
    assert!(bound < 1e-9, "a loose bound proves little: {bound:.2e}");
}

/// An exactly periodic orbit under the linear propagator: the same
/// roundings at the same steps of every period must not add up to a drift.
/// A rotation at `w` (`x' = w y`, `y' = -w x`) bounced off `x = 0` by `y ->
/// -y` returns every `pi / w`; after `N` impacts and a little more its
/// state is `(sin, cos)(w t mod pi)`, the phase taken in double-double
/// (`w t` to 1e-32 of itself, `pi` to 1e-32). Rounded to double at every
/// step, a run drifted by 3.7e-13 at `w = fl(pi)` (a tenth of an ulp of
/// the phase per period); carrying each whole step's rounding into the
/// next, by 2e-14 to 4e-13 over these frequencies (each reset at the
/// double nearest the crossing, an ulp of the time off the guard, turns
/// the motion round a little early or late); with each crossing located
/// to double-double (`Linear::sharpen`), by the final state's rounding
/// alone.
#[test]
fn an_exactly_periodic_orbit_does_not_drift_under_the_linear_propagator() {
    use flicker::models::automaton::TransitionBuilder;
    for w in [std::f64::consts::PI, 3.0, 2.7, 2.3, 1.9, 1.3, 1.0, 0.77] {
        let impact = TransitionBuilder::new("impact", "x")
            .falling()
            .barrier()
            .reset("y", "-y");
        let (outcome, log, error) = rotation_turned(w, impact, 10_000);
        assert_eq!(log.events.len(), 10_000, "w = {w}");
        assert!(
            error < 4.0 * f64::EPSILON,
            "w = {w}: drifted by {error:.2e}"
        );
        assert!(
            error <= outcome.error_bound.unwrap(),
            "w = {w}: {error:.2e} beyond the stated {:.2e}",
            outcome.error_bound.unwrap()
        );
        // Each reset is at the crossing itself, to double-double: the
        // state it turns round is on the guard to far below an ulp.
        let off = log
            .events
            .iter()
            .map(|e| e.before[0].abs())
            .fold(0.0, f64::max);
        assert!(off < 1e-30, "w = {w}: a reset {off:.1e} off the guard");
    }
}

/// The rotation `x' = w y, y' = -w x` from `(0, 1)` with `transition` on
/// `x = 0`, by the linear propagator for `half_turns` half turns and a
/// quarter of a time unit: its outcome, its events and how far its final
/// state is from `(sin, cos)` of `w t_end - k pi` (`k` the half turns,
/// each of them reflected or passed through alike), computed in
/// double-double (`w t` to 1e-32 of itself, `pi` to 1e-32).
fn rotation_turned(
    w: f64,
    transition: flicker::models::automaton::TransitionBuilder,
    half_turns: u32,
) -> (Outcome, Recorder, f64) {
    use flicker::models::automaton::AutomatonBuilder;
    use flicker::numerics::double_double::two_prod;
    const PI_LO: f64 = 1.2246467991473532e-16;
    let model = AutomatonBuilder::new()
        .parameter("w", w)
        .state("x", 0.0)
        .state("y", 1.0)
        .mode("free", [("x", "w * y"), ("y", "-w * x")], [transition])
        .build()
        .expect("the model compiles");
    let k = f64::from(half_turns);
    let t_end = k * std::f64::consts::PI / w + 0.25;
    let mut options = Options::until(t_end);
    options.method = Method::Linear;
    let mut log = Recorder::default();
    let outcome = simulate(&model, 0, &[0.0, 1.0], &options, &mut log);
    assert_eq!(outcome.status, Status::Completed, "{:?}", outcome.reason);
    // w t_end - k pi in double-double: every product split exactly.
    let (p, p_lo) = two_prod(w, t_end);
    let (q, q_lo) = two_prod(k, std::f64::consts::PI);
    let phase = (p - q) + (p_lo - q_lo - k * PI_LO);
    let error = (outcome.final_state[0] - phase.sin())
        .abs()
        .max((outcome.final_state[1] - phase.cos()).abs());
    (outcome, log, error)
}

/// The same rotation with a section `x = 0` crossed either way instead of
/// the impact: a passage resets nothing, but the run goes on from the
/// state it located, and a periodic orbit repeats that location every
/// period. Summed in double and left where the search put it (the double
/// nearest the crossing), a section drifted the rotation by 7e-14 over
/// 10,000 passages; located to double-double, as an impact is, by the
/// final state's rounding alone.
#[test]
fn a_periodic_orbit_through_a_section_does_not_drift_under_the_linear_propagator() {
    use flicker::models::automaton::TransitionBuilder;
    for w in [std::f64::consts::PI, 2.3, 1.3, 0.77] {
        let section = TransitionBuilder::new("section", "x");
        let (_, log, error) = rotation_turned(w, section, 10_000);
        // The start on the section, moving through it, and each half turn.
        assert_eq!(log.events.len(), 10_001, "w = {w}");
        assert!(
            error < 4.0 * f64::EPSILON,
            "w = {w}: drifted by {error:.2e}"
        );
    }
}
