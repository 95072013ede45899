"""Phase portraits of the impacting mechanism (models/mechanism_*.json)
from Python: several orbits of the strain formulation, each drawn from the
state sampled along its run (the closed form between impacts, from the
event log) with its impacts as jumps of the strain rate.

    target/venv/bin/pip install matplotlib
    target/venv/bin/python examples/python/phase_portrait.py   # writes out/phase_portrait.png
"""

import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import flicker

ETA = 1.2


def orbit(h0):
    """One orbit of energy h0 (from its apex) and its points between events."""
    scene = {"model": "mechanism", "formulation": "strain", "eta": ETA,
             "initial": {"energy": h0, "phase": "apex"}, "t_end": 20.0}
    run = flicker.run(scene)
    c = ETA - 1.0
    # Between events the strain is eps = c + A cos(t + phi): sample it from
    # each logged state after an impact (and from the start).
    eps0 = c + np.sqrt(2 * h0 + c * c)
    points = []
    t_prev, e_prev, r_prev = 0.0, eps0, 0.0
    times = list(run.events["t"]) + [run.summary["t_reached"]]
    after = list(run.events["after"]) + [None]
    for t, state in zip(times, after):
        s = np.linspace(0.0, t - t_prev, 200)
        u, w = e_prev - c, r_prev
        points.append((c + u * np.cos(s) + w * np.sin(s), -u * np.sin(s) + w * np.cos(s)))
        if state is not None:
            t_prev, e_prev, r_prev = t, state[0], state[1]
    return run, points


def main():
    fig, ax = plt.subplots(figsize=(6, 5))
    for h0 in (-0.015, -0.005, 0.01, 0.03, 0.06):
        run, flights = orbit(h0)
        for eps, rate in flights:
            ax.plot(eps, rate, color="tab:blue" if h0 > 0 else "tab:green", lw=1)
        for before, after in zip(run.events["before"], run.events["after"]):
            ax.plot([before[0], after[0]], [before[1], after[1]], "--", color="tab:red", lw=0.8)
        print(f"H0 = {h0:+.3f}: {run.summary['events']} impacts, energy error {run.summary['max_energy_error']:.1e}")
    ax.axvline(0.0, color="grey", lw=0.8)
    ax.set_xlabel("strain eps")
    ax.set_ylabel("strain rate eps'")
    ax.set_title(f"the mechanism at eta = {ETA}: loose (green) and impacting (blue) orbits")
    os.makedirs("out", exist_ok=True)
    fig.savefig("out/phase_portrait.png", dpi=120)
    print("wrote out/phase_portrait.png")


if __name__ == "__main__":
    main()
