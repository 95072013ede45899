//! `flicker run --ensemble`: copies of a scene with perturbed initial
//! values, run beside it to find how long its results are reproducible.
//!
//! What a model perturbs, samples and compares is its own
//! ([`SceneModel::ensemble`](crate::scene::SceneModel::ensemble)); what
//! every ensemble shares is here: the request, the report (the summary's
//! `ensemble` entry, the rows of `ensemble.csv`, the lines to print), the
//! checks of the request, and the perturbations. Copy `i` draws its
//! perturbations from its own xorshift stream seeded by `(seed, i)`, so an
//! ensemble is the same for a given seed whatever the number of threads.

use std::io;
use std::path::Path;

use rand::SeedableRng;
use rand_xorshift::XorShiftRng;
use serde_json::Value;

/// What `--ensemble K [--perturb P] [--seed S]` asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnsembleRequest {
    /// Number of perturbed copies.
    pub copies: usize,
    /// Largest perturbation of an initial value, relative to its scale.
    pub perturb: f64,
    /// Seed of the perturbations.
    pub seed: u64,
}

impl EnsembleRequest {
    /// The checks every model's ensemble makes: at least two copies, and a
    /// perturbation in `(0, 1)`; a refusal says why (of the `ensemble`
    /// field).
    pub fn check(&self) -> Result<(), String> {
        if self.copies < 2 {
            return Err(format!(
                "needs at least 2 copies to compare (got {})",
                self.copies
            ));
        }
        if !(self.perturb.is_finite() && self.perturb > 0.0 && self.perturb < 1.0) {
            return Err(format!(
                "the perturbation must be in (0, 1) (got {})",
                self.perturb
            ));
        }
        Ok(())
    }

    /// The random stream copy `copy` draws its perturbations from.
    pub fn stream(&self, copy: usize) -> XorShiftRng {
        XorShiftRng::seed_from_u64(self.seed ^ (copy as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
    }
}

/// What an ensemble found, in its model's terms.
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleReport {
    /// The `ensemble` entry of `summary.json`.
    pub summary: Value,
    /// The columns of `ensemble.csv`.
    pub header: Vec<String>,
    /// Its rows, one per sample time, as written.
    pub rows: Vec<Vec<String>>,
    /// What `flicker run` prints of it, a line each.
    pub said: Vec<String>,
}

impl EnsembleReport {
    /// Write `ensemble.csv` to `path`, whole or not at all.
    pub fn write_csv(&self, path: &Path) -> io::Result<()> {
        let tmp = path.with_extension("csv.tmp");
        let mut w = csv::Writer::from_path(&tmp)?;
        w.write_record(&self.header)?;
        for row in &self.rows {
            w.write_record(row)?;
        }
        w.flush()?;
        drop(w);
        std::fs::rename(&tmp, path)
    }
}

/// The largest difference between the copies, value by value: `copies`
/// yields each copy's values at one time, all of one length.
pub fn spread<'v>(mut copies: impl Iterator<Item = &'v [f64]>) -> Vec<f64> {
    let Some(first) = copies.next() else {
        return Vec::new();
    };
    let (mut low, mut high) = (first.to_vec(), first.to_vec());
    for values in copies {
        for ((lo, hi), x) in low.iter_mut().zip(high.iter_mut()).zip(values) {
            *lo = lo.min(*x);
            *hi = hi.max(*x);
        }
    }
    low.iter().zip(&high).map(|(lo, hi)| hi - lo).collect()
}
