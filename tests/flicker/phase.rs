//! Phase portraits: the level sets drawn from the formulas and the
//! trajectories the engine simulates lie on each other, in every plane.

use flicker::models::mechanism::Mechanism;
use flicker::plot::phase::{Plane, Portrait, first_integral};

use crate::support::flicker;

#[test]
fn simulated_trajectories_lie_on_the_drawn_level_sets() {
    let cases = [
        (1.2, Plane::Strain, 1e-12),
        (0.8, Plane::Strain, 1e-12),
        // The angle formulation is integrated numerically (rtol 1e-12).
        (0.8, Plane::Canonical, 1e-9),
        (1.2, Plane::Canonical, 1e-9),
        (1.2, Plane::Theta, 1e-9),
        (1.0, Plane::Linear { f1: 0.2 }, 1e-12),
        (1.0, Plane::Linear { f1: -0.2 }, 1e-12),
    ];
    for (eta, plane, tolerance) in cases {
        let portrait = Portrait::new(Mechanism { eta, omega: 1.0 }, plane);
        assert!(!portrait.trajectories.is_empty());
        assert!(
            portrait
                .trajectories
                .iter()
                .all(|(_, points)| points.len() > 100),
            "{plane:?}"
        );
        let mismatch = portrait.largest_mismatch();
        assert!(
            mismatch < tolerance,
            "eta {eta}, {plane:?}: mismatch {mismatch:e}"
        );
    }
}

#[test]
fn the_level_sets_are_the_first_integral() {
    // Every point of every drawn level set carries its level's value.
    let m = Mechanism {
        eta: 1.2,
        omega: 1.3,
    };
    let portrait = Portrait::new(m, Plane::Strain);
    let levels: Vec<f64> = portrait.trajectories.iter().map(|(h, _)| *h).collect();
    assert!(
        levels.iter().any(|h| *h < 0.0) && levels.iter().any(|h| *h > 0.0),
        "a loose and an impacting orbit"
    );
    for curve in &portrait.figure.curves {
        let Some(label) = &curve.label else { continue };
        let Some(level) = label
            .strip_prefix("H0 = ")
            .and_then(|v| v.parse::<f64>().ok())
        else {
            continue;
        };
        for &(x, y) in &curve.points {
            // Labels round the level to four decimals.
            assert!(
                (first_integral(m, Plane::Strain, x, y) - level).abs() < 1e-4,
                "{label} at ({x}, {y})"
            );
        }
    }
}

#[test]
fn plot_phase_draws_and_refuses_bad_flags() {
    let dir = tempfile::tempdir().unwrap();
    let svg = dir.path().join("strain.svg");
    let ok = flicker(&[
        "plot",
        "phase",
        "--eta",
        "0.8",
        "--out",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    for expected in [
        "strain eps",
        "strain rate eps",
        "H0 = ",
        "constraint eps = 0",
    ] {
        assert!(text.contains(expected), "the picture lacks {expected:?}");
    }
    let png = dir.path().join("linear.png");
    let ok = flicker(&[
        "plot",
        "phase",
        "--plane",
        "linear",
        "--f1",
        "0.2",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(ok.status.code(), Some(0));
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
    let no_f1 = flicker(&[
        "plot",
        "phase",
        "--plane",
        "linear",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(no_f1.status.code(), Some(2));
    let bad_plane = flicker(&[
        "plot",
        "phase",
        "--eta",
        "1",
        "--plane",
        "polar",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert_eq!(bad_plane.status.code(), Some(2));
}

#[test]
fn plot_dir_draws_what_a_run_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let scene = crate::support::models("mechanism_angle.json");
    assert!(
        flicker(&["run", &scene, "--out", out.to_str().unwrap(), "--quiet"])
            .status
            .success()
    );
    let drawn = flicker(&["plot", out.to_str().unwrap()]);
    assert_eq!(
        drawn.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&drawn.stderr)
    );
    for name in ["energy.svg", "energy.png", "intervals.svg", "intervals.png"] {
        assert!(
            std::fs::metadata(out.join(name)).unwrap().len() > 1000,
            "{name}"
        );
    }
    let svg = std::fs::read_to_string(out.join("energy.svg")).unwrap();
    assert!(svg.contains("energy across events") && svg.contains("time t"));
    // One dot per impact with an energy on both sides.
    let impacts = std::fs::read_to_string(out.join("events.jsonl"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(svg.matches("<circle").count(), impacts);
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert_eq!(
        flicker(&["plot", empty.to_str().unwrap()]).status.code(),
        Some(2)
    );
}
