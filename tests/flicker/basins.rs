//! Basins of attraction (`flicker basins`) against an integrator written
//! here, independent of flicker: the damped double well against a wall
//! (`double_well_wall.json`), `x'' + c x' - x + x^3 = 0`, its speed turned
//! back by `-r` where `x` reaches `-w`, settles at `x = -1` or `x = 1`;
//! classical Runge-Kutta with a fixed step, the wall found by bisection on
//! the step, says which. And the vibrating table's period-one orbit, named
//! periodic, on Holmes's closed form.

use std::f64::consts::PI;

use serde_json::Value;

use flicker::scene::Scene;
use flicker::session::{AttractorKind, Basins, BasinsRequest, Registry};

use crate::automata::automaton;
use crate::support::{flicker, read_json};

const C: f64 = 0.25;
const WALL: f64 = 1.4;
const R: f64 = 0.8;

fn field(s: [f64; 2]) -> [f64; 2] {
    let [x, v] = s;
    [v, -C * v + x - x * x * x]
}

/// One classical Runge-Kutta step of `h`.
fn rk4(s: [f64; 2], h: f64) -> [f64; 2] {
    let add = |a: [f64; 2], k: [f64; 2], f: f64| [a[0] + f * k[0], a[1] + f * k[1]];
    let k1 = field(s);
    let k2 = field(add(s, k1, h / 2.0));
    let k3 = field(add(s, k2, h / 2.0));
    let k4 = field(add(s, k3, h));
    [
        s[0] + h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
        s[1] + h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
    ]
}

/// Where the double well from `(x, v)` ends after `t_end`: -1 or 1, by the
/// side it settles on.
fn settles_at(x: f64, v: f64, t_end: f64) -> f64 {
    let h = 1e-3;
    let (mut s, mut t) = ([x, v], 0.0);
    while t < t_end {
        let next = rk4(s, h);
        if next[0] + WALL < 0.0 {
            // The wall within this step: bisect for the part of it before.
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if rk4(s, mid)[0] + WALL < 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let at = rk4(s, lo);
            s = [-WALL, -R * at[1]];
            t += lo;
            continue;
        }
        s = next;
        t += h;
    }
    assert!(
        s[1].abs() < 1e-6 && (s[0].abs() - 1.0).abs() < 1e-6,
        "{x}, {v}: {s:?}"
    );
    s[0].signum()
}

/// The bundled automaton `name` as a scene.
fn bundled(name: &str) -> Scene {
    Registry::builtin()
        .from_value(&read_json(std::path::Path::new(&automaton(name))))
        .unwrap()
}

/// Basins of `grid` read at `section`, the other settings the CLI's
/// defaults but a minute's wall time; tests change what they need.
fn request(grid: [&str; 2], section: Option<&str>) -> BasinsRequest {
    BasinsRequest {
        grid: grid.map(String::from).to_vec(),
        transient: None,
        section: section.map(String::from),
        record: 16,
        tolerance: 1e-6,
        forcing_period: None,
        past_horizon: false,
        shard: None,
        wall: 60.0,
    }
}

fn basins(
    scene: &str,
    grid: [&str; 2],
    section: Option<&str>,
    forcing_period: Option<f64>,
) -> Basins {
    let scene = bundled(scene);
    let asked = BasinsRequest {
        forcing_period,
        wall: 120.0,
        ..request(grid, section)
    };
    asked.on(&scene).unwrap().run(None, &|| {})
}

