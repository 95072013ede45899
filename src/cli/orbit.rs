//! `flicker orbit`: a periodic orbit of a scene through a Poincare section,
//! by Newton shooting, written to `DIR/orbit.json`.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use crate::log::summary::write_atomically;
use crate::session::{Registry, SearchRequest};

use crate::cli::exit::{Code, Failure};
use crate::cli::progress::WithProgress;

/// `flicker orbit`'s arguments.
#[derive(Debug, clap::Args)]
pub struct OrbitArgs {
    /// The scene file (any model with a finite state).
    scene: PathBuf,
    /// The transition whose events are the section (an impact).
    #[arg(long, value_name = "GUARD")]
    section: String,
    /// Section events per period.
    #[arg(long, value_name = "K", default_value_t = 1)]
    events: usize,
    /// Run this long first and start from the next section event (let a
    /// transient die out).
    #[arg(long, value_name = "T", default_value_t = 0.0)]
    settle: f64,
    /// The forcing's period, for an automaton that reads the clock: the
    /// orbit's period is a whole number of them.
    #[arg(long = "forcing-period", value_name = "T")]
    forcing_period: Option<f64>,
    // The `<scene name>` below is clap's placeholder, not an HTML tag.
    #[allow(rustdoc::invalid_html_tags)]
    /// Output directory (default: out/<scene name>-orbit).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Do not draw progress.
    #[arg(long)]
    quiet: bool,
    /// Stop the search, saying so, after this many seconds of wall time.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 600.0,
        allow_negative_numbers = true
    )]
    wall: f64,
}

/// Run `flicker orbit`: search, write `orbit.json`, say what was found.
/// A search that does not converge exits 3, saying why.
pub fn orbit(args: OrbitArgs, registry: &Registry) -> Result<Code, Failure> {
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
    let out = crate::cli::setup::out_dir(args.out, &args.scene, "orbit");
    let started = Instant::now();
    // On a terminal: a bar over the transient, a line per Newton iteration.
    let shown = !args.quiet && std::io::stderr().is_terminal();
    let mut bar = WithProgress::new((), args.settle, args.quiet);
    let clear = bar.clearer();
    let mut newton = |k: usize, residual: f64| {
        if k == 0 {
            clear();
        }
        if shown {
            eprintln!("  Newton iteration {k}: residual {residual:.3e}");
        }
    };
    let watch = crate::session::Watch {
        transient: Some(&mut bar),
        newton: Some(&mut newton),
    };
    let found = search.orbit(watch);
    bar.finish();
    let orbit = found.map_err(Failure::flag)?;
    let wall = started.elapsed().as_secs_f64();
    crate::cli::setup::output_folder(&out)?;
    let path = out.join("orbit.json");
    write_atomically(&path, &orbit.to_json(&args.scene, &args.section, wall))
        .map_err(|e| Failure::untrusted(format!("{}: cannot be written: {e}", path.display())))?;
    if !orbit.converged {
        say!("no orbit: {}", orbit.status);
        say!("  wrote {}", path.display());
        eprintln!("flicker: no orbit: {}", orbit.status);
        return Ok(Code::stopped(
            orbit.status.contains("interrupted: the stop flag"),
        ));
    }
    let state: Vec<String> = orbit
        .section_state
        .iter()
        .map(|(n, x)| format!("{n} = {x:e}"))
        .collect();
    say!(
        "a periodic orbit of {} `{}` events: period {:e}, {} Newton iterations, residual {:.1e}",
        orbit.events_per_period,
        args.section,
        orbit.period,
        orbit.iterations,
        orbit.residual
    );
    say!(
        "  at the section, in mode `{}`: {}",
        orbit.mode,
        state.join(", ")
    );
    let multipliers: Vec<String> = orbit
        .multipliers
        .iter()
        .map(|(re, im)| {
            if *im == 0.0 {
                format!("{re:.6e}")
            } else {
                format!("{re:.6e}{im:+.6e}i")
            }
        })
        .collect();
    say!(
        "  multipliers {} ({})",
        multipliers.join(", "),
        if orbit.stable { "stable" } else { "unstable" }
    );
    say!("  wrote {}", path.display());
    Ok(Code::Ok)
}
