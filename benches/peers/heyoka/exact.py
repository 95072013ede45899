"""Closed-form reference of the mechanism for the heyoka cases (case1_mechanism.py).

System (bistable unit in strain form, perfectly elastic impacts):
    eps'' = -omega^2 (eps - (eta - 1)),   v = eps'
    guard: eps crosses 0 while falling (v < 0);  reset: v -> -v
    H = v^2 / (2 omega^2) + eps (eps + 2 (1 - eta)) / 2   (conserved)

Between impacts eps(t) = d + A cos(theta), d = eta - 1, A = sqrt(2 H + d^2),
theta = omega t + phi.  Start: eps = 0, v = +omega sqrt(2 H) (just after an
impact), i.e. theta(0) = -theta*, theta* = atan2(sqrt(2 H), 1 - eta).  The
flight ends when theta = +theta*, so impacts are at t_k = k T (k = 1, 2, ...)
with T = 2 theta* / omega; impacts in (0, t_end] = floor(t_end / T).
At time t with n = floor(t / T): theta = -theta* + omega (t - n T).

The reference is evaluated in numpy longdouble (80-bit x87 on x86-64, ~1e-19
relative) from the *same double-rounded inputs the peers get* (eta = 0.8 as a
double, v0 = omega * sqrt(2 H) rounded to double), so that t_end - n T is not
polluted by double rounding of T (n T ~ 1e5 would cost ~1e-11 in double).
"""
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

LD = np.longdouble

CASES = {
    # name: t_end
    "case1": 1000.0,
    "case2": 100000.0,
}
TOLS = [1e-6, 1e-9, 1e-12, 1e-15]
ETA, OMEGA, H_NOMINAL = 0.8, 1.0, 0.1
HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS_DIR = os.path.join(HERE, "results")


class Exact:
    def __init__(self, eta=ETA, omega=OMEGA, H=H_NOMINAL):
        self.eta = float(eta)
        self.omega = float(omega)
        # what the peers integrate: double inputs
        self.v0 = float(self.omega * math.sqrt(2.0 * H))
        self.y0 = (0.0, self.v0)
        w = LD(self.omega)
        self.w = w
        self.d = LD(self.eta) - LD(1.0)  # exact (Sterbenz)
        self.H_ld = LD(self.v0) ** 2 / (LD(2.0) * w * w)
        self.H0 = float(self.H_ld)
        self.A = np.sqrt(LD(2.0) * self.H_ld + self.d * self.d)
        self.ths = np.arctan2(np.sqrt(LD(2.0) * self.H_ld), -self.d)
        self.T_ld = LD(2.0) * self.ths / w
        self.T = float(self.T_ld)
        self.v_imp = float(w * np.sqrt(LD(2.0) * self.H_ld))

    def n_impacts(self, t_end):
        return int(np.floor(LD(t_end) / self.T_ld))

    def t_impact(self, k):
        return float(LD(k) * self.T_ld)

    def state(self, t):
        t = LD(t)
        n = np.floor(t / self.T_ld)
        s = t - n * self.T_ld
        th = -self.ths + self.w * s
        return float(self.d + self.A * np.cos(th)), float(-self.A * self.w * np.sin(th))

    def energy(self, eps, v):
        eps = np.asarray(eps, float)
        v = np.asarray(v, float)
        w2 = self.omega ** 2
        return v * v / (2.0 * w2) + 0.5 * eps * (eps + 2.0 * (1.0 - self.eta))


def metrics(ex, t_end, t_imp, eps_imp, v_imp, t_final, eps_final, v_final):
    """Accuracy numbers of one run against the closed form.

    t_imp/eps_imp/v_imp: impact times and the state *before* the reset."""
    t_imp = np.asarray(t_imp, float)
    eps_imp = np.asarray(eps_imp, float)
    v_imp = np.asarray(v_imp, float)
    out = {
        "impacts": int(t_imp.size),
        "exact_impacts": ex.n_impacts(t_end),
        "t_final": float(t_final),
    }
    if t_imp.size:
        rel_dH = np.abs(ex.energy(eps_imp, v_imp) - ex.H0) / ex.H0
        k = np.arange(1, t_imp.size + 1, dtype=float)
        t_ex = np.array([ex.t_impact(kk) for kk in k])
        out["max_rel_energy_error"] = float(np.max(rel_dH))
        out["max_impact_time_error"] = float(np.max(np.abs(t_imp - t_ex)))
        out["max_abs_eps_at_impacts"] = float(np.max(np.abs(eps_imp)))
    else:
        out["max_rel_energy_error"] = None
        out["max_impact_time_error"] = None
        out["max_abs_eps_at_impacts"] = None
    if eps_final is not None and abs(t_final - t_end) <= 1e-9 * t_end:
        e_ex, v_ex = ex.state(t_end)
        out["final_eps_error"] = float(abs(eps_final - e_ex))
        out["final_v_error"] = float(abs(v_final - v_ex))
        out["final_rel_energy_error"] = float(abs(ex.energy(eps_final, v_final) - ex.H0) / ex.H0)
    else:
        out["final_eps_error"] = None
        out["final_v_error"] = None
        out["final_rel_energy_error"] = None
    return out


