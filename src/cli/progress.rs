//! A progress bar on stderr for long runs: simulated time reached, events
//! and events per second. Drawn only when stderr is a terminal and the user
//! did not ask for `--quiet`.

use std::io::IsTerminal;
use std::time::Instant;

use crate::session::{EventRecord, Observer};
use indicatif::{ProgressBar, ProgressStyle};

/// Steps of the bar over `[0, t_end]`.
const STEPS: u64 = 1000;

/// Passes events on to `inner` and shows progress.
pub struct WithProgress<O> {
    /// The observer the events are passed on to.
    pub inner: O,
    bar: Option<ProgressBar>,
    t_end: f64,
    started: Instant,
}

impl<O> WithProgress<O> {
    /// Wrap `inner`, with a bar over `[0, t_end]` drawn only if stderr is a
    /// terminal and not `quiet`.
    pub fn new(inner: O, t_end: f64, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(STEPS);
            bar.set_style(
                ProgressStyle::with_template("{bar:40} t = {msg} ({elapsed})")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            bar
        });
        WithProgress {
            inner,
            bar,
            t_end,
            started: Instant::now(),
        }
    }

    /// A handle that removes the bar from elsewhere (once what it measures
    /// is over, before other lines are printed).
    pub fn clearer(&self) -> impl Fn() + use<O> {
        let bar = self.bar.clone();
        move || {
            if let Some(bar) = &bar {
                bar.finish_and_clear();
            }
        }
    }

    /// Remove the bar, leaving the terminal clean for the report.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl<O: Observer> Observer for WithProgress<O> {
    fn on_event(&mut self, event: &EventRecord) -> std::io::Result<()> {
        self.inner.on_event(event)
    }

    fn wants_details(&self) -> bool {
        self.inner.wants_details()
    }

    fn on_progress(&mut self, t: f64, events: u64) {
        if let Some(bar) = &self.bar {
            let rate = events as f64 / self.started.elapsed().as_secs_f64().max(1e-9);
            bar.set_position((t / self.t_end * STEPS as f64) as u64);
            bar.set_message(format!(
                "{t:.6e} of {:e}, {events} events, {rate:.3e} events/s",
                self.t_end
            ));
        }
    }
}

/// A progress bar over the points of a sweep or a diagram, drawn only on
/// a terminal.
pub struct Points(Option<indicatif::ProgressBar>);

impl Points {
    /// A bar over `total` points; none if `quiet` or not on a terminal.
    pub fn new(total: usize, quiet: bool) -> Self {
        use std::io::IsTerminal;
        Points((!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = indicatif::ProgressBar::new(total as u64);
            bar.set_style(
                indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} points ({elapsed})")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            bar
        }))
    }

    /// One point more done.
    pub fn tick(&self) {
        if let Some(bar) = &self.0 {
            bar.inc(1);
        }
    }

    /// Clear the bar.
    pub fn finish(&self) {
        if let Some(bar) = &self.0 {
            bar.finish_and_clear();
        }
    }
}
