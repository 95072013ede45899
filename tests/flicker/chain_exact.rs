//! The chain's exact event-local flow (`TaylorChain`) against what it must
//! reproduce: hand-worked cradles, the modal solution of the unconstrained
//! chain, the independent ODE path's event sequence before the chaos
//! horizon, energy and the momentum balance over the release scene, and no
//! unit ever found below zero strain (which a missed impact would leave).

use flicker::engine::{
    LocalModel, Method, Options, Outcome, Recorder, Status, Tolerances, simulate, simulate_local,
};
use flicker::models::chain::{Chain, TaylorChain, modal};
use flicker::time::Time;

/// Run `model` to `t_end` with no samples, keeping every event.
fn run(model: &mut TaylorChain, t_end: f64) -> (Outcome, Recorder) {
    let mut log = Recorder::default();
    let o = simulate_local(model, &Options::until(t_end), &[], &mut |_, _| {}, &mut log);
    (o, log)
}

/// Gaps from node positions (node 0 at the wall, at 0).
fn gaps(y: &[f64]) -> Vec<f64> {
    (0..y.len())
        .map(|i| y[i] - if i > 0 { y[i - 1] } else { 0.0 })
        .collect()
}

/// Velocities just after the cascades of the first microsecond, for nodes
/// of unit mass with springs too weak to matter by then.
fn cradle(y: &[f64], v: &[f64]) -> (Vec<f64>, Recorder) {
    let weak = 1e-8;
    let chain = Chain::new(y.len(), 1.0, weak, weak, weak, true);
    let mut model = TaylorChain::new(chain, &gaps(y), v).unwrap();
    let (o, log) = run(&mut model, 1e-6);
    assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
    (model.state_at(Time::new(1e-6)).1, log)
}

fn close(a: &[f64], b: &[f64], tolerance: f64) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

#[test]
fn cradles_end_as_worked_out_by_hand() {
    // Node 1 at speed 2 into nodes 2-4, packed and at rest.
    let (v, log) = cradle(&[1.0; 4], &[2.0, 0.0, 0.0, 0.0]);
    assert!(close(&v, &[0.0, 0.0, 0.0, 2.0], 1e-12), "{v:?}");
    assert_eq!(log.events.len(), 1, "one cascade at t = 0");
    assert_eq!(log.events[0].labels.count("unit"), Some(2));
    assert!((log.events[0].labels.number("rel_velocity").unwrap() - 2.0).abs() < 1e-12);
    // Speeds 3 and 1 into two at rest: [0, 0, 1, 3].
    let (v, _) = cradle(&[1.0; 4], &[3.0, 1.0, 0.0, 0.0]);
    assert!(close(&v, &[0.0, 0.0, 1.0, 3.0], 1e-12), "{v:?}");
    // A block packed at the wall, the first node moving into it.
    let (v, _) = cradle(&[0.0; 3], &[-1.0, 0.0, 0.0]);
    assert!(close(&v, &[0.0, 0.0, 1.0], 1e-12), "{v:?}");
    let (v, _) = cradle(&[0.0; 2], &[-1.0, -2.0]);
    assert!(close(&v, &[1.0, 2.0], 1e-12), "{v:?}");
    // Five units: node 1 at 2.5 a gap of 1e-6 behind node 2, which moves
    // at 0.5 into the packed nodes 3-5. By hand: at t = 0 unit 3 passes
    // the 0.5 on to node 5; at t = 1e-6 / 2.5 = 4e-7 node 1 reaches node 2
    // and unit 2 passes the 2.5 to node 4 (unit 5 has opened); node 4
    // catches node 5 across the 0.5 * 4e-7 gap at 2e-7 / 2 later, t = 5e-7.
    let mut y = vec![1.0; 5];
    y[0] = 1.0 - 1e-6;
    let (v, log) = cradle(&y, &[2.5, 0.5, 0.0, 0.0, 0.0]);
    assert!(close(&v, &[0.0, 0.0, 0.0, 0.5, 2.5], 1e-9), "{v:?}");
    let seen: Vec<(Option<u64>, f64)> = log
        .events
        .iter()
        .map(|e| (e.labels.count("unit"), e.t))
        .collect();
    assert_eq!(seen.len(), 3, "{seen:?}");
    for ((unit, t), (want_unit, want_t)) in seen.iter().zip([(3, 0.0), (2, 4e-7), (5, 5e-7)]) {
        assert_eq!(*unit, Some(want_unit), "{seen:?}");
        // Gaps of 1e-6 made from positions near 1: good to 1e-10 relative.
        assert!((t - want_t).abs() < 1e-15, "{seen:?}");
    }
}