#[test]
fn the_double_well_s_basins_agree_with_an_independent_integrator() {
    let found = basins(
        "double_well_wall.json",
        ["x=-1.35:2:31", "v=-2:2:31"],
        None,
        None,
    );
    // Two attractors, both equilibria, at x = -1 and x = 1 at rest.
    assert_eq!(found.attractors.len(), 2, "{:?}", found.attractors);
    let mut sides = Vec::new();
    for a in &found.attractors {
        assert_eq!(a.kind, AttractorKind::Equilibrium);
        assert!((a.state[0].abs() - 1.0).abs() < 1e-6 && a.state[1].abs() < 1e-6);
        sides.push(a.state[0].signum());
    }
    assert_eq!(sides.iter().sum::<f64>(), 0.0, "one on each side");
    let (xs, vs) = (&found.values[0], &found.values[1]);
    let mut agree = 0;
    for (index, id) in found.attractor.iter().enumerate() {
        let (x, v) = (xs[index / vs.len()], vs[index % vs.len()]);
        let ours = sides[id.unwrap()];
        if ours == settles_at(x, v, 200.0) {
            agree += 1;
        }
    }
    // At least 99% of the 961 points: a point can fall either way only
    // within the two integrators' errors of a basin's edge.
    assert!(agree >= 952, "{agree} of 961 agree");
    // Both basins are there in earnest: neither holds nearly everything.
    let on = |id: usize| found.attractor.iter().filter(|a| **a == Some(id)).count();
    assert!(on(0) > 100 && on(1) > 100, "{} and {}", on(0), on(1));
}

#[test]
fn the_vibrating_table_s_period_one_orbit_is_named_periodic_on_its_closed_form() {
    // Starts above the table at rest: they reach Holmes's period-one
    // orbit (one impact a table period, leaving at g T / 2), or chatter
    // down to it (a Zeno point).
    let (g, r, a, w) = (9.81_f64, 0.5_f64, 0.1275_f64, 10.0_f64);
    let found = basins(
        "vibrating_table.json",
        ["y=0.05:0.6:6", "v=0:4:6"],
        Some("impact"),
        Some(2.0 * PI / w),
    );
    let periodic: Vec<_> = found
        .attractors
        .iter()
        .filter(|a| a.kind == AttractorKind::Periodic)
        .collect();
    assert!(!periodic.is_empty(), "{:?}", found.attractors);
    let v = found.names.iter().position(|n| n == "v").unwrap();
    let one = periodic.iter().find(|a| a.cycle.len() == 1).unwrap();
    let take_off = g * PI / w;
    assert!((one.cycle[0][v] - take_off).abs() < 1e-6, "{:?}", one.cycle);
    assert!(one.points > 0);
    // Refined with the forcing's period: one table period, and the exact
    // impact map's multipliers at Holmes's phase `phi` (`cos(phi) = pi (1
    // - r) / ((1 + r) Gamma)`): the roots of `mu^2 - tr mu + r^2`, `tr =
    // 1 + r^2 - (1 + r)^2 Gamma sin(phi)`, beside the clock's trivial 1.
    let orbit = one.orbit.as_ref().expect("refined with the forcing period");
    assert!(
        (orbit.period - 2.0 * PI / w).abs() < 1e-12,
        "{}",
        orbit.period
    );
    let gamma = a * w * w / g;
    let phi = (PI * (1.0 - r) / ((1.0 + r) * gamma)).acos();
    let trace = 1.0 + r * r - (1.0 + r).powi(2) * gamma * phi.sin();
    let mut found: Vec<(f64, f64)> = orbit.multipliers.clone();
    let trivial = (0..found.len())
        .min_by(|&i, &j| {
            let off = |z: (f64, f64)| (z.0 - 1.0).hypot(z.1);
            off(found[i]).total_cmp(&off(found[j]))
        })
        .unwrap();
    found.remove(trivial);
    let (sum, product) = match found[..] {
        [p, q] => (p.0 + q.0, (p.0 * q.0 - p.1 * q.1, p.0 * q.1 + p.1 * q.0)),
        _ => panic!("{:?}", orbit.multipliers),
    };
    assert!((sum - trace).abs() < 1e-8, "{sum} against {trace}");
    assert!((product.0 - r * r).abs() < 1e-8 && product.1.abs() < 1e-8);
    assert!(orbit.stable);
}

