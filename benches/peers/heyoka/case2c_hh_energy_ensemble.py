"""Diagnostic: is the bare Taylor run's energy error on Henon-Heiles heyoka's, or only one orbit's luck?

Twelve orbits (x0 = 0.05 + 0.001 k, the rest as case2b), each to t = T by heyoka and by flicker's
Taylor method (same order, same step rule), the relative energy error sampled at 200 times: per
orbit its root mean square. One orbit's final error is a random walk's single draw; the ensemble's
median says whether the rounding differs.
Usage: python case2c_hh_energy_ensemble.py [T]   (default 2000)
"""
import os, sys, csv, json, tempfile
from pathlib import Path
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import heyoka as hy
from common import FLICKER, HERE, dump, med, run_flicker

T = float(sys.argv[1]) if len(sys.argv) > 1 else 2000.0
x, y, px, py = hy.make_vars("x", "y", "px", "py")
SAMPLES = 200


def energy(s):
    x, y, px, py = s
    return (px**2 + py**2) / 2 + (x**2 + y**2) / 2 + x**2 * y - y**3 / 3


base = json.loads((HERE / "scenes/hh_noev.json").read_text())
rows = []
for k in range(12):
    x0 = [0.05 + 0.001 * k, 0.3, 0.3521363372331802, 0.0]
    e0 = energy(x0)
    ta = hy.taylor_adaptive([(x, px), (y, py), (px, -x - 2.0 * x * y), (py, -y - x**2 + y**2)], x0)
    grid = np.linspace(0.0, T, SAMPLES + 1)
    states = ta.propagate_grid(grid)[5]
    heyoka_rms = float(np.sqrt(np.mean([((energy(s) - e0) / e0) ** 2 for s in states])))
    scene = dict(base, initial=dict(zip(["x", "y", "px", "py"], x0)), t_end=T)
    path = Path(tempfile.mkdtemp(prefix="flk_ens_")) / "scene.json"
    path.write_text(json.dumps(scene))
    _, _, _, rc, msg, out = run_flicker(path, ["--samples", str(SAMPLES)])
    assert rc == 0, msg
    with open(Path(out) / "samples.csv") as f:
        sampled = [[float(r[c]) for c in ["x", "y", "px", "py"]] for r in csv.DictReader(f)]
    flicker_rms = float(np.sqrt(np.mean([((energy(s) - e0) / e0) ** 2 for s in sampled])))
    rows.append({"x0": x0[0], "heyoka": heyoka_rms, "flicker": flicker_rms})
    print(f"x0 {x0[0]:.3f}: rms relative energy error heyoka {heyoka_rms:.2e}, flicker {flicker_rms:.2e}")
h, f = med([r["heyoka"] for r in rows]), med([r["flicker"] for r in rows])
print(f"median over 12 orbits to t = {T:g}: heyoka {h:.2e}, flicker {f:.2e} (flicker / heyoka {f / h:.2f}); flicker {FLICKER}")
dump("case2c.json", {"t_end": T, "orbits": rows, "median_heyoka": h, "median_flicker": f})
