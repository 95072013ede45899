//! The continuum's cost against the chain's on the release of docs/physics.md
//! s.6 to t = 3, in one run, for both readings.
//!
//! `cargo bench --bench continuum` prints medians of several runs (log
//! off, one core): the paper's continuum by front tracking, the
//! homogenized string on 100 and 200 cells, and the exact chain at
//! N = 800 and 1600 (one run at 1600), with the chain's time over each
//! continuum's.

use flicker::engine::{LocalModel, Options, Outcome, simulate_local};
use flicker::models::chain::{Chain, TaylorChain};
use flicker::models::continuum::{Continuum, FrontTracking, Homogenized, Piece};

mod timing;

use timing::median_of;

fn string(load: f64) -> Continuum {
    Continuum {
        length: 2.0,
        wave_speed: 1.0,
        load,
        constraint: true,
    }
}

/// `model` run to t = 3, no samples, no log.
fn to_the_end(model: &mut impl LocalModel) -> Outcome {
    simulate_local(model, &Options::until(3.0), &[], &mut |_, _| {}, &mut ())
}

fn paper(load: f64) -> u64 {
    let start = Piece {
        strain: 0.1,
        velocity: 0.0,
    };
    to_the_end(&mut FrontTracking::new(string(load), &[start]).unwrap()).events
}

fn homogenized(load: f64, cells: usize) -> u64 {
    let mut model = Homogenized::new(string(load), 0.1, cells, &[3.0]).unwrap();
    to_the_end(&mut model);
    model.steps()
}

fn chain(load: f64, units: usize) -> u64 {
    let chain = Chain::in_scene_units(units, 2.0, 1.0, load, true);
    let gap = 0.1 * chain.unit_length();
    to_the_end(&mut TaylorChain::new(chain, &vec![gap; units], &vec![0.0; units]).unwrap()).events
}

fn main() {
    for (reading, load) in [
        ("traction-free (eta -> 0)", 0.0),
        ("paper's (eta -> 1)", 1.0),
    ] {
        println!("release to t = 3, {reading}:");
        let (paper_s, events) = median_of(5, || paper(load));
        println!("  paper's continuum (front tracking): {paper_s:.2e} s, {events} events");
        let mut continua = vec![("paper's continuum", paper_s)];
        for (cells, name) in [(100, "homogenized (100)"), (200, "homogenized (200)")] {
            let (s, steps) = median_of(3, || homogenized(load, cells));
            println!("  homogenized, {cells} cells: {s:.3} s, {steps} steps");
            continua.push((name, s));
        }
        for (units, repeats) in [(800, 3), (1600, 1)] {
            let (s, impacts) = median_of(repeats, || chain(load, units));
            let ratios: Vec<String> = continua
                .iter()
                .map(|(name, c)| format!("{:.1}x {name}", s / c))
                .collect();
            println!(
                "  chain N = {units}: {s:.3} s, {impacts} impacts; its time is {}",
                ratios.join(", ")
            );
        }
    }
}