#[test]
fn the_unconstrained_chain_matches_its_modes_to_round_off() {
    for units in [1, 2, 7, 40] {
        for after in [0.0, 1.0] {
            let chain = Chain::in_scene_units(units, 2.0, 1.0, after, false);
            let x0 = chain.homogeneous(0.1);
            // Unequal node velocities too, so every mode is excited.
            let v0: Vec<f64> = (0..units).map(|i| 0.01 * (i as f64 * 1.3).sin()).collect();
            let mut model = TaylorChain::new(chain.clone(), &gaps(&x0[..units]), &v0).unwrap();
            let mut start = x0.clone();
            start[units..].copy_from_slice(&v0);
            let times = [0.3, 1.7, 5.0];
            let mut worst: f64 = 0.0;
            simulate_local(
                &mut model,
                &Options::until(5.0),
                &times,
                &mut |m, t| {
                    let exact = modal(&chain, &start, t);
                    let (g, v) = m.state_at(Time::new(t));
                    let mut y = 0.0;
                    for i in 0..units {
                        y += g[i];
                        worst = worst
                            .max((y - exact[i]).abs())
                            .max((v[i] - exact[units + i]).abs());
                    }
                },
                &mut (),
            );
            // The state is of order 0.1 (the end moves by up to 0.2 L):
            // the bar is 1e-10; the flow is exact to round-off.
            assert!(
                worst < 1e-12,
                "{units} units, load {after}: error {worst:e}"
            );
        }
    }
}

/// The release scene of docs/physics.md s.6 at `units`, reading `after`.
fn release(units: usize, after: f64) -> (Chain, TaylorChain) {
    let chain = Chain::in_scene_units(units, 2.0, 1.0, after, true);
    let x0 = chain.homogeneous(0.1);
    let model = TaylorChain::new(chain.clone(), &gaps(&x0[..units]), &vec![0.0; units]).unwrap();
    (chain, model)
}

#[test]
fn the_exact_and_ode_paths_agree_on_the_events_before_the_horizon() {
    let units = 20;
    let (chain, mut model) = release(units, 0.0);
    let t_end = 1.0;
    let (_, exact) = run(&mut model, t_end);
    let mut options = Options::until(t_end);
    // At 1e-12 Dormand-Prince's stated bound leaves the order of two
    // neighbours' impacts 6e-9 apart at t = 0.3 uncertain, and the run
    // stops there, saying so.
    options.method = Method::Dopri5(Tolerances {
        rtol: 1e-13,
        atol: 1e-15,
    });
    let mut ode = Recorder::default();
    let o = simulate(&chain, 0, &chain.homogeneous(0.1), &options, &mut ode);
    assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
    assert!(exact.events.len() > 100, "{} impacts", exact.events.len());
    assert_eq!(exact.events.len(), ode.events.len());
    for (a, b) in exact.events.iter().zip(&ode.events) {
        assert_eq!(
            a.labels.count("unit"),
            b.labels.count("unit"),
            "unit at t = {}",
            a.t
        );
        // Dormand-Prince at 1e-13 times the few thousand steps so far.
        assert!((a.t - b.t).abs() < 1e-8, "t {} vs {}", a.t, b.t);
        let (ra, rb) = (
            a.labels.number("rel_velocity").unwrap(),
            b.labels.number("rel_velocity").unwrap(),
        );
        assert!(
            (ra - rb).abs() < 1e-6,
            "closing speed {ra} vs {rb} at t = {}",
            a.t
        );
    }
}

