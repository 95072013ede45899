//! Automata defined in JSON: the bundled mechanism (`models/automata/
//! mechanism.json`) run by Taylor's method, against the closed form and
//! against the built-in exact model, measured in the same run.
//!
//! `cargo bench --bench automata` prints:
//! - accuracy of `taylor` at its default tolerance (machine epsilon) after
//!   10^4 and 10^6 impacts (eta 1.2, from strain 0.5 at rest), against the
//!   closed form as `benches/mechanism.rs` computes it (whose own rounding,
//!   `t mod T_imp` in doubles, is about 1e-11 at 10^6 impacts);
//! - impacts per second, medians of 5 runs, on heyoka's case (eta 0.8,
//!   H0 0.1, starting at an impact, to t = 10^5: 43,468 impacts) for
//!   `taylor` and for the built-in exact model, and their ratio; then
//!   the automaton by its default method (the linear propagator) and the
//!   built-in model each writing its event log to a file, so that every
//!   impact fires (a run without a log jumps the periodic orbit), and
//!   their ratio.
//!
//! - the angle formulation as two charts (`models/automata/
//!   mechanism_charts.json`) by DOP853 at `rtol = atol = 1e-10` beside the
//!   built-in angle model on the same orbit (eta 1.2, from strain 0.5 at
//!   rest, 100 impacts), medians of 7 runs, and their ratio; and the charts
//!   by Taylor's method at machine precision.
//!
//! - one Taylor series of Henon-Heiles at order 20 (machine precision),
//!   compiled, called 20,000 times in a loop: nanoseconds a call, the
//!   median of 15 such loops (heyoka's whole step of the same flow, series
//!   and all, is timed by `benches/peers/heyoka/case2b_hh_noevents.py`).
//!
//! heyoka itself is timed beside it by `benches/peers/heyoka_mechanism.py`,
//! SciPy by `benches/peers/scipy_mechanism.py --automaton`.

use std::hint::black_box;
use std::time::Instant;

use serde_json::{Value, json};

use flicker::engine::HybridModel;
use flicker::engine::Limits;
use flicker::log::JsonlWriter;
use flicker::models::automaton::AutomatonBuilder;
use flicker::models::mechanism::{ExactOrbit, Mechanism};
use flicker::scene::Registry;

mod timing;

use timing::median_of;

/// The bundled automaton with `parameters`, `initial` and `t_end` replaced,
/// run by `method`: (strain, rate, largest energy error, impacts).
fn run(parameters: Value, initial: Value, t_end: f64, method: &str) -> (f64, f64, f64, u64) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/automata/mechanism.json"
    );
    let mut scene: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    scene["parameters"] = parameters;
    scene["initial"] = initial;
    scene["t_end"] = json!(t_end);
    scene["solver"] = json!({"method": method});
    let scene = Registry::builtin().from_value(&scene).unwrap();
    let report = scene.run(&Limits::default(), &mut ()).unwrap();
    let o = report.outcome;
    assert_eq!(o.status.as_str(), "completed", "{:?}", o.reason);
    (
        o.final_state[0],
        o.final_state[1],
        o.max_energy_error.unwrap(),
        o.events,
    )
}

