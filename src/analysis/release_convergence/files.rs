//! What `flicker compare-models` writes besides its pictures.
//!
//! - `compare_models.csv`: `model,units,t,right_end,front,energy`, one row
//!   per model per sample time (`units` and `front` empty where none).
//! - `coarse.csv`: `model,units,t,x,window_strain,window_velocity,hidden_energy`
//!   at each snapshot time and window centre.
//! - `compare_models.json`: per model its status, events, wall time and
//!   energy error, and its [`Distance`] from the reference (the densest
//!   chain), with the reference named.

use std::io;
use std::path::Path;

use serde_json::{Value, json};

use crate::analysis::release_convergence::{Distance, Track};

fn optional(x: Option<impl ToString>) -> String {
    x.map_or(String::new(), |x| x.to_string())
}

/// Write `compare_models.csv` and `coarse.csv` into `dir`.
pub fn write_csvs(tracks: &[Track], dir: &Path) -> io::Result<()> {
    let mut w = csv::Writer::from_path(dir.join("compare_models.csv"))?;
    w.write_record(["model", "units", "t", "right_end", "front", "energy"])?;
    for track in tracks {
        for s in &track.samples {
            w.write_record([
                track.label.clone(),
                optional(track.units()),
                s.t.to_string(),
                s.right_end.to_string(),
                optional(s.front),
                s.energy.to_string(),
            ])?;
        }
    }
    w.flush()?;
    let mut w = csv::Writer::from_path(dir.join("coarse.csv"))?;
    w.write_record([
        "model",
        "units",
        "t",
        "x",
        "window_strain",
        "window_velocity",
        "hidden_energy",
    ])?;
    for track in tracks {
        for s in &track.snapshots {
            let c = &s.coarse;
            for j in 0..c.x.len() {
                w.write_record([
                    track.label.clone(),
                    optional(track.units()),
                    s.t.to_string(),
                    c.x[j].to_string(),
                    c.strain[j].to_string(),
                    c.velocity[j].to_string(),
                    c.hidden_energy[j].to_string(),
                ])?;
            }
        }
    }
    w.flush()
}

/// The contents of `compare_models.json`.
pub fn summary(tracks: &[Track], reference: &Track, distances: &[Distance]) -> Value {
    let models: Vec<Value> = tracks
        .iter()
        .zip(distances)
        .map(|(t, d)| {
            json!({
                "model": t.label,
                "units": t.units(),
                "status": t.status.as_str(),
                "reason": t.reason,
                "events": t.events,
                "wall_seconds": t.wall_seconds,
                "max_energy_error": t.max_energy_error,
                "distance": {
                    "right_end": d.right_end,
                    "right_end_before_return": d.right_end_before_return,
                    "returned": d.returned,
                    "front": d.front,
                    "front_speed": d.front_speed,
                    "plateau_strain": d.plateau_strain,
                    "plateau_velocity": d.plateau_velocity,
                    "window_strain": d.window_strain,
                    "window_velocity": d.window_velocity,
                    "hidden_energy": d.hidden_energy,
                    "energy": d.energy,
                },
            })
        })
        .collect();
    json!({ "reference": reference.label, "models": models })
}
