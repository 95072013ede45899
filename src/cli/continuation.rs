//! `flicker continue`: a periodic orbit followed in a parameter, its
//! bifurcations labelled, written to `DIR/continuation.csv` and drawn over
//! the brute-force diagram (`DIR/brute_force.csv`) in
//! `DIR/bifurcation.svg` and `.png`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use crate::plot::draw::{Curve, Figure, Style};
use crate::session::{Branch, Column, Name, Point, Registry, SearchRequest};

use crate::cli::exit::{Code, Failure};

/// `flicker continue`'s arguments.
#[derive(Debug, clap::Args)]
pub struct ContinueArgs {
    /// The scene file (any model with a finite state).
    scene: PathBuf,
    /// The transition whose events are the section (an impact).
    #[arg(long, value_name = "GUARD")]
    section: String,
    /// The parameter to follow the orbit in.
    #[arg(long, value_name = "NAME")]
    param: String,
    /// Where the parameter is to go.
    #[arg(long, value_name = "VALUE", allow_negative_numbers = true)]
    to: f64,
    /// Section events per period.
    #[arg(long, value_name = "K", default_value_t = 1)]
    events: usize,
    /// Run this long before the first orbit is searched for.
    #[arg(long, value_name = "T", default_value_t = 0.0)]
    settle: f64,
    /// The forcing's period, for an automaton that reads the clock.
    #[arg(long = "forcing-period", value_name = "T")]
    forcing_period: Option<f64>,
    /// Orbits along the branch at most.
    #[arg(long, value_name = "N", default_value_t = 200)]
    points: usize,
    /// The longest step along the branch, as a fraction of the way from the
    /// start to --to.
    #[arg(long = "max-step", value_name = "F", default_value_t = 0.05)]
    max_step: f64,
    /// The state drawn against the parameter (default: the one that varies
    /// most along the branch).
    #[arg(long, value_name = "STATE")]
    plot: Option<String>,
    /// Parameter values of the brute-force diagram drawn beneath (0: none).
    #[arg(long = "brute-force", value_name = "N", default_value_t = 200)]
    brute_force: usize,
    /// Section events recorded at each of them, after a transient of half
    /// the scene's t_end.
    #[arg(long = "brute-force-events", value_name = "N", default_value_t = 64)]
    brute_force_events: usize,
    // The `<scene name>` below is clap's placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-continuation).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// End the branch, saying so, after this many seconds of wall time.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 600.0,
        allow_negative_numbers = true
    )]
    wall: f64,
    /// Do not print each orbit as it is found.
    #[arg(long)]
    quiet: bool,
}

