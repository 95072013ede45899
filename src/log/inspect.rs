//! Filtering and summarising an event log: counts per guard, first and last
//! times, intervals between events, the largest energy jump across a reset
//! (where a perfectly elastic model should show round-off only), and the
//! time spent sliding on each switching surface of a discontinuous flow
//! (its `slide:h` and `leave:h` events).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::log::reader::LoggedEvent;

/// Which events to keep.
#[derive(Debug, Clone, Default)]
pub struct Filter {
    /// Keep only events of the guard of this name.
    pub guard: Option<String>,
    /// Keep only events at `t >= from`.
    pub from: Option<f64>,
    /// Keep only events at `t <= to`.
    pub to: Option<f64>,
}

impl Filter {
    /// Whether `e` passes every condition that is set.
    pub fn keeps(&self, e: &LoggedEvent) -> bool {
        self.guard.as_ref().is_none_or(|g| *g == e.guard)
            && self.from.is_none_or(|t| e.t >= t)
            && self.to.is_none_or(|t| e.t <= t)
    }
}

/// Smallest, mean and largest of a stream of values.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Spread {
    /// How many values.
    pub count: u64,
    /// The smallest, once there is a value.
    pub min: Option<f64>,
    /// The mean, once there is a value.
    pub mean: Option<f64>,
    /// The largest, once there is a value.
    pub max: Option<f64>,
    #[serde(skip)]
    sum: f64,
}

impl Spread {
    fn add(&mut self, x: f64) {
        self.count += 1;
        self.sum += x;
        self.min = Some(self.min.map_or(x, |m| m.min(x)));
        self.max = Some(self.max.map_or(x, |m| m.max(x)));
        self.mean = Some(self.sum / self.count as f64);
    }
}

/// What one guard did.
#[derive(Debug, Clone, Default, Serialize)]
pub struct GuardSummary {
    /// Events of this guard.
    pub count: u64,
    /// Time of its first event.
    pub first_t: Option<f64>,
    /// Time of its last event.
    pub last_t: Option<f64>,
    /// Between consecutive events of this guard.
    pub intervals: Spread,
}

/// The event with the largest `|energy_after - energy_before|`.
#[derive(Debug, Clone, Serialize)]
pub struct EnergyJump {
    /// `|energy_after - energy_before|`.
    pub jump: f64,
    /// The event's `seq`.
    pub seq: u64,
    /// The event's time.
    pub t: f64,
    /// The guard that fired.
    pub guard: String,
}

/// Sliding on one switching surface: from each `slide:h` to the `leave:h`
/// after it.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SlidingSummary {
    /// Sliding intervals begun.
    pub intervals: u64,
    /// Time spent sliding in the intervals that ended.
    pub time: f64,
    /// When the interval still open at the last event began: the run went
    /// on sliding past it.
    pub since: Option<f64>,
}

/// A summary of the events a filter kept.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Summary {
    /// Events kept.
    pub events: u64,
    /// Time of the first kept event.
    pub first_t: Option<f64>,
    /// Time of the last kept event.
    pub last_t: Option<f64>,
    /// What each guard did, by guard name.
    pub by_guard: BTreeMap<String, GuardSummary>,
    /// Between consecutive kept events, whatever their guard.
    pub intervals: Spread,
    /// The same intervals counted per decade: `"1e-3"` holds those in
    /// `[1e-3, 1e-2)`; `"0"` holds simultaneous events.
    pub interval_histogram: BTreeMap<String, u64>,
    /// The largest energy jump across a reset, among events that log their
    /// energy on both sides.
    pub largest_energy_jump: Option<EnergyJump>,
    /// Events whose time is earlier than the one before (should be none).
    pub out_of_order: u64,
    /// Sliding, by switching surface (the `h` of its events' names); absent
    /// where nothing slid.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub sliding: BTreeMap<String, SlidingSummary>,
}

