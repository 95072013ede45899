//! A soak run: the mechanism to 10^9 impacts with the log off, in chunks,
//! printing impacts per second, the energy drift and the peak memory as it
//! goes, to show that speed and memory stay flat over a long run.
//!
//! Run: `cargo run --release --example soak [-- IMPACTS]` (default 10^9,
//! about two minutes here).

use std::time::Instant;

use flicker::engine::{EachEvent, Options, simulate};
use flicker::models::mechanism::strain::FLIGHT;
use flicker::models::mechanism::{Mechanism, StrainMechanism};

/// Peak resident memory of this process, from /proc (Linux), in MiB.
fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn main() {
    let total: u64 = match std::env::args().nth(1).map(|a| a.parse()) {
        None => 1_000_000_000,
        Some(Ok(n)) if n > 0 => n,
        _ => {
            eprintln!("soak: the number of impacts must be a positive whole number");
            std::process::exit(2);
        }
    };
    let m = Mechanism {
        eta: 1.2,
        omega: 1.0,
    };
    let model = StrainMechanism { mechanism: m };
    let (mut x, h0) = ([0.0, 0.5], m.energy(0.0, 0.5));
    let period = m.impact_period(h0);
    let chunks = 20;
    let per_chunk = total.div_ceil(chunks);
    let mut options = Options::until((per_chunk as f64 - 0.5) * period);
    options.max_events = u64::MAX;
    let (mut impacts, started) = (0u64, Instant::now());
    println!(
        "{:>6} {:>14} {:>14} {:>12} {:>10}",
        "chunk", "impacts", "impacts/s", "energy drift", "peak MiB"
    );
    for chunk in 1..=chunks {
        let clock = Instant::now();
        // Each impact fired: the orbit is periodic, and a run that looks at
        // no event would jump over its periods.
        let o = simulate(&model, FLIGHT, &x, &options, &mut EachEvent);
        x = [o.final_state[0], o.final_state[1]];
        impacts += o.events;
        let drift = (m.energy(x[0], x[1]) - h0).abs() / m.energy_scale(h0);
        println!(
            "{chunk:>6} {impacts:>14} {:>14.3e} {drift:>12.2e} {:>10.1}",
            o.events as f64 / clock.elapsed().as_secs_f64(),
            peak_memory_mib().unwrap_or(f64::NAN)
        );
    }
    println!(
        "{impacts} impacts in {:.1} s",
        started.elapsed().as_secs_f64()
    );
}
