//! Brute-force bifurcation diagrams (`flicker diagram`) of the ball on a
//! vibrating table, against Holmes's closed form for where its period-one
//! orbit doubles: `Gamma_PD^2 = (pi (1 - r) / (1 + r))^2 + (2 (1 + r^2) /
//! (1 + r)^2)^2`, `Gamma = A w^2 / g`. Below it the impacts repeat one
//! state; above it they alternate between two.

use std::f64::consts::PI;

use serde_json::{Value, json};

use flicker::session::{Diagram, DiagramRequest, Registry, Status};

use crate::automata::automaton;
use crate::support::{flicker, read_json};

const G: f64 = 9.81;
const W: f64 = 10.0;

/// The table's amplitude at which the period-one orbit doubles, for
/// restitution `r`.
fn doubling_amplitude(r: f64) -> f64 {
    let fold = PI * (1.0 - r) / (1.0 + r);
    let gamma = (fold.powi(2) + (2.0 * (1.0 + r * r) / (1.0 + r).powi(2)).powi(2)).sqrt();
    gamma * G / (W * W)
}

/// The vibrating table with restitution `r`.
fn table(r: f64) -> Value {
    let mut scene = read_json(std::path::Path::new(&automaton("vibrating_table.json")));
    scene["parameters"]["r"] = json!(r);
    scene
}

/// The diagram of `scene` in `A` at `values`: 300 table periods of
/// transient, then 16 impacts.
fn diagram_at(scene: &Value, values: &[f64]) -> Diagram {
    let scene = Registry::builtin().from_value(scene).unwrap();
    let period = 2.0 * PI / W;
    let mut diagram: Option<Diagram> = None;
    // One request a value: the request spaces its values evenly.
    for &a in values {
        let asked = DiagramRequest {
            parameter: "A".into(),
            from: a,
            to: a,
            points: 1,
            section: "impact".into(),
            transient: Some(300.0 * period),
            record: 16,
            span: Some(100.0 * period),
            follow: false,
            past_horizon: false,
            shard: None,
            wall: 60.0,
        };
        let one = asked.on(&scene).unwrap().run(None, &|| {}).unwrap();
        match &mut diagram {
            None => diagram = Some(one),
            Some(d) => d.points.extend(one.points),
        }
    }
    diagram.unwrap()
}

/// How many distinct values (apart by more than `gap`) the take-off speed
/// takes at each point.
fn branches(diagram: &Diagram, gap: f64) -> Vec<usize> {
    let v = diagram.names.iter().position(|n| n == "v").unwrap();
    diagram
        .points
        .iter()
        .map(|p| {
            assert_eq!(
                p.status,
                Status::Completed,
                "A = {}: {:?}",
                p.parameter,
                p.reason
            );
            assert_eq!(p.records.len(), 16);
            let mut speeds: Vec<f64> = p.records.iter().map(|(_, x)| x[v]).collect();
            speeds.sort_by(f64::total_cmp);
            1 + speeds.windows(2).filter(|w| w[1] - w[0] > gap).count()
        })
        .collect()
}

#[test]
fn the_period_one_orbit_doubles_where_holmes_s_formula_puts_it() {
    // Restitutions of our own: the scene's own 0.5 lies between them.
    for r in [0.4, 0.65] {
        let a_pd = doubling_amplitude(r);
        let below = [0.90, 0.94, 0.97].map(|f| f * a_pd);
        let above = [1.03, 1.05].map(|f| f * a_pd);
        let scene = table(r);
        // The speeds of an orbit not yet doubled agree to the transient's
        // decay (about 1e-5 at 0.97 A_PD); doubled, they part by tenths.
        let gap = 1e-3;
        let period_one = diagram_at(&scene, &below);
        assert_eq!(
            branches(&period_one, gap),
            [1, 1, 1],
            "r = {r}: below A_PD = {a_pd}"
        );
        // Holmes's period-one orbit: the ball leaves at g T / 2 (it flies
        // one table period T) from the table at A sin(phi), cos(phi) =
        // pi (1 - r) / ((1 + r) Gamma), on the stable branch sin(phi) > 0.
        // The records are 300 periods past a start off the orbit: within
        // 1e-4 of it at 0.97 A_PD, where it is least stable.
        for p in &period_one.points {
            let gamma = p.parameter * W * W / G;
            let phase = (PI * (1.0 - r) / ((1.0 + r) * gamma)).acos();
            let (y, v) = (p.parameter * phase.sin(), G * PI / W);
            for (_, x) in &p.records {
                assert!(
                    (x[0] - y).abs() < 1e-4 * y,
                    "r = {r}, A = {}: y {} against {y}",
                    p.parameter,
                    x[0]
                );
                assert!(
                    (x[1] - v).abs() < 1e-4 * v,
                    "r = {r}, A = {}: v {} against {v}",
                    p.parameter,
                    x[1]
                );
            }
        }
        assert_eq!(
            branches(&diagram_at(&scene, &above), gap),
            [2, 2],
            "r = {r}: above A_PD = {a_pd}"
        );
    }
}

