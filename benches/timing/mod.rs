//! Timing shared by the bench binaries: the median wall time of repeated
//! runs.

use std::hint::black_box;
use std::time::Instant;

/// Median wall time of `repeats` runs of `f`, and what the last run
/// returned (the impacts it made).
pub fn median_of(repeats: usize, mut f: impl FnMut() -> u64) -> (f64, u64) {
    let mut times = Vec::new();
    let mut impacts = 0;
    for _ in 0..repeats {
        let start = Instant::now();
        impacts = black_box(f());
        times.push(start.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    (times[repeats / 2], impacts)
}