impl Summary {
    /// Count `e` in, as the next kept event.
    pub fn add(&mut self, e: &LoggedEvent) {
        if let Some(last) = self.last_t {
            if e.t < last {
                self.out_of_order += 1;
            }
            self.intervals.add(e.t - last);
            *self
                .interval_histogram
                .entry(decade(e.t - last))
                .or_insert(0) += 1;
        }
        self.events += 1;
        self.first_t.get_or_insert(e.t);
        self.last_t = Some(e.t);
        let guard = self.by_guard.entry(e.guard.clone()).or_default();
        if let Some(last) = guard.last_t {
            guard.intervals.add(e.t - last);
        }
        guard.count += 1;
        guard.first_t.get_or_insert(e.t);
        guard.last_t = Some(e.t);
        if let Some(surface) = e.guard.strip_prefix("slide:") {
            let sliding = self.sliding.entry(surface.to_string()).or_default();
            sliding.intervals += 1;
            sliding.since = Some(e.t);
        } else if let Some(surface) = e.guard.strip_prefix("leave:") {
            let sliding = self.sliding.entry(surface.to_string()).or_default();
            if let Some(since) = sliding.since.take() {
                sliding.time += e.t - since;
            }
        }
        if let (Some(before), Some(after)) = (e.energy_before, e.energy_after) {
            let jump = (after - before).abs();
            if self
                .largest_energy_jump
                .as_ref()
                .is_none_or(|j| jump > j.jump)
            {
                self.largest_energy_jump = Some(EnergyJump {
                    jump,
                    seq: e.seq,
                    t: e.t,
                    guard: e.guard.clone(),
                });
            }
        }
    }
}

/// The decade an interval falls in, as a histogram key.
fn decade(interval: f64) -> String {
    if interval > 0.0 {
        format!("1e{}", interval.log10().floor() as i32)
    } else {
        "0".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(seq: u64, t: f64, guard: &str, jump: f64) -> LoggedEvent {
        LoggedEvent {
            seq,
            t,
            guard: guard.into(),
            energy_before: Some(1.0),
            energy_after: Some(1.0 + jump),
            mode_before: "m".into(),
            mode_after: "m".into(),
            before: Default::default(),
            after: Default::default(),
            unit: None,
            rel_velocity: None,
            x: None,
        }
    }

    #[test]
    fn summarises_counts_intervals_and_the_largest_jump() {
        let mut s = Summary::default();
        for e in [
            event(1, 1.0, "a", 0.0),
            event(2, 2.0, "b", -3e-16),
            event(3, 4.0, "a", 1e-16),
        ] {
            s.add(&e);
        }
        assert_eq!(s.events, 3);
        assert_eq!(s.by_guard["a"].count, 2);
        assert_eq!(s.by_guard["a"].intervals.mean, Some(3.0));
        assert_eq!(s.intervals.min, Some(1.0));
        assert_eq!(s.intervals.max, Some(2.0));
        let jump = s.largest_energy_jump.unwrap();
        assert_eq!((jump.seq, jump.guard.as_str()), (2, "b"));
        assert_eq!(s.out_of_order, 0);
        assert_eq!(s.interval_histogram["1e0"], 2);
    }

    #[test]
    fn sliding_time_adds_up_from_slide_to_leave() {
        let mut s = Summary::default();
        for (t, guard) in [
            (1.0, "cross:v"),
            (2.0, "slide:v"),
            (2.5, "leave:v"),
            (3.0, "slide:v"),
            (4.25, "leave:v"),
            (5.0, "slide:v"),
        ] {
            s.add(&event(0, t, guard, 0.0));
        }
        let v = &s.sliding["v"];
        assert_eq!((v.intervals, v.time, v.since), (3, 1.75, Some(5.0)));
        assert_eq!(s.sliding.len(), 1);
    }

    #[test]
    fn filters_by_guard_and_window() {
        let f = Filter {
            guard: Some("a".into()),
            from: Some(1.5),
            to: Some(5.0),
        };
        assert!(!f.keeps(&event(1, 1.0, "a", 0.0)));
        assert!(!f.keeps(&event(2, 2.0, "b", 0.0)));
        assert!(f.keeps(&event(3, 4.0, "a", 0.0)));
    }
}
