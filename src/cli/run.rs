//! `flicker run`: validate the scene, run it with the log streamed to disk,
//! write the summary, and say what happened.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

use crate::log::JsonlWriter;
use crate::log::field_files;
use crate::log::size_notice::{FIRST_NOTICE, LogSize};
use crate::log::summary::{summary, write_atomically};
use crate::log::writer::LazyFile;
use crate::session::{
    Ask, EnsembleRequest, Limits, METHODS, PreparedRun, Registry, Report, RunRequest, Samples,
    Scene, SceneError, SolverSpec, Status, Trajectory,
};

use crate::cli::exit::{Code, Failure};
use crate::cli::progress::WithProgress;

/// `flicker run`'s arguments.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// The scene file (JSON).
    scene: PathBuf,
    // This doc comment is clap's help text, printed as written: the
    // `<scene name>` in it is a placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Simulated time to stop at, replacing the scene's t_end (a chain
    /// scene's snapshots after it are not taken).
    #[arg(long = "t-end", value_name = "T", allow_negative_numbers = true)]
    t_end: Option<f64>,
    /// Do not write the event log.
    #[arg(long = "no-events")]
    no_events: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
    /// Also draw the run's pictures into the output directory, as
    /// `flicker plot DIR` does (for a continuum release: the paper's
    /// Figs. 12-14 beside the classical string).
    #[arg(long)]
    plot: bool,
    #[command(flatten)]
    solver: SolverFlags,
    #[command(flatten)]
    ensemble: EnsembleFlags,
    /// Also carry the derivatives of the state and of every event time
    /// along these directions (comma-separated: a parameter's name, or
    /// initial.STATE), into the summary's `sensitivities` and each event's
    /// states (automata).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    sensitivities: Option<Vec<String>>,
    /// Also write the state at N evenly spaced times from 0 to t_end, each
    /// with its error bound, to samples.csv (automata, the mechanism).
    #[arg(long, value_name = "N", conflicts_with = "at")]
    samples: Option<usize>,
    /// The same at these times (comma-separated).
    #[arg(
        long,
        value_name = "LIST",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    at: Option<Vec<f64>>,
    /// Go on past the run's horizon (where its error reaches 1e-3 of its
    /// state, or its bound can no longer decide what happens) as a
    /// pseudo-orbit, instead of stopping where it cannot decide: the run
    /// completes, states its horizon and no bound, and flags every event
    /// from the horizon on `"shadow": true`.
    #[arg(long = "past-horizon")]
    past_horizon: bool,
}

/// A scene's reproducibility horizon.
#[derive(Debug, clap::Args)]
pub struct EnsembleFlags {
    /// Also run K copies with perturbed initial values (chain scenes with
    /// the exact flow, automata) and report when they part (the horizon)
    /// and how far they spread, in the summary and ensemble.csv.
    #[arg(long, value_name = "K")]
    ensemble: Option<usize>,
    /// Relative perturbation of each initial value (a chain's unit strains,
    /// an automaton's states).
    #[arg(long, value_name = "P", default_value_t = 1e-12, requires = "ensemble")]
    perturb: f64,
    /// Seed of the perturbations (the same seed gives the same ensemble).
    #[arg(long, value_name = "S", default_value_t = 0, requires = "ensemble")]
    seed: u64,
}

/// Flags that override a scene's `solver`.
#[derive(Debug, clap::Args)]
pub struct SolverFlags {
    /// Method (default: the scene's, else the cheapest exact description of
    /// the model).
    #[arg(long, value_name = "M", value_parser = clap::builder::PossibleValuesParser::new(METHODS))]
    method: Option<String>,
    /// Relative tolerance (taylor, dopri5, dop853).
    #[arg(long, value_name = "R", allow_negative_numbers = true)]
    rtol: Option<f64>,
    /// Absolute tolerance (taylor, dopri5, dop853).
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    atol: Option<f64>,
    /// Fixed step (verlet).
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    step: Option<f64>,
}