#[test]
fn a_doubled_orbit_alternates_between_its_two_impacts() {
    // Just above the doubling, every other impact is the same one.
    let a = 1.04 * doubling_amplitude(0.5);
    let d = diagram_at(&table(0.5), &[a]);
    let records = &d.points[0].records;
    for k in 2..records.len() {
        let (now, before) = (&records[k].1, &records[k - 2].1);
        for (x, y) in now.iter().zip(before) {
            assert!((x - y).abs() < 1e-6, "{now:?} against {before:?}");
        }
    }
    assert!((records[0].1[1] - records[1].1[1]).abs() > 0.1);
    // Each record is after the transient, and the impacts come once per
    // table period on average.
    let period = 2.0 * PI / W;
    assert!(records[0].0 >= 300.0 * period);
    let mean = (records[15].0 - records[1].0) / 14.0;
    assert!((mean - period).abs() < 1e-6 * period, "{mean}");
}

/// `flicker diagram` of the vibrating table from `from` to `to`: exit
/// code, stdout and `diagram.json`.
fn diagram_cli(from: &str, to: &str, extra: &[&str], out: &str) -> (Option<i32>, String, Value) {
    let scene = automaton("vibrating_table.json");
    let mut args = vec![
        "diagram",
        scene.as_str(),
        "--param",
        "A",
        "--from",
        from,
        "--to",
        to,
        "--points",
        "14",
        "--section",
        "impact",
        "--transient",
        "60",
        "--record",
        "8",
        "--span",
        "60",
        "--out",
        out,
        "--quiet",
    ];
    args.extend(extra);
    let done = flicker(&args);
    let stdout = String::from_utf8_lossy(&done.stdout).into_owned();
    let summary = std::fs::read_to_string(format!("{out}/diagram.json"))
        .map(|text| serde_json::from_str(&text).unwrap())
        .unwrap_or(Value::Null);
    (done.status.code(), stdout, summary)
}

#[test]
fn a_value_that_ends_at_a_zeno_point_is_named_and_the_diagram_goes_on() {
    let out = tempfile::tempdir().unwrap();
    let out = out.path().to_str().unwrap();
    // A low table lets the ball settle on it: its impacts pile up.
    let (code, stdout, summary) = diagram_cli("0.0", "0.13", &[], out);
    assert_eq!(code, Some(0), "{stdout}");
    let zeno = summary["zeno"].as_u64().unwrap();
    let completed = summary["completed"].as_u64().unwrap();
    assert!(zeno > 0 && completed > 0, "{summary}");
    assert_eq!(zeno + completed, 14);
    let short = summary["ended_short"].as_array().unwrap();
    assert!(
        short
            .iter()
            .all(|p| p["status"] == "zeno" && p["reason"].as_str().unwrap().contains("accumulate"))
    );
    assert!(stdout.contains(": zeno ("), "{stdout}");
    // The values that completed have all their records, each past the
    // transient, in the CSV.
    let csv = std::fs::read_to_string(format!("{out}/diagram.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("param,t,y,v"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows.iter().all(|r| r[1] >= 60.0));
    let top = rows.iter().filter(|r| (r[0] - 0.13).abs() < 1e-12).count();
    assert_eq!(top, 8);
}

#[test]
fn a_chaotic_window_completes_past_its_horizon_and_fails_without() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, past) = (dir.path().join("plain"), dir.path().join("past"));
    let (code, _, without) = diagram_cli("0.165", "0.18", &[], plain.to_str().unwrap());
    assert_eq!(code, Some(0));
    assert!(without["failed"].as_u64().unwrap() > 0, "{without}");
    let (code, stdout, with) =
        diagram_cli("0.165", "0.18", &["--past-horizon"], past.to_str().unwrap());
    assert_eq!(code, Some(0), "{stdout}");
    assert_eq!(with["failed"], 0, "{with}");
    assert_eq!(with["past_horizon"], true);
}

#[test]
fn following_carries_the_clock_from_one_value_to_the_next() {
    let out = tempfile::tempdir().unwrap();
    let out = out.path().to_str().unwrap();
    let (code, stdout, _) = diagram_cli("0.13", "0.12", &["--follow"], out);
    assert_eq!(code, Some(0), "{stdout}");
    let csv = std::fs::read_to_string(format!("{out}/diagram.csv")).unwrap();
    let times: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    // Each value runs on from where the last ended: time only grows, past
    // one transient per value.
    assert!(times.windows(2).all(|w| w[1] > w[0]));
    assert!(times.last().unwrap() > &(13.0 * 60.0));
}

#[test]
fn bad_requests_name_their_flag_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = automaton("vibrating_table.json");
    for (flag, bad) in [
        ("--param", "B"),
        ("--section", "bounce"),
        ("--record", "0"),
        ("--points", "0"),
        ("--transient", "-1"),
        ("--from", "nan"),
        ("--state", "x"),
    ] {
        let out = dir.path().join(flag.trim_start_matches('-'));
        let out = out.to_str().unwrap();
        let mut asked = vec![
            ("--param", "A"),
            ("--from", "0.12"),
            ("--to", "0.13"),
            ("--points", "2"),
            ("--section", "impact"),
            ("--out", out),
        ];
        match asked.iter_mut().find(|(f, _)| *f == flag) {
            Some(given) => given.1 = bad,
            None => asked.push((flag, bad)),
        }
        let mut args = vec!["diagram", scene.as_str()];
        args.extend(asked.iter().flat_map(|(f, v)| [*f, *v]));
        let done = flicker(&args);
        let stderr = String::from_utf8_lossy(&done.stderr);
        assert_eq!(done.status.code(), Some(2), "{flag}: {stderr}");
        assert!(stderr.contains(flag), "{flag}: {stderr}");
        assert!(!std::path::Path::new(out).exists(), "{flag}: wrote {out}");
    }
}
