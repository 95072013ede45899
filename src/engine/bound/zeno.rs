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
//!
//! A method with an error bound may lose the events sooner: their spacing
//! falls below what its errors can order, and its bound cannot decide. The
//! watch then tells a pile-up from chaos by the intervals themselves: the
//! last [`SHRINKS`] each shrank by the same factor (to within
//! [`RATIO_SPREAD`]), at most [`SHRINKING`], as a chattering ball's do. So
//! every method names the same cause, in the same words
//! ([`ZenoWatch::chattering`]).

use crate::engine::model::Mode;
use crate::time::Time;

/// Consecutive unresolvable intervals of one guard that make a Zeno point.
pub const REPEATS: u32 = 8;

/// Relative time resolution, `2^-40`.
const RESOLUTION: f64 = 1.0 / (1u64 << 40) as f64;

/// Consecutive shrinking intervals of one guard that make a pile-up where
/// a run's bound can no longer order its events.
pub const SHRINKS: u32 = 6;

/// The most an interval may be of the one before to count as shrinking.
pub const SHRINKING: f64 = 0.9;

/// How far apart (as a ratio) the shrink factors of a pile-up may lie.
pub const RATIO_SPREAD: f64 = 1.5;

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
    /// Consecutive intervals that shrank, and the least and largest
    /// factor they shrank by.
    shrinks: u32,
    ratios: (f64, f64),
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
            let ratio = track.interval / track.previous_interval;
            let (lo, hi) = track.ratios;
            (track.shrinks, track.ratios) = match ratio {
                r if !(r > 0.0 && r <= SHRINKING) => (0, (0.0, 0.0)),
                r if track.shrinks > 0 && r.max(hi) <= RATIO_SPREAD * r.min(lo) => {
                    (track.shrinks + 1, (r.min(lo), r.max(hi)))
                }
                r => (1, (r, r)),
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

    /// Whether guard `slot` of `mode` is piling up (see the module's
    /// doc): its intervals' last shrink factor, if so.
    pub fn chattering(&self, mode: Mode, slot: usize) -> Option<f64> {
        let track = self.tracks.get(mode)?.get(slot)?;
        (track.shrinks >= SHRINKS).then(|| track.interval / track.previous_interval)
    }

    /// The pile-up of guard `slot` of `mode` was dealt with (settled):
    /// another must shrink anew.
    pub fn forget_chattering(&mut self, mode: Mode, slot: usize) {
        if let Some(track) = self.tracks.get_mut(mode).and_then(|t| t.get_mut(slot)) {
            track.shrinks = 0;
        }
    }

    /// What the run's bound saw of the pile-up of guard `slot` of `mode`
    /// (see [`ZenoWatch::chattering`]), for the run's `reason`.
    pub fn describe_chattering(&self, mode: Mode, slot: usize) -> Option<String> {
        let ratio = self.chattering(mode, slot)?;
        let track = self.tracks[mode][slot];
        let ahead = track.interval * ratio / (1.0 - ratio);
        Some(format!(
            "its error bound can no longer tell them apart; the last {SHRINKS} intervals \
             shrinking by {ratio:.3} per event, so the accumulation point is about {ahead:.3e} \
             past the last event it could"
        ))
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
    fn a_steady_shrink_is_a_pile_up_and_a_wandering_one_is_not() {
        // Intervals shrinking by 0.5 with a table's wobble of +-10%: a
        // pile-up once SHRINKS of them have shrunk.
        let mut watch = ZenoWatch::new(10.0);
        let (mut t, mut dt) = (Time::new(0.0), 0.1);
        for k in 0..=SHRINKS + 1 {
            watch.observe(0, 0, t);
            let seen = watch.chattering(0, 0);
            assert_eq!(seen.is_some(), k > SHRINKS, "{k}: {seen:?}");
            t = t.after(dt);
            dt *= if k % 2 == 0 { 0.45 } else { 0.55 };
        }
        assert!(
            watch
                .describe_chattering(0, 0)
                .unwrap()
                .contains("shrinking by 0.55")
        );
        // Settled: a later pile-up must shrink anew.
        watch.forget_chattering(0, 0);
        assert_eq!(watch.chattering(0, 0), None);
        watch.observe(0, 0, t);
        assert_eq!(watch.chattering(0, 0), None);
        // Chaotic intervals: some shrink, some grow, the factors unlike.
        let mut watch = ZenoWatch::new(100.0);
        let mut t = Time::new(0.0);
        for k in 0..400u64 {
            watch.observe(0, 0, t);
            assert_eq!(watch.chattering(0, 0), None, "{k}");
            let wobble = (k.wrapping_mul(2654435761) % 1000) as f64 / 1000.0;
            t = t.after(0.2 + wobble);
        }
        // Shrinking, but by factors far apart (a ball thrown back up by
        // the table now and then): no pile-up.
        let mut watch = ZenoWatch::new(10.0);
        let (mut t, mut dt) = (Time::new(0.0), 0.1);
        for k in 0..20 {
            watch.observe(0, 0, t);
            assert_eq!(watch.chattering(0, 0), None, "{k}");
            t = t.after(dt);
            dt *= if k % 2 == 0 { 0.3 } else { 0.85 };
        }
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
