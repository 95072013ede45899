"""flicker.run against the command line on the same scenes: the same
events, bit for bit, and the same summary; the arrays' dtypes and shapes;
and one run checked against physics written out here."""

import json
import math

import numpy as np
import pytest

import flicker
from conftest import MODELS, read_log

SCENES = [
    "mechanism_impacting.json",
    "mechanism_angle.json",
    "chain_cradle.json",
    "continuum_release_paper.json",
    "automata/bouncing_ball.json",
    "automata/impact_oscillator.json",
    "automata/mechanism_charts.json",
]


@pytest.mark.parametrize("name", SCENES)
def test_the_same_scene_gives_the_same_events_as_the_command_line(name, cli, tmp_path):
    done, out = cli("run", MODELS / name, "--out", tmp_path / "cli", "--quiet")
    assert done.returncode in (0, 3), done.stderr
    logged = read_log(tmp_path / "cli" / "events.jsonl")
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    run = flicker.run(MODELS / name)
    ev = run.events
    assert len(ev["t"]) == len(logged) > 0
    for k, line in enumerate(logged):
        assert ev["seq"][k] == line["seq"]
        assert ev["t"][k] == line["t"]
        assert ev["guard"][k] == line["guard"]
        assert ev["mode_before"][k] == line["mode_before"]
        assert ev["mode_after"][k] == line["mode_after"]
        for side in ("before", "after"):
            for name_, value in line[side].items():
                column = run.state_names.index(name_)
                assert ev[side][k, column] == value
        for label in ("unit", "rel_velocity", "x"):
            if label in line:
                assert ev[label][k] == line[label]
    # The summary as summary.json holds it, but for what names the run.
    for key in ("scene", "log", "wall_seconds"):
        summary.pop(key)
        run.summary.pop(key)
    assert run.summary == summary


def test_arrays_have_their_dtypes_and_shapes():
    run = flicker.run(MODELS / "automata" / "impact_oscillator.json")
    ev = run.events
    n = len(ev["t"])
    assert n > 20
    assert ev["t"].dtype == np.float64 and ev["seq"].dtype == np.uint64
    for key in ("guard", "mode_before", "mode_after"):
        assert ev[key].dtype.kind == "U" and ev[key].shape == (n,)
    # The forced oscillator carries the clock as a state.
    assert run.state_names == ["x", "v", "t"]
    assert ev["before"].shape == ev["after"].shape == (n, 3)
    assert ev["before"].dtype == np.float64
    # No energy in this file: NaN, not zero.
    assert np.isnan(ev["energy_before"]).all()
    chain = flicker.run(MODELS / "chain_cradle.json")
    assert chain.events["before"].shape == (len(chain.events["t"]), 0)
    assert chain.events["unit"].dtype == np.int64
    assert chain.trace["t"].dtype == np.float64
    assert len(chain.profiles) == 3 and chain.profiles[0]["strain"].shape == (5,)


def test_bounces_from_python_meet_the_closed_form():
    g, e, h = 9.81, 0.8, 1.0
    run = flicker.run(MODELS / "automata" / "bouncing_ball.json")
    t = run.events["t"]
    v = run.events["before"][:, run.state_names.index("v")]
    falling = v < 0
    t1 = math.sqrt(2 * h / g)
    expected = t1 + 2 * t1 * e * (1 - e ** np.arange(falling.sum())) / (1 - e)
    assert np.max(np.abs(t[falling] - expected)) < 1e-13


def test_overrides_and_a_log_on_disk(cli, tmp_path):
    log = tmp_path / "events.jsonl"
    run = flicker.run(MODELS / "mechanism_impacting.json", t_end=50, method="dop853", rtol=1e-10, atol=1e-10, log=log)
    assert run.summary["method"] == "dop853" and run.summary["t_end"] == 50
    done, _ = cli(
        "run", MODELS / "mechanism_impacting.json", "--out", tmp_path / "cli", "--quiet",
        "--t-end", "50", "--method", "dop853", "--rtol", "1e-10", "--atol", "1e-10",
    )
    assert done.returncode == 0
    assert log.read_bytes() == (tmp_path / "cli" / "events.jsonl").read_bytes()
    assert run.summary["log"] == str(log)
    quiet = flicker.run(MODELS / "mechanism_impacting.json", events=False)
    assert quiet.events is None and quiet.summary["events"] == 234


