//! Events kept in memory as columns, one vector per field: what a program
//! that wants the log as arrays takes (the Python package hands them to
//! NumPy as they are, without an object per event).
//!
//! Guard and mode names are kept once, each event holding their indices.
//! States are kept as each event's model names them; [`EventColumns::states`]
//! lays them out as one table whose columns are every name seen, in the
//! order first seen (a model whose modes name their states differently,
//! such as the angle formulation's charts, gets a column for each, empty
//! where a mode has no such state). Labels (a chain's unit and closing
//! speed, a place along a continuum) get a column each, empty where an
//! event has none.

use crate::engine::model::labels::Label;
use crate::engine::model::names::Name;
use crate::engine::run::observer::{EventRecord, Observer};

/// Every event of a run, field by field.
#[derive(Debug, Clone, Default)]
pub struct EventColumns {
    /// Position in the log, from 1.
    pub seq: Vec<u64>,
    /// Time of each event.
    pub t: Vec<f64>,
    /// The guard that fired, as an index into [`names`](Self::names).
    pub guard: Vec<u32>,
    /// The mode before the reset, as an index into [`names`](Self::names).
    pub mode_before: Vec<u32>,
    /// The mode after the reset, likewise.
    pub mode_after: Vec<u32>,
    /// The guard and mode names the indices refer to, each once.
    pub names: Vec<Name>,
    /// The energy before each reset (NaN for a model without one).
    pub energy_before: Vec<f64>,
    /// The energy after each reset.
    pub energy_after: Vec<f64>,
    /// Whether each event comes past the run's horizon, in a run asked to
    /// go on past it (see [`crate::engine::EventRecord::shadow`]).
    pub shadow: Vec<bool>,
    /// Each label's values, NaN where an event has none; whether all its
    /// values are whole numbers (a unit's index).
    pub labels: Vec<LabelColumn>,
    /// The distinct lists of state names, as events name their states.
    layouts: Vec<Vec<Name>>,
    /// Each event's layout before and after the reset.
    layout_before: Vec<u32>,
    layout_after: Vec<u32>,
    /// Each event's state values, one event after another.
    before: Vec<f64>,
    after: Vec<f64>,
}

/// One label's values over the events.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelColumn {
    /// The label's name (`unit`, `rel_velocity`, `x`).
    pub name: &'static str,
    /// Its value at each event, NaN where the event has none.
    pub values: Vec<f64>,
    /// Whether every value given is a whole number (a count).
    pub counts: bool,
}

/// The states before and after each event, as tables.
#[derive(Debug, Clone, PartialEq)]
pub struct StateTable {
    /// The columns: every state name seen, in the order first seen.
    pub names: Vec<Name>,
    /// The state before each reset, row by row (`events x names`), NaN
    /// where the event's mode has no such state.
    pub before: Vec<f64>,
    /// The state after each reset, likewise.
    pub after: Vec<f64>,
}

impl EventColumns {
    /// Events kept so far.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no event was kept.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The index of `name` among [`names`](Self::names), added if new.
    fn name(&mut self, name: &str) -> u32 {
        match self.names.iter().position(|n| *n == name) {
            Some(i) => i as u32,
            None => {
                self.names.push(Name::from(name));
                (self.names.len() - 1) as u32
            }
        }
    }

    /// The index of the layout `names`, added if new (a model has a few).
    fn layout(&mut self, names: &[Name]) -> u32 {
        match self.layouts.iter().position(|l| l.as_slice() == names) {
            Some(i) => i as u32,
            None => {
                self.layouts.push(names.to_vec());
                (self.layouts.len() - 1) as u32
            }
        }
    }

    /// The states before and after each event, laid out as one table
    /// (see the module doc); the values move out of the columns.
    pub fn states(&mut self) -> StateTable {
        let mut names: Vec<Name> = Vec::new();
        for layout in &self.layouts {
            for name in layout {
                if !names.contains(name) {
                    names.push(name.clone());
                }
            }
        }
        let before = std::mem::take(&mut self.before);
        let after = std::mem::take(&mut self.after);
        // One layout with every name: the values are the table already.
        if self.layouts.len() == 1 && self.layouts[0] == names {
            return StateTable {
                names,
                before,
                after,
            };
        }
        let width = names.len();
        let columns: Vec<Vec<usize>> = self
            .layouts
            .iter()
            .map(|l| {
                l.iter()
                    .map(|n| names.iter().position(|m| m == n).unwrap_or(0))
                    .collect()
            })
            .collect();
        let spread = |layouts: &[u32], values: &[f64]| {
            let mut table = vec![f64::NAN; layouts.len() * width];
            let mut at = 0;
            for (row, &layout) in layouts.iter().enumerate() {
                for &column in &columns[layout as usize] {
                    table[row * width + column] = values[at];
                    at += 1;
                }
            }
            table
        };
        StateTable {
            before: spread(&self.layout_before, &before),
            after: spread(&self.layout_after, &after),
            names,
        }
    }
}

