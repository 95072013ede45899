"""Case 1: strain-form mechanism, eta 0.8, omega 1, H0 0.1 from an impact, t_end 1e5 (43,468 impacts).
heyoka (tol = double eps, terminal t_event with callback flipping eps') vs flicker
(automaton default = linear propagator, automaton --method taylor, built-in model 'mechanism' strain = closed form).
Runs interleaved, N repeats each; solve-only medians; reference = exact.py closed form in long double."""
import os
import sys, time, math, statistics
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import heyoka as hy
import exact
from common import *

N = int(sys.argv[1]) if len(sys.argv) > 1 else 7
T_END = 1e5
ex = exact.Exact()
tol = float(np.finfo(float).eps)

hy.llvm_state.set_diskcache_enabled(False)
rec = []
def cb(ta, d):
    st = ta.state
    rec.append((ta.time, st[0], st[1]))
    st[1] = -st[1]
    return True
eps, v = hy.make_vars("eps", "v")
hy.llvm_state.clear_memcache()
t0 = time.perf_counter()
ta = hy.taylor_adaptive([(eps, v), (v, -ex.omega**2 * (eps - (ex.eta - 1.0)))], list(ex.y0), tol=tol,
                        t_events=[hy.t_event(eps, callback=cb, direction=hy.event_direction.negative)])
jit = time.perf_counter() - t0

def hey():
    ta.time = 0.0; ta.state[:] = ex.y0; ta.reset_cooldowns(); rec.clear()
    t0 = time.perf_counter()
    res = ta.propagate_until(T_END)
    s = time.perf_counter() - t0
    return s, res

FL = {
    "flicker automaton default (linear)": (os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes/mech_automaton.json"), []),
    "flicker automaton --method taylor": (os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes/mech_automaton.json"), ["--method", "taylor"]),
    "flicker built-in mechanism strain (exact)": (os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenes/mech_builtin_explicit.json"), []),
}
times = {"heyoka": []}
proc = {k: [] for k in FL}
wall = {k: [] for k in FL}
summ = {}
load0 = loadavg()
for i in range(N):
    s, res = hey(); times["heyoka"].append(s)
    for k, (sc, args) in FL.items():
        w, p, sm, rc, msg, _ = run_flicker(sc, args)
        wall[k].append(w); proc[k].append(p); summ[k] = sm
        assert rc == 0, msg
# accuracy
arr = np.array(rec)
m_h = exact.metrics(ex, T_END, arr[:, 0], arr[:, 1], arr[:, 2], ta.time, float(ta.state[0]), float(ta.state[1]))
rows = [{"name": "heyoka 7.13 t_event+callback, tol 2.2e-16", "median_s": med(times["heyoka"]), "runs": times["heyoka"],
         "jit_s": jit, "order": ta.order, "outcome": str(res[0]), **m_h}]
for k, (sc, args) in FL.items():
    _, _, sm, rc, msg, od = run_flicker(sc, args, events=True)
    ev = read_events(od)
    t_imp = [e["t"] for e in ev]
    keys = list(sm["final_state"].keys())
    sn = "strain" if "strain" in ev[0]["before"] else keys[0]
    e_imp = [e["before"]["strain"] for e in ev]
    v_imp = [e["before"]["strain_rate"] for e in ev]
    fs = sm["final_state"]
    m = exact.metrics(ex, T_END, t_imp, e_imp, v_imp, sm["t_reached"], fs["strain"], fs["strain_rate"])
    rows.append({"name": k, "median_s": med(wall[k]), "runs": wall[k], "proc_median_s": med(proc[k]), "proc_runs": proc[k],
                 "method": sm["method_description"], "status": sm["status"], "events": sm["events"],
                 "error_bound": sm["error_bound"], "event_time_bound": sm["event_time_bound"],
                 "ratio_to_heyoka": med(wall[k]) / med(times["heyoka"]),
                 "proc_ratio_to_heyoka": med(proc[k]) / med(times["heyoka"]), **m})
print(f"case1 mechanism t_end=1e5, exact impacts {ex.n_impacts(T_END)}; N={N}; load {load0} -> {loadavg()}")
print(f"heyoka JIT (memcache cleared, diskcache off): {jit:.4f} s, order {ta.order}")
for r in rows:
    print(f"{r['name']:45s} solve {r['median_s']*1e3:8.3f} ms  ratio {r.get('ratio_to_heyoka', 1):5.2f}  "
          f"proc {r.get('proc_median_s', float('nan'))*1e3:8.2f} ms  imp {r['impacts']}/{r['exact_impacts']}  "
          f"d_eps {r['final_eps_error']:.1e} d_v {r['final_v_error']:.1e}  max dt_imp {r['max_impact_time_error']:.1e}  "
          f"max rel dH {r['max_rel_energy_error']:.1e}  bound {r.get('error_bound', '-')}")
    print("   runs", ["%.4f" % x for x in r["runs"]])
dump("case1.json", {"rows": rows, "load": load0})