def timed_runs(run_once, n=3, single_if_over=60.0):
    """run_once() -> (seconds, payload); only the solve is inside `seconds`.

    Returns (median seconds, list of seconds, payload of the last run).
    A run slower than `single_if_over` seconds is not repeated."""
    secs = []
    payload = None
    for _ in range(n):
        s, payload = run_once()
        secs.append(s)
        if s > single_if_over:
            break
    return statistics.median(secs), secs, payload


def check_reference(ex, verbose=True):
    """Closed form vs a fine numerical integration of one period (no events)."""
    from scipy.integrate import solve_ivp

    w2, d = ex.omega ** 2, float(ex.d)

    def rhs(t, y):
        return [y[1], -w2 * (y[0] - d)]

    T = ex.T
    sol = solve_ivp(rhs, (0.0, T), list(ex.y0), method="DOP853", rtol=2.3e-14,
                    atol=1e-16, dense_output=True)
    ts = np.linspace(0.0, T, 201)
    num = sol.sol(ts)
    exa = np.array([ex.state(t) for t in ts[:-1]] + [(0.0, -ex.v_imp)]).T
    out = {
        "T": T,
        "theta_star": float(ex.ths),
        "A": float(ex.A),
        "H0": ex.H0,
        "v0": ex.v0,
        "scipy_DOP853_max_abs_eps_diff_over_one_period": float(np.max(np.abs(num[0] - exa[0]))),
        "scipy_DOP853_max_abs_v_diff_over_one_period": float(np.max(np.abs(num[1] - exa[1]))),
        "scipy_DOP853_eps_at_T": float(sol.y[0, -1]),
        "scipy_DOP853_v_at_T_plus_v_imp": float(sol.y[1, -1] + ex.v_imp),
        "exact_impacts_case1": ex.n_impacts(CASES["case1"]),
        "exact_impacts_case2": ex.n_impacts(CASES["case2"]),
    }
    try:  # a second, tighter check with heyoka (Taylor, tol = eps) if available
        import heyoka as hy

        x, v = hy.make_vars("x", "v")
        ta = hy.taylor_adaptive([(x, v), (v, -w2 * (x - d))], list(ex.y0))
        grid = ta.propagate_grid(ts)[-1]
        out["heyoka_max_abs_eps_diff_over_one_period"] = float(np.max(np.abs(grid[:, 0] - exa[0])))
        out["heyoka_max_abs_v_diff_over_one_period"] = float(np.max(np.abs(grid[:, 1] - exa[1])))
        # the first zero of eps after t = 0 (falling) must be at T
        ta2 = hy.taylor_adaptive([(x, v), (v, -w2 * (x - d))], list(ex.y0),
                                 t_events=[hy.t_event(x, direction=hy.event_direction.negative)])
        ta2.propagate_until(10 * T)
        out["heyoka_first_falling_zero_minus_T"] = float(ta2.time - T)
    except ImportError:
        pass
    if verbose:
        for k, val in out.items():
            print(f"  {k:50s} {val}")
    return out


def machine_info():
    info = {"python": sys.version.split()[0], "platform": platform.platform(),
            "nproc": os.cpu_count()}
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    info["cpu_model"] = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        load = os.getloadavg()
        info["loadavg_at_start"] = [round(x, 2) for x in load]
    except OSError:
        pass
    info["numpy"] = np.__version__
    try:
        import scipy
        info["scipy"] = scipy.__version__
    except ImportError:
        pass
    try:
        import heyoka
        info["heyoka"] = heyoka.__version__
    except ImportError:
        pass
    try:
        import pydiffsol
        info["pydiffsol"] = pydiffsol.version()
        info["diffsol"] = pydiffsol.diffsol_version()
        info["diffsl"] = pydiffsol.diffsl_version()
        info["diffsol_c"] = pydiffsol.diffsol_c_version()
    except (ImportError, AttributeError):
        pass
    return info


def busy_processes():
    """Build/benchmark processes that would disturb the timings."""
    try:
        out = subprocess.run(["ps", "-eo", "pid,comm,args"], capture_output=True,
                             text=True).stdout
    except OSError:
        return []
    hits = []
    for line in out.splitlines()[1:]:
        parts = line.split(None, 2)
        if len(parts) < 2:
            continue
        comm = parts[1]
        if comm in ("cargo", "rustc") or comm.startswith("flicker"):
            hits.append(line.strip()[:120])
    return hits


def dump(path, obj):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        json.dump(obj, f, indent=1)


def now():
    return time.strftime("%Y-%m-%d %H:%M:%S")


def wait_quiet(max_wait_s=3600, poll_s=60):
    """Block until no cargo/rustc/flicker process runs; return what was seen."""
    waited = 0
    seen = busy_processes()
    first = list(seen)
    while seen and waited < max_wait_s:
        print(f"[{now()}] machine busy ({len(seen)} build procs), sleeping {poll_s}s", flush=True)
        time.sleep(poll_s)
        waited += poll_s
        seen = busy_processes()
    return {"busy_at_first_check": first, "waited_s": waited, "busy_at_start": seen}
