//! `flicker compare-models`: the chain at several N and the continuum on
//! one release, sampled alike; the paper's continuum found where
//! docs/physics.md s.6 says it is (a front at exactly c_b; in the traction-free
//! reading an end that moves too slowly), and scenes it cannot compare
//! refused.

use flicker::analysis::release_convergence::{Model, distance, release as release_of, run_all};
use flicker::engine::Limits;
use flicker::models as scene;
use flicker::models::ContinuumScene;
use flicker::models::continuum::Variant;

use crate::support::{flicker, models, read_json};

fn release(name: &str) -> ContinuumScene {
    let scene = scene::load(std::path::Path::new(&models(name))).unwrap();
    release_of(&scene).unwrap().string
}

#[test]
fn the_paper_continuum_front_runs_at_c_and_its_free_end_lags_the_chain() {
    let mut free = release("continuum_release_free_end.json");
    free.snapshots = vec![0.2];
    let models = [
        Model::Chain(50),
        Model::Chain(100),
        Model::Continuum(Variant::Paper),
    ];
    free.samples = 41;
    let tracks = run_all(&free, &models, &Limits::default()).unwrap();
    let reference = &tracks[1];
    let d: Vec<_> = tracks.iter().map(|t| distance(t, reference)).collect();
    assert_eq!(d[1].right_end, 0.0);
    // The continuum's front: a sharp jump at x = 1 - t, seen on windows
    // 0.02 apart, so its fitted speed is c_b = 1 to within the grid.
    let speed = d[2].front_speed.unwrap();
    assert!((speed - 1.0).abs() < 0.03, "{speed}");
    // The chain's end is traction-free: until the wall is reached its
    // momentum is -(1.1 - 0) t, and its end falls far faster than the
    // paper's continuum (held at eps = 0, end speed 0.1).
    let at = |track: &flicker::analysis::release_convergence::Track, t: f64| {
        track
            .samples
            .iter()
            .find(|s| (s.t - t).abs() < 1e-12)
            .unwrap()
            .right_end
    };
    let (chain, paper) = (at(&tracks[1], 0.3), at(&tracks[2], 0.3));
    assert!((paper - (0.2 - 0.1 * 0.3)).abs() < 1e-12, "{paper}");
    assert!(
        paper - chain > 0.04,
        "chain {chain}, paper continuum {paper}"
    );
    assert!(d[2].right_end > 0.05, "{:?}", d[2]);
    // Both chains see the front running ahead of c_b (collision pulses).
    for k in 0..2 {
        assert!(d[k].front_speed.unwrap() > 3.0, "{:?}", d[k]);
    }
}

#[test]
fn the_command_writes_its_tables_summary_and_pictures() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    let o = flicker(&[
        "compare-models",
        &models("continuum_release_paper.json"),
        "--units",
        "40,80",
        "--samples",
        "31",
        "--cells",
        "50",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let summary = read_json(&out.join("compare_models.json"));
    assert_eq!(summary["reference"], "chain N=80");
    let models = summary["models"].as_array().unwrap();
    assert_eq!(models.len(), 4);
    assert_eq!(models[2]["model"], "continuum (paper)");
    assert_eq!(models[3]["model"], "continuum (homogenized)");
    let rows = std::fs::read_to_string(out.join("compare_models.csv")).unwrap();
    assert_eq!(rows.lines().count(), 1 + 4 * 31);
    let coarse = std::fs::read_to_string(out.join("coarse.csv")).unwrap();
    // Four snapshots of 101 window centres for each of four models.
    assert_eq!(coarse.lines().count(), 1 + 4 * 4 * 101);
    for name in ["right_end", "front", "window_strain", "hidden_energy"] {
        assert!(out.join(format!("{name}.svg")).exists(), "{name}");
    }
}

#[test]
fn scenes_that_cannot_be_compared_are_refused() {
    let o = flicker(&["compare-models", &models("mechanism_impacting.json")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("chain or continuum"));
    let o = flicker(&["compare-models", &models("chain_cradle.json")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("initial"));
    let o = flicker(&[
        "compare-models",
        &models("continuum_release_paper.json"),
        "--units",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn advise_weighs_a_chain_scene_against_its_continua() {
    // The paper's reading at N = 200: the chain itself is cheap, and
    // neither continuum keeps the end within 0.001 of it.
    let o = flicker(&[
        "advise",
        &models("chain_release_paper.json"),
        "--tolerance",
        "0.001",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("continuum (homogenized): loaded end within"),
        "{text}"
    );
    assert!(
        text.contains("advice: no continuum reproduces this scene within 0.001; run the chain"),
        "{text}"
    );
    // A tolerance the paper's continuum meets (its end stays within 0.1
    // of the chain's) turns the advice, with the cost ratio measured.
    let o = flicker(&[
        "advise",
        &models("chain_release_paper.json"),
        "--tolerance",
        "0.1",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("advice: continuum (paper) reproduces"),
        "{text}"
    );
    let o = flicker(&["advise", &models("continuum_release_paper.json")]);
    assert_eq!(o.status.code(), Some(2));
}
