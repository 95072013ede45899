//! Whether two events whose order a run cannot tell apart commute, so
//! that their order does not matter.
//!
//! An event's time is uncertain by its share of the carried errors over
//! its closing speed. Where that reaches half the time since an earlier
//! event, the two may have happened the other way round, and the run
//! stops ([`bound`](crate::engine::bound)) unless the order changes
//! nothing it states. It changes nothing where, from the state before the
//! earlier event (both in the same mode, neither changing it):
//! - the two resets give the same state in either order;
//! - neither reset moves the other's guard, nor its guard's rate (so
//!   neither event's time depends on whether the other came first).
//!
//! Then the final state and both event times are the same either way, to
//! first order in the time between them, which the saltations carry. The
//! units of a chain far apart are the common case: a long chain's impacts
//! come nearly at once all along it, and only neighbours interact. The log
//! lists such events in the computed order, and each one's logged state
//! holds the other's jump or not as that order has it.
//!
//! These are finite checks on the resets themselves, asked only where an
//! order is in doubt: a Jacobian's zero at one state does not make a
//! reset independent of a component another event jumps.

use crate::engine::bound::ROUNDOFF_ULPS;
use crate::engine::bound::tangent::Tangents;
use crate::engine::model::{HybridModel, Mode};
use crate::time::Time;

/// How many of the last events are kept to be checked against.
const KEPT: usize = 16;

/// A logged event, as a later one is checked against it.
#[derive(Debug, Clone)]
struct Event {
    t: Time,
    mode: Mode,
    guard: usize,
    before: Vec<f64>,
}

/// The last [`KEPT`] events that changed no mode (one that does commutes
/// with nothing), and whether older ones were dropped.
#[derive(Debug, Clone, Default)]
pub(crate) struct Recent {
    events: Vec<Event>,
    /// Where the next event goes (the ring's oldest once it is full).
    next: usize,
    /// The time of the last event dropped, or of the last mode change.
    barrier: Option<Time>,
}

/// An event the run is firing: at `t`, of `guard` in `mode`, from
/// `before`, into `mode_after`.
pub(crate) struct Firing<'a> {
    pub t: Time,
    pub mode: Mode,
    pub guard: usize,
    pub before: &'a [f64],
    pub mode_after: Mode,
}

impl Recent {
    /// Note a logged event (after its checks).
    pub fn push(&mut self, e: &Firing<'_>) {
        if e.mode_after != e.mode {
            // Nothing before a mode change commutes past it.
            self.events.clear();
            self.next = 0;
            self.barrier = Some(e.t);
            return;
        }
        if self.events.len() < KEPT {
            self.events.push(Event {
                t: e.t,
                mode: e.mode,
                guard: e.guard,
                before: e.before.to_vec(),
            });
            return;
        }
        let slot = &mut self.events[self.next];
        self.barrier = Some(slot.t);
        slot.t = e.t;
        slot.mode = e.mode;
        slot.guard = e.guard;
        slot.before.copy_from_slice(e.before);
        self.next = (self.next + 1) % KEPT;
    }

    /// Forget the events kept: none is known to commute with what comes
    /// after `at` (a run that jumped whole periods ahead to it).
    pub fn restart(&mut self, at: Time) {
        self.events.clear();
        self.next = 0;
        self.barrier = Some(at);
    }

    /// The time from the latest earlier event that `e` may not commute
    /// with to `e`, looking back only while `doubt(since)` holds (an event
    /// further back is far enough); infinite where there is none.
    pub fn since_conflict<M: HybridModel + ?Sized>(
        &self,
        model: &M,
        tangents: &mut Tangents,
        e: &Firing<'_>,
        doubt: impl Fn(f64) -> bool,
    ) -> f64 {
        let n = self.events.len();
        // Newest first.
        for k in 0..n {
            let earlier = &self.events[(self.next + n - 1 - k) % n];
            let since = e.t.since(earlier.t);
            if !doubt(since) {
                return since;
            }
            if e.mode_after != e.mode || !commute(model, tangents, earlier, e) {
                return since;
            }
        }
        // Past the kept events: a mode change, a dropped event, or nothing.
        self.barrier.map_or(f64::INFINITY, |t| e.t.since(t))
    }
}

