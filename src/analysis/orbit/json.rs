//! `orbit.json`: a found orbit (or why none was) as the command line
//! writes it and Python returns it.

use std::path::Path;

use serde_json::{Value, json};

use crate::analysis::orbit::Orbit;

impl Orbit {
    /// The contents of `orbit.json`: the orbit found in `scene` through
    /// `section`, and the search's wall time.
    pub fn to_json(&self, scene: &Path, section: &str, wall: f64) -> Value {
        let state: serde_json::Map<String, Value> = self
            .section_state
            .iter()
            .map(|(n, x)| (n.to_string(), json!(x)))
            .collect();
        let multipliers: Vec<Value> = self
            .multipliers
            .iter()
            .map(|(re, im)| json!([re, im]))
            .collect();
        json!({
            "status": self.status,
            "converged": self.converged,
            "scene": scene.display().to_string(),
            "section": section,
            "period": self.period,
            "events_per_period": self.events_per_period,
            "mode": self.mode,
            "section_state": state,
            "multipliers": multipliers,
            "stable": self.stable,
            "residual": self.residual,
            "iterations": self.iterations,
            "newton_residuals": self.residuals,
            "wall_seconds": wall,
        })
    }
}