#[test]
fn the_release_keeps_energy_momentum_balance_and_every_gap_open() {
    for after in [0.0, 1.0] {
        let units = 100;
        let (chain, mut model) = release(units, after);
        let samples: Vec<f64> = (0..=600).map(|i| 3.0 * i as f64 / 600.0).collect();
        let mut lowest: f64 = 0.0;
        let mut balance: f64 = 0.0;
        let mut log = Recorder::default();
        let o = simulate_local(
            &mut model,
            &Options::until(3.0),
            &samples,
            &mut |m, t| {
                let at = Time::new(t);
                let low = m.state_at(at).0.into_iter().fold(f64::INFINITY, f64::min);
                lowest = lowest.min(low);
                balance = balance.max((m.momentum(at) - m.momentum_by_impulses(at)).abs());
            },
            &mut log,
        );
        assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
        assert!(o.events > 1000, "{} impacts", o.events);
        let drift = o.max_energy_error.unwrap();
        assert!(drift < 1e-12, "load {after}: energy drift {drift:e}");
        // Momentum is of order 0.1 (the end load's impulse (1.1 - after) t).
        assert!(
            balance < 1e-13,
            "load {after}: momentum balance off by {balance:e}"
        );
        // A missed impact would leave a gap below zero by the closing speed
        // times the time since: round-off is 1e-17 here.
        let unit_length = chain.unit_length();
        assert!(
            lowest > -1e-14 * unit_length,
            "load {after}: a gap at {lowest:e}"
        );
        // Strict time order, every impact closing, every unit named.
        assert!(log.events.windows(2).all(|w| w[0].t <= w[1].t));
        assert!(
            log.events
                .iter()
                .all(|e| e.labels.number("rel_velocity").unwrap() > 0.0)
        );
        assert!(
            log.events
                .iter()
                .all(|e| (1..=units as u64).contains(&e.labels.count("unit").unwrap()))
        );
        // Each logged event's energies match the run's initial energy.
        let e0 = o.energy_initial.unwrap();
        assert!(
            log.events
                .iter()
                .all(|e| (e.energy_after.unwrap() - e0).abs() < 1e-12 * e0)
        );
        assert_eq!(
            model.guards().len(),
            units + 2,
            "one guard per unit, the release and the window"
        );
    }
}

#[test]
fn bad_initial_states_are_refused_with_a_reason() {
    let chain = Chain::in_scene_units(3, 2.0, 1.0, 0.0, true);
    let refused = |gaps: &[f64], v: &[f64]| TaylorChain::new(chain.clone(), gaps, v).unwrap_err();
    assert!(refused(&[0.1, -0.1, 0.1], &[0.0; 3]).contains("negative gap"));
    assert!(refused(&[0.1, 0.1], &[0.0; 3]).contains("2 gaps"));
    assert!(refused(&[0.1, f64::NAN, 0.1], &[0.0; 3]).contains("finite"));
    let empty = Chain::in_scene_units(0, 2.0, 1.0, 0.0, true);
    assert!(
        TaylorChain::new(empty, &[], &[])
            .unwrap_err()
            .contains("at least one unit")
    );
}

#[test]
fn a_unit_pushed_shut_rests_and_the_pair_bounces_off_the_wall_as_one() {
    // Two units (m = k = F_cr = 1, so omega = 1 and the unit length is 1),
    // the end load gone (F = 0): unit 2 starts shut and at rest, pushed
    // shut by F_cr (docs/physics.md s.4: resting contact), unit 1 open at 0.1.
    // By hand: nodes 1 and 2 move as one body of mass 2 under -F_cr, so
    // Delta_1'' = (-1 - Delta_1) / 2 and Delta_1 = -1 + 1.1 cos(t / sqrt 2)
    // reaches 0 at t1 = sqrt 2 arccos(1 / 1.1); the wall sends the pair
    // back as one (unit 2 stays shut: its contact force 1 - Delta_1 > 0),
    // and by symmetry it returns at 3 t1, 5 t1, ...
    let chain = Chain::in_scene_units(2, 2.0, 1.0, 0.0, true);
    assert_eq!(
        (chain.mass, chain.stiffness, chain.critical_load),
        (1.0, 1.0, 1.0)
    );
    let mut model = TaylorChain::new(chain, &[0.1, 0.0], &[0.0, 0.0]).unwrap();
    let t_end = 40.0;
    let (o, log) = run(&mut model, t_end);
    assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
    let t1 = 2f64.sqrt() * (1.0 / 1.1f64).acos();
    // First the contact at t = 0 (unit 2, no closing speed), then unit 1
    // against the wall at odd multiples of t1, nothing else.
    assert_eq!(log.events[0].labels.count("unit"), Some(2));
    assert_eq!(log.events[0].t, 0.0);
    assert_eq!(log.events[0].labels.number("rel_velocity"), Some(0.0));
    let bounces: Vec<f64> = log.events[1..].iter().map(|e| e.t).collect();
    assert!(
        log.events[1..]
            .iter()
            .all(|e| e.labels.count("unit") == Some(1)),
        "{:?}",
        log.events
    );
    let expected = ((t_end / t1 - 1.0) / 2.0).floor() as usize + 1;
    assert_eq!(bounces.len(), expected);
    for (k, t) in bounces.iter().enumerate() {
        let exact = (2 * k + 1) as f64 * t1;
        assert!(
            (t - exact).abs() < 1e-12 * t_end,
            "bounce {k}: {t} vs {exact}"
        );
    }
    // Unit 2 never opened; energy and the momentum balance hold.
    let (gaps, v) = model.state_at(Time::new(t_end));
    assert_eq!(gaps[1], 0.0);
    assert_eq!(v[0], v[1]);
    assert!(o.max_energy_error.unwrap() < 1e-13);
    let at = Time::new(t_end);
    assert!((model.momentum(at) - model.momentum_by_impulses(at)).abs() < 1e-12);
}

