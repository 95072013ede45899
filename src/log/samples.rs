//! The run's state at chosen times (`flicker run --samples N`, `--at
//! T1,T2,...`), written to `samples.csv`: a header `t,<state>...,bound`
//! (a model's clock is the `t` column), then one row per time, every
//! number in its shortest form that reads back to the same double.
//!
//! The values come from the method's own dense output (the closed form,
//! the propagator's or Taylor's series, a Runge-Kutta interpolant), taken
//! as the run goes: sampling moves neither its steps nor its events. A
//! sample at an event's time holds the state before the reset. `bound` is
//! the error bound of every component there (see
//! [`Sample::bound`](crate::engine::Sample::bound)).

use std::io::{self, Write};
use std::path::Path;

use crate::engine::Name;

/// The most samples a run takes (`--samples`, or times in `--at`).
pub const MAX_SAMPLES: usize = 10_000_000;

/// The sample times: `count` evenly spaced from 0 to `t_end` (both ends
/// included), or the times `at` (in increasing order, repeats dropped),
/// each within `[0, t_end]`. The error says what is wrong with the one
/// given.
pub fn times(count: Option<usize>, at: Option<&[f64]>, t_end: f64) -> Result<Vec<f64>, String> {
    match (count, at) {
        (Some(n), _) => {
            if !(2..=MAX_SAMPLES).contains(&n) {
                return Err(format!("from 2 to {MAX_SAMPLES} samples (got {n})"));
            }
            let last = (n - 1) as f64;
            Ok((0..n)
                .map(|i| {
                    if i == n - 1 {
                        t_end
                    } else {
                        t_end * (i as f64 / last)
                    }
                })
                .collect())
        }
        (None, Some(at)) => {
            if at.len() > MAX_SAMPLES {
                return Err(format!("at most {MAX_SAMPLES} times"));
            }
            if let Some(bad) = at.iter().find(|t| !(0.0..=t_end).contains(*t)) {
                return Err(format!("{bad} is not a time from 0 to t_end = {t_end}"));
            }
            let mut times = at.to_vec();
            times.sort_by(f64::total_cmp);
            times.dedup();
            Ok(times)
        }
        (None, None) => Ok(Vec::new()),
    }
}

/// Write `samples.csv` at `path`: `names` head the state's columns,
/// `samples` are `(t, state)`, `bounds` each sample's error bound.
pub fn write_csv(
    path: &Path,
    names: &[Name],
    samples: &[(f64, Vec<f64>)],
    bounds: &[f64],
) -> io::Result<()> {
    let tmp = path.with_extension("csv.tmp");
    let mut out = io::BufWriter::new(std::fs::File::create(&tmp)?);
    let mut floats = ryu::Buffer::new();
    // A model's clock (the state named `t`, a name no other state may
    // take) is the first column already.
    let kept: Vec<usize> = (0..names.len()).filter(|&i| names[i] != "t").collect();
    let header: Vec<&str> = kept.iter().map(|&i| names[i].as_str()).collect();
    writeln!(out, "t,{},bound", header.join(","))?;
    for ((t, state), bound) in samples.iter().zip(bounds) {
        out.write_all(number(&mut floats, *t).as_bytes())?;
        for x in kept.iter().map(|&i| &state[i]).chain([bound]) {
            out.write_all(b",")?;
            out.write_all(number(&mut floats, *x).as_bytes())?;
        }
        out.write_all(b"\n")?;
    }
    out.into_inner().map_err(io::Error::other)?.sync_all()?;
    std::fs::rename(&tmp, path)
}

/// `x` in its shortest round-trip form (`nan`, `inf` and `-inf` where it
/// is not finite).
fn number(buffer: &mut ryu::Buffer, x: f64) -> String {
    if x.is_finite() {
        buffer.format_finite(x).to_string()
    } else if x.is_nan() {
        "nan".into()
    } else if x > 0.0 {
        "inf".into()
    } else {
        "-inf".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_are_spaced_to_t_end_or_sorted_and_checked() {
        let spaced = times(Some(5), None, 3.0).unwrap();
        assert_eq!(spaced, vec![0.0, 0.75, 1.5, 2.25, 3.0]);
        assert_eq!(times(Some(3), None, 0.1).unwrap()[2], 0.1);
        assert_eq!(
            times(None, Some(&[2.0, 0.5, 2.0]), 3.0).unwrap(),
            vec![0.5, 2.0]
        );
        assert!(times(Some(1), None, 3.0).unwrap_err().contains("from 2"));
        assert!(
            times(None, Some(&[4.0]), 3.0)
                .unwrap_err()
                .starts_with("4 is not a time")
        );
        assert!(times(None, Some(&[f64::NAN]), 3.0).is_err());
        assert!(times(None, None, 3.0).unwrap().is_empty());
    }

    #[test]
    fn the_csv_reads_back_every_double() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("samples.csv");
        let awkward = [0.1 + 0.2, 1.0 / 3.0, -2.5e-300, 6.02214076e23];
        let samples = vec![(0.0, awkward[..2].to_vec()), (0.7, awkward[2..].to_vec())];
        write_csv(&path, crate::names!["a", "b"], &samples, &[1e-16, f64::NAN]).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("t,a,b,bound"));
        let row: Vec<f64> = lines
            .nth(1)
            .unwrap()
            .split(',')
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(row[..3], [0.7, awkward[2], awkward[3]]);
        assert!(row[3].is_nan());
        assert!(!path.with_extension("csv.tmp").exists());
        write_csv(
            &path,
            crate::names!["x", "t"],
            &[(2.0, vec![1.5, 2.0])],
            &[0.0],
        )
        .unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text, "t,x,bound\n2.0,1.5,0.0\n");
    }
}
