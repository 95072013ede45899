//! The `flicker` command line: arguments and their dispatch to
//! subcommands, over the scene models of a [`Registry`].
//!
//! Exit codes, decided in one place ([`exit`]): 0 completed (or a Zeno
//! accumulation recognised and handled), 2 bad input, 3 the run cannot be
//! trusted (a method failed), 130 interrupted.

/// `println!` that ignores a closed stdout (`flicker ... | head`): what the
/// reader chose not to read is no error, and must not panic.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}

/// `print!` likewise.
macro_rules! say_raw {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = write!(std::io::stdout(), $($arg)*);
    }};
}

pub mod advise;
pub mod basins;
pub mod check;
pub mod compare;
pub mod compare_models;
pub mod continuation;
pub mod diagram;
pub mod events;
pub mod exit;
pub mod lyapunov;
pub mod orbit;
pub mod plot;
pub mod plot_run;
pub mod progress;
pub mod run;
pub mod setup;
pub mod stress;
pub mod sweep;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use crate::session::Registry;

use crate::cli::exit::{Code, Failure};

/// The command line as clap parses it: one subcommand and its arguments.
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
    Run(run::RunArgs),
    /// Run a scene with every method over a range of tolerances or steps and
    /// measure each against the exact answer: DIR/compare.csv, compare.svg, compare.png.
    Compare {
        /// The scene file (JSON).
        scene: PathBuf,
        /// Methods, comma-separated (default: every method the model offers).
        #[arg(long, value_delimiter = ',', value_name = "M,M,..")]
        methods: Option<Vec<String>>,
        /// Dormand-Prince tolerances (rtol = atol), comma-separated.
        #[arg(long, value_delimiter = ',', value_name = "TOL,..")]
        tolerances: Option<Vec<f64>>,
        /// Stormer-Verlet steps, comma-separated (default: fractions of the period).
        #[arg(long, value_delimiter = ',', value_name = "H,..")]
        steps: Option<Vec<f64>>,
        /// Output directory (default: out/<scene name>-compare).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Stop, saying so, after this many seconds of wall time.
        #[arg(
            long,
            value_name = "SECONDS",
            default_value_t = 3600.0,
            allow_negative_numbers = true
        )]
        wall: f64,
    },
    /// Run a release scene as the chain at several N and as the continuum,
    /// and measure each against the densest chain: DIR/compare_models.csv,
    /// coarse.csv, compare_models.json and pictures.
    CompareModels(compare_models::CompareModelsArgs),
    /// Say whether a chain scene needs its chain, or a continuum
    /// reproduces it within a tolerance, and at what cost (measured).
    Advise(advise::AdviseArgs),
    /// Run every stress scene in DIR with every method: each verified
    /// against the exact answer or failed with a reason (exit 3 if any is
    /// silently wrong).
    Stress {
        /// The folder of stress scenes.
        #[arg(default_value = "models/stress")]
        dir: PathBuf,
        /// Wall-time budget per run, in seconds.
        #[arg(long, default_value_t = 10.0, value_name = "SECONDS")]
        wall: f64,
        /// Print the table of outcomes as Markdown.
        #[arg(long)]
        markdown: bool,
    },
    /// Run a grid of scenes in parallel: one CSV row per point.
    Sweep {
        /// The sweep file (JSON).
        sweep: PathBuf,
        /// Run only the points I, I+N, I+2N, ... (0 <= I < N), for batch jobs.
        #[arg(long, value_name = "I/N")]
        shard: Option<String>,
        /// Threads (default: one per core).
        #[arg(long, value_name = "T")]
        threads: Option<usize>,
        /// Output CSV (default: out/<sweep name>.csv, or .shard-I-of-N.csv).
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
        /// Stop after this many seconds of wall time: the points not done
        /// are written as not begun.
        #[arg(
            long,
            value_name = "SECONDS",
            default_value_t = 3600.0,
            allow_negative_numbers = true
        )]
        wall: f64,
        /// Do not draw progress.
        #[arg(long)]
        quiet: bool,
    },
    /// Join the shard CSVs of a sweep into the CSV a single run writes.
    Merge {
        /// The sweep file (JSON) the shards ran.
        sweep: PathBuf,
        /// The shard CSVs.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// The merged CSV.
        #[arg(long, value_name = "FILE")]
        out: PathBuf,
    },
    /// Draw pictures.
    #[command(args_conflicts_with_subcommands = true)]
    Plot {
        #[command(subcommand)]
        what: Option<plot::PlotCommand>,
        /// A run's output directory: draws energy.svg and intervals.svg
        /// from events.jsonl, compare.svg from compare.csv.
        dir: Option<PathBuf>,
    },
    /// Validate a scene without running it, and say what it describes.
    Check {
        /// The scene file (JSON).
        scene: PathBuf,
    },
    /// Find a periodic orbit through a Poincare section (Newton shooting)
    /// and its stability; writes DIR/orbit.json.
    Orbit(orbit::OrbitArgs),
    /// A brute-force bifurcation diagram: at each value of a parameter, the
    /// state after each of K section events past a transient; writes
    /// DIR/diagram.csv, diagram.json and diagram.svg.
    Diagram(diagram::DiagramArgs),
    /// Basins of attraction: a grid of two states' starting values, each
    /// named by the attractor it reaches; writes DIR/basins.csv,
    /// attractors.json and basins.svg.
    Basins(basins::BasinsArgs),
    /// Follow a periodic orbit in a parameter (pseudo-arclength), label its
    /// bifurcations; writes DIR/continuation.csv and DIR/bifurcation.svg.
    Continue(continuation::ContinueArgs),
    /// The Lyapunov spectrum through the events (Benettin's method with
    /// saltation matrices); writes DIR/lyapunov.json and its convergence.
    Lyapunov(lyapunov::LyapunovArgs),
    /// Print the JSON Schema of scene files, for every model this program
    /// knows (schemas/scene.schema.json is its output for the built-in ones).
    Schema,
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
        #[arg(long, conflicts_with = "csv")]
        summary: bool,
        /// Print the events as CSV (seq, t, guard, modes, energies, labels,
        /// and each state before and after).
        #[arg(long)]
        csv: bool,
    },
}