#[test]
fn a_resting_block_releases_when_its_neighbour_pulls_hard_enough() {
    // The same pair, but nodes 1 and 2 start moving out at speed 2:
    // Delta_1 = -1 + 1.1 cos(s) + 2 sqrt 2 sin(s), s = t / sqrt 2. Unit 2
    // stays shut while its contact force 1 - Delta_1 > 0; it is released
    // when Delta_1 reaches 1 (by hand: the first root of that equation).
    let chain = Chain::in_scene_units(2, 2.0, 1.0, 0.0, true);
    let mut model = TaylorChain::new(chain, &[0.1, 0.0], &[2.0, 2.0]).unwrap();
    let (o, log) = run(&mut model, 3.0);
    assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
    let (a, b) = (1.1f64, 2.0 * 2f64.sqrt());
    // 1.1 cos s + b sin s = 2: R cos(s - phi) = 2.
    let (r, phi) = ((a * a + b * b).sqrt(), b.atan2(a));
    let released = 2f64.sqrt() * (phi - (2.0 / r).acos());
    let release = log
        .events
        .iter()
        .find(|e| e.guard == "release")
        .expect("a release");
    assert_eq!(release.labels.count("unit"), Some(2));
    assert!(
        (release.t - released).abs() < 1e-12,
        "{} vs {released}",
        release.t
    );
    assert!(o.max_energy_error.unwrap() < 1e-13);
}

#[test]
fn a_chain_of_one_unit_is_the_single_mechanism() {
    // One unit against the wall under F = eta F_cr is the mechanism of
    // docs/physics.md s.2 (omega^2 = k / m, strain = gap / (F_cr / k)): its
    // impacts must come at the closed form's times, to t = 200.
    use flicker::models::mechanism::{ExactOrbit, Mechanism};
    for (eta, strain, rate) in [(1.2, 0.5, 0.0), (0.8, 0.1, 0.3), (1.5, 0.0, 0.2)] {
        let chain = Chain::new(1, 2.0, 8.0, 3.0, 3.0 * eta, true);
        let omega = 2.0;
        let unit = 3.0 / 8.0;
        let mut model = TaylorChain::new(chain, &[strain * unit], &[rate * unit]).unwrap();
        let t_end = 200.0;
        let (o, log) = run(&mut model, t_end);
        assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
        let orbit = ExactOrbit::new(Mechanism { eta, omega }, strain, rate);
        assert_eq!(
            log.events.len() as u64,
            orbit.impacts_until(t_end),
            "eta {eta}"
        );
        assert!(log.events.len() > 50, "eta {eta}: an impacting orbit");
        for (k, e) in log.events.iter().enumerate() {
            let exact = orbit.impact_time(k as u64);
            // Impact times add up over hundreds of flights: 1e-12 of t_end.
            assert!(
                (e.t - exact).abs() < 2e-10,
                "eta {eta}, impact {}: {} vs {exact}",
                k + 1,
                e.t
            );
        }
        let (eps, eps_rate) = orbit.state_at(t_end);
        let (g, v) = model.state_at(Time::new(t_end));
        assert!((g[0] / unit - eps).abs() < 1e-10 && (v[0] / unit - eps_rate).abs() < 1e-10);
    }
}

#[test]
fn a_chain_shut_all_along_and_pushed_rests_against_the_wall() {
    // Every unit shut and at rest, the end pushed by F_cr - F = 0.5 F_cr:
    // the whole chain rests on the wall (the contact spreads from the end
    // at t = 0), nothing moves, and the wall's hold balances the load.
    let units = 30;
    let chain = Chain::in_scene_units(units, 2.0, 1.0, 0.5, true);
    let mut model = TaylorChain::new(chain, &vec![0.0; units], &vec![0.0; units]).unwrap();
    let (o, log) = run(&mut model, 5.0);
    assert_eq!(o.status, Status::Completed, "{:?}", o.reason);
    assert!(
        log.events
            .iter()
            .all(|e| e.t == 0.0 && e.labels.number("rel_velocity") == Some(0.0))
    );
    let at = Time::new(5.0);
    let (gaps, v) = model.state_at(at);
    assert!(gaps.iter().chain(&v).all(|x| *x == 0.0), "{gaps:?} {v:?}");
    assert_eq!(model.momentum(at), 0.0);
    assert!(model.momentum_by_impulses(at).abs() < 1e-12);
}
