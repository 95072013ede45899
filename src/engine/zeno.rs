//! Recognising Zeno accumulation: one guard firing again and again at
//! intervals the run cannot resolve.
//!
//! The resolution is `2^-40` of the run's time scale `max(|t|, t_end)`, about
//! 4000 floating-point spacings of that scale: events closer than that could
//! not all be told apart by the end of the run, and reaching `t_end` through
//! them would take more than 10^12 events. A guard whose last
//! [`REPEATS`] intervals all fall below it is declared Zeno. Restitution below
//! one gives a true accumulation point (a bouncing ball); restitution one
//! near resting contact gives intervals that are merely too small; both are
//! caught the same way.

use crate::engine::model::Mode;
use crate::time::Time;

/// Consecutive unresolvable intervals of one guard that make a Zeno point.
pub const REPEATS: u32 = 8;

/// Relative time resolution, `2^-40`.
const RESOLUTION: f64 = 1.0 / (1u64 << 40) as f64;

/// The shortest interval between events of one guard that a run reaching
/// `t` (or `t_end`, whichever is larger) can resolve.
pub fn resolution(t: f64, t_end: f64) -> f64 {
    RESOLUTION * t.abs().max(t_end)
}

/// The event times of a run that stopped at a Zeno point, without the
/// last [`REPEATS`]: those are the events the run could no longer resolve
/// (where it stops among them is its own), and are not compared.
pub fn resolved(times: &[f64]) -> &[f64] {
    &times[..times.len().saturating_sub(REPEATS as usize)]
}

#[derive(Debug, Clone, Copy, Default)]
struct Track {
    last: Option<Time>,
    interval: f64,
    previous_interval: f64,
    short: u32,
}

/// The last firing time and run of short intervals of each guard.
#[derive(Debug, Clone)]
pub struct ZenoWatch {
    t_end: f64,
    tracks: Vec<Vec<Track>>,
    last: Track,
    resolution: f64,
}

impl ZenoWatch {
    /// A watch for a run that ends at `t_end`, with nothing seen yet.
    pub fn new(t_end: f64) -> Self {
        ZenoWatch {
            t_end,
            tracks: Vec::new(),
            last: Track::default(),
            resolution: 0.0,
        }
    }

    /// Note that guard `slot` of `mode` fired at `t`; `true` if it is now Zeno.
    pub fn observe(&mut self, mode: Mode, slot: usize, t: Time) -> bool {
        if self.tracks.len() <= mode {
            self.tracks.resize(mode + 1, Vec::new());
        }
        let tracks = &mut self.tracks[mode];
        if tracks.len() <= slot {
            tracks.resize(slot + 1, Track::default());
        }
        let track = &mut tracks[slot];
        let resolution = resolution(t.value(), self.t_end);
        if let Some(last) = track.last {
            track.previous_interval = track.interval;
            track.interval = t.since(last);
            track.short = if track.interval <= resolution {
                track.short + 1
            } else {
                0
            };
        }
        track.last = Some(t);
        if track.short >= REPEATS {
            self.last = *track;
            self.resolution = resolution;
            *track = Track::default();
            return true;
        }
        false
    }

    /// What the last Zeno detection saw, for the run's `reason`.
    pub fn describe(&self) -> String {
        let (dt, prev) = (self.last.interval, self.last.previous_interval);
        let mut text = format!(
            "{REPEATS} intervals in a row below the resolution {:.3e}; the last {dt:.3e}",
            self.resolution
        );
        if dt > 0.0 && prev > dt {
            let ratio = dt / prev;
            text += &format!(
                ", shrinking by {ratio:.3} per event, so the accumulation point is about {:.3e} ahead",
                dt * ratio / (1.0 - ratio)
            );
        }
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometric_intervals_are_zeno_once_unresolvable() {
        let mut watch = ZenoWatch::new(10.0);
        let (mut t, mut dt) = (Time::new(0.0), 1.0);
        let mut fired_at = None;
        for k in 0..200 {
            if watch.observe(0, 0, t) {
                fired_at = Some((k, dt));
                break;
            }
            t = t.after(dt);
            dt *= 0.5;
        }
        let (_, dt) = fired_at.expect("a halving sequence must be caught");
        assert!(
            dt < 1e-11 / 2f64.powi(REPEATS as i32 - 1),
            "caught late or early: dt {dt}"
        );
        assert!(watch.describe().contains("shrinking by 0.500"));
    }

    #[test]
    fn steady_resolvable_events_are_not_zeno() {
        let mut watch = ZenoWatch::new(1e3);
        let mut t = Time::new(0.0);
        for _ in 0..100_000 {
            assert!(!watch.observe(0, 0, t));
            t = t.after(1e-6);
        }
    }

    #[test]
    fn guards_are_watched_separately() {
        // A cascade: ten guards firing 1e-15 apart, once per unit of time
        // (a packed block of units). Consecutive events are unresolvably
        // close, but no single guard accumulates.
        let cascade = |k: u32, j: u32| Time::new(k as f64).after(j as f64 * 1e-15);
        let mut watch = ZenoWatch::new(100.0);
        for k in 0..20 {
            for j in 0..10 {
                assert!(!watch.observe(0, j as usize, cascade(k, j)));
            }
        }
        // Seen as one guard, the same events are Zeno at once.
        let mut merged = ZenoWatch::new(100.0);
        assert!((0..10).any(|j| merged.observe(0, 0, cascade(0, j))));
    }
}