def test_a_dict_and_a_json_string_are_scenes():
    scene = json.loads((MODELS / "automata" / "bouncing_ball.json").read_text())
    from_dict = flicker.run(scene)
    from_text = flicker.run(json.dumps(scene))
    from_path = flicker.run(str(MODELS / "automata" / "bouncing_ball.json"))
    assert np.array_equal(from_dict.events["t"], from_path.events["t"])
    assert np.array_equal(from_text.events["before"], from_path.events["before"])
    assert from_dict.summary["scene"] == "<scene>"


def test_to_pandas_has_a_row_per_event_and_a_column_per_state():
    pd = pytest.importorskip("pandas")
    run = flicker.run(MODELS / "automata" / "bouncing_ball.json")
    frame = run.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert len(frame) == len(run.events["t"])
    assert {"t", "guard", "before.y", "before.v", "after.v"} <= set(frame.columns)
    assert np.allclose(frame["after.v"], -0.8 * frame["before.v"], rtol=1e-15, atol=0)


def test_a_flow_that_reads_sign_slides_from_a_dict():
    """Dry friction written as a dict: the block turns at atan(6/13) + k pi
    and sticks at atan(6/13) + 7 pi, x = 15 - sqrt(205) (the closed form),
    the events named after the surface."""
    scene = {
        "model": "automaton",
        "states": ["x", "v"],
        "initial": {"x": 12.0, "v": 6.0},
        "modes": {"block": {"flow": {"x": "v", "v": "-x - sign(v)"}}},
        "t_end": 30.0,
    }
    run = flicker.run(scene)
    first = math.atan(6 / 13)
    assert list(run.events["guard"]) == ["cross:v"] * 7 + ["slide:v"]
    assert np.allclose(run.events["t"], [first + k * math.pi for k in range(8)], rtol=0, atol=1e-12)
    assert run.events["mode_after"][-1] == "block[v=0]"
    assert abs(run.summary["final_state"]["x"] - (15 - math.sqrt(205))) < 1e-12
    assert run.summary["final_state"]["v"] == 0.0


def test_t_eval_samples_lie_on_the_closed_form_and_match_the_command_line(cli, tmp_path):
    """The bouncing ball's first fall, y = 1 - g t^2 / 2, sampled from
    Python at times in any order and with a repeat (a row each, in the order
    asked): within 1e-12 and each sample's bound, and the same numbers, bit
    for bit, as `flicker run --at` writes (in increasing time, once each)."""
    g = 9.81
    times = [0.3, 0.0, 0.1, 0.2, 0.4, 0.1]
    run = flicker.run(MODELS / "automata/bouncing_ball.json", t_eval=times)
    s = run.samples
    assert list(s) == ["t", "y", "v", "bound"]
    assert s["t"].dtype == np.float64
    assert list(s["t"]) == times
    for t, y, v, bound in zip(s["t"], s["y"], s["v"], s["bound"]):
        assert abs(y - (1.0 - 0.5 * g * t * t)) <= 1e-12 and abs(v + g * t) <= 1e-12
        assert bound >= 0.0
    done, out = cli(
        "run", MODELS / "automata/bouncing_ball.json", "--out", tmp_path / "cli", "--quiet",
        "--at", ",".join(str(t) for t in times),
    )
    assert done.returncode == 0, done.stderr
    rows = (tmp_path / "cli" / "samples.csv").read_text().splitlines()
    assert rows[0] == "t,y,v,bound"
    assert len(rows) == 1 + len(set(times))
    for row in rows[1:]:
        values = [float(v) for v in row.split(",")]
        for k in np.flatnonzero(s["t"] == values[0]):
            assert values == [s["t"][k], s["y"][k], s["v"][k], s["bound"][k]]


