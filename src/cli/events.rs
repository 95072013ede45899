//! `flicker events`: print the events a filter keeps, or a summary of them.

use std::io::{self, Write};
use std::path::Path;

pub use crate::log::inspect::Filter;
use crate::log::inspect::Summary;
use crate::log::reader::{LoggedEvent, for_each_event};

use crate::cli::exit::{Code, Failure};

/// What to print of the kept events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The log lines as they are.
    Lines,
    /// A JSON summary.
    Summary,
    /// CSV: seq, t, guard, the modes and energies before and after, the
    /// labels the log has (unit, rel_velocity, x), then every state
    /// component before and after (`before.NAME`, `after.NAME`).
    Csv,
}

/// Run `flicker events`: read the log at `log` and print the events
/// `filter` keeps in `format`. A closed stdout is not an error.
pub fn events(log: &Path, filter: Filter, format: Format) -> Result<Code, Failure> {
    for (flag, value) in [("--from", filter.from), ("--to", filter.to)] {
        if value.is_some_and(|t| !t.is_finite()) {
            return Err(Failure::bad_input(format!("{flag}: must be a finite time")));
        }
    }
    if let (Some(from), Some(to)) = (filter.from, filter.to)
        && from > to
    {
        return Err(Failure::bad_input(format!(
            "--from {from} is after --to {to}"
        )));
    }
    let mut summary = Summary::default();
    let columns = match format {
        Format::Csv => Columns::of(log, &filter)?,
        _ => Columns::default(),
    };
    let stdout = io::stdout();
    let mut out = io::BufWriter::new(stdout.lock());
    let mut write_error = None;
    if format == Format::Csv {
        write_error = writeln!(out, "{}", columns.header()).err();
    }
    for_each_event(log, |event, line| {
        if !filter.keeps(event) || write_error.is_some() {
            return;
        }
        write_error = match format {
            Format::Summary => {
                summary.add(event);
                None
            }
            Format::Lines => writeln!(out, "{line}").err(),
            Format::Csv => writeln!(out, "{}", columns.row(event)).err(),
        };
    })
    .map_err(Failure::bad_input)?;
    if format == Format::Summary {
        let text = serde_json::to_string_pretty(&summary).map_err(Failure::untrusted)?;
        write_error = writeln!(out, "{text}").err();
    }
    match write_error.or_else(|| out.flush().err()) {
        // A closed pipe (`| head`) is the reader's choice, not an error.
        Some(e) if e.kind() != io::ErrorKind::BrokenPipe => {
            Err(Failure::untrusted(format!("stdout: {e}")))
        }
        _ => Ok(Code::Ok),
    }
}

/// The columns of `--csv`: the labels any kept event carries and the
/// state components of every kept event, in order of first appearance
/// (read in a first pass over the log, so that a model whose modes name
/// their states differently gets a column for each).
#[derive(Debug, Default)]
struct Columns {
    unit: bool,
    rel_velocity: bool,
    x: bool,
    states: Vec<String>,
}

impl Columns {
    fn of(log: &Path, filter: &Filter) -> Result<Columns, Failure> {
        let mut columns = Columns::default();
        for_each_event(log, |event, _| {
            if !filter.keeps(event) {
                return;
            }
            columns.unit |= event.unit.is_some();
            columns.rel_velocity |= event.rel_velocity.is_some();
            columns.x |= event.x.is_some();
            for (name, _) in event.before.0.iter().chain(&event.after.0) {
                if !columns.states.contains(name) {
                    columns.states.push(name.clone());
                }
            }
        })
        .map_err(Failure::bad_input)?;
        Ok(columns)
    }

    fn header(&self) -> String {
        let mut names: Vec<String> = [
            "seq",
            "t",
            "guard",
            "mode_before",
            "mode_after",
            "energy_before",
            "energy_after",
        ]
        .map(String::from)
        .to_vec();
        for (present, name) in [
            (self.unit, "unit"),
            (self.rel_velocity, "rel_velocity"),
            (self.x, "x"),
        ] {
            if present {
                names.push(name.into());
            }
        }
        for side in ["before", "after"] {
            names.extend(
                self.states
                    .iter()
                    .map(|s| csv_field(&format!("{side}.{s}"))),
            );
        }
        names.join(",")
    }

    fn row(&self, event: &LoggedEvent) -> String {
        let number = |x: Option<f64>| x.map_or(String::new(), |x| x.to_string());
        let mut fields = vec![
            event.seq.to_string(),
            event.t.to_string(),
            csv_field(&event.guard),
            csv_field(&event.mode_before),
            csv_field(&event.mode_after),
            number(event.energy_before),
            number(event.energy_after),
        ];
        if self.unit {
            fields.push(event.unit.map_or(String::new(), |u| u.to_string()));
        }
        if self.rel_velocity {
            fields.push(number(event.rel_velocity));
        }
        if self.x {
            fields.push(number(event.x));
        }
        for state in [&event.before, &event.after] {
            fields.extend(
                self.states
                    .iter()
                    .map(|name| number(state.0.iter().find(|(n, _)| n == name).map(|(_, v)| *v))),
            );
        }
        fields.join(",")
    }
}

/// A guard name as a CSV field, quoted if it needs to be.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}
