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
    /// A chain's unit.
    #[serde(default)]
    pub unit: Option<u64>,
    /// Where along a continuum.
    #[serde(default)]
    pub x: Option<f64>,
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
