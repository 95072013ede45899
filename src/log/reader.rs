//! Reading an event log back, line by line, without holding it in memory.

use std::fmt;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use serde::Deserialize;

/// The fields of a log line that inspection uses; others are ignored.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct LoggedEvent {
    /// 1-based position of the event in the run.
    pub seq: u64,
    /// Time of the event.
    pub t: f64,
    /// The guard that fired.
    pub guard: String,
    /// The model's energy just before the reset, if it has one.
    pub energy_before: Option<f64>,
    /// The model's energy just after the reset, if it has one.
    pub energy_after: Option<f64>,
    /// The mode before the reset.
    #[serde(default)]
    pub mode_before: String,
    /// The mode after the reset.
    #[serde(default)]
    pub mode_after: String,
    /// The state before the reset, by name, in the log's order.
    #[serde(default)]
    pub before: NamedState,
    /// The state after the reset.
    #[serde(default)]
    pub after: NamedState,
    /// A chain's unit.
    #[serde(default)]
    pub unit: Option<u64>,
    /// A chain's closing speed.
    #[serde(default)]
    pub rel_velocity: Option<f64>,
    /// Where along a continuum.
    #[serde(default)]
    pub x: Option<f64>,
}

/// A logged state: its components by name, in the order the log wrote
/// them (a JSON object read without sorting its keys).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NamedState(pub Vec<(String, f64)>);

impl<'de> Deserialize<'de> for NamedState {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Components;
        impl<'de> serde::de::Visitor<'de> for Components {
            type Value = NamedState;

            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of state components")
            }

            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> Result<NamedState, A::Error> {
                let mut components = Vec::new();
                while let Some((name, value)) = map.next_entry::<String, f64>()? {
                    components.push((name, value));
                }
                Ok(NamedState(components))
            }
        }
        deserializer.deserialize_map(Components)
    }
}

/// A log that could not be read: which file, which line, why.
#[derive(Debug, Clone, PartialEq)]
pub struct LogError {
    /// The log file.
    pub path: PathBuf,
    /// The 1-based line at fault, if the fault is in a line.
    pub line: Option<u64>,
    /// What is wrong.
    pub reason: String,
}

impl fmt::Display for LogError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}: line {line}: {}", self.path.display(), self.reason),
            None => write!(f, "{}: {}", self.path.display(), self.reason),
        }
    }
}

impl std::error::Error for LogError {}

/// One line of a log, or why it is not an event record.
pub fn parse_line(line: &str) -> Result<LoggedEvent, String> {
    let event: LoggedEvent =
        serde_json::from_str(line).map_err(|e| format!("is not an event record: {e}"))?;
    if !event.t.is_finite() {
        return Err(format!("has a non-finite time {}", event.t));
    }
    Ok(event)
}

/// Call `visit` with each event of the log at `path` and its raw line.
pub fn for_each_event(
    path: &Path,
    mut visit: impl FnMut(&LoggedEvent, &str),
) -> Result<(), LogError> {
    let error = |line, reason| LogError {
        path: path.to_path_buf(),
        line,
        reason,
    };
    let file = File::open(path).map_err(|e| error(None, format!("cannot be opened: {e}")))?;
    let mut reader = BufReader::new(file);
    let mut text = String::new();
    let mut number = 0;
    loop {
        text.clear();
        number += 1;
        match reader.read_line(&mut text) {
            Ok(0) => return Ok(()),
            Ok(_) => {}
            Err(e) => return Err(error(Some(number), format!("cannot be read: {e}"))),
        }
        let line = text.trim_end();
        if line.is_empty() {
            continue;
        }
        let event = parse_line(line).map_err(|reason| error(Some(number), reason))?;
        visit(&event, line);
    }
}
