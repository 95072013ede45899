"""check, compare and sweep from Python against the command line's
output for the same files."""

import csv
import math

import numpy as np

import flicker
from conftest import MODELS


def test_check_says_what_the_command_line_says(cli):
    for name in ["automata/rocking_block.json", "mechanism_loose.json", "sweeps/ball_bounces.json"]:
        path = MODELS / name
        done, _ = cli("check", path)
        assert done.returncode == 0
        assert flicker.check(path) == done.stdout.splitlines()


def test_compare_rows_are_the_command_lines(cli, tmp_path):
    path = MODELS / "mechanism_impacting.json"
    ours = flicker.compare(path, methods=["exact", "dop853"], tolerances=[1e-6, 1e-9])
    done, _ = cli("compare", path, "--methods", "exact,dop853", "--tolerances", "1e-6,1e-9", "--out", tmp_path / "cmp")
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(open(tmp_path / "cmp" / "compare.csv")))
    assert ours["reference"] in done.stdout
    assert ours["rows"]["method"] == [r["method"] for r in rows]
    assert ours["rows"]["status"] == [r["status"] for r in rows]
    for key in ("final_error", "error_bound", "events"):
        assert list(ours["rows"][key]) == [float(r[key]) for r in rows]
    # The exact flow is exact; DOP853's error falls with its tolerance.
    errors = ours["rows"]["final_error"]
    assert errors[0] < 1e-12 and errors[1] > errors[2]


def test_sweep_columns_are_the_command_lines(cli, tmp_path):
    path = MODELS / "sweeps" / "ball_bounces.json"
    ours = flicker.sweep(path, threads=2)
    out = tmp_path / "sweep.csv"
    done, _ = cli("sweep", path, "--out", out)
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(open(out)))
    assert list(ours["point"]) == [int(r["point"]) for r in rows]
    assert ours["status"] == [r["status"] for r in rows]
    for key in ("parameters.e", "initial.y", "first_impact", "t_reached"):
        assert list(ours[key]) == [float(r[key]) for r in rows]
    # Each row's first bounce is the drop's, sqrt(2 y / g).
    for y, t1 in zip(ours["initial.y"], ours["first_impact"]):
        assert abs(t1 - math.sqrt(2 * y / 9.81)) < 1e-14
    assert np.isnan(ours["exact_period"]).all()
