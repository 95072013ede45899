//! The chain of mechanisms through the library: the release scene of
//! docs/physics.md s.6 at N = 400 in both readings, run with the exact
//! event-local flow, sampled as it goes for the coarse-grained fields.
//!
//! `cargo run --release --example chain` prints, every 0.5 time units, the
//! end displacement, the momentum against the impulses the wall and the
//! end load gave, and where the coarse-grained front is.

use flicker::engine::{Options, simulate_local};
use flicker::models::chain::coarse::Coarse;
use flicker::models::chain::{Chain, TaylorChain};
use flicker::time::Time;

fn main() {
    let units = 400;
    for after in [0.0, 1.0] {
        // Scene units: length 2, wave speed 1; every unit at strain 0.1 under
        // F = 1.1 F_cr, released at t = 0 to F = after * F_cr.
        let chain = Chain::in_scene_units(units, 2.0, 1.0, after, true);
        let unit_length = chain.unit_length();
        let gaps = vec![0.1 * unit_length; units];
        let mut model = TaylorChain::new(chain.clone(), &gaps, &vec![0.0; units])
            .expect("a valid initial state");
        println!("release to F = {after} F_cr, {units} units:");
        let times: Vec<f64> = (0..=6).map(|i| 0.5 * i as f64).collect();
        let outcome = simulate_local(
            &mut model,
            &Options::until(3.0),
            &times,
            &mut |m: &TaylorChain, t| {
                let at = Time::new(t);
                let (gaps, velocities) = m.state_at(at);
                let front = Coarse::of(&chain, 2.0, &gaps, &velocities).front(0.1);
                println!(
                    "  t = {t:3.1}: y_N = {:+.5}, momentum {:+.5} (impulses say {:+.5}), front at {}",
                    m.right_end(at),
                    m.momentum(at),
                    m.momentum_by_impulses(at),
                    front.map_or("none yet".into(), |x| format!("x = {x:+.3}"))
                );
            },
            &mut (),
        );
        println!(
            "  {} impacts in {:.2} s; largest relative energy error {:.1e}",
            outcome.events,
            outcome.wall_seconds,
            outcome.max_energy_error.unwrap_or(f64::NAN)
        );
    }
}
