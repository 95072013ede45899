//! `flicker sweep` and `flicker merge`: a grid of scenes in parallel, in
//! shards for batch schedulers, and the shards joined again.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::cli::exit::{Code, Failure};
use crate::session::{Limits, Registry, Shard, SweepRun};

/// Run `flicker sweep`: run the points of the sweep in `file` (all, or one
/// `shard` given as `I/N`) on `threads` threads (default: one per core)
/// and write one CSV row per point to `out` (default:
/// `out/<sweep name>.csv`, or `.shard-I-of-N.csv`), within `wall` seconds
/// (the points not begun by then, or on Ctrl-C, are written as such).
pub fn sweep(
    registry: &Registry,
    file: &Path,
    shard: Option<String>,
    threads: Option<usize>,
    out: Option<PathBuf>,
    (wall, quiet): (f64, bool),
) -> Result<Code, Failure> {
    let deadline = crate::cli::setup::deadline(wall)?;
    let spec = crate::session::load(registry, file).map_err(Failure::bad_input)?;
    let points = SweepRun::new(&spec, shard.as_deref(), threads).map_err(|e| {
        Failure::bad_input(format!(
            "--{}: {}",
            e.field.as_deref().unwrap_or("shard"),
            e.reason
        ))
    })?;
    let shard = points.shard();
    let out = out.unwrap_or_else(|| {
        let stem = file
            .file_stem()
            .map_or_else(|| "sweep".into(), |s| s.to_string_lossy().into_owned());
        let name = if shard == Shard::WHOLE {
            format!("{stem}.csv")
        } else {
            format!("{stem}.shard-{}-of-{}.csv", shard.index, shard.count)
        };
        Path::new("out").join(name)
    });
    if let Some(folder) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(|e| {
            Failure::bad_input(format!(
                "{}: cannot create the folder: {e}",
                folder.display()
            ))
        })?;
    }
    let started = Instant::now();
    let limits = Limits {
        stop: Some(crate::cli::setup::stop_flag()),
        deadline,
        ..Default::default()
    };
    let bar = crate::cli::progress::Points::new(points.points(), quiet);
    let rows = points.run(&limits, &|| bar.tick());
    bar.finish();
    let seconds = started.elapsed().as_secs_f64();
    let file = File::create(&out)
        .map_err(|e| Failure::bad_input(format!("{}: cannot be created: {e}", out.display())))?;
    crate::session::write_sweep_csv(&spec, &rows, &mut BufWriter::new(file))
        .map_err(|e| Failure::untrusted(format!("{}: {e}", out.display())))?;
    let failed = rows
        .iter()
        .filter(|r| r.status != "completed" && !r.status.starts_with("zeno"))
        .count();
    say!(
        "{} points of {} in {seconds:.3} s on {} threads ({failed} not completed); wrote {}",
        rows.len(),
        spec.points(),
        points.threads(),
        out.display()
    );
    if limits.stopped() {
        let why = limits.stop_reason();
        eprintln!("flicker: the sweep stopped short ({why}); the points not begun say so");
        return Ok(Code::stopped(limits.interrupted()));
    }
    Ok(Code::Ok)
}

/// Run `flicker merge`: join the shard CSVs of the sweep in `file` into
/// `out`, the CSV a single run writes.
pub fn merge(
    registry: &Registry,
    file: &Path,
    shards: &[PathBuf],
    out: &Path,
) -> Result<Code, Failure> {
    let spec = crate::session::load(registry, file).map_err(Failure::bad_input)?;
    let text = crate::session::merge(&spec, shards).map_err(Failure::bad_input)?;
    std::fs::write(out, text)
        .map_err(|e| Failure::untrusted(format!("{}: cannot be written: {e}", out.display())))?;
    say!("merged {} shards into {}", shards.len(), out.display());
    Ok(Code::Ok)
}
