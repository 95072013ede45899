"""Dry friction run exactly, against dry friction smoothed.

The friction oscillator x'' + x = -sign(x') from x = 12, x' = 6
(models/automata/friction_oscillator.json) turns seven times and sticks for
good at t* = atan(6/13) + 7 pi (22.4), at x = 15 - sqrt(205). Run to
t = 30, its exact final state is that, at rest.

- flicker runs the file as written: Filippov's sliding, every method.
- SciPy's solve_ivp runs it as a user without sliding would, with the sign
  smoothed to tanh(x' / eps); the smoothing creeps where the block should
  stick (x' = -eps atanh(x) at rest), so its error is the smoothing's as
  much as the integrator's. Explicit methods slow down as eps shrinks
  (stiffness), implicit ones less so.
- flicker's own Taylor method runs the same smoothed model, to show what
  regularisation costs an exact engine.

Each row: the error of the final state against the closed form (the larger
of |x - x*| and |x'|) and the wall time (median of --repeat runs: flicker's
own `wall_seconds`, SciPy's solve_ivp call), per event of the exact run
(eight: seven turns and the stick). Not part of CI:

    bash benches/peers/run.sh --friction
"""

import argparse
import json
import math
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

TOP = Path(__file__).resolve().parents[2]
SCENE = TOP / "models/automata/friction_oscillator.json"
T_END = 30.0
EXACT = np.array([15.0 - math.sqrt(205.0), 0.0])
EVENTS = 8


def error(state):
    return float(np.max(np.abs(np.asarray(state) - EXACT)))


def flicker_run(flicker, scene, method, repeat):
    """Median wall time, error and event count of `flicker run`."""
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.json"
        path.write_text(json.dumps(scene))
        for _ in range(repeat):
            args = [flicker, "run", str(path), "--quiet", "--out", tmp]
            if method:
                args += ["--method", method]
            done = subprocess.run(args, capture_output=True, text=True, timeout=600)
            if done.returncode != 0:
                return None, done.stderr.strip().splitlines()[-1], 0
            summary = json.loads((Path(tmp) / "summary.json").read_text())
            times.append(summary["wall_seconds"])
        final = summary["final_state"]
        return (
            statistics.median(times),
            error([final["x"], final["v"]]),
            summary["events"],
        )


def scipy_run(eps, method, repeat, rtol, atol):
    def rhs(_t, y):
        return [y[1], -y[0] - math.tanh(y[1] / eps)]

    def jac(_t, y):
        return [[0.0, 1.0], [-1.0, -(1.0 - math.tanh(y[1] / eps) ** 2) / eps]]

    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        kwargs = {"jac": jac} if method in ("Radau", "BDF", "LSODA") else {}
        sol = solve_ivp(rhs, (0.0, T_END), [12.0, 6.0], method=method,
                        rtol=rtol, atol=atol, **kwargs)
        times.append(time.perf_counter() - start)
    if not sol.success:
        return None, sol.message, 0
    return statistics.median(times), error(sol.y[:, -1]), sol.nfev


def row(who, how, result):
    wall, err, extra = result
    if wall is None:
        print(f"| {who} | {how} | failed: {err} | | |")
    else:
        print(f"| {who} | {how} | {err:.1e} | {wall * 1e3:.3g} ms | "
              f"{wall / EVENTS * 1e6:.3g} us |")
    sys.stdout.flush()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--flicker", default=str(TOP / "target/release/flicker"))
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    scene = json.loads(SCENE.read_text())
    scene["t_end"] = T_END

    print("| engine | model, method | error at t = 30 | wall | per event |")
    print("|---|---|---|---|---|")
    for method in [None, "taylor", "dop853", "dopri5"]:
        row("flicker", f"sign(), {method or 'default (linear)'}",
            flicker_run(args.flicker, scene, method, args.repeat))
    for eps in [1e-2, 1e-3, 1e-4]:
        smooth = json.loads(json.dumps(scene))
        smooth["modes"] = {
            name: {**mode, "flow": {"x": "v", "v": f"-x - tanh(v / {eps!r})"}}
            for name, mode in scene["modes"].items()
        }
        row("flicker", f"tanh(v / {eps:g}), taylor",
            flicker_run(args.flicker, smooth, "taylor", args.repeat))
    for eps in [1e-2, 1e-3, 1e-4, 1e-6, 1e-8]:
        methods = ["Radau", "LSODA"] + (["DOP853", "RK45"] if eps >= 1e-3 else [])
        for method in methods:
            row("SciPy", f"tanh(v / {eps:g}), {method} rtol 1e-10",
                scipy_run(eps, method, args.repeat, 1e-10, 1e-12))


if __name__ == "__main__":
    main()
