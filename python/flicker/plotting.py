"""Pictures of a run with matplotlib (an optional dependency): its states
over time, or any two against each other, from the samples a run took
(`flicker.run(scene, t_eval=...)`), split at its events.

Between events the flow is drawn as a line through the samples, ending at
the state just before the event and starting again from the state just
after it; a reset that moves the state is a dashed jump; events are marked;
a stretch a discontinuous flow slides along a switching surface (from its
`slide:h` event to the next event) is drawn in red, as `flicker plot phase`
draws it.
"""

from typing import Any, List, Optional, Tuple

import numpy as np

SLIDING = "tab:red"


def _pieces(run) -> List[Tuple[np.ndarray, dict, bool]]:
    """The samples split at the events: for each stretch between events,
    its times, a dict of each state's values (the event's state before and
    after added at the ends) and whether it slides."""
    s = run.samples
    names = [k for k in s if k not in ("t", "bound")]
    ev = run.events
    t = s["t"]
    if ev is None or len(ev["t"]) == 0:
        return [(t, {n: s[n] for n in names}, False)]
    column = {n: run.state_names.index(n) for n in names if n in run.state_names}
    pieces = []
    start_t, start_state, sliding = None, None, False
    lo = 0
    for k, te in enumerate(ev["t"]):
        hi = int(np.searchsorted(t, te, side="left"))
        ts = list(t[lo:hi])
        values = {n: list(s[n][lo:hi]) for n in names}
        if start_t is not None:
            ts.insert(0, start_t)
            for n in names:
                values[n].insert(0, start_state[n])
        ts.append(te)
        for n in names:
            values[n].append(ev["before"][k, column[n]] if n in column else np.nan)
        pieces.append((np.array(ts), {n: np.array(v) for n, v in values.items()}, sliding))
        start_t = te
        start_state = {n: ev["after"][k, column[n]] if n in column else np.nan for n in names}
        sliding = str(ev["guard"][k]).startswith("slide:")
        lo = hi
    ts = [start_t] + list(t[lo:])
    values = {n: np.array([start_state[n]] + list(s[n][lo:])) for n in names}
    pieces.append((np.array(ts), values, sliding))
    return pieces


def plot(run, x: Optional[str] = None, y: Optional[str] = None, ax: Any = None):
    """Draw `run`: every state over time, or `y` against `x` (a phase
    plane). Returns the matplotlib Axes (a new figure's unless `ax`). A run
    without samples is drawn at its events alone (the states before each
    reset filled, after it hollow)."""
    import matplotlib.pyplot as plt

    if (x is None) != (y is None):
        raise ValueError("give both x and y for a phase plane, or neither for states over time")
    if run.samples is None:
        if run.events is None or len(run.events["t"]) == 0:
            raise ValueError(
                "this run took no samples and has no events to draw: run it with t_eval=..."
            )
        names = list(run.state_names)
    else:
        names = [k for k in run.samples if k not in ("t", "bound")]
    for axis, name in (("x", x), ("y", y)):
        if name is not None and name not in names:
            raise ValueError(f"{axis}: the run has no state {name!r} (its states: {', '.join(names)})")
    if ax is None:
        _, ax = plt.subplots()
    colours = {n: f"C{k}" for k, n in enumerate(names)}
    if run.samples is None:
        return _at_events(run, names, colours, x, y, ax)
    pieces = _pieces(run)
    legend = []
    if x is None:
        for k, (ts, values, sliding) in enumerate(pieces):
            for n in names:
                ax.plot(ts, values[n], color=SLIDING if sliding else colours[n],
                        label=n if k == 0 else None)
        ax.set_xlabel("t")
        legend += [_key(n, color=colours[n]) for n in names]
    else:
        for ts, values, sliding in pieces:
            # A slide that holds the state (a block stuck on a fixed
            # surface) is a point: a dot shows it.
            still = sliding and np.ptp(values[x]) == 0 and np.ptp(values[y]) == 0
            ax.plot(values[x], values[y], "o" if still else "-",
                    color=SLIDING if sliding else colours[y])
        jumped = False
        for (_, a, _), (_, b, _) in zip(pieces, pieces[1:]):
            before, after = (a[x][-1], a[y][-1]), (b[x][0], b[y][0])
            if before != after:
                jumped = True
                ax.plot([before[0], after[0]], [before[1], after[1]], "--", color="grey")
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        legend.append(_key("the flow", color=colours[y]))
        if jumped:
            legend.append(_key("a reset's jump", color="grey", linestyle="--"))
    if any(sliding for _, _, sliding in pieces):
        legend.append(_key("sliding on a switching surface", color=SLIDING))
    ev = run.events
    if ev is not None and len(ev["t"]) and x is None:
        # Each event a tick on the time axis.
        ax.plot(ev["t"], np.zeros_like(ev["t"]), "|", color="black", markersize=8,
                transform=ax.get_xaxis_transform())
        legend.append(_key("events", color="black", marker="|", linestyle="none"))
    ax.legend(handles=legend)
    return ax


def _key(label: str, **style):
    """A legend entry drawn nowhere else."""
    from matplotlib.lines import Line2D

    return Line2D([], [], label=label, **style)


