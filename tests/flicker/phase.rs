//! Phase portraits: every point of every drawn level set, separatrix
//! included, and of every simulated trajectory lies on its level of the
//! plane's first integral, written out here, in every plane.

use flicker::models::mechanism::Mechanism;
use flicker::plot::draw::Style;
use flicker::plot::phase::{Plane, Portrait};

use crate::support::flicker;

/// The plane's first integral at `(x, y)`, written out from docs/physics.md
/// s.2-3 (not the plot module's): `H0` in the strain plane; in
/// `(theta, theta')` with `eps = sec theta - 1` and
/// `eps' = theta' sin theta / cos^2 theta`; in `(theta, p0)` with
/// `p0 = tan^2 theta sec^2 theta theta' / omega`, so
/// `eps' = p0 omega cos^2 theta / sin theta`; and in the linearised plane
/// `K = b'^2 + omega^2 (b - 2 f1)^2` with `b = theta1^2`.
fn integral(eta: f64, omega: f64, plane: Plane, x: f64, y: f64) -> f64 {
    let h0 = |eps: f64, rate: f64| {
        rate * rate / (2.0 * omega * omega) + eps * (eps + 2.0 * (1.0 - eta)) / 2.0
    };
    match plane {
        Plane::Strain => h0(x, y),
        Plane::Theta => h0(1.0 / x.cos() - 1.0, y * x.sin() / x.cos().powi(2)),
        Plane::Canonical => h0(1.0 / x.cos() - 1.0, y * omega * x.cos().powi(2) / x.sin()),
        Plane::Linear { f1 } => {
            let (b, b_rate) = (x * x, 2.0 * x * y);
            b_rate * b_rate + (omega * (b - 2.0 * f1)).powi(2)
        }
    }
}

/// Every plane, below, at and above the critical load; the linearised
/// plane on both sides of it.
const CASES: [(f64, Plane); 9] = [
    (1.2, Plane::Strain),
    (0.8, Plane::Strain),
    (1.0, Plane::Strain),
    (1.2, Plane::Canonical),
    (0.8, Plane::Canonical),
    (1.2, Plane::Theta),
    (0.8, Plane::Theta),
    (1.0, Plane::Linear { f1: 0.2 }),
    (1.0, Plane::Linear { f1: -0.2 }),
];
const OMEGA: f64 = 1.3;

/// The largest |level| drawn: the scale of the plane's round-off.
fn scale(portrait: &Portrait) -> f64 {
    portrait
        .level_sets
        .iter()
        .fold(0.0, |m: f64, (level, _)| m.max(level.abs()))
}

#[test]
fn every_drawn_level_set_lies_on_its_exact_level() {
    for (eta, plane) in CASES {
        let portrait = Portrait::new(Mechanism { eta, omega: OMEGA }, plane);
        // The curves reported are the curves drawn, one for one.
        let drawn: Vec<_> = portrait
            .figure
            .curves
            .iter()
            .filter(|c| matches!(c.style, Style::Level | Style::Separatrix))
            .collect();
        assert_eq!(drawn.len(), portrait.level_sets.len(), "{plane:?}");
        for (curve, (_, points)) in drawn.iter().zip(&portrait.level_sets) {
            assert_eq!(&curve.points, points, "{plane:?}");
        }
        // A separatrix where there is one: H0 = 0 above the critical load,
        // K = (2 omega f1)^2 in the linearised plane for f1 > 0 (18).
        let separatrix: Vec<f64> = drawn
            .iter()
            .zip(&portrait.level_sets)
            .filter(|(c, _)| c.style == Style::Separatrix)
            .map(|(_, (level, _))| *level)
            .collect();
        let expected = match plane {
            Plane::Linear { f1 } if f1 > 0.0 => Some((2.0 * OMEGA * f1).powi(2)),
            Plane::Linear { .. } => None,
            _ if eta > 1.0 => Some(0.0),
            _ => None,
        };
        match expected {
            Some(k) => {
                assert!(
                    !separatrix.is_empty(),
                    "{plane:?} at eta {eta}: no separatrix"
                );
                assert!(
                    separatrix.iter().all(|s| (s - k).abs() <= 1e-15 * k),
                    "{plane:?}: separatrix at {separatrix:?}, not {k}"
                );
            }
            None => assert!(separatrix.is_empty(), "{plane:?} at eta {eta}"),
        }
        // Each point is a few operations on numbers of the size of the
        // levels (the rate from a square root of the level's balance), so
        // its integral is off by some ulps of the largest level (at most
        // 1.1e-15 measured); 1e-13 leaves room for the sec, sin and cos of
        // the angle planes. A level drawn from its four-decimal label
        // would be off by up to 5e-5.
        let scale = scale(&portrait);
        let mut points = 0;
        for (level, curve) in &portrait.level_sets {
            for &(x, y) in curve {
                if plane == Plane::Canonical && x == 0.0 {
                    // theta = 0 on an impacting orbit: p0 -> 0 there (it
                    // goes as theta), where the integral is 0 / 0.
                    assert_eq!(y, 0.0, "{plane:?}");
                    continue;
                }
                let value = integral(eta, OMEGA, plane, x, y);
                assert!(
                    (value - level).abs() <= 1e-13 * scale,
                    "eta {eta}, {plane:?}: level {level} but {value} at ({x}, {y})"
                );
                points += 1;
            }
        }
        assert!(points > 1000, "{plane:?}: only {points} points");
        // The dashed resets of the strain plane join (0, v) and (0, -v) on
        // an impacting level: eps' -> -eps' at eps = 0.
        for jump in portrait
            .figure
            .curves
            .iter()
            .filter(|c| c.style == Style::Jump)
        {
            let [(x0, v0), (x1, v1)] = jump.points[..] else {
                panic!("a jump is one segment: {:?}", jump.points)
            };
            assert_eq!((x0, x1, v0), (0.0, 0.0, -v1), "{plane:?}");
            let h = integral(eta, OMEGA, plane, 0.0, v1);
            assert!(
                portrait
                    .level_sets
                    .iter()
                    .any(|(level, _)| *level > 0.0 && (h - level).abs() <= 1e-13 * scale),
                "{plane:?}: a jump at H0 = {h} on no impacting level"
            );
        }
    }
}

#[test]
fn simulated_trajectories_stay_on_the_curves_they_are_drawn_on() {
    for (eta, plane) in CASES {
        let portrait = Portrait::new(Mechanism { eta, omega: OMEGA }, plane);
        // Exact flows keep the level to some ulps per sample (480 samples,
        // each run from the last: 2e-14 of the scale measured), so 1e-12;
        // the angle formulation is integrated by Dormand-Prince at
        // rtol = atol = 1e-12, whose local errors over the two periods'
        // ~10^3 steps add up to ~1e-9 at most (4e-11 measured).
        let tolerance = match plane {
            Plane::Strain | Plane::Linear { .. } => 1e-12,
            Plane::Canonical | Plane::Theta => 1e-9,
        };
        let scale = scale(&portrait);
        assert!(!portrait.trajectories.is_empty(), "{plane:?}");
        for (level, points) in &portrait.trajectories {
            assert!(points.len() > 100, "{plane:?}: {} points", points.len());
            assert!(
                portrait.level_sets.iter().any(|(l, _)| l == level),
                "{plane:?}: a trajectory at {level}, a level not drawn"
            );
            for &(x, y) in points {
                let value = integral(eta, OMEGA, plane, x, y);
                assert!(
                    (value - level).abs() <= tolerance * scale,
                    "eta {eta}, {plane:?}: a trajectory of level {level} at ({x}, {y}), where the integral is {value}"
                );
            }
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
