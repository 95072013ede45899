//! `flicker compare`: every method on one scene, measured against the exact
//! answer; writes `compare.csv`, `compare.svg` and `compare.png`.

use std::path::{Path, PathBuf};

use crate::session::{
    CompareRequest, CompareRow as Row, Limits, Registry, compare_chart as chart,
    write_compare_csv as write_csv,
};

use crate::cli::exit::{Code, Failure};

/// Run `flicker compare`: run the scene with each of `methods` (default:
/// every method its model offers) over `tolerances` or `steps`, print one
/// line per run, and write `compare.csv`, `compare.svg` and `compare.png`
/// into `out` (default: `out/<scene name>-compare`), within `wall`
/// seconds.
pub fn compare(
    registry: &Registry,
    scene_path: &Path,
    methods: Option<Vec<String>>,
    tolerances: Option<Vec<f64>>,
    steps: Option<Vec<f64>>,
    out: Option<PathBuf>,
    wall: f64,
) -> Result<Code, Failure> {
    let deadline = crate::cli::setup::deadline(wall)?;
    let scene = registry.load(scene_path).map_err(Failure::bad_input)?;
    let asked = CompareRequest {
        methods,
        tolerances,
        steps,
    };
    let comparison = asked.on(scene).map_err(|e| {
        Failure::bad_input(format!("--{}: {}", e.field.unwrap_or_default(), e.reason))
    })?;
    let out = crate::cli::setup::out_dir(out, scene_path, "compare");
    eprintln!(
        "{:<8} {:>9} {:>9} {:>10} {:>10} {:>9} {:>10}  status",
        "method", "tol", "step", "seconds", "evals", "events", "error"
    );
    let stop = crate::cli::setup::stop_flag();
    let limits = Limits {
        stop: Some(stop.clone()),
        deadline,
        ..Default::default()
    };
    let (reference, rows) = comparison
        .run(&limits, &mut |row| eprintln!("{}", line(row)))
        .map_err(|e| {
            if limits.interrupted() {
                Failure {
                    code: Code::Interrupted,
                    message: e.in_path(scene_path).to_string(),
                }
            } else if e.untrusted {
                Failure::untrusted(e.in_path(scene_path).to_string())
            } else {
                Failure::bad_input(e.in_path(scene_path))
            }
        })?;
    crate::cli::setup::output_folder(&out)?;
    let csv = out.join("compare.csv");
    write_csv(&rows, &csv).map_err(|e| Failure::untrusted(format!("{}: {e}", csv.display())))?;
    let title = format!(
        "work-precision: {}",
        scene_path.file_stem().unwrap_or_default().to_string_lossy()
    );
    let mut written = vec![csv];
    for chart_file in ["compare.svg", "compare.png"] {
        let path = out.join(chart_file);
        chart::draw(&rows, &title, &path)
            .map_err(|e| Failure::untrusted(format!("{}: {e}", path.display())))?;
        written.push(path);
    }
    say!("reference: {}", reference.kind);
    let names: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    say!("wrote {}", names.join(", "));
    Ok(Code::Ok)
}

fn line(row: &Row) -> String {
    let opt = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.0e}"));
    format!(
        "{:<8} {:>9} {:>9} {:>10.3e} {:>10} {:>9} {:>10.2e}  {}",
        row.method,
        opt(row.tolerance),
        opt(row.step),
        row.wall_seconds,
        row.flow_evals,
        row.events,
        row.final_error,
        row.status
    )
}