/// Run `flicker run`: validate the scene and the flags, run it with the
/// event log streamed to disk, write the summary (and a chain's fields and
/// ensemble), and print what happened. The exit code follows the run's
/// status.
pub fn run(args: RunArgs, registry: &Registry) -> Result<Code, Failure> {
    let RunArgs {
        scene: scene_path,
        out,
        t_end,
        no_events,
        quiet,
        plot,
        solver,
        ensemble,
        sensitivities,
        samples,
        at,
        past_horizon,
    } = args;
    let scene_path = scene_path.as_path();
    let log_events = !no_events;
    let request = RunRequest {
        t_end,
        solver: SolverSpec {
            method: solver.method,
            rtol: solver.rtol,
            atol: solver.atol,
            step: solver.step,
        },
        sensitivities,
        samples: match (samples, at) {
            (Some(n), _) => Some(Samples::Count(n)),
            (None, Some(at)) => Some(Samples::At(at)),
            (None, None) => None,
        },
        ensemble: ensemble.ensemble.map(|copies| EnsembleRequest {
            copies,
            perturb: ensemble.perturb,
            seed: ensemble.seed,
        }),
        past_horizon,
    };
    // Everything is checked before any file is touched: bad input loses nothing.
    let scene = registry.load(scene_path).map_err(Failure::bad_input)?;
    let run = request.prepare(scene).map_err(|refused| {
        let flag = match refused.ask {
            Ask::TEnd => "--t-end",
            Ask::Solver => {
                return Failure::bad_input(format!(
                    "--method/--rtol/--atol/--step: {}",
                    refused.error.in_path(scene_path)
                ));
            }
            Ask::Sensitivities => "--sensitivities",
            Ask::Ensemble => "--ensemble",
            Ask::Samples if samples.is_some() => "--samples",
            Ask::Samples => "--at",
        };
        Failure::bad_input(format!("{flag}: {}", refused.error.reason))
    })?;
    let scene = run.scene();
    let out = out.unwrap_or_else(|| default_out(scene_path));
    crate::cli::setup::output_folder(&out)?;
    let limits = run.limits(Some(crate::cli::setup::stop_flag()));

    let log_path = out.join("events.jsonl");
    let log = log_events.then_some(log_path.as_path());
    let (report, states) = run_logged(&run, &limits, log, quiet)
        .map_err(|e| Failure::bad_input(e.in_path(scene_path)))?;
    let mut summary = summary(&report, scene.model(), scene_path, log);
    let mut written = write_fields_and_samples(&report, states.as_ref(), &out, &mut summary)?;
    // The copies run only after a run that completed: an interrupted or
    // failed run says so by itself.
    let ensemble = if report.outcome.status == Status::Completed {
        run.ensemble(&limits)
    } else {
        None
    };
    let (horizon, ensemble_failed) = match ensemble {
        None => (None, None),
        Some(found) => {
            let path = out.join("ensemble.csv");
            let found = found.and_then(|found| {
                found
                    .write_csv(&path)
                    .map(|()| found)
                    .map_err(|e| format!("{}: cannot be written: {e}", path.display()))
            });
            match found {
                Ok(found) => {
                    written.push(path);
                    summary["ensemble"] = found.summary.clone();
                    (Some(found), None)
                }
                Err(why) => {
                    // The run itself stands; the ensemble's failure is said
                    // in its summary and in the exit code.
                    summary["ensemble"] = serde_json::json!({ "error": why });
                    (None, Some(why))
                }
            }
        }
    };
    let summary_path = out.join("summary.json");
    write_atomically(&summary_path, &summary).map_err(|e| {
        Failure::untrusted(format!(
            "{}: cannot be written: {e}",
            summary_path.display()
        ))
    })?;
    print_report(&report, scene, &summary_path, log, &written);
    if plot {
        let drawn = crate::cli::plot_run::plot_run(&out).map_err(Failure::untrusted)?;
        let names: Vec<String> = drawn.iter().map(|p| p.display().to_string()).collect();
        say!("  drew {}", names.join(", "));
    }
    if let Some(found) = horizon {
        for line in &found.said {
            say!("  {line}");
        }
    }
    if let Some(why) = ensemble_failed {
        say!("  ensemble failed: {why}");
        eprintln!("flicker: the ensemble failed: {why}");
        let interrupted = limits
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed));
        return Ok(Code::stopped(interrupted));
    }
    // A run that cannot be trusted says why on stderr too, where a caller
    // that keeps only the errors (`2>err`) looks.
    if matches!(report.outcome.status, Status::Failed | Status::Interrupted) {
        eprintln!(
            "flicker: the run {} at t = {}: {}",
            report.outcome.status.as_str(),
            report.outcome.t_reached,
            report
                .outcome
                .reason
                .as_deref()
                .unwrap_or("no reason given")
        );
    }
    Ok(Code::of(report.outcome.status))
}

/// Run `run` under `limits` with its progress drawn (unless `quiet`) and
/// its events streamed to `log` where given: the report (failed where the
/// log could not be written) and the samples taken.
fn run_logged(
    run: &PreparedRun,
    limits: &Limits,
    log: Option<&Path>,
    quiet: bool,
) -> Result<(Report, Option<Trajectory>), SceneError> {
    let t_end = run.scene().t_end();
    let Some(log_path) = log else {
        let mut observer = WithProgress::new((), t_end, quiet);
        let ran = run.run(limits, &mut observer);
        observer.finish();
        return ran;
    };
    // Created with the first event or at the end: a run the scene refuses
    // as it starts leaves no log, and an earlier one untouched.
    let file = LogSize::new(LazyFile::new(log_path), FIRST_NOTICE, |s| {
        eprintln!("flicker: {s}")
    });
    let mut observer = WithProgress::new(JsonlWriter::new(file), t_end, quiet);
    let ran = run.run(limits, &mut observer);
    observer.finish();
    let (mut report, sampled) = ran?;
    // A log that could not be written spoils the run, but its summary
    // still says how far it got and why it stopped.
    if let Err(e) = observer.inner.flush()
        && report.outcome.status != Status::Failed
    {
        report.outcome.status = Status::Failed;
        report.outcome.reason = Some(format!(
            "could not write the event log {}: {e}",
            log_path.display()
        ));
    }
    if report.outcome.status == Status::Failed {
        // A write that failed half way (a full disk) may have left part of
        // a line: cut the log back to its last whole line.
        let _ = crate::log::writer::cut_to_last_line(log_path);
    }
    Ok((report, sampled))
}

