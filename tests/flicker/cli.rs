//! The `flicker` binary: exit codes, the files a run writes, one-line errors
//! that name the file and the field, nothing lost on bad input, and
//! `flicker events` keeping exactly the logged events its filter selects.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

use crate::oscillator::Unit;
use crate::support::{flicker, models, read_json};

fn scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_run_writes_a_summary_and_a_log_that_agree() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let result = flicker(&[
        "run",
        &models("mechanism_impacting.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        result.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let summary = read_json(&out.join("summary.json"));
    for key in [
        "status",
        "reason",
        "events",
        "events_by_guard",
        "t_end",
        "t_reached",
        "energy_initial",
        "energy_final",
        "max_energy_error",
        "final_state",
        "zeno",
        "method",
        "wall_seconds",
    ] {
        assert!(summary.get(key).is_some(), "summary lacks {key}");
    }
    assert_eq!(summary["status"], "completed");
    assert_eq!(summary["method"], "exact");
    assert_eq!(summary["zeno"], false);
    assert!(summary["max_energy_error"].as_f64().unwrap() < 1e-14);
    let log = std::fs::read_to_string(out.join("events.jsonl")).unwrap();
    let lines: Vec<Value> = log
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len() as u64, summary["events"].as_u64().unwrap());
    assert_eq!(summary["events_by_guard"]["impact"], summary["events"]);
    let mut last = 0.0;
    for line in &lines {
        let t = line["t"].as_f64().unwrap();
        assert!(t >= last);
        last = t;
        assert_eq!(line["guard"], "impact");
        assert_eq!(
            line["before"]["strain_rate"].as_f64().unwrap(),
            -line["after"]["strain_rate"].as_f64().unwrap()
        );
        let jump = line["energy_after"].as_f64().unwrap() - line["energy_before"].as_f64().unwrap();
        assert!(jump.abs() < 1e-15);
    }
    // The final state is the arc's from the last impact (eta 1.2, H0 0.05
    // from the apex), written out in crate::oscillator.
    let u = Unit {
        eta: 1.2,
        omega: 1.0,
    };
    let (eps, rate) = u.state_at(u.apex(0.05), 1000.0);
    assert!((summary["final_state"]["strain"].as_f64().unwrap() - eps).abs() < 1e-12);
    assert!((summary["final_state"]["strain_rate"].as_f64().unwrap() - rate).abs() < 1e-12);
}

#[test]
fn no_events_and_t_end_flags_are_honoured() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = out.to_str().unwrap();
    let result = flicker(&[
        "run",
        &models("mechanism_subcritical.json"),
        "--out",
        o,
        "--no-events",
        "--t-end",
        "50",
    ]);
    assert_eq!(result.status.code(), Some(0));
    assert!(!out.join("events.jsonl").exists());
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["t_end"], 50.0);
    assert_eq!(summary["t_reached"], 50.0);
    assert!(summary["log"].is_null());
}

#[test]
fn a_failing_method_exits_3_with_its_reason() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let result = flicker(&[
        "run",
        &models("mechanism_angle_plain.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(3));
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed");
    assert!(
        summary["reason"]
            .as_str()
            .unwrap()
            .contains("singular at theta = 0")
    );
    assert!(summary["t_reached"].as_f64().unwrap() < 100.0);
    // The reason is on stderr too, for a caller that keeps only errors.
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.contains("singular at theta = 0"), "stderr: {stderr}");
}

#[test]
fn check_recognises_a_sweep_file_and_checks_it_as_one() {
    let result = flicker(&["check", &models("sweeps/impact_period.json")]);
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert_eq!(result.status.code(), Some(0), "{stdout}");
    // 100 x 100 points, as the file's two axes say.
    assert!(
        stdout.contains("a valid sweep of 10000 mechanism scenes"),
        "{stdout}"
    );
    assert!(
        stdout.contains("eta: 100 values from 0.5 to 1.5"),
        "{stdout}"
    );
    // A broken axis is still bad input, named.
    let dir = tempfile::tempdir().unwrap();
    let broken = scene(
        dir.path(),
        "sweep.json",
        r#"{"scene": {"model": "mechanism", "eta": 1.0, "omega": 1.0, "initial": {"strain": 0.1, "strain_rate": 0.0}, "t_end": 1.0},
            "grid": [{"key": "eta", "from": 0.5, "to": 1.5, "count": 0}]}"#,
    );
    let result = flicker(&["check", broken.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.contains("count"), "{stderr}");
}

#[test]
fn zeno_handled_by_resting_contact_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let result = flicker(&[
        "run",
        &models("mechanism_chattering.json"),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(0));
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "zeno");
    assert_eq!(summary["zeno"], true);
    assert_eq!(summary["final_mode"], "resting");
    assert!(summary["reason"].as_str().unwrap().contains("resting"));
}

