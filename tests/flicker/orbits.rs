//! Periodic orbits (`flicker orbit`) against closed forms written out
//! here: the mechanism's impacting orbits (period `T_imp`, both
//! multipliers 1), the ball on a vibrating table (Holmes's period-one
//! orbit: its phase, speed and the eigenvalues of the exact impact map),
//! and the forced impact oscillator (its period-one impacting orbit from
//! the linear oscillator's closed form, and its stability from the flow's
//! fundamental matrix and the impact's saltation matrix), and the sliding
//! orbit of Piiroinen and Kuznetsov's relay feedback system (a fixed point
//! of its piecewise closed form: matrix exponentials between the surface's
//! events, the sliding flow's on it).

use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector};
use serde_json::{Value, json};

use crate::automata::{automaton, forced_oscillator};
use crate::support::{flicker, read_json};

/// `flicker orbit` of `scene` (a value) with `args`: exit code and
/// `orbit.json`.
fn orbit(scene: &Value, args: &[&str]) -> (Option<i32>, Value) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let out = dir.path().join("o");
    let mut all = vec![
        "orbit",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    let done = flicker(&all);
    (done.status.code(), read_json(&out.join("orbit.json")))
}

fn read(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(automaton(name)).unwrap()).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

/// The orbit's multipliers as complex pairs, the trivial 1 (nearest to 1)
/// left out.
fn nontrivial(orbit: &Value) -> Vec<(f64, f64)> {
    let mut all: Vec<(f64, f64)> = orbit["multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|z| (f(&z[0]), f(&z[1])))
        .collect();
    let trivial = all
        .iter()
        .enumerate()
        .min_by(|a, b| ((a.1.0 - 1.0).hypot(a.1.1)).total_cmp(&(b.1.0 - 1.0).hypot(b.1.1)))
        .unwrap()
        .0;
    all.remove(trivial);
    all
}

/// Roots of `mu^2 - tr mu + det` as complex pairs.
fn roots(tr: f64, det: f64) -> [(f64, f64); 2] {
    let disc = tr * tr - 4.0 * det;
    if disc >= 0.0 {
        let s = disc.sqrt();
        [((tr + s) / 2.0, 0.0), ((tr - s) / 2.0, 0.0)]
    } else {
        let s = (-disc).sqrt();
        [(tr / 2.0, s / 2.0), (tr / 2.0, -s / 2.0)]
    }
}

/// Each expected multiplier has one found within `tol`.
fn same_multipliers(found: &[(f64, f64)], expected: &[(f64, f64)], tol: f64) {
    assert_eq!(
        found.len(),
        expected.len(),
        "{found:?} against {expected:?}"
    );
    for e in expected {
        assert!(
            found.iter().any(|z| (z.0 - e.0).hypot(z.1 - e.1) < tol),
            "{e:?} not among {found:?}"
        );
    }
}

/// The mechanism's impacting orbits, from rest at several energies,
/// below, at and above the critical load: the period is the closed-form
/// `T_imp = (2 / omega) atan2(sqrt(2 H0), 1 - eta)` to 1e-12 (relative),
/// and the system is conservative and autonomous: both multipliers 1 to
/// 1e-10.
#[test]
fn the_mechanisms_impacting_orbits_have_the_closed_form_period_and_unit_multipliers() {
    for (eta, omega, eps) in [
        (1.2, 1.0, 0.5),
        (0.8, 2.0, 0.3),
        (1.0, 1.5, 0.1),
        (1.5, 1.0, 1.2),
    ] {
        let mut scene = read("mechanism.json");
        scene["parameters"] = json!({"eta": eta, "omega": omega});
        scene["initial"] = json!({"strain": eps, "strain_rate": 0.0});
        let (code, o) = orbit(&scene, &["--section", "impact"]);
        assert_eq!(code, Some(0), "{o}");
        let h0: f64 = eps * (eps + 2.0 * (1.0 - eta)) / 2.0;
        let period = 2.0 / omega * (2.0 * h0).sqrt().atan2(1.0 - eta);
        assert!(
            (f(&o["period"]) - period).abs() < 1e-12 * period,
            "eta {eta}: {o}"
        );
        for z in o["multipliers"].as_array().unwrap() {
            assert!(
                (f(&z[0]) - 1.0).abs() < 1e-10 && f(&z[1]).abs() < 1e-10,
                "eta {eta}: {o}"
            );
        }
        assert_eq!(o["stable"], true);
        assert!(f(&o["residual"]) < 1e-12);
        // At the section: just after the impact, on the constraint, opening.
        assert_eq!(f(&o["section_state"]["strain"]), 0.0);
        assert!((f(&o["section_state"]["strain_rate"]) - omega * (2.0 * h0).sqrt()).abs() < 1e-12);
    }
}

/// Holmes's ball on a table moving as `A sin(w t)`, restitution `r`: the
/// period-one orbit leaves the table at speed `g T / 2` (`T = 2 pi / w`)
/// at the phase `cos(phi) = pi (1 - r) / ((1 + r) Gamma)`, `Gamma = A w^2
/// / g`, `sin(phi) > 0` on the stable branch; the exact impact map's
/// Jacobian there has determinant `r^2` and trace `1 + r^2 - (1 + r)^2
/// Gamma sin(phi)`, whose roots are the orbit's multipliers. Newton,
/// started from the drop of `vibrating_table.json` after a transient of 2,
/// finds the phase and speed to 1e-10 and the multipliers to 1e-9.
#[test]
fn the_vibrating_table_has_holmes_period_one_orbit() {
    let (g, r, a, w) = (9.81_f64, 0.5_f64, 0.1275_f64, 10.0_f64);
    let period = 2.0 * PI / w;
    let (code, o) = orbit(
        &read("vibrating_table.json"),
        &[
            "--section",
            "impact",
            "--settle",
            "2",
            "--forcing-period",
            &period.to_string(),
        ],
    );
    assert_eq!(code, Some(0), "{o}");
    assert!(f(&o["iterations"]) >= 1.0, "Newton had work to do: {o}");
    let gamma = a * w * w / g;
    let phi = (PI * (1.0 - r) / ((1.0 + r) * gamma)).acos();
    let state = &o["section_state"];
    let phase = (w * f(&state["t"])).rem_euclid(2.0 * PI);
    assert!((phase - phi).abs() < 1e-10, "phase {phase} against {phi}");
    assert!((f(&state["v"]) - g * period / 2.0).abs() < 1e-10);
    assert!((f(&state["y"]) - a * phi.sin()).abs() < 1e-10);
    assert!((f(&o["period"]) - period).abs() < 1e-12);
    let trace = 1.0 + r * r - (1.0 + r).powi(2) * gamma * phi.sin();
    same_multipliers(&nontrivial(&o), &roots(trace, r * r), 1e-9);
    assert_eq!(o["stable"], true);
}

/// The forced impact oscillator `x'' + 2 zeta x' + x = cos(w t)` against a
/// stop at `x = s` (restitution `r`; `w = 1.2`): its period-one orbit
/// impacts once per forcing period `T` at a phase `t0` with incoming speed
/// `u`, so that from `(s, -r u)` at `t0` the closed form comes back to `(s,
/// u)` at `t0 + T` without touching the stop between. Solved here by
/// Newton on the closed form, from flicker's answer; flicker's section
/// state agrees to 1e-10. Its multipliers are the eigenvalues of the
/// impact's saltation matrix times the flow's fundamental matrix over `T`
/// (both written out here), to 1e-9.
#[test]
fn the_forced_impact_oscillator_has_its_closed_form_period_one_orbit() {
    let (zeta, w, s, r) = (0.05_f64, 1.2_f64, 0.5_f64, 0.8_f64);
    let period = 2.0 * PI / w;
    let mut scene = read("impact_oscillator.json");
    scene["parameters"]["w"] = json!(w);
    scene["t_end"] = json!(400.0);
    let (code, o) = orbit(
        &scene,
        &[
            "--section",
            "impact",
            "--settle",
            "20",
            "--forcing-period",
            &period.to_string(),
        ],
    );
    assert_eq!(code, Some(0), "{o}");
    let state = &o["section_state"];
    assert_eq!(f(&state["x"]), s);
    // The closed form's equations in (t0, u): back at the stop, at speed u.
    let back = |t0: f64, u: f64| forced_oscillator(zeta, w, t0, s, -r * u, t0 + period);
    let (mut t0, mut u) = (f(&state["t"]).rem_euclid(period), -f(&state["v"]) / r);
    for _ in 0..20 {
        let residual = |t0: f64, u: f64| {
            let (x, v) = back(t0, u);
            (x - s, v - u)
        };
        let (f1, f2) = residual(t0, u);
        let h = 1e-7;
        let (a1, a2) = residual(t0 + h, u);
        let (b1, b2) = residual(t0, u + h);
        let (j11, j21, j12, j22) = ((a1 - f1) / h, (a2 - f2) / h, (b1 - f1) / h, (b2 - f2) / h);
        let det = j11 * j22 - j12 * j21;
        t0 -= (j22 * f1 - j12 * f2) / det;
        u -= (-j21 * f1 + j11 * f2) / det;
    }
    let (x, v) = back(t0, u);
    assert!(
        (x - s).abs() < 1e-13 && (v - u).abs() < 1e-13,
        "the closed form's orbit"
    );
    for k in 1..400 {
        let (x, _) = forced_oscillator(zeta, w, t0, s, -r * u, t0 + period * k as f64 / 400.0);
        assert!(
            x < s,
            "the closed-form orbit touches the stop between impacts"
        );
    }
    let phase = f(&state["t"]).rem_euclid(period);
    assert!((phase - t0).abs() < 1e-10, "phase {phase} against {t0}");
    assert!(
        (-f(&state["v"]) / r - u).abs() < 1e-10,
        "speed {} against {u}",
        -f(&state["v"]) / r
    );
    // Stability: saltation times the fundamental matrix over the period.
    let column = |dx: f64, dv: f64| {
        let (x1, v1) = forced_oscillator(zeta, w, t0, s + dx, -r * u + dv, t0 + period);
        let (x0, v0) = back(t0, u);
        ((x1 - x0), (v1 - v0))
    };
    // The homogeneous flow is linear: a unit perturbation's image is exact.
    let (p11, p21) = column(1.0, 0.0);
    let (p12, p22) = column(0.0, 1.0);
    let force = (w * (t0 + period)).cos();
    let a_before = force - 2.0 * zeta * u - s;
    let a_after = force + 2.0 * zeta * r * u - s;
    let (s11, s12, s21, s22) = (-r, 0.0, (a_after + r * a_before) / u, -r);
    let (m11, m12) = (s11 * p11 + s12 * p21, s11 * p12 + s12 * p22);
    let (m21, m22) = (s21 * p11 + s22 * p21, s21 * p12 + s22 * p22);
    same_multipliers(
        &nontrivial(&o),
        &roots(m11 + m22, m11 * m22 - m12 * m21),
        1e-9,
    );
    let stable = nontrivial(&o).iter().all(|z| z.0.hypot(z.1) < 1.0);
    assert_eq!(o["stable"], stable);
}

/// A search that cannot succeed says why, exit 3: a loose mechanism
/// (no impact to make a section of), an unknown section, a forced system
/// without its forcing period (bad input, exit 2).
#[test]
fn a_search_that_cannot_succeed_says_why() {
    let mut loose = read("mechanism.json");
    loose["initial"] = json!({"strain": 0.3, "strain_rate": 0.0});
    let (code, o) = orbit(&loose, &["--section", "impact"]);
    assert_eq!(code, Some(3));
    assert_eq!(o["converged"], false);
    assert!(
        o["status"]
            .as_str()
            .unwrap()
            .contains("no start on the section"),
        "{o}"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let bad = flicker(&[
        "orbit",
        &automaton("mechanism.json"),
        "--section",
        "bounce",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no transition is called `bounce`"));
    let unforced = flicker(&[
        "orbit",
        &automaton("impact_oscillator.json"),
        "--section",
        "impact",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(unforced.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&unforced.stderr).contains("forcing"));
}

/// The relay feedback system `x' = A x - b sign(x1)`
/// (`models/automata/relay_feedback_3d.json`) by its closed form: off the
/// surface `x(t) = exp(M t) (x, 1)` with `M = [[A, -s b], [0, 0]]` on side
/// `s`; on it (`x1 = 0`, the equivalent control `u = x2`) `x2' = 2 sigma x2
/// + x3`, `x3' = -x2`, until `|x2|` reaches 1 and the run leaves to the
/// side of `x2`. Events are found on a 1e-3 grid and bisected.
struct Relay {
    region: [DMatrix<f64>; 2],
    sliding: DMatrix<f64>,
}

impl Relay {
    fn new(p: &Value) -> Self {
        let (w, xi, l, sigma) = (f(&p["w"]), f(&p["xi"]), f(&p["l"]), f(&p["sigma"]));
        let side = |s: f64| {
            let rows = [
                [-(2.0 * xi * w + l), 1.0, 0.0, -s],
                [-(2.0 * xi * w * l + w * w), 0.0, 1.0, 2.0 * sigma * s],
                [-l * w * w, 0.0, 0.0, -s],
                [0.0; 4],
            ];
            DMatrix::from_fn(4, 4, |i, j| rows[i][j])
        };
        Relay {
            region: [side(1.0), side(-1.0)],
            sliding: DMatrix::from_row_slice(2, 2, &[2.0 * sigma, 1.0, -1.0, 0.0]),
        }
    }

    /// The first time `g` falls from positive to zero or below.
    fn first(g: &dyn Fn(f64) -> f64) -> f64 {
        let mut lo = 1e-3;
        while g(lo + 1e-3) > 0.0 {
            lo += 1e-3;
            assert!(lo < 100.0, "no event");
        }
        let mut hi = lo + 1e-3;
        for _ in 0..100 {
            let m = 0.5 * (lo + hi);
            if g(m) > 0.0 { lo = m } else { hi = m }
        }
        hi
    }

    /// From `(0, x2, x3)` just after a leave to side `s`, the state just
    /// after the `k`-th next leave, its side and the time taken.
    fn leaves(&self, mut s: f64, x3: f64, k: usize) -> (f64, f64, f64) {
        let (mut x, mut t) = (DVector::from_vec(vec![0.0, s, x3, 1.0]), 0.0);
        for _ in 0..k {
            let m = &self.region[if s > 0.0 { 0 } else { 1 }];
            let at = |tau: f64| (m * tau).exp() * &x;
            let tau = Self::first(&|tau| s * at(tau)[0]);
            x = at(tau);
            assert!(x[1].abs() < 1.0, "it crosses, not slides: {x}");
            t += tau;
            let on = DVector::from_vec(vec![x[1], x[2]]);
            let along = |tau: f64| (&self.sliding * tau).exp() * &on;
            let tau = Self::first(&|tau| 1.0 - along(tau)[0].abs());
            let y = along(tau);
            s = y[0].signum();
            x = DVector::from_vec(vec![0.0, s, y[1], 1.0]);
            t += tau;
        }
        (x[2], s, t)
    }
}

/// Piiroinen and Kuznetsov's relay feedback system slides on `x1 = 0`
/// seven times each half period; the orbit `flicker orbit` finds is a
/// fixed point of the closed-form map to 1e-12 (the matrix exponentials'
/// rounding, 1e-15 a phase, over 28 phases), with its period, and its one nontrivial
/// multiplier is the map's derivative (by central differences, to 1e-6).
#[test]
fn the_relay_feedback_systems_sliding_orbit_is_its_closed_forms_fixed_point() {
    let scene = read("relay_feedback_3d.json");
    let (code, o) = orbit(
        &scene,
        &["--section", "leave:x1", "--events", "14", "--settle", "20"],
    );
    assert_eq!(code, Some(0), "{o}");
    assert_eq!(o["converged"], true, "{o}");
    let at = &o["section_state"];
    assert_eq!(f(&at["x1"]), 0.0, "{o}");
    let side = f(&at["x2"]);
    assert_eq!(side.abs(), 1.0, "{o}");
    let relay = Relay::new(&scene["parameters"]);
    let x3 = f(&at["x3"]);
    let (back, back_side, period) = relay.leaves(side, x3, 14);
    assert_eq!(back_side, side);
    assert!((back - x3).abs() <= 1e-12, "{back} against {x3}");
    assert!(
        (period - f(&o["period"])).abs() <= 1e-12,
        "{period} against {o}"
    );
    // Half a period on, the orbit's mirror image: the relay is odd.
    let (half, half_side, half_period) = relay.leaves(side, x3, 7);
    assert_eq!(half_side, -side);
    assert!((half + x3).abs() <= 1e-12 && (2.0 * half_period - period).abs() <= 1e-12);
    let d = 1e-5;
    let slope = (relay.leaves(side, x3 + d, 14).0 - relay.leaves(side, x3 - d, 14).0) / (2.0 * d);
    let found = nontrivial(&o);
    let largest = found.iter().map(|z| z.0.hypot(z.1)).fold(0.0, f64::max);
    assert!(
        (largest - slope.abs()).abs() <= 1e-6,
        "{found:?} against {slope}"
    );
    assert_eq!(o["stable"], true);
}
