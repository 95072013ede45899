//! `flicker run --samples N` and `--at T1,T2,...`: the state at chosen
//! times, each with its error bound, in `samples.csv`, against closed
//! forms written here:
//!
//! - the paper's mechanism above the critical load (its strain a harmonic
//!   about `eta - 1`, the rate flipped at each impact), by the exact flow:
//!   every sample within 1e-12 of the closed form started from the last
//!   logged impact, and within its stated bound;
//! - the forced impact oscillator (`x'' + 2 zeta x' + x = cos(w t)`, an
//!   automaton run by Taylor's method): within 1e-11;
//! - a sample at an event's time holds the state before the reset.

use std::path::Path;

use serde_json::Value;

use crate::automata::{automaton, f, forced_oscillator};
use crate::support::{flicker, models, read_json};

/// Run `scene` with `args` into a temporary folder: the summary, the log
/// and the rows of `samples.csv` (its header checked against `names`).
fn sampled(scene: &str, args: &[&str], names: &[&str]) -> (Value, Vec<Value>, Vec<Vec<f64>>) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let mut all = vec!["run", scene, "--quiet", "--out", out.to_str().unwrap()];
    all.extend_from_slice(args);
    let done = flicker(&all);
    assert_eq!(
        done.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let summary = read_json(&out.join("summary.json"));
    let events = std::fs::read_to_string(out.join("events.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let text = std::fs::read_to_string(out.join("samples.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("t,{},bound", names.join(","))
    );
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (summary, events, rows)
}

/// The last logged event at or before `t` (strictly before, for a sample
/// at an event's own time, which holds the state before it).
fn last_before<'a>(events: &'a [Value], t: f64) -> Option<&'a Value> {
    events.iter().take_while(|e| f(&e["t"]) < t).last()
}

#[test]
fn the_mechanisms_samples_lie_on_its_closed_form() {
    let scene = models("mechanism_impacting.json");
    let text: Value = serde_json::from_str(&std::fs::read_to_string(&scene).unwrap()).unwrap();
    let (c, w) = (f(&text["eta"]) - 1.0, f(&text["omega"]));
    let (summary, events, rows) =
        sampled(&scene, &["--samples", "2001"], &["strain", "strain_rate"]);
    assert_eq!(rows.len(), 2001);
    assert_eq!(summary["samples"]["count"], 2001);
    assert!(events.len() > 100, "{} impacts", events.len());
    let (e0, r0) = (rows[0][1], rows[0][2]);
    let mut worst: f64 = 0.0;
    for row in &rows {
        let (t, bound) = (row[0], row[3]);
        let (t0, e, r) = match last_before(&events, t) {
            Some(ev) => (
                f(&ev["t"]),
                f(&ev["after"]["strain"]),
                f(&ev["after"]["strain_rate"]),
            ),
            None => (0.0, e0, r0),
        };
        // The harmonic about c from (e, r) at t0.
        let (s, co) = (w * (t - t0)).sin_cos();
        let strain = c + (e - c) * co + r / w * s;
        let rate = -(e - c) * w * s + r * co;
        for (got, want) in [(row[1], strain), (row[2], rate)] {
            let error = (got - want).abs();
            worst = worst.max(error);
            // The closed form here is evaluated in doubles too: a few
            // ulps of the state beside the stated bound.
            assert!(error <= 1e-12, "t {t}: {got} against {want}");
            assert!(
                error <= bound + 4e-16,
                "t {t}: error {error:e}, bound {bound:e}"
            );
        }
    }
    assert!(worst > 0.0 || rows.len() < 10);
}

#[test]
fn the_forced_impact_oscillators_samples_lie_on_its_closed_form() {
    let (zeta, w) = (0.05, 0.8);
    let (_, events, rows) = sampled(
        &automaton("impact_oscillator.json"),
        &["--samples", "1000"],
        &["x", "v"],
    );
    assert!(events.len() >= 20);
    for row in &rows {
        let t = row[0];
        let (t0, x0, v0) = match last_before(&events, t) {
            Some(ev) => (f(&ev["t"]), f(&ev["after"]["x"]), f(&ev["after"]["v"])),
            None => (0.0, 0.0, 0.0),
        };
        let (x, v) = forced_oscillator(zeta, w, t0, x0, v0, t);
        assert!(
            (row[1] - x).abs() <= 1e-11,
            "t {t}: x {} against {x}",
            row[1]
        );
        assert!(
            (row[2] - v).abs() <= 1e-11,
            "t {t}: v {} against {v}",
            row[2]
        );
    }
}

/// `--at` an impact's own time: the state before the flip (closing), and
/// the times sorted whatever order they are given in.
#[test]
fn a_sample_at_an_event_holds_the_state_before_it() {
    let scene = models("mechanism_impacting.json");
    let (_, events, _) = sampled(&scene, &["--samples", "2"], &["strain", "strain_rate"]);
    let impact = &events[3];
    let t = f(&impact["t"]);
    let at = format!("{},{}", t + 1.0, t);
    let (_, _, rows) = sampled(&scene, &["--at", &at], &["strain", "strain_rate"]);
    assert_eq!(rows[0][0], t);
    assert_eq!(rows[1][0], t + 1.0);
    let before = f(&impact["before"]["strain_rate"]);
    assert!(before < 0.0);
    assert!(
        (rows[0][2] - before).abs() <= 1e-12,
        "{:?} against {impact}",
        rows[0]
    );
}

/// Bad sample requests are refused before anything is written, naming the
/// flag: too few samples, a time past t_end, a model with no samples.
#[test]
fn bad_sample_requests_are_refused_naming_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let scene = models("mechanism_impacting.json");
    for (args, says) in [
        (vec!["--samples", "1"], "--samples"),
        (vec!["--at", "0.5,2000"], "--at: 2000"),
    ] {
        let mut all = vec!["run", scene.as_str(), "--out", out.to_str().unwrap()];
        all.extend(args);
        let done = flicker(&all);
        assert_eq!(done.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&done.stderr).contains(says));
        assert!(!Path::new(&out).exists());
    }
    let chain = models("chain_cradle.json");
    let done = flicker(&[
        "run",
        &chain,
        "--samples",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(done.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&done.stderr).contains("offers no samples"));
    assert!(!Path::new(&out).exists());
}
