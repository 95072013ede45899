"""Case 2d: what a Taylor step's tangent map costs heyoka itself, beside flicker's bound.

flicker carries an error bound through every step: the step's tangent map
(Magnus' generator) and the error set it moves. heyoka carries none unless
asked; asked for the same tangent (its variational equations to first order
in the initial state, `var_ode_sys(..., var_args.vars, order=1)`: the
issue's "tangent from the step's own Taylor series"), it integrates 4 + 16
components. Henon-Heiles to t = 2000 as in cases 2 and 2b, bare and with the
section x = 0 rising; solve times, interleaved with flicker's
`scenes/hh_noev.json` and `scenes/hh.json` (no event log), per step and
whole."""
import os
import sys, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, heyoka as hy
from common import *
N = int(sys.argv[1]) if len(sys.argv) > 1 else 7
X0 = [0.05, 0.3, 0.3521363372331802, 0.0]
T_END = 2000.0
hy.llvm_state.set_diskcache_enabled(False)
x, y, px, py = hy.make_vars("x", "y", "px", "py")
sys_ = [(x, px), (y, py), (px, -x - 2.0 * x * y), (py, -y - x**2 + y**2)]
crossings = []
def section():
    return [hy.nt_event(x, callback=lambda ta, t, d: crossings.append(t), direction=hy.event_direction.positive)]
tangent_sys = hy.var_ode_sys(sys_, hy.var_args.vars, order=1)
JIT = {}
def make(name, system, **kw):
    hy.llvm_state.clear_memcache()
    t0 = time.perf_counter()
    ta = hy.taylor_adaptive(system, X0, **kw)
    JIT[name] = time.perf_counter() - t0
    return ta
HEY = {
    "plain": make("plain", sys_),
    "plain, section": make("plain, section", sys_, nt_events=section()),
    "tangent": make("tangent", tangent_sys),
    "tangent, section": make("tangent, section", tangent_sys, nt_events=section()),
}
def hey(ta):
    ta.time = 0.0
    ta.state[:] = 0.0
    ta.state[:4] = X0
    if ta.dim > 4:
        ta.state[4:] = np.eye(4).ravel()  # the tangent starts as the identity
    crossings.clear()
    t0 = time.perf_counter(); res = ta.propagate_until(T_END)
    return time.perf_counter() - t0, res[3], len(crossings), ta.state[:4].copy()
scene = lambda name: os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes", name)
FL = {"bare": scene("hh_noev.json"), "section": scene("hh.json")}
H = {k: [] for k in HEY}; W = {k: [] for k in FL}
info = {}
for i in range(N):
    for k, ta in HEY.items():
        t, steps, count, final = hey(ta); H[k].append(t); info[k] = (steps, count, final)
    for k, path in FL.items():
        w, _, sm, rc, msg, _ = run_flicker(path, [])
        assert rc == 0, msg
        W[k].append(w); info["flicker " + k] = (sm["flow_evaluations"], sm["events"], sm["error_bound"])
print(f"load {loadavg()}, N = {N}, heyoka JIT (s): " + ", ".join(f"{k} {v:.3f}" for k, v in JIT.items()))
# heyoka's tangent run follows the same orbit: its state agrees with the plain run's.
drift = float(np.max(np.abs(info["tangent"][2] - info["plain"][2])))
print(f"heyoka's final state with and without the tangent differ by {drift:.1e}")
per = {}
for k in HEY:
    steps, count = info[k][:2]
    per[k] = med(H[k]) / steps
    print(f"heyoka {k:18s} {med(H[k])*1e3:7.3f} ms  {steps:5d} steps  {per[k]*1e9:6.0f} ns/step  crossings {count}")
# A bare run's flow evaluations are its steps (a guard's series counts as
# one too, so the section's are not).
for k in FL:
    evaluations, count, bound = info["flicker " + k]
    print(f"flicker {k:17s} {med(W[k])*1e3:7.3f} ms  {evaluations:5d} series  events {count}  bound {bound:.2e}")
per["flicker bare"] = med(W["bare"]) / info["flicker bare"][0]
print(f"heyoka's tangent: {per['tangent'] / per['plain']:.2f}x its plain step ({1 - per['plain'] / per['tangent']:.0%} of a step with it)")
print(f"flicker's step (with its bound) per heyoka's plain step: {per['flicker bare'] / per['plain']:.2f}x; per heyoka's step with its tangent: {per['flicker bare'] / per['tangent']:.2f}x")
print(f"section, whole run: flicker / heyoka plain {med(W['section']) / med(H['plain, section']):.2f}x; flicker / heyoka with its tangent {med(W['section']) / med(H['tangent, section']):.2f}x")
dump("case2d.json", {"heyoka": H, "flicker": W, "steps": {k: v[0] for k, v in info.items()}, "jit": JIT, "load": loadavg()})
