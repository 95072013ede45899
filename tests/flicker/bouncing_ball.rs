//! The engine is generic: a bouncing ball (examples/bouncing_ball.rs) with
//! restitution below one reaches its Zeno point where the closed form puts
//! it, is recognised there, and settles.

#[allow(dead_code)]
#[path = "../../examples/bouncing_ball.rs"]
mod example;

use flicker::engine::Status;

#[test]
fn the_ball_settles_at_the_closed_form_accumulation_point() {
    for restitution in [0.1, 0.5, 0.8, 0.95] {
        let drop = example::drop_ball(restitution, 1.0, 20.0);
        let o = &drop.outcome;
        assert_eq!(o.status, Status::Zeno, "e = {restitution}");
        assert!(o.zeno && o.reason.as_deref().unwrap().contains("settled"));
        // The bounces sum to t*; the engine stops them within a few
        // unresolvable intervals (< 1e-11 each) of it.
        assert!(
            (drop.settled_at - drop.zeno_time).abs() < 1e-9,
            "e = {restitution}: {} vs {}",
            drop.settled_at,
            drop.zeno_time
        );
        assert_eq!(o.t_reached, 20.0);
        assert_eq!(o.final_state, vec![0.0, 0.0]);
        assert_eq!(o.final_mode_name, "resting");
    }
}

#[test]
fn each_bounce_keeps_e_squared_of_the_energy() {
    let e = 0.6;
    let drop = example::drop_ball(e, 2.0, 20.0);
    let bounces: Vec<_> = drop
        .log
        .events
        .iter()
        .filter(|ev| ev.guard == "bounce")
        .collect();
    assert!(bounces.len() > 20);
    for ev in bounces.iter().take(20) {
        let ratio = ev.energy_after.unwrap() / ev.energy_before.unwrap();
        assert!((ratio - e * e).abs() < 1e-12, "ratio {ratio}");
        assert_eq!(ev.after[0], 0.0);
    }
}