fn main() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let (eps0, rate0) = (0.5, 0.0);
    println!(
        "taylor at machine precision against the closed form (eta 1.2, from strain 0.5 at rest)"
    );
    for impacts in [10_000u64, 1_000_000] {
        let exact = ExactOrbit::new(m, eps0, rate0);
        let period = m.impact_period(m.energy(eps0, rate0));
        let t_end = m.time_to_closing(eps0, rate0).unwrap() + (impacts as f64 - 0.63) * period;
        let start = Instant::now();
        let (eps, rate, energy, events) = run(
            json!({"eta": 1.2, "omega": 1.0}),
            json!({"strain": eps0, "strain_rate": rate0}),
            t_end,
            "taylor",
        );
        let seconds = start.elapsed().as_secs_f64();
        let (e, r) = exact.state_at(t_end);
        println!(
            "  {impacts:>8} impacts: count {events} (exact {}), |d eps| {:.1e}, |d eps'| {:.1e}, energy {:.1e}, {seconds:.3} s",
            exact.impacts_until(t_end),
            (eps - e).abs(),
            (rate - r).abs(),
            energy
        );
    }

    println!();
    println!("heyoka's case (eta 0.8, H0 0.1, from an impact, t = 1e5), medians of 5");
    let parameters = json!({"eta": 0.8, "omega": 1.0});
    let initial = json!({"strain": 0.0, "strain_rate": "omega * sqrt(2 * 0.1)"});
    let m = Mechanism {
        eta: 0.8,
        omega: 1.0,
    };
    let v0 = (2.0f64 * 0.1).sqrt();
    let exact = ExactOrbit::new(m, 0.0, v0);
    let mut last = (0.0, 0.0);
    let (taylor, impacts) = median_of(5, || {
        let (e, r, _, n) = run(parameters.clone(), initial.clone(), 1e5, "taylor");
        last = (e, r);
        n
    });
    let (e, r) = exact.state_at(1e5);
    println!(
        "  taylor (order 20)   {impacts} impacts in {taylor:.4} s: {:.0} impacts/s, |d eps| {:.1e}, |d eps'| {:.1e}",
        impacts as f64 / taylor,
        (last.0 - e).abs(),
        (last.1 - r).abs()
    );
    let builtin = Registry::builtin()
        .from_value(
            &json!({"model": "mechanism", "formulation": "strain", "eta": 0.8,
            "initial": {"energy": 0.1, "phase": "impact"}, "t_end": 1e5}),
        )
        .unwrap();
    let (exact_seconds, exact_impacts) = median_of(5, || {
        builtin
            .run(&Limits::default(), &mut ())
            .unwrap()
            .outcome
            .events
    });
    println!(
        "  built-in exact      {exact_impacts} impacts in {exact_seconds:.4} s: {:.0} impacts/s ({:.1}x taylor's speed)",
        exact_impacts as f64 / exact_seconds,
        taylor / exact_seconds
    );
    // With an event log every impact fires (no period is jumped), as a
    // `flicker run` writing events.jsonl does: the automaton by its
    // default method (the exact linear propagator) against the built-in
    // model, each writing its log to a file.
    let mut automaton: Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/models/automata/mechanism.json"
        ))
        .unwrap(),
    )
    .unwrap();
    automaton["parameters"] = parameters.clone();
    automaton["initial"] = initial.clone();
    automaton["t_end"] = json!(1e5);
    let automaton = Registry::builtin().from_value(&automaton).unwrap();
    let log = std::env::temp_dir().join(format!("flicker_bench_{}.jsonl", std::process::id()));
    let logged = |scene: &flicker::scene::Scene| {
        median_of(5, || {
            let file = std::io::BufWriter::new(std::fs::File::create(&log).unwrap());
            let mut writer = JsonlWriter::new(file);
            let report = scene.run(&Limits::default(), &mut writer).unwrap();
            writer.flush().unwrap();
            report.outcome.events
        })
    };
    let (logged_automaton, logged_impacts) = logged(&automaton);
    let (logged_builtin, _) = logged(&builtin);
    let _ = std::fs::remove_file(&log);
    println!(
        "  with their event logs ({logged_impacts} impacts fired): the automaton (linear) {logged_automaton:.4} s, the built-in model {logged_builtin:.4} s ({:.2}x)",
        logged_automaton / logged_builtin
    );

    println!();
    println!("the angle formulation, 100 impacts (eta 1.2, from strain 0.5 at rest), medians of 7");
    let t_end = 465.0;
    let charts_path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/models/automata/mechanism_charts.json"
    );
    let charts: Value =
        serde_json::from_str(&std::fs::read_to_string(charts_path).unwrap()).unwrap();
    let timed = |scene: Value| {
        let scene = Registry::builtin().from_value(&scene).unwrap();
        median_of(7, || {
            let report = scene.run(&Limits::default(), &mut ()).unwrap();
            assert_eq!(
                report.outcome.status.as_str(),
                "completed",
                "{:?}",
                report.outcome.reason
            );
            report
                .outcome
                .events_by_guard
                .get("impact")
                .copied()
                .unwrap_or(0)
        })
    };
    let dop853 = json!({"method": "dop853", "rtol": 1e-10, "atol": 1e-10});
    let mut automaton = charts.clone();
    automaton["t_end"] = json!(t_end);
    automaton["solver"] = dop853.clone();
    let (auto_seconds, auto_impacts) = timed(automaton);
    let (builtin_seconds, builtin_impacts) = timed(json!({
        "model": "mechanism", "formulation": "angle", "eta": 1.2,
        "initial": {"strain": 0.5, "strain_rate": 0.0}, "t_end": t_end, "solver": dop853}));
    let mut taylor = charts;
    taylor["t_end"] = json!(t_end);
    let (taylor_seconds, taylor_impacts) = timed(taylor);
    println!(
        "  built-in angle model, dop853 1e-10   {builtin_impacts} impacts in {builtin_seconds:.4} s"
    );
    println!(
        "  charts automaton, dop853 1e-10       {auto_impacts} impacts in {auto_seconds:.4} s ({:.2}x the built-in model's time)",
        auto_seconds / builtin_seconds
    );
    println!(
        "  charts automaton, taylor (default)   {taylor_impacts} impacts in {taylor_seconds:.4} s ({:.2}x)",
        taylor_seconds / builtin_seconds
    );

    println!();
    series_in_a_loop();
}

/// One compiled Taylor series of Henon-Heiles at order 20, in a loop.
fn series_in_a_loop() {
    let henon_heiles = AutomatonBuilder::new()
        .state("x", 0.05)
        .state("y", 0.3)
        .state("px", 0.3521363372331802)
        .state("py", 0.0)
        .mode(
            "m",
            [
                ("x", "px"),
                ("y", "py"),
                ("px", "-x - 2 * x * y"),
                ("py", "-y - x^2 + y^2"),
            ],
            [],
        )
        .build()
        .unwrap();
    let (order, calls) = (20, 20_000);
    let x0 = [0.05, 0.3, 0.3521363372331802, 0.0];
    let mut series = vec![0.0; 4 * (order + 1)];
    // Warmed up: the series is compiled after its first calls.
    for _ in 0..1000 {
        henon_heiles.flow_series(0, &x0, order, &mut series);
    }
    let (seconds, _) = median_of(15, || {
        for i in 0..calls {
            // A state that changes, as a run's does.
            let mut x = black_box(x0);
            x[0] += (i % 2) as f64 * 1e-9;
            henon_heiles.flow_series(0, &x, order, &mut series);
            black_box(&series);
        }
        calls
    });
    println!(
        "a Henon-Heiles series at order 20, compiled, in a loop: {:.0} ns a call (median of 15 loops of {calls})",
        seconds / calls as f64 * 1e9
    );
}
