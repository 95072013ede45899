//! What a run of a chain or a continuum writes besides the log and the summary.
//!
//! - `profiles.json`: `{"snapshots": [{"t", "x", "strain", "displacement",
//!   "velocity"}], "classical": ...}`, one entry per snapshot time. For a
//!   chain, entry `n` of each array is unit `n + 1` (its centre `x` and
//!   strain) and node `n + 1` (the unit's end away from the wall: its
//!   displacement and velocity); for a continuum, the string at the centre
//!   `x` of each of `resolution` equal cells. `classical` holds the same scene with the constraint off
//!   (the classical string, for comparison) as `{"snapshots": [..],
//!   "trace": [{"t", "right_end", "energy"}]}`, or null (constraint off already, a
//!   run that did not complete, or more than
//!   [`CLASSICAL_MAX_UNITS`](crate::runner::CLASSICAL_MAX_UNITS) units).
//! - `trace.csv`: columns `t,energy,momentum,right_end` at the scene's
//!   sample times, `right_end` being the loaded end's displacement.
//! (`ensemble.csv`, with `--ensemble`, is the model's own:
//! [`crate::runner::ensemble`].)

use std::io;
use std::path::Path;

use serde_json::{Value, json};

use crate::runner::{FieldOutputs, Profile};

/// The contents of `profiles.json`.
pub fn profiles(chain: &FieldOutputs) -> Value {
    let classical = chain.classical.as_ref().map(|c| {
        let trace: Vec<Value> = c
            .trace
            .iter()
            .map(|r| json!({"t": r.t, "right_end": r.right_end, "energy": r.energy}))
            .collect();
        json!({ "snapshots": snapshots(&c.profiles), "trace": trace })
    });
    json!({ "snapshots": snapshots(&chain.profiles), "classical": classical })
}

fn snapshots(profiles: &[Profile]) -> Vec<Value> {
    profiles
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
        .collect()
}

/// Write `trace.csv` through a temporary file and a rename.
pub fn write_trace(chain: &FieldOutputs, path: &Path) -> io::Result<()> {
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
