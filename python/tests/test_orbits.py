"""Sensitivities, orbits and continuation from Python, against the closed
forms of the ball on a vibrating table and the command line's output."""

import json
import math

import numpy as np
import pytest

import flicker
from conftest import MODELS

TABLE = MODELS / "automata" / "vibrating_table.json"
G, R, W = 9.81, 0.5, 10.0
PERIOD = 2 * math.pi / W


def mechanism_closed_form(eta, strain0, t):
    """The strain mechanism of mechanism.json (omega 1) from rest at
    `strain0`: impact k at (2k + 1) acos(-c / A), c = eta - 1, A = strain0 -
    c (the arc starts at its apex), and the state at `t` on the arc since the
    last impact."""
    c = eta - 1.0
    a = strain0 - c
    half = math.acos(-c / a)
    impacts = int((t / half + 1) // 2)
    last = (2 * impacts - 1) * half
    if impacts == 0:
        return [], (c + a * math.cos(t), -a * math.sin(t))
    # From the impact at eps = 0 opening: the arc's phase is -half there.
    phase = t - last - half
    return [(2 * k + 1) * half for k in range(impacts)], (c + a * math.cos(phase), -a * math.sin(phase))


def test_sensitivities_come_back_in_the_summary_and_the_events(tmp_path):
    run = flicker.run(MODELS / "automata" / "mechanism.json", t_end=100.0, sensitivities=["eta", "initial.strain"])
    s = run.summary["sensitivities"]
    assert set(s) == {"eta", "initial.strain"}
    assert "dt/deta" in run.state_names and "dstrain/deta" in run.state_names
    # The last event's time derivative is the last event's dt/deta.
    column = run.state_names.index("dt/deta")
    assert run.events["after"][-1, column] == s["eta"]["last_event_time"]
    # Every value against central differences of the closed form (eta 1.2,
    # strain 0.5 at rest), to 1e-6 of its size.
    eta, strain0, h = 1.2, 0.5, 1e-6
    times, _ = mechanism_closed_form(eta, strain0, 100.0)
    assert len(times) == len(run.events["t"])
    for name, (up, down) in {
        "eta": ((eta + h, strain0), (eta - h, strain0)),
        "initial.strain": ((eta, strain0 + h), (eta, strain0 - h)),
    }.items():
        t_up, x_up = mechanism_closed_form(*up, 100.0)
        t_down, x_down = mechanism_closed_form(*down, 100.0)
        want = (t_up[-1] - t_down[-1]) / (2 * h)
        assert abs(s[name]["last_event_time"] - want) <= 1e-6 * abs(want), (name, s[name], want)
        for i, state in enumerate(["strain", "strain_rate"]):
            want = (x_up[i] - x_down[i]) / (2 * h)
            got = s[name]["final_state"][state]
            assert abs(got - want) <= 1e-6 * max(abs(want), 1.0), (name, state, got, want)
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run(MODELS / "automata" / "mechanism.json", sensitivities=["etta"])
    assert caught.value.field == "sensitivities"
    # omega multiplies the strain: no affine flow, so no linear propagator,
    # refused before the log is touched.
    log = tmp_path / "events.jsonl"
    log.write_text("an earlier run\n")
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run(MODELS / "automata" / "mechanism.json", method="linear", sensitivities=["omega"], log=str(log))
    assert caught.value.field == "sensitivities" and "dop853" in str(caught.value)
    assert log.read_text() == "an earlier run\n"


def test_the_table_orbit_and_its_multipliers_meet_holmes_closed_form(cli, tmp_path):
    found = flicker.orbit(TABLE, "impact", settle=2.0, forcing_period=PERIOD)
    assert found["converged"], found
    gamma = 0.1275 * W * W / G
    phi = math.acos(math.pi * (1 - R) / ((1 + R) * gamma))
    assert abs((W * found["section_state"]["t"]) % (2 * math.pi) - phi) < 1e-10
    trace = 1 + R * R - (1 + R) ** 2 * gamma * math.sin(phi)
    roots = np.roots([1.0, -trace, R * R])
    got = [complex(*z) for z in found["multipliers"][1:]]
    for z in roots:
        assert min(abs(z - g) for g in got) < 1e-9
    done, _ = cli("orbit", TABLE, "--section", "impact", "--settle", "2", "--forcing-period", repr(PERIOD), "--out", tmp_path / "o")
    assert done.returncode == 0, done.stderr
    on_disk = json.loads((tmp_path / "o" / "orbit.json").read_text())
    for key in ("period", "section_state", "multipliers", "stable", "iterations", "residual"):
        assert found[key] == on_disk[key], key


def test_the_table_branch_period_doubles_where_the_closed_form_says():
    branch = flicker.continuation(TABLE, "impact", "A", 0.16, settle=2.0, forcing_period=PERIOD)
    assert branch["ended"] == "reached"
    labels = branch["label"]
    k = labels.index("period doubling")
    gamma_1 = math.pi * (1 - R) / (1 + R)
    gamma_pd = math.sqrt(gamma_1**2 + 4 * (1 + R * R) ** 2 / (1 + R) ** 4)
    assert abs(branch["parameter"][k] - gamma_pd * G / W**2) < 1e-8
    assert branch["parameter"].dtype == np.float64
    assert all(branch["stable"][:k]) and not any(branch["stable"][k + 1 :])


def test_the_built_in_mechanism_has_orbits_and_sensitivities_too():
    """The paper's own model (not an automaton): its impacting orbit's period
    is T_imp = 2 atan2(sqrt(2 H0), 1 - eta), both multipliers 1, and its
    sensitivity along initial.strain meets a central difference of the
    closed form."""
    scene = MODELS / "mechanism_impacting.json"
    found = flicker.orbit(scene, "impact")
    assert found["converged"], found
    t_imp = 2 * math.atan2(math.sqrt(0.1), 1 - 1.2)
    assert abs(found["period"] - t_imp) < 1e-12 * t_imp
    assert all(abs(re - 1) < 1e-8 and abs(im) < 1e-8 for re, im in found["multipliers"])

    run = flicker.run(scene, t_end=20.0, sensitivities=["initial.strain"])
    got = run.summary["sensitivities"]["initial.strain"]["final_state"]["strain"]
    # From the apex of H0 = 0.05 at eta 1.2: strain0 = c + sqrt(c^2 + 2 H0).
    c = 0.2
    strain0 = c + math.sqrt(c * c + 0.1)
    h = 1e-6
    up = mechanism_closed_form(1.2, strain0 + h, 20.0)[1][0]
    down = mechanism_closed_form(1.2, strain0 - h, 20.0)[1][0]
    assert abs(got - (up - down) / (2 * h)) < 1e-6


def test_lyapunov_spectrum_of_the_table_ball_sums_to_its_restitution_loss():
    """The ball on the vibrating table: each impact's saltation matrix has
    determinant r^2 and the flight keeps volume, so the exponents sum to
    2 ln(r) x impacts per unit time; the clock gives a 0."""
    found = flicker.lyapunov(TABLE, t_end=100.0, transient=2.0)
    assert found["status"] == "completed"
    rate = found["events"] / found["t_span"]
    assert abs(sum(found["exponents"]) - 2 * math.log(R) * rate) < 1e-6
    assert min(abs(x) for x in found["exponents"]) < 1e-9
    assert found["history"][-1]["t"] == found["t_span"]


def doubling_amplitude(r):
    """Holmes's period doubling of the vibrating table: Gamma_PD^2 =
    (pi (1 - r) / (1 + r))^2 + (2 (1 + r^2) / (1 + r)^2)^2, A = Gamma g / w^2."""
    fold = math.pi * (1 - r) / (1 + r)
    return math.hypot(fold, 2 * (1 + r * r) / (1 + r) ** 2) * G / W**2


def test_diagram_splits_at_the_period_doubling_and_matches_the_command_line(cli):
    a_pd = doubling_amplitude(R)
    lo, hi = 0.95 * a_pd, 1.05 * a_pd
    asked = dict(section="impact", points=3, transient=300 * PERIOD, record=8, span=100 * PERIOD)
    found = flicker.diagram(TABLE, "A", lo, hi, **asked)
    assert set(found) == {"param", "t", "y", "v", "ended_short"}
    assert found["ended_short"] == []
    for value, count in [(lo, 1), (hi, 2)]:
        v = np.sort(found["v"][found["param"] == value])
        assert len(v) == 8
        assert 1 + np.count_nonzero(np.diff(v) > 1e-3) == count, (value, v)
    # Below the doubling: Holmes's take-off speed g T / 2.
    below = found["v"][found["param"] == lo]
    assert np.allclose(below, G * PERIOD / 2, rtol=1e-4)
    # The command line writes the same records.
    done, out = cli(
        "diagram", TABLE, "--param", "A", "--from", repr(lo), "--to", repr(hi),
        "--points", "3", "--section", "impact", "--transient", repr(300 * PERIOD),
        "--record", "8", "--span", repr(100 * PERIOD), "--out", "cli", "--quiet",
    )
    assert done.returncode == 0, done.stderr
    rows = np.loadtxt(out / "diagram.csv", delimiter=",", skiprows=1)
    for k, name in enumerate(["param", "t", "y", "v"]):
        assert np.allclose(rows[:, k], found[name], rtol=1e-12, atol=0), name
    frame = flicker.diagram_frame(found)
    assert list(frame.columns) == ["param", "t", "y", "v"] and len(frame) == 24


def test_diagram_shards_join_into_the_whole_and_draw(cli, tmp_path):
    # Shards run disjoint values: their rows, joined, are the whole
    # diagram's (docs/orbits.md), and the joined CSV draws.
    import matplotlib

    matplotlib.use("Agg")
    pd = pytest.importorskip("pandas")
    asked = ["--param", "A", "--from", "0.11", "--to", "0.13", "--points", "6",
             "--section", "impact", "--record", "8", "--quiet"]
    frames = []
    for shard in [None, "0/2", "1/2"]:
        out = tmp_path / f"shard{shard}".replace("/", "of")
        extra = [] if shard is None else ["--shard", shard]
        done, _ = cli("diagram", TABLE, *asked, *extra, "--out", out)
        assert done.returncode == 0, done.stderr
        frames.append(pd.read_csv(out / "diagram.csv"))
    whole, joined = frames[0], pd.concat(frames[1:], ignore_index=True)
    key = list(whole.columns)
    assert len(joined) == len(whole) > 0
    assert whole.sort_values(key).reset_index(drop=True).equals(
        joined.sort_values(key).reset_index(drop=True)
    )
    assert flicker.diagram_plot(joined) is not None


def test_diagram_names_its_zeno_values_and_goes_on():
    found = flicker.diagram(TABLE, "A", 0.0, 0.13, section="impact", points=5, transient=60,
                            record=4, span=60)
    short = found["ended_short"]
    assert short and all(s["status"] == "zeno" for s in short)
    assert found["param"].max() == 0.13
    with pytest.raises(flicker.SceneError, match="no parameter"):
        flicker.diagram(TABLE, "B", 0.0, 0.1, section="impact", points=2)


def test_basins_name_the_double_well_s_two_equilibria_as_the_command_line_does(cli):
    well = MODELS / "automata" / "double_well_wall.json"
    found = flicker.basins(well, {"x": (-1.35, 2.0, 11), "v": (-2.0, 2.0, 9)})
    kinds = [a["kind"] for a in found["attractors"]]
    assert kinds == ["equilibrium", "equilibrium"]
    at = sorted(round(a["state"]["x"], 6) for a in found["attractors"])
    assert at == [-1.0, 1.0]
    assert len(found["x"]) == len(found["v"]) == len(found["attractor"]) == 99
    done, out = cli("basins", well, "--grid", "x=-1.35:2:11,v=-2:2:9", "--out", "cli", "--quiet")
    assert done.returncode == 0, done.stderr
    rows = np.loadtxt(out / "basins.csv", delimiter=",", skiprows=1)
    assert np.array_equal(rows[:, 2], found["attractor"])
    assert np.allclose(rows[:, 0], found["x"]) and np.allclose(rows[:, 1], found["v"])
    with pytest.raises(ValueError, match="two states"):
        flicker.basins(well, {"x": (0, 1, 3)})


def test_basins_refine_a_forced_orbit_with_its_forcing_period():
    # Holmes's period-one orbit of the ball on the vibrating table: its
    # impact map's multipliers multiply to r^2 (beside the clock's 1).
    table = MODELS / "automata" / "vibrating_table.json"
    grid = {"y": (0.05, 0.6, 3), "v": (0.0, 4.0, 3)}
    period = 2 * np.pi / 10.0
    found = flicker.basins(table, grid, section="impact", record=16, forcing_period=period)
    one = next(a for a in found["attractors"] if a.get("period") == 1)
    assert abs(one["period_time"] - period) < 1e-12
    assert one["stable"] is True
    assert abs(np.prod(one["multipliers"]) - 0.25) < 1e-8
    bare = flicker.basins(table, grid, section="impact", record=16)
    assert all("multipliers" not in a for a in bare["attractors"])
    with pytest.raises(ValueError, match="forcing_period"):
        well = MODELS / "automata" / "double_well_wall.json"
        flicker.basins(well, {"x": (-1, 1, 3), "v": (-1, 1, 3)}, forcing_period=1.0)
