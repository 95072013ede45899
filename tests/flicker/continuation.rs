//! Continuation (`flicker continue`) of the ball on a vibrating table in
//! the table's amplitude `A`, against Holmes's closed forms written out
//! here: along the period-one branch the impact phase `cos(phi) = pi (1 -
//! r) / ((1 + r) Gamma)` and the take-off speed `g T / 2`; the branch is
//! born in a fold at `Gamma_1 = pi (1 - r) / (1 + r)`, and the exact
//! impact map's eigenvalue reaches -1 (trace `1 + r^2 - (1 + r)^2 Gamma
//! sin(phi)` equal to `-(1 + r^2)`) at `Gamma_PD^2 = Gamma_1^2 + 4 (1 +
//! r^2)^2 / (1 + r)^4`.

use std::f64::consts::PI;
use std::path::Path;

use crate::automata::automaton;
use crate::support::flicker;

const G: f64 = 9.81;
const R: f64 = 0.5;
const W: f64 = 10.0;

/// `flicker continue` of `vibrating_table.json` in `A` to `to`: exit code,
/// stdout, and the rows of `continuation.csv` (header first).
fn follow(to: f64, points: usize, out: &Path) -> (Option<i32>, String, Vec<Vec<String>>) {
    let period = (2.0 * PI / W).to_string();
    let done = flicker(&[
        "continue",
        &automaton("vibrating_table.json"),
        "--section",
        "impact",
        "--param",
        "A",
        "--to",
        &to.to_string(),
        "--settle",
        "2",
        "--forcing-period",
        &period,
        "--points",
        &points.to_string(),
        "--brute-force",
        "20",
        "--out",
        out.to_str().unwrap(),
    ]);
    let rows = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_path(out.join("continuation.csv"))
        .unwrap()
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (
        done.status.code(),
        String::from_utf8_lossy(&done.stdout).into_owned(),
        rows,
    )
}

fn gamma(a: f64) -> f64 {
    a * W * W / G
}

/// The row whose label is `label`.
fn labelled<'r>(rows: &'r [Vec<String>], label: &str) -> &'r Vec<String> {
    rows.iter()
        .find(|r| r.last().map(String::as_str) == Some(label))
        .unwrap_or_else(|| panic!("no `{label}` in {rows:?}"))
}

#[test]
fn the_table_branch_follows_the_closed_form_and_period_doubles_where_it_should() {
    let dir = tempfile::tempdir().unwrap();
    let (code, said, rows) = follow(0.16, 200, dir.path());
    assert_eq!(code, Some(0), "{said}");
    assert_eq!(
        rows[0],
        [
            "parameter",
            "period",
            "y",
            "v",
            "t",
            "largest_multiplier",
            "stable",
            "label"
        ]
    );
    let gamma_1 = PI * (1.0 - R) / (1.0 + R);
    let gamma_pd = (gamma_1.powi(2) + 4.0 * (1.0 + R * R).powi(2) / (1.0 + R).powi(4)).sqrt();
    let a_pd = gamma_pd * G / (W * W);
    let pd = labelled(&rows, "period doubling");
    let found: f64 = pd[0].parse().unwrap();
    assert!(
        (found - a_pd).abs() < 1e-8,
        "period doubling at {found}, closed form {a_pd}"
    );
    assert!(said.contains("period doubling at A ="), "{said}");
    let period = 2.0 * PI / W;
    for row in &rows[1..] {
        let x = |k: usize| row[k].parse::<f64>().unwrap();
        let (a, v, t) = (x(0), x(3), x(4));
        let phi = (PI * (1.0 - R) / ((1.0 + R) * gamma(a))).acos();
        let phase = (W * t).rem_euclid(2.0 * PI);
        assert!(
            (phase - phi).abs() < 1e-9,
            "A {a}: phase {phase} against {phi}"
        );
        assert!((v - G * period / 2.0).abs() < 1e-9, "A {a}: speed {v}");
        assert!((x(1) - period).abs() < 1e-9);
        // Stable below the period doubling, not above (the point itself
        // sits on the boundary).
        if row[7].is_empty() {
            assert_eq!(row[6] == "true", a < a_pd, "A {a}: {row:?}");
        }
    }
    assert!(rows.len() > 20);
    for picture in ["bifurcation.svg", "bifurcation.png"] {
        assert!(std::fs::metadata(dir.path().join(picture)).unwrap().len() > 1000);
    }
    // The brute-force dots span the whole branch, hold the clock as the
    // forcing's phase (they climbed as a ladder of absolute times), and
    // where the orbit is stable, well inside its range, lie on it.
    let dots: Vec<Vec<f64>> = csv::Reader::from_path(dir.path().join("brute_force.csv"))
        .unwrap()
        .records()
        .map(|r| r.unwrap().iter().map(|v| v.parse().unwrap()).collect())
        .collect();
    let params: Vec<f64> = rows[1..].iter().map(|r| r[0].parse().unwrap()).collect();
    let (lo, hi) = params
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &a| {
            (l.min(a), h.max(a))
        });
    let (first, last) = (dots[0][0], dots[dots.len() - 1][0]);
    assert!(
        (first - lo).abs() < 1e-12 && (last - hi).abs() < 1e-12,
        "{first}..{last} against {lo}..{hi}"
    );
    let a_fold = gamma_1 * G / (W * W);
    let mut on_branch = 0;
    for dot in &dots {
        let (a, t) = (dot[0], dot[3]);
        assert!((0.0..period).contains(&t), "A {a}: t {t} is not a phase");
        if a > a_fold + 0.2 * (a_pd - a_fold) && a < a_pd - 0.2 * (a_pd - a_fold) {
            let phi = (PI * (1.0 - R) / ((1.0 + R) * gamma(a))).acos();
            assert!(
                (W * t - phi).abs() < 1e-3,
                "A {a}: phase {} against {phi}",
                W * t
            );
            on_branch += 1;
        }
    }
    assert!(on_branch > 10, "{on_branch}");
}

