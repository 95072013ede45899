//! No silent spinning: every long command (`orbit`, `continue`,
//! `lyapunov`, `sweep`, `compare`, `diagram`, `basins`) takes a
//! wall-clock budget (`--wall`),
//! stops there saying so (exit 3), keeps what it found, and refuses a
//! budget that is not a time > 0 (exit 2).

use crate::automata::automaton;
use crate::support::{flicker, models};

const TABLE_PERIOD: &str = "0.6283185307179586";

fn stderr(done: &std::process::Output) -> String {
    String::from_utf8_lossy(&done.stderr).into_owned()
}

/// A branch past its budget (steps of 1e-4 of the way, some 10^4 orbits
/// and 48 s on this machine, given half a second) ends there, its orbits
/// so far written: it takes its half second, and stops well short of the
/// whole (10 s allows for a loaded machine's start-up).
#[test]
fn a_branch_past_its_budget_ends_saying_so_with_its_orbits_kept() {
    let dir = tempfile::tempdir().unwrap();
    let started = std::time::Instant::now();
    let done = flicker(&[
        "continue",
        &automaton("vibrating_table.json"),
        "--section",
        "impact",
        "--param",
        "A",
        "--to",
        "0.16",
        "--settle",
        "2",
        "--forcing-period",
        TABLE_PERIOD,
        "--brute-force",
        "0",
        "--points",
        "100000",
        "--max-step",
        "0.0001",
        "--wall",
        "0.5",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let elapsed = started.elapsed().as_secs_f64();
    assert_eq!(done.status.code(), Some(3), "{}", stderr(&done));
    assert!(
        stderr(&done).contains("wall-clock budget"),
        "{}",
        stderr(&done)
    );
    assert!(
        (0.5..10.0).contains(&elapsed),
        "{elapsed} s for a budget of 0.5 s"
    );
    let csv = std::fs::read_to_string(dir.path().join("continuation.csv")).unwrap();
    assert!(csv.lines().count() >= 2, "the first orbit is kept: {csv}");
}

/// An orbit search, a sweep and a comparison past their budgets stop
/// saying so; the sweep writes every point, those not begun as such.
#[test]
fn searches_sweeps_and_comparisons_stop_at_their_budget() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let orbit = flicker(&[
        "orbit",
        &automaton("vibrating_table.json"),
        "--section",
        "impact",
        "--settle",
        "2",
        "--forcing-period",
        TABLE_PERIOD,
        "--wall",
        "1e-6",
        "--out",
        &out("orbit"),
    ]);
    assert_eq!(orbit.status.code(), Some(3), "{}", stderr(&orbit));
    assert!(
        stderr(&orbit).contains("wall-clock budget"),
        "{}",
        stderr(&orbit)
    );

    let csv = out("sweep.csv");
    let sweep = flicker(&[
        "sweep",
        &models("sweeps/impact_period.json"),
        "--wall",
        "1e-6",
        "--out",
        &csv,
    ]);
    assert_eq!(sweep.status.code(), Some(3), "{}", stderr(&sweep));
    let rows = std::fs::read_to_string(&csv).unwrap();
    let not_begun = rows.lines().filter(|r| r.contains("not begun")).count();
    assert!(
        not_begun > 0 && rows.contains("wall-clock budget"),
        "{rows:.300}"
    );
    assert_eq!(rows.lines().count(), 10001, "every point has its row");

    let compare = flicker(&[
        "compare",
        &models("mechanism_impacting.json"),
        "--wall",
        "1e-6",
        "--out",
        &out("compare"),
    ]);
    assert_eq!(compare.status.code(), Some(3), "{}", stderr(&compare));
    assert!(stderr(&compare).contains("wall"), "{}", stderr(&compare));
}

/// A budget that is not a time > 0 is refused before anything runs.
#[test]
fn a_budget_that_is_not_a_positive_time_is_refused() {
    let scene = models("mechanism_impacting.json");
    for args in [
        vec![
            "orbit",
            scene.as_str(),
            "--section",
            "impact",
            "--wall",
            "0",
        ],
        vec!["lyapunov", scene.as_str(), "--wall", "-1"],
        vec!["compare", scene.as_str(), "--wall", "nan"],
        vec!["sweep", &models("sweeps/impact_period.json"), "--wall", "0"],
    ] {
        let done = flicker(&args);
        assert_eq!(done.status.code(), Some(2), "{args:?}: {}", stderr(&done));
        assert!(
            stderr(&done).contains("--wall"),
            "{args:?}: {}",
            stderr(&done)
        );
    }
}

/// A diagram or a basin grid past its budget (each some seconds of work
/// on 2 cores, given a fifth of a second) stops there saying so, exit 3,
/// with what it ran written.
#[test]
fn a_diagram_and_a_basin_grid_past_their_budget_stop_saying_so() {
    let dir = tempfile::tempdir().unwrap();
    let table = automaton("vibrating_table.json");
    let well = automaton("double_well_wall.json");
    let runs: [(&str, Vec<&str>, &str); 2] = [
        (
            "diagram",
            vec![
                "diagram",
                &table,
                "--param",
                "A",
                "--from",
                "0.11",
                "--to",
                "0.2",
                "--points",
                "20000",
                "--section",
                "impact",
                "--transient",
                "60",
                "--record",
                "64",
                "--span",
                "60",
                "--past-horizon",
            ],
            "diagram.csv",
        ),
        (
            "basins",
            vec!["basins", &well, "--grid", "x=-1.35:2:200,v=-2:2:200"],
            "basins.csv",
        ),
    ];
    for (name, mut args, file) in runs {
        let out = dir.path().join(name);
        let out = out.to_str().unwrap().to_string();
        args.extend(["--wall", "0.2", "--quiet", "--out", &out]);
        let started = std::time::Instant::now();
        let done = flicker(&args);
        let elapsed = started.elapsed().as_secs_f64();
        assert_eq!(done.status.code(), Some(3), "{name}: {}", stderr(&done));
        assert!(
            stderr(&done).contains("wall-clock budget"),
            "{name}: {}",
            stderr(&done)
        );
        assert!(elapsed < 10.0, "{name}: {elapsed} s for a budget of 0.2 s");
        assert!(std::path::Path::new(&out).join(file).exists(), "{name}");
    }
}
