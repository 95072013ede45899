//! Sweeps: every row against the closed form written out in the tests
//! (the period from the row's `eta` and `H0`, the first impact, the impact
//! count, and the row's own `exact_period` and `period_error` recomputed),
//! the same CSV whatever the thread count, and shards that merge into the
//! single run byte for byte.

use std::path::Path;

use crate::oscillator::Unit;
use crate::support::flicker;

const EPS: f64 = f64::EPSILON;

/// A sweep's CSV: the header and the rows.
fn read_rows(path: &Path) -> (csv::StringRecord, Vec<csv::StringRecord>) {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    (header, reader.records().map(|r| r.unwrap()).collect())
}

/// The number in column `name` of `row` (`None` if empty).
fn number(header: &csv::StringRecord, row: &csv::StringRecord, name: &str) -> Option<f64> {
    let col = header.iter().position(|h| h == name).unwrap();
    (!row[col].is_empty()).then(|| row[col].parse().unwrap())
}

/// Checks a completed impacting row of a sweep with `omega = 1` run to
/// `t_end`, whose first impact comes `first` periods in (1/2 from the
/// apex, 1 from an impact): returns whether it had a period to check.
///
/// The run starts from the scene's state of energy `H0`, rounded: the
/// apex `(eta - 1) + A` to an ulp or two of `|eta - 1| + A`, which moves
/// the energy by up to `dH = 2 eps A (|eta - 1| + A)`, and the period by
/// `|dT/dH0| dH` with `dT/dH0 = -2 (eta - 1) / (omega A^2 s)`,
/// `s = sqrt(2 H0)` (large near grazing and chattering). Beyond that, the
/// measured period is a mean over `n - 1` flights, so it carries the
/// rounding of one flight's time (some ulps of T: up to 28 seen over 1500
/// chattering impacts) plus an ulp of `t_end` at each end over the span:
/// 64 ulps + 4 eps t_end / span. The first impact is one flight: 8 ulps.
fn check_row(header: &csv::StringRecord, r: &csv::StringRecord, t_end: f64, first: f64) -> bool {
    let get = |name: &str| number(header, r, name);
    let (eta, h0) = (get("eta").unwrap(), get("initial.energy").unwrap());
    let u = Unit { eta, omega: 1.0 };
    let period = u.period_atan2(h0);
    let (c, a, s) = ((eta - 1.0).abs(), u.amplitude(h0), (2.0 * h0).sqrt());
    let start = 2.0 * c / (a * a * s) * 2.0 * EPS * a * (c + a);
    let t1 = first * period;
    let events = get("events").unwrap();
    // Impacts at t1 + k T up to t_end, unless t_end is within rounding of one.
    let count = ((t_end - t1) / period).floor() + 1.0;
    if ((t_end - t1) / period - ((t_end - t1) / period).round()).abs() > 1e-9 {
        assert_eq!(events, count, "eta {eta}, H0 {h0}: impacts");
    }
    let first_impact = get("first_impact").unwrap();
    assert!(
        (first_impact - t1).abs() <= first * start + 8.0 * EPS * t1,
        "eta {eta}, H0 {h0}: first impact {first_impact} vs {t1}"
    );
    let Some(measured) = get("impact_period") else {
        assert!(
            events < 2.0,
            "eta {eta}, H0 {h0}: no period over {events} impacts"
        );
        return false;
    };
    let error = ((measured - period) / period).abs();
    let span = (events - 1.0) * period;
    let tolerance = start / period + 64.0 * EPS + 4.0 * EPS * t_end / span;
    assert!(
        error < tolerance,
        "eta {eta}, H0 {h0}: measured period {measured} vs {period}: {error:e} > {tolerance:e}"
    );
    // The row's own closed form is the period of the rounded starting
    // state's energy: T to the same start term and atan2's 2 ulps; its
    // error is the relative difference of the row's two periods.
    let exact = get("exact_period").unwrap();
    assert!(
        (exact - period).abs() <= start + 2.0 * EPS * period,
        "eta {eta}, H0 {h0}: exact_period {exact} vs {period}"
    );
    let reported = get("period_error").unwrap();
    let own = ((measured - exact) / exact).abs();
    assert!(
        (reported - own).abs() <= 4.0 * EPS,
        "eta {eta}, H0 {h0}: period_error {reported:e} vs {own:e}"
    );
    true
}