/// Write a chain's or continuum's fields and the samples, where the run
/// has them, into `out`, and say the samples in `summary`: the files
/// written.
fn write_fields_and_samples(
    report: &Report,
    states: Option<&Trajectory>,
    out: &Path,
    summary: &mut serde_json::Value,
) -> Result<Vec<PathBuf>, Failure> {
    let mut written = Vec::new();
    if let Some(chain) = &report.fields {
        let profiles = out.join("profiles.json");
        let trace = out.join("trace.csv");
        write_atomically(&profiles, &field_files::profiles(chain))
            .and_then(|()| field_files::write_trace(chain, &trace))
            .map_err(|e| {
                Failure::untrusted(format!("{}: cannot be written: {e}", out.display()))
            })?;
        written.extend([profiles, trace]);
    }
    if let Some(trajectory) = states {
        let path = out.join("samples.csv");
        let Trajectory {
            names,
            samples,
            bounds,
            ..
        } = trajectory;
        crate::log::samples::write_csv(&path, names, samples, bounds).map_err(|e| {
            Failure::untrusted(format!("{}: cannot be written: {e}", path.display()))
        })?;
        summary["samples"] = serde_json::json!({
            "file": path.display().to_string(),
            "count": samples.len(),
            "largest_bound": bounds.iter().copied().fold(0.0, f64::max),
        });
        written.push(path);
    }
    Ok(written)
}

fn default_out(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "run".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

fn print_report(
    report: &Report,
    scene: &Scene,
    summary: &Path,
    log: Option<&Path>,
    written: &[PathBuf],
) {
    let o = &report.outcome;
    say!(
        "{} {} at t = {} of {}",
        scene.model(),
        o.status.as_str(),
        o.t_reached,
        o.t_end
    );
    say!("  method: {} ({})", report.method, report.description);
    if let Some(reason) = &o.reason {
        say!("  reason: {reason}");
    }
    let by_guard: Vec<String> = o
        .events_by_guard
        .iter()
        .map(|(g, n)| format!("{g}: {n}"))
        .collect();
    if by_guard.is_empty() {
        say!("  events: none");
    } else {
        say!("  events: {} ({})", o.events, by_guard.join(", "));
    }
    if let Some(f) = &o.fast_forward {
        say!(
            "  fast-forwarded: {} periods of {:e} between t = {:e} and {:e}, {} each, counted, \
             not fired (the orbit returned to its state to round-off; a run that writes its event log fires each)",
            f.periods,
            f.period,
            f.from,
            f.to,
            match f.events_per_period {
                1 => "one event".to_string(),
                k => format!("{k} events"),
            }
        );
    }
    if let (Some(e0), Some(e1), Some(err)) = (o.energy_initial, o.energy_final, o.max_energy_error)
    {
        say!("  energy: initial {e0:e}, final {e1:e}, largest relative error {err:.2e}");
    }
    let state: Vec<String> = report
        .final_state
        .iter()
        .map(|(n, x)| format!("{n} = {x:e}"))
        .collect();
    say!("  final state: {}", state.join(", "));
    match (o.error_bound, &o.error_estimate, o.event_time_bound) {
        (Some(bound), _, Some(times)) => {
            say!("  error bound: {bound:.2e} on every state component, {times:.2e} on event times")
        }
        (Some(bound), _, None) => say!("  error bound: {bound:.2e} on every state component"),
        (None, Some(estimate), _) => say!(
            "  no error bound: an estimate of {:.2e}, {}",
            estimate.value,
            estimate.made_by
        ),
        (None, None, _) => {}
    }
    match o.horizon {
        Some(h) if o.shadow_events > 0 || o.error_bound.is_none() && o.error_estimate.is_none() => {
            say!(
                "  past its horizon at t = {h}: a pseudo-orbit from there, {} events flagged shadow, no bound",
                o.shadow_events
            )
        }
        Some(h) => say!(
            "  horizon: t = {h} (its error reached 1e-3 of the state, or its bound could no longer decide)"
        ),
        None => {}
    }
    if let Some(err) = report
        .fields
        .as_ref()
        .and_then(|c| c.momentum_balance_error)
    {
        say!("  momentum against the end load's and the wall's impulses: relative error {err:.2e}");
    }
    let files: Vec<String> = std::iter::once(summary)
        .chain(log)
        .chain(written.iter().map(PathBuf::as_path))
        .map(|p| p.display().to_string())
        .collect();
    say!("  wrote {}", files.join(", "));
}