#[test]
fn the_table_branch_turns_back_at_its_fold_onto_the_unstable_orbit() {
    let dir = tempfile::tempdir().unwrap();
    let (code, said, rows) = follow(0.09, 60, dir.path());
    assert_eq!(code, Some(0), "{said}");
    let a_fold = PI * (1.0 - R) / (1.0 + R) * G / (W * W);
    let fold = labelled(&rows, "fold");
    let found: f64 = fold[0].parse().unwrap();
    assert!(
        (found - a_fold).abs() < 1e-8,
        "fold at {found}, closed form {a_fold}"
    );
    // Past the fold the parameter grows again, on the other branch: the
    // impact phase's sine negative, the orbit unstable.
    let at = rows
        .iter()
        .position(|r| r.last().map(String::as_str) == Some("fold"))
        .unwrap();
    let after = &rows[at + 1..];
    assert!(!after.is_empty());
    // The clock is the forcing's phase, in [0, T) as in brute_force.csv,
    // on both branches (Newton leaves the unstable one's below zero).
    for row in &rows[1..] {
        let t: f64 = row[4].parse().unwrap();
        assert!((0.0..2.0 * PI / W).contains(&t), "{row:?}");
    }
    for row in after {
        let x = |k: usize| row[k].parse::<f64>().unwrap();
        let phase = (W * x(4)).rem_euclid(2.0 * PI);
        assert!(phase.sin() < 0.0, "{row:?}");
        assert_eq!(row[6], "false");
        let phi = -(PI * (1.0 - R) / ((1.0 + R) * gamma(x(0)))).acos();
        assert!((phase - phi.rem_euclid(2.0 * PI)).abs() < 1e-8, "{row:?}");
    }
}

