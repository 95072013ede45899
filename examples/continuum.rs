//! The continuum through the library: the traction-free release of
//! docs/physics.md s.6 as the paper's incompressible string (exact front
//! tracking) and as the homogenized string (finite volumes with the
//! rattling kept), beside the chain it should describe.
//!
//! `cargo run --release --example continuum` prints, every 0.1 time units
//! to t = 0.6 (when the wave reflected at the wall is back at the loaded
//! end), the loaded end's displacement in each description and the chain's
//! (N = 400), then each run's cost and energy error.

use flicker::engine::{LocalModel, Options, simulate_local};
use flicker::models::chain::{Chain, TaylorChain};
use flicker::models::continuum::{Continuum, FrontTracking, Homogenized, Piece, StringModel};
use flicker::time::Time;

/// The loaded end's displacement at `times`, the wall time and the largest
/// relative energy error of running `model` to the last of them.
fn end_displacement<M: LocalModel>(
    model: &mut M,
    times: &[f64],
    right_end: impl Fn(&M, Time) -> f64,
) -> (Vec<f64>, f64, f64) {
    let mut ends = Vec::new();
    let outcome = simulate_local(
        model,
        &Options::until(*times.last().unwrap()),
        times,
        &mut |m: &M, t| ends.push(right_end(m, Time::new(t))),
        &mut (),
    );
    (
        ends,
        outcome.wall_seconds,
        outcome.max_energy_error.unwrap_or(f64::NAN),
    )
}

fn main() {
    let times: Vec<f64> = (0..=6).map(|i| 0.1 * i as f64).collect();
    let string = Continuum {
        length: 2.0,
        wave_speed: 1.0,
        load: 0.0,
        constraint: true,
    };
    let start = Piece {
        strain: 0.1,
        velocity: 0.0,
    };
    let mut paper = FrontTracking::new(string.clone(), &[start]).unwrap();
    let mut homogenized = Homogenized::new(string, 0.1, 200, &times).unwrap();
    let chain = Chain::in_scene_units(400, 2.0, 1.0, 0.0, true);
    let gaps = vec![0.1 * chain.unit_length(); 400];
    let mut dense = TaylorChain::new(chain, &gaps, &vec![0.0; 400]).unwrap();
    let runs = [
        (
            "paper's continuum",
            end_displacement(&mut paper, &times, |m, t| m.right_end(t)),
        ),
        (
            "homogenized (200 cells)",
            end_displacement(&mut homogenized, &times, |m, t| m.right_end(t)),
        ),
        (
            "chain (N = 400)",
            end_displacement(&mut dense, &times, |m, t| m.right_end(t)),
        ),
    ];
    println!("loaded end's displacement after a traction-free release:");
    println!(
        "  {:>5} {:>18} {:>24} {:>16}",
        "t", runs[0].0, runs[1].0, runs[2].0
    );
    for (i, t) in times.iter().enumerate() {
        println!(
            "  {t:5.1} {:>18.5} {:>24.5} {:>16.5}",
            runs[0].1.0[i], runs[1].1.0[i], runs[2].1.0[i]
        );
    }
    for (name, (_, seconds, energy)) in &runs {
        println!("  {name}: {seconds:.3} s, largest relative energy error {energy:.1e}");
    }
}