/// Run `flicker continue`.
pub fn continue_orbit(args: ContinueArgs, registry: &Registry) -> Result<Code, Failure> {
    let scene = registry.load(&args.scene).map_err(Failure::bad_input)?;
    let search = SearchRequest {
        section: args.section.clone(),
        events: args.events,
        settle: args.settle,
        forcing_period: args.forcing_period,
        wall: args.wall,
    }
    .on(&scene, Some(crate::cli::setup::stop_flag()))
    .map_err(|e| Failure::refused(&args.scene, e))?;
    let (branch, names, p) = search
        .branch(
            &args.param,
            args.to,
            (args.points, args.max_step),
            &mut |q| {
                // One line per orbit on a terminal: a branch never goes quiet.
                if !args.quiet && std::io::stderr().is_terminal() {
                    eprintln!(
                        "  orbit at {} = {:.10e}: period {:.10e}{}",
                        args.param,
                        q.parameter,
                        q.period,
                        if q.label.is_empty() {
                            String::new()
                        } else {
                            format!(" ({})", q.label)
                        }
                    );
                }
            },
        )
        .map_err(Failure::flag)?;
    let out = crate::cli::setup::out_dir(args.out.clone(), &args.scene, "continuation");
    crate::cli::setup::output_folder(&out)?;
    let csv = out.join("continuation.csv");
    write_csv(&branch, &names, p, &csv)
        .map_err(|e| Failure::untrusted(format!("{}: cannot be written: {e}", csv.display())))?;
    let Some(first) = branch.points.first() else {
        say!("no branch: {}", branch.ended);
        eprintln!("flicker: no branch: {}", branch.ended);
        return Ok(Code::stopped(
            branch.ended.contains("interrupted: the stop flag"),
        ));
    };
    let plotted = match &args.plot {
        Some(name) => names
            .iter()
            .position(|n| n == name.as_str())
            .filter(|&i| i != p)
            .ok_or_else(|| {
                Failure::bad_input(format!(
                    "--plot: no state `{name}` (states: {})",
                    names.join(", ")
                ))
            })?,
        None => most_varied(&branch, names.len(), p),
    };
    let mut columns = if args.brute_force > 0 {
        // The whole branch's span: one that turns back at a fold reaches
        // past its last point.
        let (lo, hi) = branch
            .points
            .iter()
            .fold((first.parameter, first.parameter), |(lo, hi), q| {
                (lo.min(q.parameter), hi.max(q.parameter))
            });
        let values: Vec<f64> = (0..args.brute_force)
            .map(|i| lo + (hi - lo) * i as f64 / (args.brute_force.max(2) - 1) as f64)
            .collect();
        search
            .brute_force(&args.param, &values, args.brute_force_events)
            .map_err(Failure::flag)?
    } else {
        Vec::new()
    };
    // A forced system's clock is drawn as the forcing's phase, as the
    // branch holds it: the brute-force runs' absolute times would climb
    // the picture as a ladder.
    if let (Some(period), Some(clock)) = (args.forcing_period, names.iter().position(|n| *n == "t"))
    {
        for x in columns.iter_mut().flat_map(|c| c.states.iter_mut()) {
            x[clock] = x[clock].rem_euclid(period);
        }
    }
    let label = if names[plotted] == "t" && args.forcing_period.is_some() {
        "t mod T (the forcing's phase)"
    } else {
        names[plotted].as_str()
    };
    let figure = chart(&branch, &columns, &args.param, label, plotted);
    let mut written = vec![csv];
    if !columns.is_empty() {
        let path = out.join("brute_force.csv");
        write_brute_force(&columns, &names, p, &path).map_err(|e| {
            Failure::untrusted(format!("{}: cannot be written: {e}", path.display()))
        })?;
        written.push(path);
    }
    written.extend(crate::cli::setup::draw_both(&figure, &out, "bifurcation")?);
    say_branch(&branch, &args.param, first.parameter);
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("  wrote {}", names.join(", "));
    // A branch that turned back at a fold, or ended at a graze, is an
    // answer; one the method lost is not.
    let lost = ["no orbit", "the step shrank", "the branch's tangent"]
        .iter()
        .any(|why| branch.ended.starts_with(why));
    if lost {
        eprintln!("flicker: the branch was lost: {}", branch.ended);
    }
    let interrupted = branch.ended.contains("interrupted: the stop flag");
    if interrupted || branch.ended.contains("past the wall-clock budget") {
        eprintln!("flicker: the branch stopped short: {}", branch.ended);
        return Ok(Code::stopped(interrupted));
    }
    Ok(if lost { Code::Untrusted } else { Code::Ok })
}

/// Print the branch followed in `param` from `from`: how far it went and
/// why it ended, and each bifurcation labelled on it.
fn say_branch(branch: &Branch, param: &str, from: f64) {
    say!(
        "{} orbits along `{param}` from {from} to {} ({})",
        branch.points.len(),
        branch.points.last().map_or(f64::NAN, |q| q.parameter),
        branch.ended
    );
    for q in branch
        .points
        .iter()
        .filter(|q| !q.label.is_empty() && q.label != "end")
    {
        say!(
            "  {} at {param} = {:.12e} (period {:e}, largest multiplier modulus {:.9})",
            q.label,
            q.parameter,
            q.period,
            largest(q)
        );
    }
}

/// The largest modulus among an orbit's multipliers but the trivial one.
fn largest(q: &Point) -> f64 {
    q.multipliers
        .iter()
        .skip(1)
        .map(|z| z.0.hypot(z.1))
        .fold(0.0, f64::max)
}