/// Whether `earlier` and `later` (same mode, neither changing it) commute,
/// checked from the state before `earlier`.
fn commute<M: HybridModel + ?Sized>(
    model: &M,
    tangents: &mut Tangents,
    earlier: &Event,
    later: &Firing<'_>,
) -> bool {
    if earlier.mode != later.mode {
        return false;
    }
    let (mode, x) = (earlier.mode, &earlier.before[..]);
    let scale = x.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let close = |a: f64, b: f64| (a - b).abs() <= ROUNDOFF_ULPS * f64::EPSILON * scale.max(a.abs());
    let reset = |g: usize, from: &[f64]| -> Option<Vec<f64>> {
        let mut y = from.to_vec();
        (model.reset(mode, g, &mut y).mode == mode).then_some(y)
    };
    let (a, b) = (earlier.guard, later.guard);
    let (Some(xa), Some(xb)) = (reset(a, x), reset(b, x)) else {
        return false;
    };
    let (Some(xab), Some(xba)) = (reset(b, &xa), reset(a, &xb)) else {
        return false;
    };
    if !xab.iter().zip(&xba).all(|(&p, &q)| close(p, q)) {
        return false;
    }
    // Each guard and its rate, with and without the other's reset.
    let mut gradient = vec![0.0; x.len()];
    let mut rate = vec![0.0; x.len()];
    let mut watched = |g: usize, at: &[f64]| -> (f64, f64) {
        tangents.gradient(model, mode, g, at, &mut gradient);
        tangents.rate(model, mode, at, &mut rate);
        let speed = gradient.iter().zip(&rate).map(|(d, f)| d * f).sum();
        (model.guard(mode, g, at), speed)
    };
    let unmoved = |(p, dp): (f64, f64), (q, dq): (f64, f64)| close(p, q) && close(dp, dq);
    unmoved(watched(b, x), watched(b, &xa)) && unmoved(watched(a, x), watched(a, &xb))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{Direction, Flow, Guard, Jump, Name};
    use crate::names;

    /// Two free particles `x1, x2` at speeds `v1, v2`: each bounces off a
    /// wall at zero (its speed flips), they collide (swap speeds) where
    /// `x1 = x2`, a marker watches `x1` and another `x1 + x2`, a guard
    /// sends the run to a second mode, and a last one moves `x2` by `v1`.
    struct Particles;

    const GUARDS: &[Guard] = &[
        Guard::affine("wall1", Direction::Falling),
        Guard::affine("wall2", Direction::Falling),
        Guard::affine("collide", Direction::Falling),
        Guard::affine("mark1", Direction::Rising),
        Guard::affine("mark_sum", Direction::Rising),
        Guard::affine("switch", Direction::Rising),
        Guard::affine("kick", Direction::Rising),
    ];

    #[rustfmt::skip]
    impl HybridModel for Particles {
        fn dimension(&self) -> usize { 4 }
        fn state_names(&self, _: Mode) -> &[Name] { names!["x1", "x2", "v1", "v2"] }
        fn mode_name(&self, _: Mode) -> &str { "free" }
        fn guards(&self, _: Mode) -> &[Guard] { GUARDS }
        fn guard(&self, _: Mode, g: usize, x: &[f64]) -> f64 {
            [x[0], x[1], x[1] - x[0], x[0], x[0] + x[1], x[0] - 5.0, x[1] - 7.0][g]
        }
        fn flow(&self, _: Mode) -> Flow { Flow::Ode }
        fn rhs(&self, _: Mode, x: &[f64], dx: &mut [f64]) {
            dx.copy_from_slice(&[x[2], x[3], 0.0, 0.0]);
        }
        fn reset(&self, mode: Mode, g: usize, x: &mut [f64]) -> Jump {
            match g {
                0 => x[2] = -x[2],
                1 => x[3] = -x[3],
                2 => x.swap(2, 3),
                5 => return Jump::to(1),
                6 => x[1] += x[2],
                _ => {}
            }
            Jump::to(mode)
        }
    }

    /// Whether an event of `a` then one of `b` at nearly the same time
    /// commute, both from `x`.
    fn commutes(a: usize, b: usize, x: &[f64]) -> bool {
        let mut recent = Recent::default();
        let mut tangents = Tangents::new(4);
        let at = |t: f64, guard: usize| Firing {
            t: Time::new(t),
            mode: 0,
            guard,
            before: x,
            mode_after: Particles.reset(0, guard, &mut x.to_vec()).mode,
        };
        recent.push(&at(1.0, a));
        let since = recent.since_conflict(&Particles, &mut tangents, &at(1.0 + 1e-9, b), |_| true);
        assert!(
            since == f64::INFINITY || (since - 1e-9).abs() < 1e-15,
            "{since}"
        );
        since == f64::INFINITY
    }

    #[test]
    fn events_that_touch_what_the_other_reads_do_not_commute() {
        let x = [1.0, 2.0, -0.5, 0.3];
        // Each wall flips its own particle.
        assert!(commutes(0, 1, &x));
        assert!(commutes(1, 0, &x));
        // The collision reads both speeds that the walls flip.
        assert!(!commutes(0, 2, &x));
        assert!(!commutes(2, 1, &x));
        // A marker on x1 moves with v1 alone: the second wall leaves it.
        assert!(commutes(3, 1, &x));
        assert!(commutes(1, 3, &x));
        // A marker on x1 + x2 closes at v1 + v2, which the second wall
        // changes: which came first decides when it fires.
        assert!(!commutes(4, 1, &x));
        // The kick reads the speed the first wall flips (neither moves
        // the other's guard or its rate).
        assert!(!commutes(6, 0, &x));
        assert!(!commutes(0, 6, &x));
        // The second wall flips the speed the kick's guard closes at.
        assert!(!commutes(6, 1, &x));
        // Nothing commutes past a change of mode.
        assert!(!commutes(5, 1, &x));
        assert!(!commutes(1, 5, &x));
    }

    #[test]
    fn only_the_kept_events_are_looked_back_on() {
        let x = [1.0, 2.0, -0.5, 0.3];
        let mut recent = Recent::default();
        let mut tangents = Tangents::new(4);
        let firing = |t: f64, guard: usize| Firing {
            t: Time::new(t),
            mode: 0,
            guard,
            before: &x,
            mode_after: 0,
        };
        // The second wall again and again: then the first wall commutes
        // with every kept event, but not with one dropped (unknown).
        for k in 0..=KEPT {
            recent.push(&firing(k as f64, 1));
        }
        let now = firing(KEPT as f64 + 0.5, 0);
        let since = recent.since_conflict(&Particles, &mut tangents, &now, |_| true);
        assert_eq!(since, KEPT as f64 + 0.5, "the dropped event at t = 0");
        // Looking back stops where the doubt does.
        let since = recent.since_conflict(&Particles, &mut tangents, &now, |s| s < 2.0);
        assert_eq!(since, 2.5);
        // After a jump over whole periods the kept events are a period
        // behind: none may excuse a doubt, and the time that counts is
        // since the jump's end.
        let mut jumped = recent.clone();
        jumped.restart(Time::new(100.0));
        let since = jumped.since_conflict(&Particles, &mut tangents, &firing(100.25, 0), |_| true);
        assert_eq!(since, 0.25);
        // A collision conflicts with the latest kept event.
        let since = recent.since_conflict(
            &Particles,
            &mut tangents,
            &firing(KEPT as f64 + 0.5, 2),
            |_| true,
        );
        assert_eq!(since, 0.5);
    }
}