impl Observer for EventColumns {
    fn on_event(&mut self, e: &EventRecord) -> std::io::Result<()> {
        let row = self.t.len();
        self.seq.push(e.seq);
        self.t.push(e.t);
        let guard = self.name(e.guard);
        let before = self.name(e.mode_before);
        let after = self.name(e.mode_after);
        self.guard.push(guard);
        self.mode_before.push(before);
        self.mode_after.push(after);
        self.energy_before.push(e.energy_before.unwrap_or(f64::NAN));
        self.energy_after.push(e.energy_after.unwrap_or(f64::NAN));
        self.shadow.push(e.shadow);
        // A state carries as many values as its names (an event-local
        // model's carries none).
        let n_before = e.names_before.len().min(e.before.len());
        let n_after = e.names_after.len().min(e.after.len());
        let layout = self.layout(&e.names_before[..n_before]);
        self.layout_before.push(layout);
        let layout = self.layout(&e.names_after[..n_after]);
        self.layout_after.push(layout);
        self.before.extend_from_slice(&e.before[..n_before]);
        self.after.extend_from_slice(&e.after[..n_after]);
        for (key, value) in e.labels.iter() {
            let column = match self.labels.iter().position(|c| c.name == key) {
                Some(i) => i,
                None => {
                    self.labels.push(LabelColumn {
                        name: key,
                        values: vec![f64::NAN; row],
                        counts: true,
                    });
                    self.labels.len() - 1
                }
            };
            let column = &mut self.labels[column];
            column.values.push(value.as_f64());
            column.counts &= matches!(value, Label::Count(_));
        }
        for column in &mut self.labels {
            if column.values.len() <= row {
                column.values.push(f64::NAN);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::model::labels::Labels;
    use crate::names;

    fn event<'a>(
        t: f64,
        guard: &'static str,
        names: &'a [Name],
        before: &'a [f64],
        after: &'a [f64],
        labels: &'a Labels,
    ) -> EventRecord<'a> {
        EventRecord {
            seq: 0,
            t,
            guard,
            mode_before: "m",
            mode_after: "n",
            from: 0,
            to: 1,
            energy_before: Some(1.0),
            energy_after: None,
            names_before: names,
            before,
            names_after: names,
            after,
            labels,
            shadow: false,
        }
    }

    #[test]
    fn states_of_modes_that_name_them_differently_share_one_table() {
        let mut columns = EventColumns::default();
        let none = Labels::NONE;
        let unit = Labels::NONE.with("unit", Label::Count(3));
        columns
            .on_event(&event(
                1.0,
                "a",
                names!["x", "v"],
                &[1.0, 2.0],
                &[1.0, -2.0],
                &none,
            ))
            .unwrap();
        columns
            .on_event(&event(
                2.0,
                "b",
                names!["q", "v"],
                &[3.0, 4.0],
                &[3.0, -4.0],
                &unit,
            ))
            .unwrap();
        assert_eq!(columns.len(), 2);
        assert_eq!(columns.names, ["a", "m", "n", "b"]);
        assert_eq!(columns.guard, [0, 3]);
        assert!(columns.energy_after.iter().all(|e| e.is_nan()));
        let label = &columns.labels[0];
        assert_eq!((label.name, label.counts), ("unit", true));
        assert!(label.values[0].is_nan() && label.values[1] == 3.0);
        let table = columns.states();
        assert_eq!(table.names, ["x", "v", "q"]);
        let nan_as = |v: &[f64]| {
            v.iter()
                .map(|x| if x.is_nan() { -9.0 } else { *x })
                .collect::<Vec<_>>()
        };
        assert_eq!(nan_as(&table.before), [1.0, 2.0, -9.0, -9.0, 4.0, 3.0]);
        assert_eq!(nan_as(&table.after), [1.0, -2.0, -9.0, -9.0, -4.0, 3.0]);
    }

    #[test]
    fn one_layout_is_the_table_as_it_came() {
        let mut columns = EventColumns::default();
        let none = Labels::NONE;
        for k in 0..3 {
            let x = k as f64;
            columns
                .on_event(&event(
                    x,
                    "a",
                    names!["x", "v"],
                    &[x, 1.0],
                    &[x, -1.0],
                    &none,
                ))
                .unwrap();
        }
        let table = columns.states();
        assert_eq!(table.before, [0.0, 1.0, 1.0, 1.0, 2.0, 1.0]);
        assert_eq!(table.after, [0.0, -1.0, 1.0, -1.0, 2.0, -1.0]);
    }
}