/// The state (not the parameter, nor one the section pins to it) whose
/// range along the branch is widest.
fn most_varied(branch: &Branch, n: usize, p: usize) -> usize {
    // A state the section pins to the parameter (the position at a stop
    // that moves with it) draws only the diagonal.
    let pinned = |i: usize| branch.points.iter().all(|q| q.state[i] == q.parameter);
    (0..n)
        .filter(|&i| i != p && !pinned(i))
        .max_by(|&a, &b| {
            let range = |i: usize| {
                let (lo, hi) = branch
                    .points
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                        (lo.min(q.state[i]), hi.max(q.state[i]))
                    });
                hi - lo
            };
            range(a).total_cmp(&range(b))
        })
        .unwrap_or(0)
}

/// `continuation.csv`: parameter, period, each state at the section (the
/// parameter's own left out), the largest multiplier modulus, stable, label.
fn write_csv(branch: &Branch, names: &[Name], p: usize, path: &Path) -> csv::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec!["parameter".to_string(), "period".to_string()];
    header.extend(
        names
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != p)
            .map(|(_, n)| n.to_string()),
    );
    header.extend(["largest_multiplier", "stable", "label"].map(String::from));
    w.write_record(&header)?;
    for q in &branch.points {
        let mut row = vec![q.parameter.to_string(), q.period.to_string()];
        row.extend(
            q.state
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != p)
                .map(|(_, x)| x.to_string()),
        );
        row.extend([
            largest(q).to_string(),
            q.stable.to_string(),
            q.label.clone(),
        ]);
        w.write_record(&row)?;
    }
    w.flush()?;
    Ok(())
}

/// `brute_force.csv`: parameter, then each state just after a section
/// event (the parameter's own left out; a forced system's clock as the
/// forcing's phase), a row per event recorded.
fn write_brute_force(columns: &[Column], names: &[Name], p: usize, path: &Path) -> csv::Result<()> {
    let mut w = csv::Writer::from_path(path)?;
    let mut header = vec!["parameter"];
    header.extend(
        names
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != p)
            .map(|(_, n)| n.as_str()),
    );
    w.write_record(&header)?;
    for c in columns {
        for x in &c.states {
            let mut row = vec![c.parameter.to_string()];
            row.extend(
                x.iter()
                    .enumerate()
                    .filter(|(i, _)| *i != p)
                    .map(|(_, v)| v.to_string()),
            );
            w.write_record(&row)?;
        }
    }
    w.flush()?;
    Ok(())
}

/// The branch (solid where stable, dashed where not, its bifurcations
/// circled and named) over the brute-force diagram's dots.
fn chart(branch: &Branch, columns: &[Column], param: &str, state: &str, i: usize) -> Figure {
    let mut curves = vec![Curve {
        label: None,
        points: columns
            .iter()
            .flat_map(|c| c.states.iter().map(move |x| (c.parameter, x[i])))
            .collect(),
        style: Style::Dots(4),
    }];
    let mut run: Vec<(f64, f64)> = Vec::new();
    let mut stable = None;
    for q in &branch.points {
        if stable.is_some_and(|s| s != q.stable) {
            let last = *run.last().unwrap_or(&(q.parameter, q.state[i]));
            curves.push(segment(std::mem::take(&mut run), stable.unwrap_or(true)));
            run.push(last);
        }
        stable = Some(q.stable);
        run.push((q.parameter, q.state[i]));
    }
    curves.push(segment(run, stable.unwrap_or(true)));
    for q in branch
        .points
        .iter()
        .filter(|q| !q.label.is_empty() && q.label != "end")
    {
        curves.push(Curve {
            label: Some(q.label.clone()),
            points: vec![(q.parameter, q.state[i])],
            style: Style::Circles(1),
        });
    }
    Figure {
        title: format!(
            "{state} at the section against {param} (solid: stable, dashed: unstable; dots: brute force)"
        ),
        x_label: param.to_string(),
        y_label: state.to_string(),
        curves,
        y_limit: None,
    }
}

fn segment(points: Vec<(f64, f64)>, stable: bool) -> Curve {
    Curve {
        label: None,
        points,
        style: if stable {
            Style::Line(0)
        } else {
            Style::Dashed(0)
        },
    }
}