fn small_sweep(dir: &Path) -> String {
    let path = dir.join("sweep.json");
    std::fs::write(
        &path,
        r#"{"scene": {"model": "mechanism", "formulation": "strain", "eta": 1.0,
                      "initial": {"energy": 0.1, "phase": "apex"}, "t_end": 50.0},
            "grid": [{"key": "eta", "from": 0.5, "to": 1.5, "count": 7},
                     {"key": "initial.energy", "values": [-0.01, 1e-3, 0.1, 1.0]}]}"#,
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn every_point_matches_the_closed_form_period() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let out = dir.path().join("all.csv");
    let result = flicker(&["sweep", &sweep, "--out", out.to_str().unwrap()]);
    assert_eq!(
        result.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let (header, rows) = read_rows(&out);
    assert_eq!(rows.len(), 28);
    let mut checked = 0;
    for r in &rows {
        let (eta, h0) = (
            number(&header, r, "eta").unwrap(),
            number(&header, r, "initial.energy").unwrap(),
        );
        let status = &r[header.iter().position(|h| h == "status").unwrap()];
        if h0 < 0.0 && eta <= 1.0 {
            // No state has negative energy below critical load: refused, not run.
            assert!(status.starts_with("invalid"), "{r:?}");
            continue;
        }
        assert_eq!(status, "completed", "{r:?}");
        if h0 < 0.0 {
            // Loose: no impact, no period.
            assert_eq!(number(&header, r, "events"), Some(0.0), "{r:?}");
            assert_eq!(number(&header, r, "exact_period"), None, "{r:?}");
            continue;
        }
        // From the apex, the first impact is half a period in.
        if check_row(&header, r, 50.0, 0.5) {
            checked += 1;
        }
    }
    assert!(checked >= 20);
}

#[test]
fn shards_merge_into_the_single_run_and_threads_do_not_matter() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    assert!(
        flicker(&["sweep", &sweep, "--threads", "1", "--out", &path("one.csv")])
            .status
            .success()
    );
    assert!(
        flicker(&["sweep", &sweep, "--threads", "2", "--out", &path("two.csv")])
            .status
            .success()
    );
    assert_eq!(
        std::fs::read(path("one.csv")).unwrap(),
        std::fs::read(path("two.csv")).unwrap()
    );
    for i in 0..3 {
        let shard = format!("{i}/3");
        assert!(
            flicker(&[
                "sweep",
                &sweep,
                "--shard",
                &shard,
                "--out",
                &path(&format!("s{i}.csv"))
            ])
            .status
            .success()
        );
    }
    let merged = flicker(&[
        "merge",
        &sweep,
        &path("s2.csv"),
        &path("s0.csv"),
        &path("s1.csv"),
        "--out",
        &path("merged.csv"),
    ]);
    assert!(
        merged.status.success(),
        "{}",
        String::from_utf8_lossy(&merged.stderr)
    );
    assert_eq!(
        std::fs::read(path("merged.csv")).unwrap(),
        std::fs::read(path("one.csv")).unwrap()
    );
    // A missing shard is refused, naming the first missing point.
    let partial = flicker(&[
        "merge",
        &sweep,
        &path("s0.csv"),
        &path("s1.csv"),
        "--out",
        &path("bad.csv"),
    ]);
    assert_eq!(partial.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&partial.stderr).contains("point 2 is missing"));
}

#[test]
fn bad_sweeps_and_shards_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = small_sweep(dir.path());
    let bad_shard = flicker(&["sweep", &sweep, "--shard", "3/3"]);
    assert_eq!(bad_shard.status.code(), Some(2));
    let typo = dir.path().join("typo.json");
    std::fs::write(
        &typo,
        r#"{"scene": {"model": "mechanism", "formulation": "strain", "eta": 1.0,
                      "initial": {"energy": 0.1, "phase": "impact"}, "t_end": 5.0},
            "grid": [{"key": "etta", "values": [1.0]}]}"#,
    )
    .unwrap();
    let result = flicker(&["sweep", typo.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("typo.json") && stderr.contains("etta"),
        "{stderr}"
    );
}

#[test]
fn the_bundled_sweep_loads_and_its_points_match_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let bundled = format!(
        "{}/models/sweeps/impact_period.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let out = dir.path().join("part.csv");
    let result = flicker(&[
        "sweep",
        &bundled,
        "--shard",
        "7/50",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let (header, rows) = read_rows(&out);
    assert_eq!(rows.len(), 200);
    let status = header.iter().position(|h| h == "status").unwrap();
    assert!(
        rows.iter().all(|r| &r[status] == "completed"),
        "every point completes"
    );
    // From an impact (the bundled scene's phase), the next comes a whole
    // period later; t_end = 200.
    let checked = rows
        .iter()
        .filter(|r| check_row(&header, r, 200.0, 1.0))
        .count();
    assert!(checked > 150, "only {checked} rows have a period to check");
}
