//! Command-line arguments and their dispatch to subcommands.

pub mod events;
pub mod exit;
pub mod run;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use crate::cli::exit::{Code, Failure};

#[derive(Debug, Parser)]
#[command(
    name = "flicker",
    version,
    about = "An event-driven engine for hybrid systems"
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Run a scene and write DIR/summary.json and DIR/events.jsonl.
    Run {
        /// The scene file (JSON).
        scene: PathBuf,
        /// Output directory (default: out/<scene name>).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Simulated time to stop at, replacing the scene's t_end.
        #[arg(long = "t-end", value_name = "T", allow_negative_numbers = true)]
        t_end: Option<f64>,
        /// Do not write the event log.
        #[arg(long = "no-events")]
        no_events: bool,
    },
    /// Filter or summarise an event log.
    Events {
        /// The log (events.jsonl).
        log: PathBuf,
        /// Keep only events of this guard.
        #[arg(long, value_name = "NAME")]
        guard: Option<String>,
        /// Keep only events at t >= T.
        #[arg(long, value_name = "T", allow_negative_numbers = true)]
        from: Option<f64>,
        /// Keep only events at t <= T.
        #[arg(long, value_name = "T", allow_negative_numbers = true)]
        to: Option<f64>,
        /// Print a summary (JSON) instead of the events.
        #[arg(long)]
        summary: bool,
    },
}

pub fn dispatch(cli: Cli) -> Result<Code, Failure> {
    match cli.command {
        Command::Run {
            scene,
            out,
            t_end,
            no_events,
        } => run::run(&scene, out, t_end, !no_events),
        Command::Events {
            log,
            guard,
            from,
            to,
            summary,
        } => events::events(&log, events::Filter { guard, from, to }, summary),
    }
}