def test_a_scene_dict_holding_nan_names_the_field():
    scene = json.loads((MODELS / "automata/bouncing_ball.json").read_text())
    scene["parameters"]["e"] = float("nan")
    with pytest.raises(flicker.SceneError) as bad:
        flicker.run(scene)
    assert bad.value.field == "parameters.e"
    assert "NaN" in bad.value.reason or "nan" in bad.value.reason
    # NumPy numbers are written as JSON numbers.
    scene["parameters"]["e"] = np.float64(0.8)
    scene["t_end"] = np.int64(1)
    assert flicker.run(scene).summary["t_end"] == 1.0


def test_t_eval_out_of_range_or_on_a_chain_is_refused():
    with pytest.raises(flicker.SceneError) as bad:
        flicker.run(MODELS / "automata/bouncing_ball.json", t_eval=[1e6])
    assert bad.value.field == "t_eval"
    with pytest.raises(flicker.SceneError) as chain:
        flicker.run(MODELS / "chain_cradle.json", t_eval=[0.0, 1.0])
    assert "offers no samples" in str(chain.value)
    assert flicker.run(MODELS / "automata/bouncing_ball.json").samples is None


@pytest.mark.parametrize("name, states", [
    ("mechanism_impacting.json", ["strain", "strain_rate"]),
    ("automata/impact_oscillator.json", ["x", "v"]),
])
def test_samples_are_the_command_lines_bit_for_bit(name, states, cli, tmp_path):
    """The mechanism's and the forced impact oscillator's samples, which
    tests/flicker/samples.rs holds to their closed forms (1e-12, 1e-11),
    are the same from Python as from the command line."""
    times = np.linspace(0.0, 100.0, 501)
    run = flicker.run(MODELS / name, t_eval=times)
    done, out = cli("run", MODELS / name, "--out", tmp_path / "cli", "--quiet", "--samples", "2",
                    "--at", ",".join(repr(float(t)) for t in times))
    assert done.returncode == 2, "--samples and --at together are refused"
    done, out = cli("run", MODELS / name, "--out", tmp_path / "cli", "--quiet",
                    "--at", ",".join(repr(float(t)) for t in times))
    assert done.returncode == 0, done.stderr
    lines = (tmp_path / "cli" / "samples.csv").read_text().splitlines()
    assert lines[0] == ",".join(["t", *states, "bound"])
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    assert np.array_equal(table[:, 0], run.samples["t"])
    for k, state in enumerate(states):
        assert np.array_equal(table[:, k + 1], run.samples[state])
    assert np.array_equal(table[:, -1], run.samples["bound"])


def test_past_the_horizon_from_python_matches_the_command_line(cli, tmp_path):
    # The chaotic table ball (restitution 0.8, Gamma = 3.7): it stops at
    # its horizon, and with past_horizon goes on to t = 400, every event
    # from the horizon on a shadow, as `flicker run --past-horizon` logs.
    scene = json.loads((MODELS / "automata" / "vibrating_table.json").read_text())
    p = scene["parameters"]
    p["r"], p["A"] = 0.8, 3.7 * p["g"] / p["w"] ** 2
    scene["t_end"] = 400.0
    stopped = flicker.run(scene)
    assert stopped.status == "failed" and "--past-horizon" in stopped.summary["reason"]
    run = flicker.run(scene, past_horizon=True)
    s = run.summary
    assert s["status"] == "completed" and s["error_bound"] is None
    assert s["horizon"] == stopped.summary["horizon"]
    shadow = run.events["shadow"]
    assert shadow.dtype == np.bool_
    assert np.array_equal(shadow, run.events["t"] >= s["horizon"])
    assert shadow.sum() == s["shadow_events"] > 100
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    done, _ = cli("run", path, "--out", tmp_path / "cli", "--quiet", "--past-horizon")
    assert done.returncode == 0, done.stderr
    logged = read_log(tmp_path / "cli" / "events.jsonl")
    assert [line.get("shadow", False) for line in logged] == list(shadow)
