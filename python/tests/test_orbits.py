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


def test_sensitivities_come_back_in_the_summary_and_the_events(tmp_path):
    run = flicker.run(MODELS / "automata" / "mechanism.json", t_end=100.0, sensitivities=["eta", "initial.strain"])
    s = run.summary["sensitivities"]
    assert set(s) == {"eta", "initial.strain"}
    assert "dt/deta" in run.state_names and "dstrain/deta" in run.state_names
    # The last event's time derivative is the last event's dt/deta.
    column = run.state_names.index("dt/deta")
    assert run.events["after"][-1, column] == s["eta"]["last_event_time"]
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