/// The built-in mechanism's impacting orbit followed in `eta` (its
/// family, not an automaton): every orbit's period is the closed form's
/// `T_imp = 2 atan2(sqrt(2 H), 1 - eta)` at the energy `H` of its section
/// state, and stays neutral (the mechanism is integrable). The continuum,
/// with no finite state, is refused in one line (exit 2).
#[test]
fn the_built_in_mechanism_is_continued_on_its_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let done = flicker(&[
        "continue",
        &crate::support::models("mechanism_impacting.json"),
        "--section",
        "impact",
        "--param",
        "eta",
        "--to",
        "1.5",
        "--points",
        "40",
        "--brute-force",
        "0",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let text = std::fs::read_to_string(dir.path().join("continuation.csv")).unwrap();
    let mut rows = text.lines();
    assert_eq!(
        rows.next(),
        Some("parameter,period,strain,strain_rate,largest_multiplier,stable,label")
    );
    let mut last_eta = 0.0;
    for row in rows {
        let row: Vec<&str> = row.split(',').collect();
        let number = |i: usize| row[i].parse::<f64>().unwrap();
        let (eta, period, rate) = (number(0), number(1), number(3));
        let t_imp = 2.0 * (rate.abs()).atan2(1.0 - eta);
        assert!((period - t_imp).abs() < 1e-10, "{row:?}: T_imp {t_imp}");
        assert!((number(4) - 1.0).abs() < 1e-8, "{row:?}");
        last_eta = eta;
    }
    assert!(last_eta > 1.49, "the branch reached eta = {last_eta}");
    let done = flicker(&[
        "continue",
        &crate::support::models("continuum_release_paper.json"),
        "--section",
        "impact",
        "--param",
        "load",
        "--to",
        "1.5",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(done.status.code(), Some(2));
    let err = String::from_utf8_lossy(&done.stderr);
    assert!(
        err.contains("no finite state") && err.trim().lines().count() == 1,
        "{err}"
    );
}

/// The table's frequency `w` sets the forcing, whose period
/// `--forcing-period` holds fixed: following it is refused (exit 2), not
/// run on orbits that close on the wrong period.
#[test]
fn continuation_in_the_forcing_frequency_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let done = flicker(&[
        "continue",
        &automaton("vibrating_table.json"),
        "--section",
        "impact",
        "--param",
        "w",
        "--to",
        "11",
        "--forcing-period",
        &(2.0 * PI / W).to_string(),
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(done.status.code(), Some(2));
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(said.contains("`w`") && said.contains("forcing"), "{said}");
    assert!(!dir.path().join("continuation.csv").exists());
}

/// The forced linear oscillator `x'' + 2 zeta x' + x = cos(w t)` against a
/// stop at `s` (`impact_oscillator.json`, from `s = 2`): its impacting
/// period-one orbit, followed as the stop moves out, grazes where `s` is
/// the free response's amplitude `1 / sqrt((1 - w^2)^2 + (2 zeta w)^2)`.
/// The branch labels `grazing` there to 1e-8, says the impacting orbits
/// lie below it, and ends, within its minute (`--wall 60`).
#[test]
fn the_impact_oscillator_s_branch_grazes_at_the_free_amplitude() {
    let (zeta, w) = (0.05_f64, 0.8_f64);
    let amplitude = 1.0 / ((1.0 - w * w).powi(2) + (2.0 * zeta * w).powi(2)).sqrt();
    let params = serde_json::json!({"zeta": zeta, "w": w, "r": 0.8, "s": 2.0, "A": 1.0});
    let (said, rows) = continue_oscillator(params, ("s", 3.0), 300.0, 2000.0);
    assert!(said.contains("impacting orbits exist below"), "{said}");
    let graze: Vec<&str> = rows.lines().filter(|r| r.ends_with(",grazing")).collect();
    assert_eq!(graze.len(), 1, "{rows}");
    let s: f64 = graze[0].split(',').next().unwrap().parse().unwrap();
    assert!(
        (s - amplitude).abs() < 1e-8,
        "grazing at {s}, closed form {amplitude}"
    );
    let last = rows.lines().last().unwrap();
    assert!(last.ends_with(",grazing"), "the branch ends there: {last}");
}

/// `flicker continue` of the forced oscillator `x'' + 2 zeta x' + x = A
/// cos(w t)` against a stop at `s` (`impact_oscillator.json` with the
/// forcing's amplitude a parameter) with `params`, in `(parameter, to)`
/// after `settle`, the scene's `t_end` given: what it said (exit 0
/// asserted) and `continuation.csv`.
fn continue_oscillator(
    params: serde_json::Value,
    (param, to): (&str, f64),
    settle: f64,
    t_end: f64,
) -> (String, String) {
    let w = params["w"].as_f64().unwrap();
    let mut scene =
        crate::support::read_json(std::path::Path::new(&automaton("impact_oscillator.json")));
    scene["parameters"] = params;
    scene["modes"]["free"]["flow"]["v"] = serde_json::json!("A * cos(w * t) - 2 * zeta * v - x");
    scene["t_end"] = serde_json::json!(t_end);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("oscillator.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let (period, to, settle) = (
        (2.0 * PI / w).to_string(),
        to.to_string(),
        settle.to_string(),
    );
    let done = flicker(&[
        "continue",
        path.to_str().unwrap(),
        "--section",
        "impact",
        "--param",
        param,
        "--to",
        &to,
        "--settle",
        &settle,
        "--forcing-period",
        &period,
        "--brute-force",
        "0",
        "--wall",
        "60",
        "--quiet",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let said = String::from_utf8_lossy(&done.stdout).into_owned();
    assert_eq!(
        done.status.code(),
        Some(0),
        "{said}{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let rows = std::fs::read_to_string(dir.path().join("continuation.csv")).unwrap();
    (said, rows)
}

/// A forced oscillator of our own, `x'' + 2 zeta x' + x = A cos(w t)`
/// against a stop at `s`, continued in the forcing amplitude `A` from an
/// impacting orbit: its impacting branch grazes where the free response's
/// amplitude `A / sqrt((1 - w^2)^2 + (2 zeta w)^2)` reaches the stop.
/// Where the corrector cannot come near the graze (its orbits' returns
/// graze within their own error), the last orbits' impact speeds locate it;
/// the label sits there to 1e-8, not on the last orbit the corrector
/// reached (which impacts still, 1.1e-5 short of it, where it was once
/// put). The stop's position moves it too: see the test above.
#[test]
fn a_graze_is_labelled_only_where_located_whichever_parameter_moves_it() {
    for (zeta, w, r, stop) in [(0.2_f64, 1.2_f64, 0.5, None), (0.05, 0.8, 0.8, Some(2.0))] {
        let gain = 1.0 / ((1.0 - w * w).powi(2) + (2.0 * zeta * w).powi(2)).sqrt();
        // The stop at 0.8 of the free amplitude at A = 1, or where given.
        let stop = stop.unwrap_or(0.8 * gain);
        let grazing = stop / gain;
        let params = serde_json::json!({"zeta": zeta, "w": w, "r": r, "s": stop, "A": 1.0});
        let (said, rows) = continue_oscillator(params, ("A", 0.5), 400.0, 5000.0);
        let graze: Vec<&str> = rows.lines().filter(|r| r.ends_with(",grazing")).collect();
        assert_eq!(graze.len(), 1, "zeta {zeta}: {said}\n{rows}");
        let a: f64 = graze[0].split(',').next().unwrap().parse().unwrap();
        assert!(
            (a - grazing).abs() < 1e-8,
            "zeta {zeta}: grazing at A = {a}, closed form {grazing}"
        );
    }
}
