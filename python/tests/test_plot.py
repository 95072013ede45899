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
    # Its legend says what red is.
    assert "sliding on a switching surface" in [t.get_text() for t in ax.get_legend().get_texts()]
    with pytest.raises(ValueError, match="t_eval"):
        flicker.run(scene, events=False).plot()
    with pytest.raises(ValueError, match="no state 'w'"):
        run.plot("x", "w")
    with pytest.raises(ValueError, match="both"):
        run.plot("x")


def test_a_bifurcation_diagram_is_solid_where_stable_and_names_its_bifurcations():
    branch = flicker.continuation(MODELS / "automata/vibrating_table.json", "impact", "A", 0.16,
                                  settle=2, forcing_period=2 * np.pi / 10)
    ax = flicker.bifurcation(branch, "t")
    p, t, stable = branch["parameter"], branch["t"], np.asarray(branch["stable"])
    solid = [l for l in ax.get_lines() if l.get_linestyle() == "-"]
    dashed = [l for l in ax.get_lines() if l.get_linestyle() == "--"]
    assert solid and dashed
    # Every drawn point is a branch point, and a solid stretch's points are
    # stable orbits but perhaps its last (the next stretch's first).
    for line in solid:
        x, y = line.get_data()
        for a, b in zip(x[:-1], y[:-1]):
            k = int(np.flatnonzero(p == a)[0])
            assert t[k] == b and stable[k]
    names = [c.get_text() for c in ax.texts]
    assert "period doubling" in names
    k = list(branch["label"]).index("period doubling")
    assert ax.texts[names.index("period doubling")].xy == (p[k], t[k])
    with pytest.raises(ValueError, match="no 'w'"):
        flicker.bifurcation(branch, "w")


def test_a_work_precision_chart_has_a_line_per_method_through_its_runs():
    compared = flicker.compare(MODELS / "automata/impact_oscillator.json",
                               methods=["taylor", "dop853"], tolerances=[1e-6, 1e-9, 1e-12])
    ax = flicker.work_precision(compared)
    lines = {l.get_label(): l for l in ax.get_lines()}
    assert set(lines) == {"taylor", "dop853"}
    rows = compared["rows"]
    for method, line in lines.items():
        x, y = line.get_data()
        mine = [i for i, m in enumerate(rows["method"]) if m == method]
        assert sorted(x) == sorted(rows["wall_seconds"][mine])
        assert sorted(y) == sorted(rows["final_error"][mine])
    assert ax.get_xscale() == ax.get_yscale() == "log"


def test_a_run_without_samples_is_drawn_at_its_events():
    run = flicker.run(MODELS / "automata/bouncing_ball.json", t_end=2.0)
    ax = run.plot()
    assert "t_eval" in ax.get_title()
    points = ax.get_lines()
    # Before and after each bounce, for each state.
    assert len(points) == 2 * len(run.state_names)
    t, y = points[0].get_data()
    assert np.array_equal(t, run.events["t"])
    assert np.array_equal(y, run.events["before"][:, run.state_names.index(run.state_names[0])])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "before each reset" in labels and "after it" in labels


def test_the_legend_says_what_the_ticks_are():
    run = flicker.run(MODELS / "automata/bouncing_ball.json", t_end=2.0,
                      t_eval=np.linspace(0.0, 2.0, 101))
    labels = [t.get_text() for t in run.plot().get_legend().get_texts()]
    assert "events" in labels and "y" in labels


def test_a_diagram_is_drawn_as_its_records():
    found = flicker.diagram(MODELS / "automata/vibrating_table.json", "A", 0.14, 0.16,
                            section="impact", points=5, transient=60, record=6, span=60)
    ax = flicker.diagram_plot(found, "v")
    (dots,) = ax.get_lines()
    x, y = dots.get_data()
    assert np.array_equal(x, found["param"]) and np.array_equal(y, found["v"])
    assert ax.get_ylabel() == "v"
    with pytest.raises(ValueError, match="no 'w'"):
        flicker.diagram_plot(found, "w")


def test_basins_are_drawn_a_colour_per_attractor():
    found = flicker.basins(MODELS / "automata/double_well_wall.json",
                           {"x": (-1.35, 2.0, 6), "v": (-2.0, 2.0, 5)})
    ax = flicker.basins_plot(found)
    lines = ax.get_lines()
    assert len(lines) == len(found["attractors"]) == 2
    assert sum(len(l.get_xdata()) for l in lines) == 30
    assert {t.get_text() for t in ax.get_legend().get_texts()} == {"0: equilibrium", "1: equilibrium"}
