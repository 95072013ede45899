//! Evenly spaced values, as a diagram's parameter and a basin grid's axes
//! take them: both ends exact, whatever the rounding between.

/// `n` values evenly spaced from `from` to `to`, both ends exact.
pub fn evenly_spaced(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| match i {
            0 => from,
            _ if i == n - 1 => to,
            _ => from + (to - from) * i as f64 / (n - 1) as f64,
        })
        .collect()
}