#[test]
fn a_forced_orbit_is_left_unrefined_without_its_forcing_period() {
    let found = basins(
        "vibrating_table.json",
        ["y=0.05:0.6:3", "v=0:4:3"],
        Some("impact"),
        None,
    );
    let periodic = found
        .attractors
        .iter()
        .find(|a| a.kind == AttractorKind::Periodic);
    assert!(periodic.expect("periodic").orbit.is_none());
    // A forcing period for an autonomous model is refused, naming it.
    let scene = bundled("double_well_wall.json");
    let asked = BasinsRequest {
        forcing_period: Some(1.0),
        ..request(["x=-1:1:3", "v=-1:1:3"], None)
    };
    let refused = asked.on(&scene).err().expect("refused");
    assert!(refused.to_string().contains("forcing_period"), "{refused}");
}

#[test]
fn a_quasi_periodic_orbit_is_not_called_chaotic() {
    // A ball bouncing elastically on the floor beside an undamped
    // oscillator of frequency 1: at the bounces the oscillator's phase
    // turns by 2 u / g, irrational for almost every start, so the section
    // states never repeat; yet nearby orbits part only linearly (the
    // bounce period's shear), an exponent of about ln(t) / t, below ten
    // times the 1 / span floor. Unresolved, with the exponent said.
    let scene = serde_json::json!({
        "model": "automaton",
        "parameters": {"g": 1.0},
        "states": ["x", "p", "y", "u"],
        "initial": {"x": 1.0, "p": 0.0, "y": 0.3, "u": 0.0},
        "modes": {"flight": {
            "flow": {"x": "p", "p": "-x", "y": "u", "u": "-g"},
            "transitions": [{"name": "bounce", "guard": "y", "direction": "falling",
                             "barrier": true, "reset": {"u": "-u"}}]}},
        "t_end": 200.0
    });
    let scene = Registry::builtin().from_value(&scene).unwrap();
    let asked = BasinsRequest {
        record: 32,
        past_horizon: true,
        ..request(["x=0.5:1:2", "y=0.3:0.37:2"], Some("bounce"))
    };
    let found = asked.on(&scene).unwrap().run(None, &|| {});
    assert_eq!(found.attractors.len(), 1, "{:?}", found.attractors);
    let torus = &found.attractors[0];
    assert_eq!(torus.kind, AttractorKind::Unresolved, "{torus:?}");
    assert!(
        torus
            .reason
            .as_ref()
            .unwrap()
            .contains("no positive exponent")
    );
    let exponent = torus.exponent.expect("measured");
    assert!(exponent.abs() < 10.0 / 200.0, "{exponent}");
    assert_eq!(torus.points, 4);
}

