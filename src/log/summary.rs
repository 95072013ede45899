//! `summary.json`: what a run did, in one object.
//!
//! Keys: `status` (`completed`, `zeno`, `failed`, `interrupted`), `reason`
//! (null when completed), `model`, `method`, `method_description`,
//! `scene`, `events`, `events_by_guard`, `t_end`, `t_reached`,
//! `energy_initial`, `energy_final`, `max_energy_error` (relative, against
//! the model's energy scale), `final_state` (named components), `final_mode`,
//! `zeno`, `flow_evaluations`, `error_bound` (the largest error a state
//! component may carry; null where no bound is carried),
//! `error_estimate` and `error_estimate_by` (where no bound is carried,
//! what stands in for it and how it was made; null where a bound is, and
//! past the horizon of a run that went on past it),
//! `event_time_bound` (the same for event times, null where not carried),
//! `horizon` (where the run's own error reached 1e-3 of its state's scale,
//! or its bound could no longer decide what happens; null if neither, see
//! `engine::horizon`), `shadow_events` (events logged past the horizon by
//! a run that went on past it, `--past-horizon` or a chain's, each flagged
//! `shadow`),
//! `wall_seconds`, `log` (path of the event log or
//! null); for chains, `momentum` (total, at the end) and
//! `momentum_balance_error` (against the end load's and the wall's
//! impulses, relative; exact path only), null for other models; with
//! `--sensitivities`, `sensitivities`: for each direction, the derivatives
//! of the final state (`final_state`, by name) and of the last event's time
//! (`last_event_time`); where the run jumped over whole periods of an
//! exactly periodic orbit (no event log, see `engine::periodic`),
//! `fast_forward`: `periods` (their events counted, not fired),
//! `events_per_period`, `period` (the last jump's), `from` and `to` (where
//! the jumps began and ended).

use std::io;
use std::path::Path;

use serde_json::{Value, json};

use crate::runner::Report;

/// The summary of `report`, run from the scene file `scene`.
pub fn summary(report: &Report, model: &str, scene: &Path, log: Option<&Path>) -> Value {
    let o = &report.outcome;
    let final_state: serde_json::Map<String, Value> = report
        .final_state
        .iter()
        .map(|(name, x)| (name.to_string(), json!(x)))
        .collect();
    let mut value = json!({
        "status": o.status.as_str(),
        "reason": o.reason,
        "model": model,
        "method": report.method.name(),
        "method_description": report.description,
        "scene": scene.display().to_string(),
        "events": o.events,
        "events_by_guard": o.events_by_guard,
        "t_end": o.t_end,
        "t_reached": o.t_reached,
        "energy_initial": o.energy_initial,
        "energy_final": o.energy_final,
        "max_energy_error": o.max_energy_error,
        "final_state": final_state,
        "final_mode": o.final_mode_name,
        "zeno": o.zeno,
        "flow_evaluations": o.flow_evaluations,
        "error_bound": o.error_bound,
        "error_estimate": o.error_estimate.as_ref().map(|e| e.value),
        "error_estimate_by": o.error_estimate.as_ref().map(|e| e.made_by.as_str()),
        "event_time_bound": o.event_time_bound,
        "horizon": o.horizon,
        "shadow_events": o.shadow_events,
        "wall_seconds": o.wall_seconds,
        "log": log.map(|p| p.display().to_string()),
        "momentum": report.fields.as_ref().map(|c| c.momentum),
        "momentum_balance_error": report.fields.as_ref().and_then(|c| c.momentum_balance_error),
    });
    if let Some(f) = &o.fast_forward {
        value["fast_forward"] = json!({
            "periods": f.periods,
            "events_per_period": f.events_per_period,
            "period": f.period,
            "from": f.from,
            "to": f.to,
        });
    }
    if let Some(sensitivities) = &report.sensitivities {
        value["sensitivities"] = sensitivities.clone();
    }
    value
}

/// Write `value` to `path` through a temporary file and a rename, so a
/// reader never sees half a summary.
pub fn write_atomically(path: &Path, value: &Value) -> io::Result<()> {
    let tmp = path.with_extension("json.tmp");
    let mut text = serde_json::to_string_pretty(value).map_err(io::Error::other)?;
    text.push('\n');
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}
