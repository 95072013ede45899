//! The bundled automata beyond the first three (`models/automata/`): the
//! mechanism's angle formulation as two charts, Housner's rocking block
//! and its linearisation, and four units of the chain, each against an
//! answer that does not come from its own file: the strain mechanism's
//! closed form written out in `oscillator.rs`, the rocking block's cosh
//! and sinh solution written out here, and the built-in chain.

use serde_json::{Value, json};

use crate::automata::{automaton, f, run, run_value};
use crate::oscillator::Unit;

/// The angle formulation as two charts (`mechanism_charts.json`: eta 1.2,
/// from `theta = acos(1 / 1.5)`, strain 0.5, at rest), by Taylor's method:
/// every `impact` (theta through zero, crossed in the strain chart) at the
/// strain model's closed-form time `t1 + k T_imp` and speed
/// `omega sqrt(2 H0)` to 1e-9 over the first 100, and the energy, written
/// per chart, kept to 1e-12 relative.
#[test]
fn the_angle_formulation_in_two_charts_agrees_with_the_strain_closed_form() {
    let unit = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let start = (0.5, 0.0);
    let h0 = unit.energy(start.0, start.1);
    let (t1, period) = (unit.first_closing(start).unwrap(), unit.period_atan2(h0));
    let (summary, events) = run(&automaton("mechanism_charts.json"), &[]);
    assert_eq!(summary["status"], "completed", "{summary}");
    assert_eq!(summary["method"], "taylor");
    let impacts: Vec<&Value> = events.iter().filter(|e| e["guard"] == "impact").collect();
    assert!(impacts.len() >= 100, "{} impacts", impacts.len());
    for (k, e) in impacts.iter().take(100).enumerate() {
        let t = t1 + k as f64 * period;
        assert!(
            (f(&e["t"]) - t).abs() < 1e-9,
            "impact {k}: {} vs {t}",
            e["t"]
        );
        let speed = unit.impact_speed(h0);
        assert!(
            (f(&e["before"]["strain_rate"]) + speed).abs() < 1e-9,
            "impact {k}: rate {} vs -{speed}",
            e["before"]["strain_rate"]
        );
        // theta changes side at each impact.
        let sides = if k % 2 == 0 {
            ("strain_positive", "strain_negative")
        } else {
            ("strain_negative", "strain_positive")
        };
        assert_eq!(
            (e["mode_before"].as_str(), e["mode_after"].as_str()),
            (Some(sides.0), Some(sides.1))
        );
    }
    // Between impacts the motion leaves the strain chart for the angle
    // chart and comes back: the strain chart is entered and left at its
    // thresholds, strain 0.05 and 0.1, and the energy, written in each
    // chart's coordinates, is the same on both sides of a change.
    for e in &events {
        match e["guard"].as_str().unwrap() {
            "enter_strain_chart" => {
                assert!((f(&e["after"]["strain"]) - 0.05).abs() < 1e-12, "{e}")
            }
            "leave_strain_chart" => {
                assert!((f(&e["before"]["strain"]) - 0.1).abs() < 1e-12, "{e}")
            }
            _ => {}
        }
        let (before, after) = (f(&e["energy_before"]), f(&e["energy_after"]));
        assert!((before - after).abs() < 1e-14, "{e}");
    }
    assert!(f(&summary["max_energy_error"]) < 1e-12, "{summary}");
}

/// Housner's block linearised, `theta'' = p^2 (theta - alpha sgn theta)`,
/// in closed form: from rest at `theta0` the first impact comes at
/// `cosh(p t1) = alpha / (alpha - theta0)` with speed
/// `p (alpha - theta0) sinh(p t1)`; leaving `theta = 0` at speed `w`, the
/// block swings out and back to zero in `(2 / p) atanh(w / (p alpha))`
/// (the flight is symmetric, and so is the other corner), and each impact
/// keeps `r = 1 - 1.5 sin^2 alpha` of the speed. Impact times and speeds
/// `(t_k, w_k)`, for `b`, `h`, `g` and `theta0 = alpha / 2`.
fn linear_block(g: f64, b: f64, h: f64, impacts: usize) -> Vec<(f64, f64)> {
    let alpha = (b / h).atan();
    let p = (3.0 * g / (4.0 * b.hypot(h))).sqrt();
    let r = 1.0 - 1.5 * alpha.sin().powi(2);
    let theta0 = 0.5 * alpha;
    let t1 = (alpha / (alpha - theta0)).acosh() / p;
    let mut w = p * (alpha - theta0) * (p * t1).sinh();
    let mut t = t1;
    let mut out = Vec::new();
    for _ in 0..impacts {
        out.push((t, w));
        w *= r;
        t += 2.0 / p * (w / (p * alpha)).atanh();
    }
    out
}

