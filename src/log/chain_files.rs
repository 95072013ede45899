//! What a chain run writes besides the log and the summary.
//!
//! - `profiles.json`: `{"snapshots": [{"t", "x", "strain", "displacement",
//!   "velocity"}]}`, one entry per snapshot time; entry `n` of each array is
//!   unit `n + 1` (its centre `x` and strain) and node `n + 1` (the unit's
//!   end away from the wall: its displacement and velocity).
//! - `trace.csv`: columns `t,energy,momentum,right_end` at the scene's
//!   sample times, `right_end` being the loaded end's displacement `y_N`.

use std::io;
use std::path::Path;

use serde_json::{Value, json};

use crate::runner::ChainOutputs;

/// The contents of `profiles.json`.
pub fn profiles(chain: &ChainOutputs) -> Value {
    let snapshots: Vec<Value> = chain
        .profiles
        .iter()
        .map(|p| {
            json!({
                "t": p.t,
                "x": p.x,
                "strain": p.strain,
                "displacement": p.displacement,
                "velocity": p.velocity,
            })
        })
        .collect();
    json!({ "snapshots": snapshots })
}

/// Write `trace.csv` through a temporary file and a rename.
pub fn write_trace(chain: &ChainOutputs, path: &Path) -> io::Result<()> {
    let tmp = path.with_extension("csv.tmp");
    let mut w = csv::Writer::from_path(&tmp)?;
    w.write_record(["t", "energy", "momentum", "right_end"])?;
    for row in &chain.trace {
        w.write_record([row.t, row.energy, row.momentum, row.right_end].map(|x| x.to_string()))?;
    }
    w.flush()?;
    drop(w);
    std::fs::rename(&tmp, path)
}
