"""A bouncing ball defined as a dict (an automaton), run from Python, its
height drawn over time with each bounce marked, and its bounce times
checked against the closed form.

    target/venv/bin/pip install matplotlib
    target/venv/bin/python examples/python/bouncing_ball.py   # writes out/bouncing_ball.png
"""

import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import flicker

G, E, H = 9.81, 0.8, 1.0
BALL = {
    "model": "automaton",
    "parameters": {"g": G, "e": E},
    "states": ["y", "v"],
    "initial": {"y": H, "v": 0.0},
    "modes": {"flight": {
        "flow": {"y": "v", "v": "-g"},
        "transitions": [{"name": "bounce", "guard": "y", "direction": "falling",
                         "barrier": True, "reset": {"v": "-e * v"}}]}},
    "energy": "v^2 / 2 + g * y",
    "t_end": 10.0,
}


def main():
    run = flicker.run(BALL)
    print(run)
    t = run.events["t"]
    v_after = run.events["after"][:, run.state_names.index("v")]
    # The flight after each bounce is a parabola: draw it from the log.
    fig, ax = plt.subplots(figsize=(8, 4))
    starts = np.concatenate([[0.0], t])
    speeds = np.concatenate([[0.0], v_after])
    heights = np.concatenate([[H], np.zeros(len(t))])
    ends = np.concatenate([t, [run.summary["t_reached"]]])
    for t0, v0, y0, t1 in zip(starts, speeds, heights, ends):
        s = np.linspace(0.0, t1 - t0, 50)
        ax.plot(t0 + s, y0 + v0 * s - G * s * s / 2, color="tab:blue")
    ax.plot(t, np.zeros_like(t), "|", color="tab:red", markersize=12, label="bounces")
    zeno = math.sqrt(2 * H / G) * (1 + E) / (1 - E)
    ax.axvline(zeno, color="grey", linestyle="--", label=f"Zeno point {zeno:.4f}")
    ax.set_xlabel("time t")
    ax.set_ylabel("height y")
    ax.legend()
    os.makedirs("out", exist_ok=True)
    fig.savefig("out/bouncing_ball.png", dpi=120)
    t1 = math.sqrt(2 * H / G)
    falling = run.events["before"][:, 1] < 0
    k = np.arange(falling.sum())
    exact = t1 + 2 * t1 * E * (1 - E**k) / (1 - E)
    print(f"{len(t)} bounces, status {run.status}; largest bounce-time error "
          f"against the closed form {np.max(np.abs(t[falling] - exact)):.1e}; wrote out/bouncing_ball.png")


if __name__ == "__main__":
    main()
