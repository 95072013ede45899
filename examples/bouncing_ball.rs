//! A ball bouncing on the floor with restitution below one: a hybrid model
//! from outside the paper, written against the public engine API.
//!
//! Flight is free fall (exact flow, exact landing time); the guard is the
//! height reaching zero while falling; the reset sends the ball up at `e`
//! times its landing speed. The bounces come faster and faster and pile up
//! at `t* = t1 + (2 v1 / g) e / (1 - e)`: a Zeno point. The engine sees
//! the intervals fall below what it can resolve, and the model settles the
//! ball on the floor, where the run goes on.
//!
//! Run: `cargo run --release --example bouncing_ball [-- RESTITUTION]`

use flicker::engine::Name;
use flicker::engine::{
    Direction, Flow, Guard, HybridModel, Jump, Mode, Options, Recorder, simulate,
};
use flicker::names;

/// The ball in the air.
pub const FLYING: Mode = 0;
const RESTING: Mode = 1;
const BOUNCE: &[Guard] = &[Guard::affine("bounce", Direction::Falling)];

/// State `[height, velocity]`.
pub struct BouncingBall {
    /// Acceleration of gravity.
    pub gravity: f64,
    /// Fraction of its speed the ball keeps at a bounce, in `[0, 1)`.
    pub restitution: f64,
}

impl HybridModel for BouncingBall {
    fn dimension(&self) -> usize {
        2
    }

    fn state_names(&self, _: Mode) -> &[Name] {
        names!["height", "velocity"]
    }

    fn mode_name(&self, mode: Mode) -> &str {
        if mode == RESTING { "resting" } else { "flying" }
    }

    fn guards(&self, mode: Mode) -> &[Guard] {
        if mode == RESTING { &[] } else { BOUNCE }
    }

    fn guard(&self, _: Mode, _: usize, x: &[f64]) -> f64 {
        x[0]
    }

    fn flow(&self, mode: Mode) -> Flow {
        if mode == RESTING {
            Flow::Frozen
        } else {
            Flow::Exact
        }
    }

    fn advance(&self, _: Mode, x0: &[f64], tau: f64, x: &mut [f64]) {
        x[0] = x0[0] + x0[1] * tau - 0.5 * self.gravity * tau * tau;
        x[1] = x0[1] - self.gravity * tau;
    }

    /// The later root of `h + v tau - g tau^2 / 2 = 0`, written so that it
    /// does not cancel when `h` is tiny.
    fn next_crossing(&self, _: Mode, _: usize, x0: &[f64]) -> Option<f64> {
        let (h, v, g) = (x0[0], x0[1], self.gravity);
        let root = (v * v + 2.0 * g * h).sqrt();
        Some(if v > 0.0 {
            (v + root) / g
        } else {
            2.0 * h / (root - v)
        })
    }

    fn reset(&self, mode: Mode, _: usize, x: &mut [f64]) -> Jump {
        x[0] = 0.0;
        x[1] *= -self.restitution;
        Jump::to(mode)
    }

    fn energy(&self, _: Mode, x: &[f64]) -> Option<f64> {
        Some(0.5 * x[1] * x[1] + self.gravity * x[0])
    }

    fn settle(&self, _: Mode, x: &mut [f64]) -> Option<Mode> {
        x.copy_from_slice(&[0.0, 0.0]);
        Some(RESTING)
    }
}

/// What a drop from rest at `height` did, beside the closed form.
pub struct Drop {
    pub outcome: flicker::engine::Outcome,
    /// The accumulation point `t*` from the closed form.
    pub zeno_time: f64,
    /// When the engine settled the ball.
    pub settled_at: f64,
    pub log: Recorder,
}

/// Drop the ball from rest at `height` and run to `t_end`.
pub fn drop_ball(restitution: f64, height: f64, t_end: f64) -> Drop {
    let ball = BouncingBall {
        gravity: 9.81,
        restitution,
    };
    let mut log = Recorder::default();
    let outcome = simulate(
        &ball,
        FLYING,
        &[height, 0.0],
        &Options::until(t_end),
        &mut log,
    );
    let first = (2.0 * height / ball.gravity).sqrt();
    let landing_speed = ball.gravity * first;
    let zeno_time = first + 2.0 * landing_speed / ball.gravity * restitution / (1.0 - restitution);
    let settled_at = log
        .events
        .iter()
        .find(|e| e.guard == "settle")
        .map_or(f64::NAN, |e| e.t);
    Drop {
        outcome,
        zeno_time,
        settled_at,
        log,
    }
}

fn main() {
    let restitution: f64 = match std::env::args().nth(1).map(|a| a.parse()) {
        None => 0.8,
        Some(Ok(e)) if (0.0..1.0).contains(&e) => e,
        _ => {
            eprintln!("bouncing_ball: the restitution must be a number in [0, 1)");
            std::process::exit(2);
        }
    };
    let Drop {
        outcome,
        zeno_time,
        settled_at,
        ..
    } = drop_ball(restitution, 1.0, 10.0);
    println!(
        "restitution {restitution}: {} bounces, then {}",
        outcome.events - 1,
        outcome.status.as_str()
    );
    println!("  Zeno point: closed form t* = {zeno_time:.12}, settled at t = {settled_at:.12}");
    println!("  reason: {}", outcome.reason.as_deref().unwrap_or("-"));
    println!(
        "  final mode {} at t = {}, state {:?}",
        outcome.final_mode_name, outcome.t_reached, outcome.final_state
    );
}
