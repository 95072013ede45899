//! The mechanism's figures: accuracy against the closed form, and the
//! engine's throughput against a bare closed-form loop measured in the same
//! run.
//!
//! `cargo bench --bench mechanism` prints the largest state and energy
//! errors after 10^4, 10^6 and 10^7 impacts (strain formulation) and over
//! 100 impacts (angle formulation), then, as medians of several runs:
//! - impacts per second of the strain formulation without a log, each
//!   impact fired, and the ratio to a bare loop doing the same arithmetic
//!   with no engine; the same run jumping over whole periods (what a run
//!   without a log does, `engine::periodic`);
//! - impacts per second with the event log written to disk;
//! - the cost per impact of the angle formulation (Dormand-Prince with chart
//!   switching) against the strain formulation.

use std::fs::File;
use std::hint::black_box;
use std::io::BufWriter;
use std::time::Instant;

use flicker::engine::{EachEvent, Observer, Options, simulate};
use flicker::log::JsonlWriter;
use flicker::models::mechanism::angle::STRAIN_POSITIVE;
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{AngleMechanism, Charts, ExactOrbit, Mechanism, StrainMechanism};

mod timing;

use timing::median_of;

const REPEATS: usize = 7;

/// Median wall time of `REPEATS` runs of `f`, which returns the impacts it made.
fn median_seconds(f: impl FnMut() -> u64) -> (f64, u64) {
    median_of(REPEATS, f)
}

/// The same closed-form arithmetic as the strain model, with no queue, no
/// modes, no energy audit and no log.
fn bare_loop(m: Mechanism, mut eps: f64, mut rate: f64, t_end: f64) -> u64 {
    let (mut t, mut impacts) = (0.0, 0);
    while let Some(tau) = m.time_to_closing(eps, rate) {
        if t + tau > t_end {
            break;
        }
        t += tau;
        rate = -m.flow(eps, rate, tau).1;
        eps = 0.0;
        impacts += 1;
    }
    black_box((eps, rate));
    impacts
}

/// Errors of a run of `impacts` impacts against the closed form.
fn accuracy(
    model: &dyn Fn(f64) -> (f64, f64, f64, u64),
    m: Mechanism,
    x0: [f64; 2],
    impacts: u64,
) -> String {
    let exact = ExactOrbit::new(m, x0[0], x0[1]);
    let period = m.impact_period(m.energy(x0[0], x0[1]));
    let t_end = m.time_to_closing(x0[0], x0[1]).unwrap() + (impacts as f64 - 0.63) * period;
    let start = Instant::now();
    let (eps, rate, energy_error, events) = model(t_end);
    let seconds = start.elapsed().as_secs_f64();
    let (eps_exact, rate_exact) = exact.state_at(t_end);
    format!(
        "{impacts:>9} impacts: count {} (exact {}), |d eps| {:.1e}, |d eps'| {:.1e}, energy {:.1e}, {:.3} s",
        events,
        exact.impacts_until(t_end),
        (eps - eps_exact).abs(),
        (rate - rate_exact).abs(),
        energy_error,
        seconds
    )
}

fn main() {
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let start = [0.5, 0.0];
    // Each impact fired (EachEvent), or whole periods jumped over (an
    // observer that looks at no event).
    let strain_run = |observer: &mut dyn Observer, t_end: f64| {
        let o = simulate(
            &StrainMechanism { mechanism: m },
            FLIGHT,
            &start,
            &Options::until(t_end),
            observer,
        );
        (
            o.final_state[0],
            o.final_state[1],
            o.max_energy_error.unwrap(),
            o.events,
        )
    };
    println!("accuracy against the closed form (eta 1.2, from strain 0.5 at rest)");
    for impacts in [10_000, 1_000_000, 10_000_000] {
        println!(
            "  strain, exact  {}",
            accuracy(&|t| strain_run(&mut EachEvent, t), m, start, impacts)
        );
    }
    let angle_run = |t_end: f64| {
        let model = AngleMechanism {
            mechanism: m,
            charts: Charts::Switch,
        };
        let (mode, x0) = model.start_from_strain(start[0], start[1]).unwrap();
        let o = simulate(&model, mode, &x0, &Options::until(t_end), &mut ());
        let (eps, rate) = model.strain(o.final_mode, &o.final_state);
        (eps, rate, o.max_energy_error.unwrap(), o.events)
    };
    println!(
        "  strain, jumped {}",
        accuracy(&|t| strain_run(&mut (), t), m, start, 10_000_000)
    );
    println!("  angle, dopri5  {}", accuracy(&angle_run, m, start, 100));
    println!();

    let x0 = [0.0, 0.5];
    let period = m.impact_period(m.energy(x0[0], x0[1]));
    let impacts = 2_000_000.0;
    let t_end = (impacts - 0.5) * period;
    let strain = StrainMechanism { mechanism: m };

    let (bare, n_bare) = median_seconds(|| bare_loop(m, x0[0], x0[1], t_end));
    let (engine, n_engine) = median_seconds(|| {
        simulate(&strain, FLIGHT, &x0, &Options::until(t_end), &mut EachEvent).events
    });
    let (jumped, n_jumped) =
        median_seconds(|| simulate(&strain, FLIGHT, &x0, &Options::until(t_end), &mut ()).events);
    assert_eq!(
        n_jumped, n_engine,
        "a jump must count the impacts it passes"
    );
    assert_eq!(
        n_bare, n_engine,
        "the bare loop and the engine must make the same impacts"
    );
    let log_path = std::env::temp_dir().join("flicker-bench-events.jsonl");
    let (logged, n_logged) = median_seconds(|| {
        let mut writer = JsonlWriter::new(BufWriter::new(File::create(&log_path).unwrap()));
        let n = simulate(&strain, FLIGHT, &x0, &Options::until(t_end), &mut writer).events;
        writer.flush().unwrap();
        n
    });
    let log_bytes = std::fs::metadata(&log_path).map_or(0, |m| m.len());
    let _ = std::fs::remove_file(&log_path);

    let angle = AngleMechanism {
        mechanism: m,
        charts: Charts::Switch,
    };
    let angle_t_end = 1_999.5 * period;
    let (angle_time, n_angle) = median_seconds(|| {
        simulate(
            &angle,
            STRAIN_POSITIVE,
            &x0,
            &Options::until(angle_t_end),
            &mut (),
        )
        .events
    });

    let rate = |n: u64, s: f64| n as f64 / s;
    println!(
        "flicker throughput, medians of {REPEATS} runs (eta 1.2, H0 {:.3})",
        m.energy(x0[0], x0[1])
    );
    println!(
        "  bare closed-form loop      {:>12.0} impacts/s",
        rate(n_bare, bare)
    );
    println!(
        "  engine, no log             {:>12.0} impacts/s   ({:.2}x the bare loop's time)",
        rate(n_engine, engine),
        engine / bare
    );
    println!(
        "  engine, periods jumped     {:>12.0} impacts/s   ({:.1e} s for {n_jumped} impacts)",
        rate(n_jumped, jumped),
        jumped
    );
    println!(
        "  engine, log to disk        {:>12.0} impacts/s   ({:.0} MB/s of JSON Lines)",
        rate(n_logged, logged),
        log_bytes as f64 / logged / 1e6
    );
    println!(
        "  angle formulation (dopri5) {:>12.0} impacts/s   ({:.0}x the strain formulation's cost per impact)",
        rate(n_angle, angle_time),
        (angle_time / n_angle as f64) / (engine / n_engine as f64)
    );
}
