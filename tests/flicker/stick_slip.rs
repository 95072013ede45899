//! Stick-slip on a belt (`models/automata/stick_slip_belt.json`): dry
//! friction in the slip speed `v - vb`, static where the block moves with
//! the belt, kinetic below it, and a wall that takes half the block's
//! speed. A discontinuous flow combined with a reset:
//!
//! - with the bundled Stribeck law, each stick (a slide on `v = vb`) is the
//!   closed form `x = x_s + vb (t - t_s)`, ending where the spring pulls
//!   harder than static friction, at `x = ms`; each wall hit returns `-e v`;
//!   and every method agrees with Taylor's within their bounds;
//! - with friction falling linearly in the slip speed, `ms - c |v - vb|`,
//!   every region is a linear oscillator with negative damping, whose
//!   closed form gives every event: to 1e-12 by the exact methods, within
//!   their bounds by the others.

use serde_json::Value;

use crate::automata::{automaton, f, run, run_value};
use crate::filippov::{EXACT, OTHERS, allowance, events_match};
use crate::support::{SvgChart, flicker};

const STICK: &str = "block[v - vb=0]";
const BELOW: &str = "block[v - vb<0]";
const ABOVE: &str = "block[v - vb>0]";

fn belt() -> Value {
    serde_json::from_str(&std::fs::read_to_string(automaton("stick_slip_belt.json")).unwrap())
        .unwrap()
}

#[test]
fn the_belt_carries_the_block_until_the_spring_beats_static_friction() {
    let scene = belt();
    let p = &scene["parameters"];
    let (vb, ms, e) = (f(&p["vb"]), f(&p["ms"]), f(&p["e"]));
    let (reference, reference_events) =
        run(&automaton("stick_slip_belt.json"), &["--method", "taylor"]);
    for args in EXACT[1..].iter().chain(&OTHERS) {
        let (summary, events) = run(&automaton("stick_slip_belt.json"), args);
        let what = format!("{args:?}");
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        let (time, state) = (
            f(&summary["event_time_bound"]).max(1e-12),
            f(&summary["error_bound"]).max(1e-12),
        );
        let by_guard = &summary["events_by_guard"];
        assert!(
            by_guard["slide:v - vb"].as_u64().unwrap() >= 5,
            "{what}: {summary}"
        );
        assert!(by_guard["wall"].as_u64().unwrap() >= 5, "{what}: {summary}");
        for pair in events.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            if a["guard"] == "slide:v - vb" {
                // Stuck: moving with the belt until x = ms.
                assert_eq!(b["guard"], "leave:v - vb", "{what}: {b}");
                assert_eq!(b["mode_after"], BELOW, "{what}: {b}");
                let (ts, xs) = (f(&a["t"]), f(&a["after"]["x"]));
                assert_eq!(f(&a["after"]["v"]), vb, "{what}: {a}");
                assert!(
                    (f(&b["t"]) - (ts + (ms - xs) / vb)).abs() <= 2.0 * time,
                    "{what}: {b}"
                );
                assert!((f(&b["after"]["x"]) - ms).abs() <= state, "{what}: {b}");
            }
            if b["guard"] == "wall" {
                assert_eq!(
                    f(&b["after"]["v"]),
                    -e * f(&b["before"]["v"]),
                    "{what}: {b}"
                );
                assert_eq!(b["mode_after"], ABOVE, "{what}: {b}");
            }
        }
        // Every method's events are the reference's, within both bounds.
        assert_eq!(events.len(), reference_events.len(), "{what}");
        let both = time + f(&reference["event_time_bound"]);
        for (g, r) in events.iter().zip(&reference_events) {
            assert_eq!(g["guard"], r["guard"], "{what}");
            assert!(
                (f(&g["t"]) - f(&r["t"])).abs() <= both,
                "{what}: {g} against {r}"
            );
        }
    }
}

/// The belt with friction `ms - c |v - vb|` by its closed form. In region
/// `s = sign(v - vb)` the block obeys `x'' - c x' + x = -s ms - c vb`: about
/// its centre it turns at `sqrt(1 - c^2 / 4)` while growing as `exp(c t /
/// 2)`. It reaches `v = vb` from below where `x > -ms` (and from above where
/// `x < ms`) to stick, else crosses; stuck, it moves with the belt to `x =
/// ms`; the wall at `xw` returns `-e v`. Each next event is found on a
/// fine grid and bisected.
struct Linear {
    vb: f64,
    ms: f64,
    c: f64,
    xw: f64,
    e: f64,
}

