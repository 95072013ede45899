"""heyoka and flicker's Taylor method on the same impacting mechanism.

The strain-form mechanism (eps'' = -omega^2 (eps - (eta - 1)), impact at
eps = 0 closing, eps' -> -eps'), eta = 0.8, omega = 1, H0 = 0.1, starting
at an impact (eps = 0, eps' = sqrt(2 H0)), to t = 10^5: 43,468 impacts.

heyoka (Taylor's method compiled by LLVM) runs it with a terminal event on
eps (direction negative) whose callback flips eps' and lets the run go on;
its JIT compilation is timed apart. flicker runs models/automata/
mechanism.json with the same parameters, `--method taylor` at the same
tolerance and its default, the exact linear propagator (the flow is
affine); its time is the run's own wall time from summary.json (the
process start and the file writing left out, as heyoka's Python call is
timed alone). Both final states are measured against the closed form
evaluated in long double (t mod T_imp is the delicate part at t = 10^5).

    bash benches/peers/run.sh --heyoka        (installs heyoka into target/peers-venv)
"""

import argparse
import json
import math
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

ETA, OMEGA, H0, T_END = 0.8, 1.0, 0.1, 1e5
LD = np.longdouble


def closed_form(t_end):
    """(eps, eps', impacts) at t_end, from an impact at t = 0, in long double."""
    v0 = OMEGA * math.sqrt(2.0 * H0)  # the double both runs start from
    w, d = LD(OMEGA), LD(ETA) - LD(1.0)
    h = LD(v0) ** 2 / (LD(2.0) * w * w)
    amplitude = np.sqrt(LD(2.0) * h + d * d)
    half = np.arctan2(np.sqrt(LD(2.0) * h), -d)  # phase of the impact
    period = LD(2.0) * half / w
    n = np.floor(LD(t_end) / period)
    theta = -half + w * (LD(t_end) - n * period)
    return float(d + amplitude * np.cos(theta)), float(-amplitude * w * np.sin(theta)), int(n)


def heyoka_run(tol, repeats):
    import heyoka as hy

    eps, v = hy.make_vars("eps", "v")
    impacts = [0]

    def flip(ta, _sign):
        ta.state[1] = -ta.state[1]
        impacts[0] += 1
        return True

    event = hy.t_event(eps, callback=flip, direction=hy.event_direction.negative)
    start = time.perf_counter()
    ta = hy.taylor_adaptive(
        [(eps, v), (v, -OMEGA**2 * (eps - (ETA - 1.0)))],
        [0.0, OMEGA * math.sqrt(2.0 * H0)],
        tol=tol,
        t_events=[event],
    )
    jit = time.perf_counter() - start
    times = []
    for _ in range(repeats):
        ta.time = 0.0
        ta.state[:] = [0.0, OMEGA * math.sqrt(2.0 * H0)]
        ta.reset_cooldowns()
        impacts[0] = 0
        start = time.perf_counter()
        ta.propagate_until(T_END)
        times.append(time.perf_counter() - start)
    return statistics.median(times), impacts[0], (float(ta.state[0]), float(ta.state[1])), jit


def flicker_run(binary, tol, repeats, method="taylor"):
    top = Path(__file__).resolve().parents[2]
    scene = json.loads((top / "models/automata/mechanism.json").read_text())
    scene["parameters"] = {"eta": ETA, "omega": OMEGA}
    scene["initial"] = {"strain": 0.0, "strain_rate": f"omega * sqrt(2 * {H0})"}
    scene["t_end"] = T_END
    scene["solver"] = ({"method": method, "rtol": tol, "atol": tol} if method == "taylor"
                       else {"method": method})
    times = []
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.json"
        path.write_text(json.dumps(scene))
        for _ in range(repeats):
            subprocess.run([binary, "run", str(path), "--out", tmp, "--no-events", "--quiet"],
                           check=True, capture_output=True)
            summary = json.loads((Path(tmp) / "summary.json").read_text())
            times.append(summary["wall_seconds"])
    state = summary["final_state"]
    return statistics.median(times), summary["events"], (state["strain"], state["strain_rate"])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--flicker", required=True)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    eps, rate, exact_impacts = closed_form(T_END)
    tol = float(np.finfo(float).eps)
    print(f"mechanism, eta {ETA}, H0 {H0}, from an impact to t = {T_END:g}: "
          f"{exact_impacts} impacts; tolerance {tol:.1e}; medians of {args.repeats}")
    rows = []
    seconds, impacts, state, jit = heyoka_run(tol, args.repeats)
    rows.append((f"heyoka (JIT {jit:.3f} s apart)", seconds, impacts, state))
    seconds, impacts, state = flicker_run(args.flicker, tol, args.repeats)
    rows.append(("flicker taylor", seconds, impacts, state))
    seconds, impacts, state = flicker_run(args.flicker, tol, args.repeats, "linear")
    rows.append(("flicker linear (its default)", seconds, impacts, state))
    for name, seconds, impacts, (e, r) in rows:
        print(f"  {name:28} {impacts} impacts in {seconds:.4f} s = {impacts / seconds:>9.0f} impacts/s, "
              f"|d eps| {abs(e - eps):.1e}, |d eps'| {abs(r - rate):.1e}")
    print(f"  flicker taylor / heyoka time: {rows[1][1] / rows[0][1]:.2f}, "
          f"flicker linear / heyoka: {rows[2][1] / rows[0][1]:.2f}")


if __name__ == "__main__":
    main()
