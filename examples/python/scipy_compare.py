"""The impacting mechanism (models/mechanism_impacting.json's parameters,
eta = 0.8, H0 = 0.1, from an impact, t <= 1000: 434 impacts) with SciPy's
solve_ivp (a Python right-hand side, a terminal event at eps = 0, the state
flipped and the integration restarted at each impact, as a SciPy user
would) and with flicker from the same script: accuracy against the closed
form and wall time side by side, and the ratio at matched error.

    target/venv/bin/pip install scipy
    target/venv/bin/python examples/python/scipy_compare.py
"""

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

import flicker

ETA, OMEGA, H0, T_END = 0.8, 1.0, 0.1, 1000.0
SCENE = {"model": "mechanism", "formulation": "strain", "eta": ETA, "omega": OMEGA,
         "initial": {"energy": H0, "phase": "impact"}, "t_end": T_END}


def exact_final_state():
    """The closed form: impacts every T_imp from t = 0 (the scene starts at one)."""
    c = ETA - 1.0
    period = 2.0 / OMEGA * math.atan2(math.sqrt(2.0 * H0), 1.0 - ETA)
    tau = math.fmod(T_END, period)
    u, w = -c, math.sqrt(2.0 * H0)
    s, co = math.sin(OMEGA * tau), math.cos(OMEGA * tau)
    return np.array([c + u * co + w * s, OMEGA * (w * co - u * s)])


def scipy_run(method, tol):
    def rhs(_t, y):
        return [y[1], -OMEGA**2 * (y[0] - (ETA - 1.0))]

    def closing(_t, y):
        return y[0]

    closing.terminal = True
    closing.direction = -1
    t, y, impacts = 0.0, np.array([0.0, OMEGA * math.sqrt(2.0 * H0)]), 0
    start = time.perf_counter()
    while t < T_END:
        sol = solve_ivp(rhs, (t, T_END), y, method=method, rtol=tol, atol=tol, events=closing)
        if sol.status == 1 and sol.t_events[0].size:
            t, y = float(sol.t_events[0][0]), np.array(sol.y_events[0][0])
            y[0], y[1] = 0.0, -y[1]
            impacts += 1
            continue
        t, y = T_END, sol.y[:, -1]
    return time.perf_counter() - start, float(np.max(np.abs(y - exact_final_state()))), impacts


def flicker_run(**solver):
    """Median wall time of 5 calls from Python, and the final error."""
    walls = []
    for _ in range(5):
        start = time.perf_counter()
        run = flicker.run(SCENE, events=False, **solver)
        walls.append(time.perf_counter() - start)
    state = np.array(list(run.summary["final_state"].values()))
    return float(np.median(walls)), float(np.max(np.abs(state - exact_final_state()))), run


def main():
    rows = []
    # Both sides at every decade of tolerance, each side's fastest run to
    # an error then compared.
    tolerances = [10.0**-k for k in range(4, 14)]
    for method in ("RK45", "DOP853", "LSODA"):
        for tol in tolerances:
            wall, error, impacts = scipy_run(method, tol)
            rows.append(("scipy", method, tol, wall, error))
            print(f"scipy   {method:<7} tol {tol:.0e}: error {error:.2e} in {wall:.3f} s ({impacts} impacts)")
    for method in ("dopri5", "dop853"):
        for tol in tolerances:
            wall, error, run = flicker_run(method=method, rtol=tol, atol=tol)
            if run.status == "completed":
                rows.append(("flicker", method, tol, wall, error))
            print(f"flicker {method:<7} tol {tol:.0e}: error {error:.2e} in {wall * 1e3:.2f} ms ({run.status})")
    exact_wall, exact_error, _ = flicker_run()
    print(f"flicker exact          : error {exact_error:.2e} in {exact_wall * 1e3:.3f} ms")
    print("\nat matched final error (each side's fastest run reaching it):")
    for target in (1e-3, 1e-4, 1e-5, 1e-6):
        fits = lambda who: [r for r in rows if r[0] == who and r[4] <= target]
        s, f = fits("scipy"), fits("flicker")
        if s and f:
            s, f = min(s, key=lambda r: r[3]), min(f, key=lambda r: r[3])
            print(f"  error <= {target:.0e}: SciPy {s[1]} {s[3]:.3f} s, flicker {f[1]} {f[3] * 1e3:.2f} ms: {s[3] / f[3]:.0f}x")
    best = min((r for r in rows if r[0] == "scipy"), key=lambda r: r[4])
    print(f"SciPy's most accurate run ({best[1]} at {best[2]:.0e}, error {best[4]:.1e}, {best[3]:.2f} s) "
          f"against flicker's exact flow (error {exact_error:.1e}): {best[3] / exact_wall:.0f}x")


if __name__ == "__main__":
    main()
