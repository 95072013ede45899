//! `flicker run`: validate the scene, run it with the log streamed to disk,
//! write the summary, and say what happened.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use flicker::engine::Status;
use flicker::log::JsonlWriter;
use flicker::log::summary::{summary, write_atomically};
use flicker::runner::{Control, Report, run as run_scene};
use flicker::scene::solver::SolverSpec;
use flicker::scene::{self, Scene};

use crate::cli::exit::{Code, Failure};

pub fn run(
    scene_path: &Path,
    out: Option<PathBuf>,
    t_end: Option<f64>,
    solver: SolverSpec,
    log_events: bool,
) -> Result<Code, Failure> {
    // Everything is checked before any file is touched: bad input loses nothing.
    let mut scene = scene::load(scene_path).map_err(Failure::bad_input)?;
    if let Some(t) = t_end {
        scene
            .set_t_end(t)
            .map_err(|e| Failure::bad_input(format!("--t-end: {}", e.reason)))?;
    }
    if solver != SolverSpec::default() {
        scene.override_solver(&solver).map_err(|e| {
            Failure::bad_input(format!(
                "--method/--rtol/--atol/--step: {}",
                e.in_path(scene_path)
            ))
        })?;
    }
    let out = out.unwrap_or_else(|| default_out(scene_path));
    std::fs::create_dir_all(&out).map_err(|e| {
        Failure::bad_input(format!(
            "{}: cannot create the output directory: {e}",
            out.display()
        ))
    })?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    // A second handler cannot be installed in the same process; a run
    // without one still works, it just cannot be interrupted cleanly.
    let _ = ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed));
    let control = Control {
        stop: Some(stop),
        max_wall_seconds: None,
    };

    let log_path = out.join("events.jsonl");
    let report = if log_events {
        let file = File::create(&log_path).map_err(|e| {
            Failure::bad_input(format!("{}: cannot be created: {e}", log_path.display()))
        })?;
        let mut writer = JsonlWriter::new(BufWriter::new(file));
        let report = run_scene(&scene, &control, &mut writer)
            .map_err(|e| Failure::bad_input(e.in_path(scene_path)))?;
        writer.flush().map_err(|e| {
            Failure::untrusted(format!(
                "{}: the event log could not be written: {e}",
                log_path.display()
            ))
        })?;
        report
    } else {
        run_scene(&scene, &control, &mut ())
            .map_err(|e| Failure::bad_input(e.in_path(scene_path)))?
    };

    let log = log_events.then_some(log_path.as_path());
    let summary_path = out.join("summary.json");
    write_atomically(
        &summary_path,
        &summary(&report, model_name(&scene), scene_path, log),
    )
    .map_err(|e| {
        Failure::untrusted(format!(
            "{}: cannot be written: {e}",
            summary_path.display()
        ))
    })?;
    print_report(&report, &scene, &summary_path, log);
    Ok(match report.outcome.status {
        Status::Completed | Status::Zeno => Code::Ok,
        Status::Failed => Code::Untrusted,
        Status::Interrupted => Code::Interrupted,
    })
}

fn default_out(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map_or_else(|| "run".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

fn model_name(scene: &Scene) -> &'static str {
    match scene {
        Scene::Mechanism(_) => "mechanism",
    }
}

fn print_report(report: &Report, scene: &Scene, summary: &Path, log: Option<&Path>) {
    let o = &report.outcome;
    println!(
        "{} {} at t = {} of {}",
        model_name(scene),
        o.status.as_str(),
        o.t_reached,
        o.t_end
    );
    println!("  method: {} ({})", report.method, report.description);
    if let Some(reason) = &o.reason {
        println!("  reason: {reason}");
    }
    let by_guard: Vec<String> = o
        .events_by_guard
        .iter()
        .map(|(g, n)| format!("{g}: {n}"))
        .collect();
    if by_guard.is_empty() {
        println!("  events: none");
    } else {
        println!("  events: {} ({})", o.events, by_guard.join(", "));
    }
    if let (Some(e0), Some(e1), Some(err)) = (o.energy_initial, o.energy_final, o.max_energy_error)
    {
        println!("  energy: initial {e0:e}, final {e1:e}, largest relative error {err:.2e}");
    }
    let state: Vec<String> = report
        .final_state
        .iter()
        .map(|(n, x)| format!("{n} = {x:e}"))
        .collect();
    println!("  final state: {}", state.join(", "));
    println!(
        "  wrote {}{}",
        summary.display(),
        log.map_or(String::new(), |l| format!(" and {}", l.display()))
    );
}