impl Linear {
    /// `(x, v)` a time `tau` into region `s` from `(x, v)`.
    fn slip(&self, s: f64, (x, v): (f64, f64), tau: f64) -> (f64, f64) {
        let centre = -s * self.ms - self.c * self.vb;
        let (alpha, omega) = (self.c / 2.0, (1.0 - self.c * self.c / 4.0).sqrt());
        let (a, b) = (x - centre, (v - alpha * (x - centre)) / omega);
        let (grow, (sin, cos)) = ((alpha * tau).exp(), (omega * tau).sin_cos());
        (
            centre + grow * (a * cos + b * sin),
            grow * ((alpha * a + omega * b) * cos + (alpha * b - omega * a) * sin),
        )
    }

    fn events(&self, t_end: f64) -> (Vec<(f64, &'static str, &'static str)>, (f64, f64)) {
        let (mut t, mut state, mut region) = (0.0f64, (0.0f64, 0.0f64), Some(-1.0f64));
        let mut want = Vec::new();
        loop {
            let Some(s) = region else {
                let leave = t + (self.ms - state.0) / self.vb;
                if leave > t_end {
                    return (want, (state.0 + self.vb * (t_end - t), self.vb));
                }
                want.push((leave, "leave:v - vb", BELOW));
                (t, state, region) = (leave, (self.ms, self.vb), Some(-1.0));
                continue;
            };
            // Positive until the slip ends (`surface`) or the wall is hit;
            // each counts where it falls from positive to zero, so neither
            // fires again on the zero it starts from, nor the wall where the
            // block starts left of it.
            let surface = |tau: f64| s * (self.slip(s, state, tau).1 - self.vb);
            let wall = |tau: f64| self.slip(s, state, tau).0 - self.xw;
            let first = |g: &dyn Fn(f64) -> f64| -> Option<f64> {
                let grid = 1e-3;
                let mut lo = 0.0;
                while t + lo < t_end {
                    let hi = lo + grid;
                    if g(lo) > 0.0 && g(hi) <= 0.0 {
                        let (mut l, mut h) = (lo, hi);
                        for _ in 0..200 {
                            let m = 0.5 * (l + h);
                            if g(m) > 0.0 { l = m } else { h = m }
                        }
                        return Some(h);
                    }
                    lo = hi;
                }
                None
            };
            let next = match (first(&surface), first(&wall)) {
                (Some(a), Some(b)) => Some((a.min(b), a <= b)),
                (Some(a), None) => Some((a, true)),
                (None, Some(b)) => Some((b, false)),
                (None, None) => None,
            };
            match next {
                Some((tau, on_surface)) if t + tau <= t_end => {
                    let (x, v) = self.slip(s, state, tau);
                    t += tau;
                    if !on_surface {
                        let bounced = -self.e * v;
                        let into = (bounced - self.vb).signum();
                        want.push((t, "wall", if into > 0.0 { ABOVE } else { BELOW }));
                        (state, region) = ((x, bounced), Some(into));
                    } else if s * x < self.ms {
                        // The other side's flow points back: it sticks.
                        want.push((t, "slide:v - vb", STICK));
                        (state, region) = ((x, self.vb), None);
                    } else {
                        want.push((t, "cross:v - vb", if s < 0.0 { ABOVE } else { BELOW }));
                        (state, region) = ((x, self.vb), Some(-s));
                    }
                }
                _ => return (want, self.slip(s, state, t_end - t)),
            }
        }
    }
}

#[test]
fn with_friction_falling_linearly_every_event_is_its_closed_form() {
    let (c, xw) = (0.2, 0.8);
    let mut scene = belt();
    scene["parameters"]["c"] = c.into();
    scene["parameters"]["xw"] = xw.into();
    scene["modes"]["block"]["flow"]["v"] = "-x - (ms - c * abs(v - vb)) * sign(v - vb)".into();
    let p = &scene["parameters"];
    let belt = Linear {
        vb: f(&p["vb"]),
        ms: f(&p["ms"]),
        c,
        xw,
        e: f(&p["e"]),
    };
    let (want, (xe, ve)) = belt.events(f(&scene["t_end"]));
    let count = |g: &str| want.iter().filter(|w| w.1 == g).count();
    assert!(count("slide:v - vb") >= 4 && count("wall") >= 4, "{want:?}");
    for args in EXACT.iter().chain(&OTHERS) {
        let (summary, events) = run_value(&scene, args);
        let what = format!("{args:?}");
        let (time, state) = allowance(args, &summary);
        if args.is_empty() {
            // Every region is affine: the exact propagator runs it.
            assert_eq!(summary["method"], "linear", "{summary}");
        }
        assert_eq!(summary["status"], "completed", "{what}: {summary}");
        events_match(&events, &want, time, &what);
        let end = &summary["final_state"];
        assert!(
            (f(&end["x"]) - xe).abs() <= state,
            "{what}: {end} against {xe}"
        );
        assert!(
            (f(&end["v"]) - ve).abs() <= state,
            "{what}: {end} against {ve}"
        );
    }
}