#[test]
fn the_command_line_writes_the_grid_and_its_attractors() {
    let out = tempfile::tempdir().unwrap();
    let dir = out.path().to_str().unwrap();
    let scene = automaton("double_well_wall.json");
    let done = flicker(&[
        "basins",
        &scene,
        "--grid",
        "x=-1.35:2:11,v=-2:2:9",
        "--out",
        dir,
        "--quiet",
    ]);
    let stdout = String::from_utf8_lossy(&done.stdout);
    assert_eq!(done.status.code(), Some(0), "{stdout}");
    assert!(stdout.contains("reach 2 attractors"), "{stdout}");
    let csv = std::fs::read_to_string(out.path().join("basins.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("x,v,attractor"));
    assert_eq!(lines.count(), 99);
    let list: Value = read_json(&out.path().join("attractors.json"));
    let list = list.as_array().unwrap();
    assert_eq!(list.len(), 2);
    for a in list {
        assert_eq!(a["kind"], "equilibrium");
        let x = a["state"]["x"].as_f64().unwrap();
        assert!((x.abs() - 1.0).abs() < 1e-6, "{a}");
    }
    let points: u64 = list.iter().map(|a| a["points"].as_u64().unwrap()).sum();
    assert_eq!(points, 99);
    // A grid that names no state of the scene is refused, nothing written.
    let bad = out.path().join("bad");
    let done = flicker(&[
        "basins",
        &scene,
        "--grid",
        "y=0:1:3,v=0:1:3",
        "--out",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(done.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&done.stderr).contains("--grid: no state is called `y`"));
    assert!(!bad.exists());
}

#[test]
fn the_stick_slip_cycle_is_refined_with_its_multipliers_from_every_start() {
    // The block on the belt: whatever its start (on either side of the
    // belt's speed, each begun in its own region of the discontinuous
    // flow), it ends on the one stick-slip cycle. Right after the wall
    // the block is at the wall, moving away from it.
    let scene = bundled("stick_slip_belt.json");
    let asked = BasinsRequest {
        transient: Some(100.0),
        record: 6,
        ..request(["x=-0.5:1:6", "v=-1:1:6"], Some("wall"))
    };
    let found = asked.on(&scene).unwrap().run(None, &|| {});
    assert_eq!(found.attractors.len(), 1, "{:?}", found.attractors);
    let cycle = &found.attractors[0];
    assert_eq!(
        (cycle.kind, cycle.cycle.len(), cycle.points),
        (AttractorKind::Periodic, 1, 36)
    );
    let (x, v) = (cycle.cycle[0][0], cycle.cycle[0][1]);
    assert!((x - 0.4).abs() < 1e-9 && v > 0.0, "{x}, {v}");
    // Refined by the orbit finder: the trivial multiplier 1 along the
    // flow, and 0: the sticking forgets where the slip began.
    let orbit = cycle.orbit.as_ref().expect("refined");
    let mut moduli: Vec<f64> = orbit.multipliers.iter().map(|m| m.0.hypot(m.1)).collect();
    moduli.sort_by(f64::total_cmp);
    assert!(
        moduli[0] < 1e-9 && (moduli[1] - 1.0).abs() < 1e-9,
        "{moduli:?}"
    );
    assert!(orbit.stable && orbit.period > 0.0);
}

#[test]
fn a_chaotic_attractor_is_named_by_its_positive_exponent_past_the_horizon() {
    // The vibrating table at A = 0.169, inside the band the brute-force
    // diagram shows after the period-doubling cascade: starts either
    // chatter to rest (Zeno) or reach an attractor whose impacts never
    // repeat and whose neighbours part.
    let mut scene = read_json(std::path::Path::new(&automaton("vibrating_table.json")));
    scene["parameters"]["A"] = serde_json::json!(0.169);
    scene["t_end"] = serde_json::json!(60.0);
    let scene = Registry::builtin().from_value(&scene).unwrap();
    let asked = |past_horizon| BasinsRequest {
        record: 64,
        past_horizon,
        ..request(["y=0.05:0.6:4", "v=0:4:4"], Some("impact"))
    };
    let found = asked(true).on(&scene).unwrap().run(None, &|| {});
    let chaotic: Vec<_> = found
        .attractors
        .iter()
        .filter(|a| a.kind == AttractorKind::Chaotic)
        .collect();
    assert_eq!(chaotic.len(), 1, "{:?}", found.attractors);
    // Positive well beyond its measurement's 1/span floor (10 / 60).
    let exponent = chaotic[0].exponent.unwrap();
    assert!(exponent > 0.2, "{exponent}");
    assert!(
        found
            .attractors
            .iter()
            .all(|a| a.kind != AttractorKind::Unresolved)
    );
    // Without going past the horizon, those runs fail there: unresolved,
    // and said why.
    let found = asked(false).on(&scene).unwrap().run(None, &|| {});
    let unresolved = found
        .attractors
        .iter()
        .find(|a| a.kind == AttractorKind::Unresolved)
        .expect("runs stopped at their horizon");
    assert!(
        unresolved.reason.as_deref().unwrap().contains("horizon"),
        "{:?}",
        unresolved.reason
    );
}