def _at_events(run, names, colours, x, y, ax):
    """`plot` for a run without samples: each event's state before its reset
    (filled) and after it (hollow)."""
    ev = run.events
    column = {n: run.state_names.index(n) for n in names}
    before, after = ev["before"], ev["after"]
    if x is None:
        for n in names:
            k = column[n]
            ax.plot(ev["t"], before[:, k], "o", color=colours[n])
            ax.plot(ev["t"], after[:, k], "o", mfc="none", color=colours[n])
        ax.set_xlabel("t")
        legend = [_key(n, color=colours[n], marker="o", linestyle="none") for n in names]
    else:
        i, j = column[x], column[y]
        ax.plot(before[:, i], before[:, j], "o", color=colours[y])
        ax.plot(after[:, i], after[:, j], "o", mfc="none", color=colours[y])
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        legend = []
    legend += [
        _key("before each reset", color="grey", marker="o", linestyle="none"),
        _key("after it", color="grey", marker="o", mfc="none", linestyle="none"),
    ]
    ax.legend(handles=legend)
    ax.set_title("at the events only (run with t_eval=... for the trajectory)")
    return ax


def bifurcation(branch: dict, state: Optional[str] = None, ax: Any = None):
    """Draw a branch `flicker.continuation` returned: `state` at the section
    (default: the one that varies most) against the parameter, solid where
    the orbit is stable and dashed where not, each bifurcation circled and
    named. Returns the Axes."""
    import matplotlib.pyplot as plt

    fixed = {"parameter", "period", "largest_multiplier", "stable", "label", "ended"}
    states = [k for k in branch if k not in fixed]
    if state is None:
        state = max(states, key=lambda k: np.ptp(branch[k]))
    elif state not in states:
        raise ValueError(f"state: the branch has no {state!r} (its states: {', '.join(states)})")
    if ax is None:
        _, ax = plt.subplots()
    p, y, stable = np.asarray(branch["parameter"]), np.asarray(branch[state]), branch["stable"]
    start = 0
    for k in range(1, len(p) + 1):
        if k == len(p) or stable[k] != stable[start]:
            # Each stretch joins the next one's first point: no gap.
            end = min(k + 1, len(p))
            ax.plot(p[start:end], y[start:end], "-" if stable[start] else "--", color="C0")
            start = k
    for k, label in enumerate(branch["label"]):
        if label and label != "end":
            ax.plot(p[k], y[k], "o", mfc="none", color="C3")
            ax.annotate(label, (p[k], y[k]), textcoords="offset points", xytext=(4, 4))
    ax.set_xlabel("parameter")
    ax.set_ylabel(state)
    return ax


def diagram_plot(found: dict, state: Optional[str] = None, ax: Any = None):
    """Draw a `flicker.diagram`: `state` (default: the first) just after
    each section event against the parameter, as small dots, the way
    bifurcation diagrams are drawn. Returns the Axes."""
    import matplotlib.pyplot as plt

    states = [k for k in found if k not in ("param", "t", "ended_short")]
    if state is None:
        state = states[0]
    elif state not in states:
        raise ValueError(f"state: the diagram has no {state!r} (its states: {', '.join(states)})")
    if ax is None:
        _, ax = plt.subplots()
    ax.plot(found["param"], found[state], ",", color="C3")
    ax.set_xlabel("parameter")
    ax.set_ylabel(state)
    return ax


def basins_plot(found: dict, ax: Any = None):
    """Draw what `flicker.basins` returned: each point at its two starting
    values, coloured by the attractor it reaches, a legend naming each.
    Returns the Axes."""
    import matplotlib.pyplot as plt

    x, y = [k for k in found if k not in ("attractor", "attractors")]
    if ax is None:
        _, ax = plt.subplots()
    for a in found["attractors"]:
        at = found["attractor"] == a["id"]
        ax.plot(found[x][at], found[y][at], "s", ms=3, color=f"C{a['id'] % 10}",
                label=f"{a['id']}: {a['kind']}")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.legend()
    return ax


def work_precision(compared: dict, ax: Any = None):
    """Draw what `flicker.compare` returned: each method's error at the end
    against its wall time, both logarithmic, a line per method through its
    tolerances (or steps). Runs that did not complete are left out.
    Returns the Axes."""
    import matplotlib.pyplot as plt

    rows = compared["rows"]
    if ax is None:
        _, ax = plt.subplots()
    methods = list(dict.fromkeys(rows["method"]))
    for k, method in enumerate(methods):
        keep = [i for i, (m, s) in enumerate(zip(rows["method"], rows["status"]))
                if m == method and s == "completed"]
        seconds = np.asarray(rows["wall_seconds"])[keep]
        # An exact answer's zero error drawn at the smallest positive double.
        error = np.maximum(np.asarray(rows["final_error"])[keep], np.finfo(float).tiny)
        order = np.argsort(seconds)
        ax.loglog(seconds[order], error[order], "o-", color=f"C{k}", label=method)
    ax.set_xlabel("wall seconds")
    ax.set_ylabel("error at the end")
    ax.set_title(f"against {compared['reference']}")
    ax.legend()
    return ax
