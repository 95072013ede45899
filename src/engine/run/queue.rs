//! The queue of predicted events: one slot per guard, earliest first.
//!
//! Priorities are `(time, slot)` so that events at the same `f64` time pop in
//! slot order and the log is the same on every run; they are packed into
//! one integer (the time's bits made to sort as the time, then the slot),
//! which the heap compares in an instruction or two. Times are checked with
//! `NotNan` when they are scheduled: a NaN time would otherwise sort last and
//! silently never fire. The exact double-double time of each prediction is
//! kept beside the queue, so firing an event moves the clock without
//! rounding.

use std::cmp::Reverse;

use ordered_float::NotNan;
use priority_queue::PriorityQueue;
use rustc_hash::FxBuildHasher;

use crate::time::{Span, Time};

type Priority = Reverse<u128>;

/// Predicted events, one slot per guard, popped earliest first (ties in
/// slot order), each with its exact time.
#[derive(Default)]
pub struct EventQueue {
    /// Slots are small integers: a fast non-cryptographic hash will do.
    queue: PriorityQueue<usize, Priority, FxBuildHasher>,
    exact: Vec<Time>,
    /// Whether each slot is in the queue: most cancellations are of slots
    /// that are not (a chain re-predicts every unit each window), and this
    /// answers them without hashing.
    queued: Vec<bool>,
}

impl EventQueue {
    /// Schedule `slot` at `time`, replacing its previous prediction.
    /// Returns `false` (and schedules nothing) if the time is NaN.
    pub fn schedule(&mut self, slot: usize, time: Time) -> bool {
        let Ok(t) = NotNan::new(time.value()) else {
            return false;
        };
        let key = (u128::from(order_bits(*t)) << 64) | slot as u128;
        if self.exact.len() <= slot {
            self.exact.resize(slot + 1, Time::default());
            self.queued.resize(slot + 1, false);
        }
        self.exact[slot] = time;
        self.queued[slot] = true;
        self.queue.push(slot, Reverse(key));
        true
    }

    /// Forget the prediction for `slot`, if any.
    #[inline]
    pub fn cancel(&mut self, slot: usize) {
        if let Some(queued) = self.queued.get_mut(slot).filter(|q| **q) {
            *queued = false;
            self.queue.remove(&slot);
        }
    }

    /// The earliest slot and its exact time, without removing it.
    #[inline]
    pub fn peek(&self) -> Option<(usize, Time)> {
        self.queue
            .peek()
            .map(|(slot, _)| (*slot, self.exact[*slot]))
    }

    /// Remove and return the earliest slot and its exact time.
    #[inline]
    pub fn pop(&mut self) -> Option<(usize, Time)> {
        let (slot, _) = self.queue.pop()?;
        self.queued[slot] = false;
        Some((slot, self.exact[slot]))
    }

    /// The slots predicted at or before `time`, into `out`.
    pub fn due_by(&self, time: Time, out: &mut Vec<usize>) {
        out.clear();
        out.extend(
            self.queue
                .iter()
                .map(|(slot, _)| *slot)
                .filter(|&slot| self.exact[slot] <= time),
        );
    }

    /// Move every prediction `k tau` later (a run that jumps over `k`
    /// periods of `tau`); the order is unchanged.
    pub fn postpone(&mut self, k: u64, tau: Span) {
        let slots: Vec<usize> = self.queue.iter().map(|(slot, _)| *slot).collect();
        for slot in slots {
            self.schedule(slot, self.exact[slot].after_multiple(k, tau));
        }
    }

    /// Forget every prediction.
    pub fn clear(&mut self) {
        self.queue.clear();
        self.queued.fill(false);
    }
}

/// The bits of `t` as an integer that sorts as `t` does (negative times
/// below positive ones, `-0.0` with `0.0`).
fn order_bits(t: f64) -> u64 {
    let bits = (t + 0.0).to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_time_order_then_slot_order() {
        let mut q = EventQueue::default();
        q.schedule(3, Time::new(2.0));
        q.schedule(1, Time::new(1.0));
        q.schedule(0, Time::new(2.0));
        q.schedule(1, Time::new(3.0)); // replaces the 1.0 prediction
        let order: Vec<usize> = std::iter::from_fn(|| q.pop().map(|(s, _)| s)).collect();
        assert_eq!(order, vec![0, 3, 1]);
    }

    #[test]
    fn postponing_moves_every_prediction_by_the_same_multiple() {
        let mut q = EventQueue::default();
        q.schedule(0, Time::new(2.0));
        q.schedule(4, Time::new(1.5));
        q.postpone(1000, Span::from(0.25));
        assert_eq!(q.pop(), Some((4, Time::new(251.5))));
        assert_eq!(q.pop(), Some((0, Time::new(252.0))));
        assert!(q.pop().is_none());
    }

    #[test]
    fn cancelled_and_popped_slots_can_be_scheduled_again() {
        let mut q = EventQueue::default();
        q.schedule(2, Time::new(1.0));
        q.cancel(2);
        q.cancel(5); // never scheduled
        assert!(q.peek().is_none());
        q.schedule(2, Time::new(4.0));
        q.schedule(1, Time::new(3.0));
        assert_eq!(q.pop().map(|(s, _)| s), Some(1));
        q.cancel(1); // already popped
        q.schedule(1, Time::new(5.0));
        let order: Vec<usize> = std::iter::from_fn(|| q.pop().map(|(s, _)| s)).collect();
        assert_eq!(order, vec![2, 1]);
    }

    #[test]
    fn the_order_key_sorts_as_the_times() {
        let times = [
            -3.5,
            -1e-300,
            -0.0,
            0.0,
            1e-300,
            0.25,
            1.0,
            7e10,
            f64::INFINITY,
        ];
        for pair in times.windows(2) {
            let (a, b) = (order_bits(pair[0]), order_bits(pair[1]));
            if pair[0] == pair[1] {
                assert_eq!(a, b, "{pair:?}");
            } else {
                assert!(a < b, "{pair:?}");
            }
        }
        // Negative and positive times interleave in time order in the queue.
        let mut q = EventQueue::default();
        for (slot, &t) in [2.0, -1.0, 0.5, -0.0].iter().enumerate() {
            q.schedule(slot, Time::new(t));
        }
        let order: Vec<usize> = std::iter::from_fn(|| q.pop().map(|(s, _)| s)).collect();
        assert_eq!(order, vec![1, 3, 2, 0]);
    }

    #[test]
    fn refuses_nan_times() {
        let mut q = EventQueue::default();
        assert!(!q.schedule(0, Time::new(f64::NAN)));
        assert!(q.pop().is_none());
    }
}