/// `rocking_block_linear.json` runs on the exact linear propagator (both
/// corners are affine) and meets the closed form: every impact time and
/// speed to 1e-10, corners alternating, the times within the stated bound
/// (widened by the closed form's own rounding in f64, 16 ulps of each
/// time) and the bound within 1e3 of their errors or of that rounding
/// (round-off alone).
#[test]
fn the_linearised_rocking_block_meets_its_cosh_sinh_closed_form() {
    let (summary, events) = run(&automaton("rocking_block_linear.json"), &[]);
    assert_eq!(summary["method"], "linear", "{summary}");
    assert_eq!(summary["status"], "completed", "{summary}");
    let exact = linear_block(9.81, 0.1, 1.0, events.len());
    assert!(events.len() >= 10, "{} impacts", events.len());
    let time_bound = f(&summary["event_time_bound"]);
    let mut largest = 0.0_f64;
    for (k, (e, (t, w))) in events.iter().zip(&exact).enumerate() {
        let (off, rounding) = ((f(&e["t"]) - t).abs(), 16.0 * f64::EPSILON * t);
        largest = largest.max(off.max(rounding));
        assert!(
            off <= time_bound + rounding,
            "impact {k}: {off:e} off, bound {time_bound:e}"
        );
        assert!(
            (f(&e["t"]) - t).abs() < 1e-10,
            "impact {k}: {} vs {t}",
            e["t"]
        );
        assert!(
            (f(&e["before"]["theta_rate"]).abs() - w).abs() < 1e-10,
            "impact {k}: speed {} vs {w}",
            e["before"]["theta_rate"]
        );
        let (from, to) = if k % 2 == 0 {
            ("right", "left")
        } else {
            ("left", "right")
        };
        assert_eq!(
            (e["mode_before"].as_str(), e["mode_after"].as_str()),
            (Some(from), Some(to))
        );
    }
    assert!(time_bound <= 1e3 * largest, "{time_bound:e} vs {largest:e}");
}

/// The nonlinear block (`sin(alpha - theta)`) against the linearised one,
/// both from `theta0 = alpha / 2`: their equations differ by
/// `(alpha - theta)^3 / 6 <= alpha^3 / 6` in `theta'' / p^2`, so over the
/// first impacts their impact speeds (of order `p alpha`) differ by
/// `O(p alpha^3)`. Checked as a law: at most `p alpha^3`, and halving alpha
/// divides the largest difference by about 8 (between 6 and 10).
#[test]
fn the_rocking_block_approaches_its_linearisation_as_alpha_cubed() {
    let (g, h) = (9.81_f64, 1.0_f64);
    let mut differences = Vec::new();
    for b in [0.2_f64, 0.1, 0.05] {
        let alpha = (b / h).atan();
        let p = (3.0 * g / (4.0 * b.hypot(h))).sqrt();
        let mut scene: Value = serde_json::from_str(
            &std::fs::read_to_string(automaton("rocking_block.json")).unwrap(),
        )
        .unwrap();
        scene["parameters"]["b"] = json!(b);
        let (summary, events) = run_value(&scene, &[]);
        assert_eq!(summary["status"], "completed", "{summary}");
        let exact = linear_block(g, b, h, 4);
        assert!(events.len() >= 4, "b {b}: {} impacts", events.len());
        let largest = events
            .iter()
            .zip(&exact)
            .map(|(e, (_, w))| (f(&e["before"]["theta_rate"]).abs() - w).abs())
            .fold(0.0, f64::max);
        assert!(
            largest < p * alpha.powi(3),
            "b {b}: {largest} vs {}",
            p * alpha.powi(3)
        );
        // Energy, written per corner, is kept along each swing: every
        // impact takes away 1 - r^2 of the kinetic energy and nothing else
        // changes it.
        let r = 1.0 - 1.5 * alpha.sin().powi(2);
        let potential = g * b.hypot(h) * alpha.cos();
        for e in &events {
            let (before, after) = (f(&e["energy_before"]), f(&e["energy_after"]));
            let lost = (1.0 - r * r) * (before - potential);
            assert!((before - after - lost).abs() < 1e-12 * before, "b {b}: {e}");
        }
        differences.push(largest);
    }
    for pair in differences.windows(2) {
        let ratio = pair[0] / pair[1];
        assert!(
            (6.0..10.0).contains(&ratio),
            "{differences:?}: ratio {ratio}"
        );
    }
}

