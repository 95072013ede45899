"""The impacting mechanism with SciPy's solve_ivp against flicker.

SciPy integrates eps'' = -omega^2 (eps - (eta - 1)) with a terminal event at
eps = 0 (closing), flips eps' and restarts, as a user of solve_ivp would.
flicker runs the same scene through `flicker compare`. Both are measured
against the closed form; the script prints the accuracy each reaches and
the ratio of wall time at matched accuracy. With `--automaton`, flicker
runs the mechanism as the automaton of models/automata/mechanism.json
(expressions compiled from the file, Taylor's method and the Runge-Kutta
methods on its tapes) instead of the built-in model.
"""

import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ETA, OMEGA, H0, T_END = 0.8, 1.0, 0.1, 1000.0
SCENE = {
    "model": "mechanism", "formulation": "strain", "eta": ETA, "omega": OMEGA,
    "initial": {"energy": H0, "phase": "impact"}, "t_end": T_END,
}


def exact_final_state():
    """Closed form: impacts every T_imp from t = 0 (the scene starts at one)."""
    c = ETA - 1.0
    period = 2.0 / OMEGA * math.atan2(math.sqrt(2.0 * H0), 1.0 - ETA)
    tau = math.fmod(T_END, period)
    u, w = -c, math.sqrt(2.0 * H0)
    s, co = math.sin(OMEGA * tau), math.cos(OMEGA * tau)
    return np.array([c + u * co + w * s, OMEGA * (w * co - u * s)])


def rhs(_t, y):
    return [y[1], -OMEGA**2 * (y[0] - (ETA - 1.0))]


def closing(_t, y):
    return y[0]


closing.terminal = True
closing.direction = -1


def scipy_run(method, tol):
    t, y, impacts = 0.0, np.array([0.0, OMEGA * math.sqrt(2.0 * H0)]), 0
    start = time.perf_counter()
    while t < T_END:
        sol = solve_ivp(rhs, (t, T_END), y, method=method, rtol=tol, atol=tol, events=closing)
        if sol.status == 1 and sol.t_events[0].size:
            t = float(sol.t_events[0][0])
            y = np.array(sol.y_events[0][0])
            y[0], y[1] = 0.0, -y[1]
            impacts += 1
            # The restart sits on eps = 0 while opening: solve_ivp reports
            # sign changes after its start only, so it is not found again.
            continue
        t, y = T_END, sol.y[:, -1]
    wall = time.perf_counter() - start
    error = float(np.max(np.abs(y - exact_final_state())))
    return {"method": method, "tol": tol, "wall": wall, "error": error, "impacts": impacts}


def automaton_scene():
    """models/automata/mechanism.json on the same orbit, from an impact."""
    top = Path(__file__).resolve().parents[2]
    scene = json.loads((top / "models/automata/mechanism.json").read_text())
    scene["parameters"] = {"eta": ETA, "omega": OMEGA}
    scene["initial"] = {"strain": 0.0, "strain_rate": f"omega * sqrt(2 * {H0})"}
    scene["t_end"] = T_END
    return scene


def flicker_rows(binary, scene_json):
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "scene.json"
        scene.write_text(json.dumps(scene_json))
        out = Path(tmp) / "cmp"
        subprocess.run([binary, "compare", str(scene), "--out", str(out),
                        "--tolerances", "1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12,1e-13"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(out / "compare.csv") as f:
            return [r for r in csv.DictReader(f) if r["status"] == "completed"]


def fastest(rows, error, key_error, key_wall):
    fits = [r for r in rows if float(r[key_error]) <= error]
    return min(fits, key=lambda r: float(r[key_wall])) if fits else None


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--flicker", required=True, help="path to the flicker binary")
    parser.add_argument("--automaton", action="store_true",
                        help="run flicker on the mechanism written as an automaton")
    args = parser.parse_args()
    exact_method = "linear" if args.automaton else "exact"

    scipy = []
    for method in ["RK45", "DOP853", "LSODA"]:
        for tol in [1e-6, 1e-8, 1e-10, 1e-12]:
            r = scipy_run(method, tol)
            scipy.append(r)
            print(f"scipy   {method:<7} tol {tol:.0e}: error {r['error']:.2e}, {r['wall']:.3f} s, "
                  f"{r['impacts']} impacts", flush=True)
    ours = flicker_rows(args.flicker, automaton_scene() if args.automaton else SCENE)
    for r in ours:
        tol = r["tolerance"] or r["step"] or "-"
        print(f"flicker {r['method']:<7} {tol:>7}: error {float(r['final_error']):.2e}, "
              f"{float(r['wall_seconds']):.2e} s")

    numeric = [r for r in ours if r["method"] != exact_method]
    scipy_rows = [{"error": r["error"], "wall": r["wall"], **r} for r in scipy]
    print("\nratio of wall time at matched accuracy (SciPy's fastest run reaching the error / flicker's)")
    for target in [1e-3, 1e-4, 1e-5, 1e-6]:
        s = fastest(scipy_rows, target, "error", "wall")
        f = fastest(numeric, target, "final_error", "wall_seconds")
        if s and f:
            print(f"  error <= {target:.0e}: SciPy {s['method']} {s['wall']:.3f} s, flicker {f['method']} "
                  f"{float(f['wall_seconds']):.2e} s: {s['wall'] / float(f['wall_seconds']):.0f}x")
        else:
            print(f"  error <= {target:.0e}: reached by {'SciPy' if s else 'not SciPy'}, "
                  f"{'flicker' if f else 'not flicker'}")
    exact = next(r for r in ours if r["method"] == exact_method)
    best = min(scipy_rows, key=lambda r: r["error"])
    print(f"\nflicker {exact_method}: error {float(exact['final_error']):.1e} in {float(exact['wall_seconds']):.1e} s; "
          f"SciPy's most accurate run: {best['method']} tol {best['tol']:.0e}, error {best['error']:.1e} "
          f"in {best['wall']:.2f} s: {best['wall'] / float(exact['wall_seconds']):.0f}x")
    s9 = fastest(scipy_rows, 1e-9, "error", "wall")
    print("SciPy at error <= 1e-9: " + (f"{s9['method']} in {s9['wall']:.2f} s, "
          f"{s9['wall'] / float(exact['wall_seconds']):.0f}x the exact flow" if s9 else "not reached"))


if __name__ == "__main__":
    sys.exit(main())
