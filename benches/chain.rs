//! The chain's figures: cost per impact against the number of units, the
//! release scene, and the exact path against the ODE path on one scene.
//!
//! `cargo bench --bench chain` prints, as medians of several runs (log off):
//! - wall time per impact for N = 25 ... 3200 in the release scene of
//!   docs/physics.md s.6 (traction-free reading) to t = 3 (about 1.1 N^2
//!   impacts per unit time; 3 runs at N = 1600, 1 at N = 3200), and in a
//!   chain rattling sparsely all along from the start (every unit at strain
//!   0.05, node velocities alternating +-0.05, load F_cr: about 0.15 N^2
//!   impacts per unit time) to about 4 * 10^5 impacts; writes them to
//!   `target/chain_cost.csv` with a chart `target/chain_cost.svg` (and
//!   `.png`);
//! - the whole release to t = 3 at N = 800 (about 2 million impacts);
//! - impacts per second at N = 1000 to t = 1;
//! - at N = 50, the exact path against Dormand-Prince (rtol 1e-12) on the
//!   chain as an ODE, to t = 3: cost ratio in the same run.

use flicker::engine::{Method, Options, Tolerances, simulate, simulate_local};
use flicker::models::chain::{Chain, TaylorChain};
use flicker::plot::draw::{Curve, Figure, Style};

mod timing;

use timing::median_of;

const REPEATS: usize = 5;

/// Median wall time of `REPEATS` runs of `f`, which returns the impacts.
fn median_seconds(f: impl FnMut() -> u64) -> (f64, u64) {
    median_of(REPEATS, f)
}

fn released(units: usize) -> (Chain, TaylorChain) {
    let chain = Chain::in_scene_units(units, 2.0, 1.0, 0.0, true);
    let gap = 0.1 * chain.unit_length();
    let model = TaylorChain::new(chain.clone(), &vec![gap; units], &vec![0.0; units]).unwrap();
    (chain, model)
}

/// Every unit at strain 0.05, neighbours moving apart and together at
/// +-0.05: impacts all along the chain from the start.
fn rattling(units: usize) -> TaylorChain {
    let chain = Chain::in_scene_units(units, 2.0, 1.0, 1.0, true);
    let gap = 0.05 * chain.unit_length();
    let v: Vec<f64> = (0..units)
        .map(|i| if i % 2 == 0 { 0.05 } else { -0.05 })
        .collect();
    TaylorChain::new(chain, &vec![gap; units], &v).unwrap()
}

fn run(mut model: TaylorChain, t_end: f64) -> u64 {
    let o = simulate_local(
        &mut model,
        &Options::until(t_end),
        &[],
        &mut |_, _| {},
        &mut (),
    );
    assert!(
        o.max_energy_error.unwrap() < 1e-12,
        "{:?}",
        o.max_energy_error
    );
    o.events
}

fn exact(units: usize, t_end: f64) -> u64 {
    run(released(units).1, t_end)
}

fn main() {
    let mut rows = Vec::new();
    println!("cost per impact, log off, median of {REPEATS} (3 at N = 1600, 1 at 3200):");
    for units in [25, 50, 100, 200, 400, 800, 1600, 3200] {
        let repeats = match units {
            3200 => 1,
            1600 => 3,
            _ => REPEATS,
        };
        let (seconds, impacts) = median_of(repeats, || exact(units, 3.0));
        let release = seconds / impacts as f64;
        let t_end = 4e5 / (0.15 * (units * units) as f64);
        let (seconds, sparse) = median_of(repeats, || run(rattling(units), t_end));
        let rattle = seconds / sparse as f64;
        println!(
            "  N = {units:>5}: release to t = 3, {impacts:>9} impacts: {:.3} us per impact ({:.3e}/s); \
             sparse rattling, {sparse:>7} impacts: {:.3} us per impact",
            release * 1e6,
            1.0 / release,
            rattle * 1e6,
        );
        rows.push((units, rattle, Some(release)));
    }
    let csv: String = std::iter::once(
        "units,rattling_seconds_per_impact,release_seconds_per_impact\n".to_string(),
    )
    .chain(rows.iter().map(|(n, r, e)| {
        format!(
            "{n},{r:e},{}\n",
            e.map_or(String::new(), |e| format!("{e:e}"))
        )
    }))
    .collect();
    std::fs::write("target/chain_cost.csv", csv).expect("target/ is writable");
    let figure = Figure {
        title: "chain: cost per impact against the number of units".into(),
        x_label: "log10 N".into(),
        y_label: "microseconds per impact".into(),
        curves: vec![
            Curve {
                label: Some("sparse rattling".into()),
                points: rows
                    .iter()
                    .map(|(n, r, _)| ((*n as f64).log10(), r * 1e6))
                    .collect(),
                style: Style::Line(0),
            },
            Curve {
                label: Some("release to t = 3".into()),
                points: rows
                    .iter()
                    .filter_map(|(n, _, e)| Some(((*n as f64).log10(), (*e)? * 1e6)))
                    .collect(),
                style: Style::Line(1),
            },
        ],
        y_limit: None,
    };
    for path in ["target/chain_cost.svg", "target/chain_cost.png"] {
        figure
            .draw(std::path::Path::new(path))
            .expect("the chart draws");
    }
    println!("  wrote target/chain_cost.csv, target/chain_cost.svg and .png");

    let (seconds, impacts) = median_seconds(|| exact(800, 3.0));
    println!("release to t = 3 at N = 800: {impacts} impacts in {seconds:.3} s");
    let (seconds, impacts) = median_seconds(|| exact(1000, 1.0));
    println!(
        "N = 1000 to t = 1: {impacts} impacts in {seconds:.3} s = {:.3e} impacts/s",
        impacts as f64 / seconds
    );

    let units = 50;
    let (exact_seconds, exact_impacts) = median_seconds(|| exact(units, 3.0));
    let (chain, _) = released(units);
    let mut options = Options::until(3.0);
    options.method = Method::Dopri5(Tolerances {
        rtol: 1e-12,
        atol: 1e-14,
    });
    let (ode_seconds, ode_impacts) =
        median_seconds(|| simulate(&chain, 0, &chain.homogeneous(0.1), &options, &mut ()).events);
    println!(
        "N = {units} to t = 3: exact {exact_impacts} impacts in {exact_seconds:.4} s; Dormand-Prince (1e-12) on the ODE {ode_impacts} in {ode_seconds:.4} s: {:.1}x",
        ode_seconds / exact_seconds
    );
}