#[test]
fn bad_scenes_exit_2_naming_file_field_and_reason() {
    let dir = tempfile::tempdir().unwrap();
    let base = r#""model": "mechanism", "formulation": "strain", "eta": 1.2, "omega": 1.0"#;
    let good_initial = r#""initial": {"strain": 0.05, "strain_rate": 0.0}"#;
    let cases: Vec<(&str, String, &str)> = vec![
        ("malformed", "{\"model\": ".into(), "not valid JSON"),
        ("unknown_model", r#"{"model": "pendulum"}"#.into(), "field model: unknown model"),
        ("unknown_key", format!("{{{base}, {good_initial}, \"t_end\": 1, \"colour\": 3}}"), "field colour"),
        ("missing_t_end", format!("{{{base}, {good_initial}}}"), "field t_end: is missing"),
        ("nan", format!("{{{base}, {good_initial}, \"t_end\": NaN}}"), "not valid JSON"),
        ("nan_string", format!("{{{base}, {good_initial}, \"t_end\": \"NaN\"}}"), "field t_end: must be a finite number"),
        (
            "omega",
            format!(r#"{{"model": "mechanism", "formulation": "strain", "eta": 1.2, "omega": 0, {good_initial}, "t_end": 1}}"#),
            "field omega: must be > 0",
        ),
        ("t_end", format!("{{{base}, {good_initial}, \"t_end\": -1}}"), "field t_end: must be > 0"),
        (
            "strain",
            format!("{{{base}, \"initial\": {{\"strain\": -0.1, \"strain_rate\": 0}}, \"t_end\": 1}}"),
            "field initial.strain: must be >= 0",
        ),
        (
            "energy",
            format!("{{{base}, \"initial\": {{\"energy\": -1, \"phase\": \"apex\"}}, \"t_end\": 1}}"),
            "field initial.energy",
        ),
        (
            "formulation",
            r#"{"model": "mechanism", "formulation": "polar", "eta": 1, "initial": {"strain": 0, "strain_rate": 0}, "t_end": 1}"#.into(),
            "field formulation",
        ),
        ("not_object", "[1, 2]".into(), "must be a JSON object"),
        ("huge", format!("{{{base}, {good_initial}, \"t_end\": 1e999}}"), "not valid JSON"),
        (
            "tiny_step",
            format!("{{{base}, {good_initial}, \"t_end\": 1000, \"solver\": {{\"method\": \"verlet\", \"step\": 1e-9}}}}"),
            "field solver.step",
        ),
    ];
    for (name, text, expected) in cases {
        let path = scene(dir.path(), &format!("{name}.json"), &text);
        let out = dir.path().join(format!("out_{name}"));
        let result = flicker(&[
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(2), "{name}: {stderr}");
        assert_eq!(stderr.lines().count(), 1, "{name}: one line, got {stderr}");
        assert!(
            stderr.contains(&format!("{name}.json")),
            "{name}: names the file: {stderr}"
        );
        assert!(
            stderr.contains(expected),
            "{name}: expected {expected:?} in {stderr}"
        );
        assert!(!out.exists(), "{name}: bad input must not create outputs");
    }
}

#[test]
fn bad_input_leaves_an_earlier_run_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = out.to_str().unwrap();
    assert_eq!(
        flicker(&["run", &models("mechanism_impacting.json"), "--out", o])
            .status
            .code(),
        Some(0)
    );
    let before = std::fs::read(out.join("events.jsonl")).unwrap();
    let bad = scene(dir.path(), "bad.json", r#"{"model": "mechanism"}"#);
    assert_eq!(
        flicker(&["run", bad.to_str().unwrap(), "--out", o])
            .status
            .code(),
        Some(2)
    );
    assert_eq!(
        flicker(&[
            "run",
            &models("mechanism_impacting.json"),
            "--out",
            o,
            "--t-end",
            "0"
        ])
        .status
        .code(),
        Some(2)
    );
    assert_eq!(std::fs::read(out.join("events.jsonl")).unwrap(), before);
}

#[test]
fn a_missing_scene_file_is_bad_input() {
    let result = flicker(&["run", "/nonexistent/scene.json"]);
    assert_eq!(result.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&result.stderr).contains("/nonexistent/scene.json"));
}

/// The lines `flicker events LOG ARGS` prints.
fn filtered(log: &Path, args: &[&str]) -> Vec<String> {
    let mut all = vec!["events", log.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = flicker(&all);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// The lines of `log` whose guard and time pass, read independently of
/// the tool: each line parsed as JSON.
fn expected(log: &Path, guard: Option<&str>, from: f64, to: f64) -> Vec<String> {
    std::fs::read_to_string(log)
        .unwrap()
        .lines()
        .filter(|line| {
            let e: Value = serde_json::from_str(line).unwrap();
            let t = e["t"].as_f64().unwrap();
            guard.is_none_or(|g| e["guard"] == g) && from <= t && t <= to
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn events_keeps_exactly_the_events_of_its_window_and_guard() {
    let dir = tempfile::tempdir().unwrap();
    let run = |scene: &str, name: &str, t_end: &str| {
        let out = dir.path().join(name);
        let o = flicker(&[
            "run",
            &models(scene),
            "--out",
            out.to_str().unwrap(),
            "--t-end",
            t_end,
        ]);
        assert_eq!(o.status.code(), Some(0), "{scene}");
        out.join("events.jsonl")
    };
    let log = run("mechanism_impacting.json", "impacting", "100");
    let times: Vec<f64> = std::fs::read_to_string(&log)
        .unwrap()
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["t"]
                .as_f64()
                .unwrap()
        })
        .collect();
    assert!(times.len() > 20, "{} impacts", times.len());
    // Windows with round ends, and with ends exactly on events (kept: the
    // filter is t >= from and t <= to), given as the shortest decimal that
    // reads back as the logged time.
    let (t5, t12) = (times[4].to_string(), times[11].to_string());
    for (args, guard, from, to) in [
        (
            vec!["--guard", "impact", "--from", "10", "--to", "50"],
            Some("impact"),
            10.0,
            50.0,
        ),
        (vec!["--from", &t5, "--to", &t12], None, times[4], times[11]),
        (vec!["--from", &t12], None, times[11], f64::INFINITY),
        (vec!["--to", &t5], None, f64::NEG_INFINITY, times[4]),
        (vec!["--from", &t5, "--to", &t5], None, times[4], times[4]),
        (vec![], None, f64::NEG_INFINITY, f64::INFINITY),
    ] {
        let want = expected(&log, guard, from, to);
        assert!(!want.is_empty(), "{args:?}");
        assert_eq!(filtered(&log, &args), want, "{args:?}");
    }
    assert_eq!(expected(&log, None, times[4], times[11]).len(), 8);
    // Guards: a chattering run logs impacts, then one settle.
    let log = run("mechanism_chattering.json", "chattering", "100");
    for guard in ["impact", "settle"] {
        let want = expected(&log, Some(guard), f64::NEG_INFINITY, f64::INFINITY);
        assert!(!want.is_empty(), "{guard}");
        assert_eq!(filtered(&log, &["--guard", guard]), want, "{guard}");
    }
    assert!(filtered(&log, &["--guard", "nothing"]).is_empty());
}

#[test]
fn events_summarises_a_log() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = out.to_str().unwrap();
    flicker(&[
        "run",
        &models("mechanism_impacting.json"),
        "--out",
        o,
        "--t-end",
        "100",
    ]);
    let log = out.join("events.jsonl");
    let l = log.to_str().unwrap();
    let total = std::fs::read_to_string(&log).unwrap().lines().count();
    let summary = flicker(&["events", l, "--summary"]);
    let s: Value = serde_json::from_slice(&summary.stdout).unwrap();
    assert_eq!(s["events"].as_u64().unwrap() as usize, total);
    assert_eq!(
        s["by_guard"]["impact"]["count"].as_u64().unwrap() as usize,
        total
    );
    // Impacts are periodic: every interval is the period of eta 1.2,
    // H0 0.05, written out (a flight's time to some ulps).
    let period = Unit {
        eta: 1.2,
        omega: 1.0,
    }
    .period_atan2(0.05);
    for key in ["min", "max"] {
        assert!((s["intervals"][key].as_f64().unwrap() - period).abs() < 1e-12);
    }
    assert!(s["largest_energy_jump"]["jump"].as_f64().unwrap() < 1e-15);
    assert_eq!(s["out_of_order"], 0);
    let none = flicker(&["events", l, "--guard", "nothing", "--summary"]);
    let s: Value = serde_json::from_slice(&none.stdout).unwrap();
    assert_eq!(s["events"], 0);
}

#[test]
fn events_refuses_a_broken_log_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let log = scene(
        dir.path(),
        "events.jsonl",
        "{\"seq\":1,\"t\":1.0,\"guard\":\"impact\",\"energy_before\":1,\"energy_after\":1}\nnot json\n",
    );
    let result = flicker(&["events", log.to_str().unwrap()]);
    assert_eq!(result.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(stderr.contains("line 2"), "{stderr}");
    let window = flicker(&["events", log.to_str().unwrap(), "--from", "5", "--to", "1"]);
    assert_eq!(window.status.code(), Some(2));
}

#[test]
fn an_interrupted_run_keeps_its_log_and_says_so() {
    for signal in ["-INT", "-TERM"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let child = crate::support::command()
            .args([
                "run",
                &models("mechanism_impacting.json"),
                "--t-end",
                "4e7",
                "--out",
                out.to_str().unwrap(),
            ])
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap();
        // Wait until the run is writing, then interrupt it.
        let log = out.join("events.jsonl");
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
        while std::fs::metadata(&log).map_or(0, |m| m.len()) == 0
            && std::time::Instant::now() < deadline
        {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let killed = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let result = child.wait_with_output().unwrap();
        assert_eq!(result.status.code(), Some(130), "{signal}");
        let summary = read_json(&out.join("summary.json"));
        assert_eq!(summary["status"], "interrupted");
        assert!(summary["t_reached"].as_f64().unwrap() < 4e7);
        let text = std::fs::read_to_string(&log).unwrap();
        assert!(text.ends_with('\n'));
        let lines = text.lines().count() as u64;
        assert_eq!(lines, summary["events"].as_u64().unwrap());
        let last: Value = serde_json::from_str(text.lines().last().unwrap()).unwrap();
        assert_eq!(last["t"], summary["t_reached"]);
    }
}

#[test]
fn a_full_disk_ends_the_run_with_a_clear_message() {
    // The log is a link to /dev/full, where every write fails with ENOSPC.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink("/dev/full", out.join("events.jsonl")).unwrap();
    let result = flicker(&[
        "run",
        &models("mechanism_impacting.json"),
        "--t-end",
        "1e6",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(result.status.code(), Some(3));
    let summary = read_json(&out.join("summary.json"));
    assert_eq!(summary["status"], "failed");
    let reason = summary["reason"].as_str().unwrap();
    assert!(reason.contains("could not write the event log"), "{reason}");
    // It stopped at the first full buffer, not at t_end.
    assert!(summary["t_reached"].as_f64().unwrap() < 1e6);
}

#[test]
fn events_exports_csv_with_one_row_per_kept_event() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    flicker(&[
        "run",
        &models("mechanism_subcritical.json"),
        "--out",
        out.to_str().unwrap(),
        "--t-end",
        "40",
    ]);
    let log = out.join("events.jsonl");
    let lines = std::fs::read_to_string(&log).unwrap().lines().count();
    let csv_out = flicker(&["events", log.to_str().unwrap(), "--csv"]);
    assert_eq!(csv_out.status.code(), Some(0));
    let mut reader = csv::Reader::from_reader(csv_out.stdout.as_slice());
    assert_eq!(
        reader.headers().unwrap(),
        vec![
            "seq",
            "t",
            "guard",
            "mode_before",
            "mode_after",
            "energy_before",
            "energy_after",
            "before.strain",
            "before.strain_rate",
            "after.strain",
            "after.strain_rate"
        ]
    );
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), lines);
    let number = |r: &csv::StringRecord, i: usize| r[i].parse::<f64>().unwrap();
    for (k, r) in rows.iter().enumerate() {
        assert_eq!(r[0].parse::<usize>().unwrap(), k + 1);
        let jump = number(r, 6) - number(r, 5);
        assert!(jump.abs() < 1e-15);
        // The elastic reset: the strain on zero, its rate flipped.
        assert_eq!(number(r, 9), 0.0);
        assert_eq!(number(r, 10), -number(r, 8));
    }
    let both = flicker(&["events", log.to_str().unwrap(), "--csv", "--summary"]);
    assert_eq!(both.status.code(), Some(2));
}

#[test]
fn a_closed_stdout_is_not_a_crash() {
    // `flicker run ... | head -1`: the reader goes away; the run must still
    // finish its files and exit normally, not panic.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let mut child = crate::support::command()
        .args([
            "run",
            &models("mechanism_impacting.json"),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let result = child.wait_with_output().unwrap();
    assert_eq!(
        result.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert_eq!(read_json(&out.join("summary.json"))["status"], "completed");
}

/// `events --csv` gives every number of the log back bit for bit: each
/// value's text in the log and in the CSV parse (by Rust's correctly
/// rounded `str::parse`, not through the JSON reader under test) to the
/// same double, over thousands of impacts of the forced impact oscillator.
#[test]
fn events_csv_keeps_every_number_of_the_log_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let done = flicker(&[
        "run",
        &crate::automata::automaton("impact_oscillator.json"),
        "--out",
        out.to_str().unwrap(),
        "--t-end",
        "20000",
        "--quiet",
    ]);
    assert_eq!(done.status.code(), Some(0));
    let log = out.join("events.jsonl");
    let text = std::fs::read_to_string(&log).unwrap();
    let csv_out = flicker(&["events", log.to_str().unwrap(), "--csv"]);
    let mut reader = csv::Reader::from_reader(csv_out.stdout.as_slice());
    let headers = reader.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), text.lines().count());
    assert!(rows.len() > 4000, "{} impacts", rows.len());
    // The text after `"key":` (searched from `from`) up to the next , or }.
    let raw = |line: &str, from: &str, key: &str| -> f64 {
        let start = line.find(from).unwrap_or(0);
        let at = start + line[start..].find(&format!("\"{key}\":")).unwrap() + key.len() + 3;
        let end = at + line[at..].find([',', '}']).unwrap();
        line[at..end].parse().unwrap()
    };
    let mut compared = 0;
    for (line, row) in text.lines().zip(&rows) {
        for (column, value) in headers.iter().zip(row.iter()) {
            let want = match column.split_once('.') {
                Some((side, state)) => raw(line, &format!("\"{side}\":"), state),
                None if column == "t" => raw(line, "", "t"),
                None => continue,
            };
            let got: f64 = value.parse().unwrap();
            assert_eq!(got.to_bits(), want.to_bits(), "{column}: {value} in {line}");
            compared += 1;
        }
    }
    assert!(compared > 20_000, "{compared}");
}