/// `flicker plot phase` draws each stick in red: a segment along `v = vb`
/// from where the belt caught the block to `x = ms` (or to where the run
/// ends, stuck), one per slide.
#[test]
fn the_phase_plane_draws_each_stick_along_the_belt() {
    let dir = tempfile::tempdir().unwrap();
    let picture = dir.path().join("belt.svg");
    let scene = automaton("stick_slip_belt.json");
    let out = flicker(&[
        "plot",
        "phase",
        &scene,
        "--x",
        "x",
        "--y",
        "v",
        "--out",
        picture.to_str().unwrap(),
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (summary, events) = run(&scene, &[]);
    let slides: Vec<&Value> = events
        .iter()
        .filter(|e| e["guard"] == "slide:v - vb")
        .collect();
    let p = &belt()["parameters"];
    let (vb, ms) = (f(&p["vb"]), f(&p["ms"]));
    let chart = SvgChart::read(&picture);
    let (dx, dv) = chart.pixel_size();
    let sticks = chart.polylines("#D62728", "2");
    assert_eq!(sticks.len(), slides.len());
    for (k, (stick, slide)) in sticks.iter().zip(&slides).enumerate() {
        let stuck_at_the_end = k + 1 == slides.len() && events.last() == Some(*slide);
        let end = if stuck_at_the_end {
            f(&summary["final_state"]["x"])
        } else {
            ms
        };
        let ends = [chart.value(stick[0]), chart.value(*stick.last().unwrap())];
        for point in stick {
            let (_, v) = chart.value(*point);
            assert!((v - vb).abs() <= 2.0 * dv, "off the belt: v {v}");
        }
        assert!(
            (ends[0].0 - f(&slide["after"]["x"])).abs() <= 2.0 * dx,
            "{ends:?}"
        );
        assert!((ends[1].0 - end).abs() <= 2.0 * dx, "{ends:?}");
    }
}

/// The bundled belt against a reference made outside flicker: its 19
/// events by mpmath at 30 digits (Taylor series of each slip, events
/// bisected; `tests/fixtures/scripts/stick_slip_belt.py` writes
/// `tests/fixtures/stick_slip_belt.json`). Taylor's method meets each to
/// 1e-13 in time and 1e-14 in position, every method within its stated
/// bounds, and each bound within 1e3 of its error (or of 16 ulps of
/// t_end): 4.6 measured for Taylor, 150 for dopri5 at 1e-10, 46 for DOP853
/// at 1e-12.
#[test]
fn the_belt_meets_an_outside_reference() {
    let fixture = crate::support::fixture("stick_slip_belt.json");
    let number = crate::support::digits;
    let want: Vec<(&str, f64, f64)> = fixture["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["guard"].as_str().unwrap(),
                number(&e["t"]),
                number(&e["x"]),
            )
        })
        .collect();
    assert_eq!(want.len(), 19);
    for args in [
        &[][..],
        &["--method", "dopri5", "--rtol", "1e-10", "--atol", "1e-10"],
        &["--method", "dop853", "--rtol", "1e-12", "--atol", "1e-12"],
    ] {
        let (summary, events) = run(&automaton("stick_slip_belt.json"), args);
        assert_eq!(summary["status"], "completed", "{args:?}: {summary}");
        assert_eq!(events.len(), want.len(), "{args:?}");
        let (time_bound, state_bound) =
            (f(&summary["event_time_bound"]), f(&summary["error_bound"]));
        let mut largest = 16.0 * f64::EPSILON * 40.0;
        for (e, (guard, t, x)) in events.iter().zip(&want) {
            assert_eq!(e["guard"], *guard, "{args:?}");
            let (dt, dx) = ((f(&e["t"]) - t).abs(), (f(&e["before"]["x"]) - x).abs());
            assert!(dt <= time_bound && dx <= state_bound, "{args:?}: {e}");
            if args.is_empty() {
                assert!(dt < 1e-13 && dx < 1e-14, "{dt:e} {dx:e}");
            }
            largest = largest.max(dt);
        }
        assert!(
            time_bound <= 1e3 * largest,
            "{args:?}: {time_bound:e} vs {largest:e}"
        );
    }
}