/// Parse the process's arguments and run the command they name, for the
/// scene models `registry` knows: what the `flicker` binary does (with
/// [`Registry::builtin`]), and what a program with models of its own does
/// with a registry that knows them. Returns the exit code (see
/// [`exit::Code`]).
pub fn main(registry: Registry) -> i32 {
    let code = match dispatch(Cli::parse(), &registry) {
        Ok(code) => code,
        Err(error) => {
            eprintln!("flicker: {}", error.message);
            error.code
        }
    };
    code as i32
}

/// Run one parsed command line.
pub fn dispatch(cli: Cli, registry: &Registry) -> Result<Code, Failure> {
    match cli.command {
        Command::Run(args) => run::run(args, registry),
        Command::Compare {
            scene,
            methods,
            tolerances,
            steps,
            out,
            wall,
        } => compare::compare(registry, &scene, methods, tolerances, steps, out, wall),
        Command::CompareModels(args) => compare_models::compare_models(args, registry),
        Command::Orbit(args) => orbit::orbit(args, registry),
        Command::Continue(args) => continuation::continue_orbit(args, registry),
        Command::Diagram(args) => diagram::diagram(args, registry),
        Command::Basins(args) => basins::basins(args, registry),
        Command::Lyapunov(args) => lyapunov::lyapunov(args, registry),
        Command::Advise(args) => advise::advise(args, registry),
        Command::Stress {
            dir,
            wall,
            markdown,
        } => stress::stress(registry, &dir, wall, markdown),
        Command::Sweep {
            sweep: file,
            shard,
            threads,
            out,
            wall,
            quiet,
        } => sweep::sweep(registry, &file, shard, threads, out, (wall, quiet)),
        Command::Merge {
            sweep: file,
            shards,
            out,
        } => sweep::merge(registry, &file, &shards, &out),
        Command::Check { scene } => check::check(registry, &scene),
        Command::Schema => {
            let schema = registry.schema().map_err(Failure::bad_input)?;
            let text = serde_json::to_string_pretty(&schema).map_err(Failure::bad_input)?;
            say!("{text}");
            Ok(Code::Ok)
        }
        Command::Plot {
            what: Some(what), ..
        } => plot::plot(what, registry),
        Command::Plot {
            what: None,
            dir: Some(dir),
        } => plot::plot_dir(&dir),
        Command::Plot {
            what: None,
            dir: None,
        } => Err(Failure::bad_input(
            "plot: give a run's directory, or `plot phase ...`",
        )),
        Command::Events {
            log,
            guard,
            from,
            to,
            summary,
            csv,
        } => {
            let format = match (summary, csv) {
                (true, _) => events::Format::Summary,
                (_, true) => events::Format::Csv,
                _ => events::Format::Lines,
            };
            events::events(&log, events::Filter { guard, from, to }, format)
        }
    }
}
