"""What the Python package costs beyond the engine's own run.

For the bundled impacting scene (models/mechanism_impacting.json, 234
impacts to t = 1000) and the same scene run longer, a call of
`flicker.run` from Python against the run's own wall time as the engine
measures it in process (`summary["wall_seconds"]`, what the command line
reports): medians of 7 calls. The difference is the package's overhead:
reading the scene, the thread the run goes on, the summary, and the events
handed to NumPy. Then 10^6 events returned as arrays, and what that takes
beyond the same run keeping no events.

    bash .ci/test                                  # builds and installs the package into target/venv
    target/venv/bin/python benches/python_package.py
"""

import json
import statistics
import time
from pathlib import Path

import flicker

SCENE = Path(__file__).resolve().parents[1] / "models" / "mechanism_impacting.json"


def timed(scene, events=True, repeats=7):
    """Median call time, median in-process run time, events."""
    calls, walls = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        run = flicker.run(scene, events=events)
        calls.append(time.perf_counter() - start)
        walls.append(run.summary["wall_seconds"])
    return statistics.median(calls), statistics.median(walls), run.summary["events"]


def main():
    base = json.loads(SCENE.read_text())
    print("flicker.run from Python against the run's in-process time (medians of 7)")
    rows = []
    for t_end in (1e3, 1e5, 1e6):
        scene = dict(base, t_end=t_end)
        call, wall, events = timed(scene)
        rows.append((events, call, wall))
        print(f"  {events:>8} events: call {call * 1e3:8.3f} ms, run {wall * 1e3:8.3f} ms, "
              f"beyond the run {(call - wall) * 1e3:6.3f} ms ({call / wall:.2f}x)")
    fixed = rows[0][1] - rows[0][2]
    print(f"  fixed overhead (the bundled scene): {fixed * 1e3:.3f} ms; "
          f"every call within {max(c / (w + fixed) for _, c, w in rows):.2f}x of run + fixed")
    scene = dict(base, t_end=1e3 * 1e6 / 234)
    call, wall, events = timed(scene, repeats=5)
    quiet_call, quiet_wall, _ = timed(scene, events=False, repeats=5)
    print(f"{events} events as arrays: call {call:.3f} s; the run alone (no events kept) "
          f"{quiet_wall:.3f} s: {call - quiet_wall:.3f} s for the events (kept as columns during "
          f"the run {wall - quiet_wall:.3f} s, handed to NumPy {call - wall:.3f} s)")


if __name__ == "__main__":
    main()
