"""Run.plot with matplotlib (Agg): the lines drawn are the samples split
at the events, each flight of the bouncing ball on its own parabola, each
bounce a dashed jump that keeps the height, and the belt's sticks in red
along v = vb."""

import numpy as np
import pytest

import flicker
from conftest import MODELS

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def test_states_over_time_are_the_samples_split_at_the_bounces():
    run = flicker.run(MODELS / "automata/bouncing_ball.json", t_end=2.0,
                      t_eval=np.linspace(0.0, 2.0, 401))
    ax = run.plot()
    bounces = len(run.events["t"])
    assert bounces >= 3
    lines = [l for l in ax.get_lines() if l.get_linestyle() == "-"]
    # Two states, one line each per flight.
    assert len(lines) == 2 * (bounces + 1)
    t, y = lines[0].get_data()
    first = run.samples["t"] < run.events["t"][0]
    assert np.array_equal(t[:-1], run.samples["t"][first])
    assert np.array_equal(y[:-1], run.samples["y"][first])
    assert t[-1] == run.events["t"][0]
    assert {l.get_label() for l in lines} >= {"y", "v"}


def test_the_phase_plane_draws_parabolas_and_dashed_bounces():
    g = 9.81
    run = flicker.run(MODELS / "automata/bouncing_ball.json", t_end=2.0,
                      t_eval=np.linspace(0.0, 2.0, 401))
    ax = run.plot("y", "v")
    flights = [l for l in ax.get_lines() if l.get_linestyle() == "-"]
    jumps = [l for l in ax.get_lines() if l.get_linestyle() == "--"]
    assert len(jumps) == len(run.events["t"]) and len(flights) == len(jumps) + 1
    for line in flights:
        y, v = line.get_data()
        level = v * v + 2 * g * y
        assert np.ptp(level) <= 1e-9 * max(1.0, level.max())
    for line in jumps:
        y, v = line.get_data()
        assert y[0] == y[1] == pytest.approx(0.0, abs=1e-12) and v[0] < 0 < v[1]


def test_sliding_is_red_and_bad_requests_say_why():
    scene = MODELS / "automata/stick_slip_belt.json"
    run = flicker.run(scene, t_eval=np.linspace(0.0, 40.0, 2001))
    ax = run.plot("x", "v")
    red = [l for l in ax.get_lines()
           if matplotlib.colors.same_color(l.get_color(), "tab:red")]
    slides = sum(str(g).startswith("slide:") for g in run.events["guard"])
    assert len(red) == slides >= 5
    for line in red:
        _, v = line.get_data()
        assert np.all(np.abs(v - 0.2) <= 1e-12)
    with pytest.raises(ValueError, match="t_eval"):
        flicker.run(scene).plot()
    with pytest.raises(ValueError, match="no state 'w'"):
        run.plot("x", "w")
    with pytest.raises(ValueError, match="both"):
        run.plot("x")