/// Four units of the chain written out as an automaton (`chain4.json`: a
/// Newton's cradle, node 1 into a packed block, then rattling) against
/// mpmath's event-driven solution (`tests/fixtures/scripts/chain4.py`,
/// normal modes between impacts at 40 digits): by every method the same
/// 31 impacts in the same order (the cradle's simultaneous impacts at
/// `t = 0` one pair at a time, by priority), each within the stated time
/// bound, and the end within the stated error bound. The bounds are not
/// far above the errors: within 3e4 for the Runge-Kutta pairs (their
/// embedded estimate, see `conformance.rs`: 7.9e3 measured), 1e3 for
/// Stormer-Verlet's truncation (74), and 1e4 for the exact propagator and
/// Taylor's method, whose errors are round-off below one event's
/// allowance (16 ulps) while the bound adds 31 events' allowances and the
/// cradle amplifies them about a hundredfold (3.4e3 and 380 measured).
/// The built-in chain ends at the same right end and momentum.
#[test]
fn four_units_written_out_meet_an_outside_reference() {
    let fixture = crate::support::fixture("chain4.json");
    let number = crate::support::digits;
    let impacts: Vec<(f64, String)> = fixture["impacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| (number(&i["t"]), format!("unit{}", i["unit"])))
        .collect();
    assert_eq!(impacts.len(), 31);
    let names = ["y1", "y2", "y3", "y4", "v1", "v2", "v3", "v4"];
    let end: Vec<f64> = names.iter().map(|k| number(&fixture["final"][k])).collect();
    let floor = 16.0 * f64::EPSILON;
    for (args, looseness) in [
        (&[][..], 1e4),
        (&["--method", "taylor"], 1e4),
        (&["--method", "dopri5"], 3e4),
        (&["--method", "dop853"], 3e4),
        (&["--method", "verlet", "--step", "1e-3"], 1e3),
    ] {
        let (summary, events) = run(&automaton("chain4.json"), args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        let (time_bound, bound) = (f(&summary["event_time_bound"]), f(&summary["error_bound"]));
        assert_eq!(events.len(), impacts.len(), "{args:?}");
        let mut late = 0.0_f64;
        for (k, (e, (t, unit))) in events.iter().zip(&impacts).enumerate() {
            assert_eq!(e["guard"], unit.as_str(), "{args:?}: impact {k}");
            let off = (f(&e["t"]) - t).abs();
            late = late.max(off);
            assert!(
                off <= time_bound,
                "{args:?}: impact {k} at {} vs {t}",
                e["t"]
            );
        }
        let error = names
            .iter()
            .zip(&end)
            .map(|(k, x)| (f(&summary["final_state"][k]) - x).abs())
            .fold(0.0, f64::max);
        assert!(
            error <= bound,
            "{args:?}: error {error:e} over its bound {bound:e}"
        );
        assert!(
            bound <= looseness * error.max(floor) && time_bound <= looseness * late.max(floor),
            "{args:?}: bounds {bound:e} and {time_bound:e} against errors {error:e} and {late:e}"
        );
        if args.is_empty() {
            assert!(f(&summary["max_energy_error"]) < 1e-12, "{summary}");
        }
    }
    let builtin = json!({
        "model": "chain", "units": 4, "length": 4.0, "wave_speed": 1.0,
        "load": {"before": 1.0, "after": 1.0}, "constraint": true,
        "initial": {"strain": [0.5, 0.0, 0.0, 0.5], "velocity": [1.0, 0.0, 0.0, 0.0]},
        "t_end": 20.0});
    let (chain, _) = run_value(&builtin, &[]);
    assert_eq!(chain["status"], "completed", "{chain}");
    let momentum: f64 = end[4..].iter().sum();
    assert!((f(&chain["final_state"]["right_end"]) - end[3]).abs() < 1e-9);
    assert!((f(&chain["final_state"]["momentum"]) - momentum).abs() < 1e-9);
}

/// The ball on the vibrating table (`vibrating_table.json`), thrown up at
/// `g T / 2` from the table at `t = 0` (`T = 2 pi / w`), lands at `t = T`,
/// where the table is back at zero: by every method, though its flight is
/// a polynomial whose series ends (a step could be as long as the run)
/// while the guard reads the clock through `sin(w t)`. A step as long as
/// its flow allows summed the guard's series far past where it converges,
/// and Taylor's method found this impact 3e-5 late, below the table; at
/// `w = 100` (the same `Gamma`) the linear propagator, which measured the
/// guard's series against its own large coefficients, missed it.
#[test]
fn the_vibrating_tables_first_impact_is_found_by_every_method() {
    let scene: Value =
        serde_json::from_str(&std::fs::read_to_string(automaton("vibrating_table.json")).unwrap())
            .unwrap();
    for w in [10.0_f64, 100.0] {
        let mut scene = scene.clone();
        scene["parameters"]["w"] = json!(w);
        scene["parameters"]["A"] = json!(f(&scene["parameters"]["A"]) * (10.0 / w).powi(2));
        scene["t_end"] = json!(20.0 * 10.0 / w);
        let period = 2.0 * std::f64::consts::PI / w;
        for method in ["linear", "taylor", "dop853"] {
            let (summary, events) = run_value(&scene, &["--method", method]);
            assert_eq!(summary["status"], "completed", "w {w}, {method}: {summary}");
            let first = &events[0];
            assert!(
                (f(&first["t"]) - period).abs() < 1e-12,
                "w {w}, {method}: first impact at {}",
                first["t"]
            );
            assert!(
                f(&first["before"]["y"]).abs() < 1e-12,
                "w {w}, {method}: {first}"
            );
        }
    }
}

/// The rocking block (`rocking_block.json`, nonlinear: no closed form)
/// against a reference made outside flicker: its impact times, the speeds
/// before them and the state at `t_end` by quadrature in mpmath at 40
/// digits (`tests/fixtures/scripts/rocking_block.py`, which writes
/// `tests/fixtures/rocking_block.json`). Every method completes within
/// its stated bounds, and the bounds are not far above the errors: within
/// 1e3 of them for Taylor's method (round-off alone: 180 measured, for the
/// times and the final state) and Stormer-Verlet (120), and within 3e4
/// for the Runge-Kutta pairs, whose bounds carry their embedded estimate
/// of the lower order (570 for dopri5, 1.4e3 for DOP853). Each half-swing
/// is a fall away from an unstable equilibrium (errors grow as e^{p t},
/// p = 2.7 /s, and the next impact takes that back), which bounds made of
/// norms could not follow.
#[test]
fn the_rocking_block_meets_an_outside_reference() {
    let fixture = crate::support::fixture("rocking_block.json");
    let number = crate::support::digits;
    let impacts: Vec<(f64, f64)> = fixture["impacts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| (number(&i["t"]), number(&i["speed_before"])))
        .collect();
    assert_eq!(impacts.len(), 12);
    let last = [
        number(&fixture["final"]["theta"]),
        number(&fixture["final"]["theta_rate"]),
    ];
    for (args, looseness) in [
        (&[][..], 1e3),
        (
            &["--method", "dopri5", "--rtol", "1e-10", "--atol", "1e-10"],
            3e4,
        ),
        (
            &["--method", "dop853", "--rtol", "1e-12", "--atol", "1e-12"],
            3e4,
        ),
        (&["--method", "verlet", "--step", "1e-3"], 1e3),
    ] {
        let (summary, events) = run(&automaton("rocking_block.json"), args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        assert_eq!(events.len(), impacts.len(), "{args:?}");
        let (time_bound, bound) = (f(&summary["event_time_bound"]), f(&summary["error_bound"]));
        let mut late = 0.0_f64;
        for (e, (t, speed)) in events.iter().zip(&impacts) {
            let off = (f(&e["t"]) - t).abs();
            late = late.max(off);
            assert!(off <= time_bound, "{args:?}: impact at {} vs {t}", e["t"]);
            let rate = f(&e["before"]["theta_rate"]).abs();
            assert!(
                (rate - speed).abs() <= bound,
                "{args:?}: speed {rate} vs {speed}"
            );
        }
        let state = &summary["final_state"];
        let error = (f(&state["theta"]) - last[0])
            .abs()
            .max((f(&state["theta_rate"]) - last[1]).abs());
        assert!(
            error <= bound,
            "{args:?}: final state {error:e} off, bound {bound:e}"
        );
        // Round-off's floor: 16 ulps of the speed, and of the time.
        let (floor, time_floor) = (16.0 * f64::EPSILON * 0.25, 16.0 * f64::EPSILON * 10.0);
        assert!(
            bound <= looseness * error.max(floor) && time_bound <= looseness * late.max(time_floor),
            "{args:?}: bounds {bound:e} and {time_bound:e} against errors {error:e} and {late:e}"
        );
    }
}
