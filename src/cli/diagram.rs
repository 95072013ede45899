//! `flicker diagram`: a brute-force bifurcation diagram of a scene in one
//! of its parameters; writes `DIR/diagram.csv` (a row per section event
//! recorded: `param`, `t`, each state), `DIR/diagram.json` (the
//! settings and every value that ended short, and why) and the picture
//! `DIR/diagram.svg` and `.png`.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cli::exit::{Code, Failure};
use crate::cli::progress::Points;
use crate::log::summary::write_atomically;
use crate::plot::draw::{Curve, Figure, Style};
use crate::session::{Diagram, DiagramRequest, Registry, Status};

/// `flicker diagram`'s arguments.
#[derive(Debug, clap::Args)]
pub struct DiagramArgs {
    /// The scene file (any model with a finite state).
    scene: PathBuf,
    /// The parameter varied.
    #[arg(long, value_name = "NAME")]
    param: String,
    /// Its first value.
    #[arg(long, value_name = "A", allow_negative_numbers = true)]
    from: f64,
    /// Its last value.
    #[arg(long, value_name = "B", allow_negative_numbers = true)]
    to: f64,
    /// How many values, evenly spaced from A to B.
    #[arg(long, value_name = "N", default_value_t = 100)]
    points: usize,
    /// The guard whose events are recorded (an impact).
    #[arg(long, value_name = "GUARD")]
    section: String,
    /// Time run at each value before recording (default: the scene's t_end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    transient: Option<f64>,
    /// Section events recorded at each value.
    #[arg(long, value_name = "K", default_value_t = 50)]
    record: usize,
    /// The longest a value runs after its transient (default: the scene's t_end).
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    span: Option<f64>,
    /// Start each value from the state the one before ended in, the clock
    /// continuing: an attractor is followed, and a sweep up and a sweep
    /// down (swap --from and --to) show hysteresis.
    #[arg(long)]
    follow: bool,
    /// Go on past each run's horizon as a pseudo-orbit (chaotic windows).
    #[arg(long = "past-horizon")]
    past_horizon: bool,
    /// The state drawn against the parameter (default: the first).
    #[arg(long, value_name = "NAME")]
    state: Option<String>,
    /// Run only the values I, I+N, I+2N, ... (0 <= I < N), for batch jobs.
    #[arg(long, value_name = "I/N", conflicts_with = "follow")]
    shard: Option<String>,
    /// Stop, saying so, after this many seconds of wall time.
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
    // This doc comment is clap's help text, printed as written: the
    // `<scene name>` in it is a placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-diagram).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Run `flicker diagram`: check the request, run every value (in parallel
/// unless following), write the CSV, the summary and the picture, and say
/// which values ended short. A value that ends at a Zeno point or fails
/// is named and the diagram goes on; one stopped by Ctrl-C or `--wall`
/// makes the exit code say so.
pub fn diagram(args: DiagramArgs, registry: &Registry) -> Result<Code, Failure> {
    let scene = registry.load(&args.scene).map_err(Failure::bad_input)?;
    let asked = DiagramRequest {
        parameter: args.param.clone(),
        from: args.from,
        to: args.to,
        points: args.points,
        section: args.section.clone(),
        transient: args.transient,
        record: args.record,
        span: args.span,
        follow: args.follow,
        past_horizon: args.past_horizon,
        shard: args.shard.clone(),
        wall: args.wall,
    };
    let prepared = asked
        .on(&scene)
        .map_err(|e| Failure::refused(&args.scene, e))?;
    let names = prepared.names();
    let drawn = args
        .state
        .clone()
        .unwrap_or_else(|| names.first().cloned().unwrap_or_default());
    let Some(column) = names.iter().position(|n| *n == drawn) else {
        return Err(Failure::bad_input(format!(
            "--state: no state is called `{drawn}` (states: {})",
            names.join(", ")
        )));
    };
    let out = crate::cli::setup::out_dir(args.out.clone(), &args.scene, "diagram");
    crate::cli::setup::output_folder(&out)?;
    let stop = crate::cli::setup::stop_flag();
    let started = Instant::now();
    let bar = Points::new(prepared.points(), args.quiet);
    let found = prepared.run(Some(stop.clone()), &|| bar.tick());
    bar.finish();
    let diagram = found.map_err(|why| Failure::bad_input(format!("--param: {why}")))?;
    let seconds = started.elapsed().as_secs_f64();
    let untrusted = |path: &Path, e: String| Failure::untrusted(format!("{}: {e}", path.display()));
    let csv = out.join("diagram.csv");
    write_csv(&diagram, &csv).map_err(|e| untrusted(&csv, e.to_string()))?;
    let summary_path = out.join("diagram.json");
    let summary = summary(&args, &diagram, prepared.request(), seconds);
    write_atomically(&summary_path, &summary)
        .map_err(|e| untrusted(&summary_path, e.to_string()))?;
    let mut written = vec![csv, summary_path];
    let figure = picture(&diagram, &args.param, &drawn, column, &args.section);
    written.extend(crate::cli::setup::draw_both(&figure, &out, "diagram")?);
    let short: Vec<_> = diagram
        .points
        .iter()
        .filter(|p| p.status != Status::Completed)
        .collect();
    say!(
        "{} values of `{}` from {} to {} in {seconds:.3} s, {} section events recorded ({} ended short)",
        diagram.points.len(),
        args.param,
        args.from,
        args.to,
        diagram
            .points
            .iter()
            .map(|p| p.records.len())
            .sum::<usize>(),
        short.len()
    );
    for p in short.iter().take(10) {
        say!(
            "  {} = {}: {} ({})",
            args.param,
            p.parameter,
            p.status.as_str(),
            p.reason.as_deref().unwrap_or("no reason given")
        );
    }
    if short.len() > 10 {
        say!("  ... and {} more: see diagram.json", short.len() - 10);
    }
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("  wrote {}", names.join(", "));
    let interrupted = stop.load(std::sync::atomic::Ordering::Relaxed);
    if let Some(p) = short.iter().find(|p| p.status == Status::Interrupted) {
        eprintln!(
            "flicker: the diagram stopped short ({}); the values not run say so",
            p.reason.as_deref().unwrap_or("interrupted")
        );
        return Ok(Code::stopped(interrupted));
    }
    Ok(Code::Ok)
}

/// A row per section event: the parameter's value (`param`), the time,
/// each state.
fn write_csv(diagram: &Diagram, path: &Path) -> std::io::Result<()> {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(file, "param,t,{}", diagram.names.join(","))?;
    for point in &diagram.points {
        for (t, state) in &point.records {
            let state: Vec<String> = state.iter().map(|x| format!("{x:e}")).collect();
            writeln!(file, "{:e},{t:e},{}", point.parameter, state.join(","))?;
        }
    }
    file.flush()
}

/// What `diagram.json` says: the settings, how the values ended, and each
/// one that ended short with its reason.
fn summary(
    args: &DiagramArgs,
    diagram: &Diagram,
    request: &crate::session::DiagramSettings,
    seconds: f64,
) -> serde_json::Value {
    let count = |status: Status| diagram.points.iter().filter(|p| p.status == status).count();
    let short: Vec<serde_json::Value> = diagram
        .points
        .iter()
        .filter(|p| p.status != Status::Completed)
        .map(|p| {
            serde_json::json!({
                "param": p.parameter,
                "status": p.status.as_str(),
                "reason": p.reason,
                "records": p.records.len(),
            })
        })
        .collect();
    serde_json::json!({
        "scene": args.scene.display().to_string(),
        "param": args.param,
        "from": args.from,
        "to": args.to,
        "points": diagram.points.len(),
        "section": args.section,
        "transient": request.transient,
        "record": request.record,
        "span": request.span,
        "follow": args.follow,
        "past_horizon": args.past_horizon,
        "states": diagram.names,
        "completed": count(Status::Completed),
        "zeno": count(Status::Zeno),
        "failed": count(Status::Failed),
        "interrupted": count(Status::Interrupted),
        "ended_short": short,
        "wall_seconds": seconds,
    })
}

/// The state `name` (column `i`) at each record against the parameter, as
/// small dots.
fn picture(diagram: &Diagram, param: &str, name: &str, i: usize, section: &str) -> Figure {
    let points = diagram
        .points
        .iter()
        .flat_map(|p| p.records.iter().map(move |(_, x)| (p.parameter, x[i])))
        .collect();
    Figure {
        title: format!("{name} just after each `{section}` event, against {param}"),
        x_label: param.to_string(),
        y_label: name.to_string(),
        curves: vec![Curve {
            label: None,
            points,
            style: Style::Dots(1),
        }],
        y_limit: None,
    }
}
