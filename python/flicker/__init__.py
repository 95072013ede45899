"""flicker: an event-driven engine for hybrid systems, from Python.

Smooth flows between events, guards that fire when a function of the state
crosses zero, resets that jump the state: impacting mechanisms, chains of
them, their continuum limits, and any hybrid automaton written in JSON. The
engine is flicker's own (Rust); this package runs its scenes and hands the
results over as NumPy arrays.

    >>> import flicker
    >>> run = flicker.run("models/automata/bouncing_ball.json")
    >>> run.summary["status"]
    'zeno'
    >>> run.events["t"][:3]          # bounce times, float64
    >>> run.events["before"][:, 1]   # the speed before each bounce

A scene is a path, a JSON string or a dict, in the format `flicker run`
reads (see the repository's docs/command_line.md and docs/automata.md). A scene flicker
refuses raises `SceneError` (a `ValueError`); a run that cannot be trusted
returns, with `summary["status"] == "failed"` and the reason in
`summary["reason"]`, as the command line does. Runs release the GIL (runs
in several threads use several cores), and Ctrl-C stops a run within a
second, leaving `status == "interrupted"`.
"""

import json
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _flicker
from ._flicker import SceneError
from .plotting import basins_plot, bifurcation, diagram_plot, work_precision

__all__ = [
    "Run",
    "SceneError",
    "basins",
    "basins_plot",
    "bifurcation",
    "check",
    "diagram_plot",
    "compare",
    "continuation",
    "diagram",
    "diagram_frame",
    "orbit",
    "lyapunov",
    "run",
    "sweep",
    "work_precision",
]

Scene = Union[str, "os.PathLike[str]", Dict[str, Any]]


def _not_finite(value: Any, path: str) -> Optional[str]:
    """The path of the first number in `value` that JSON cannot hold (NaN,
    an infinity), or None."""
    if isinstance(value, dict):
        for key, item in value.items():
            found = _not_finite(item, f"{path}.{key}" if path else str(key))
            if found:
                return found
    elif isinstance(value, (list, tuple)):
        for k, item in enumerate(value):
            found = _not_finite(item, f"{path}[{k}]")
            if found:
                return found
    elif isinstance(value, (float, np.floating)) and not np.isfinite(value):
        return f"{path} is {value}"
    return None


def _plain(value: Any) -> Any:
    """A NumPy number or array in a scene dict, as JSON writes it."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"a scene holds {type(value).__name__}, which JSON cannot write")


def _source(scene: Scene):
    """(text, path) for the native module: a dict or a JSON string is text,
    anything else a path."""
    if isinstance(scene, dict):
        bad = _not_finite(scene, "")
        if bad:
            field, _, value = bad.partition(" is ")
            reason = f"is {value}, which JSON cannot hold: give a finite number"
            error = SceneError(f"flicker: field {field}: {reason}")
            error.field, error.reason = field, reason
            raise error
        return json.dumps(scene, default=_plain), None
    if isinstance(scene, os.PathLike):
        return None, os.fspath(scene)
    if isinstance(scene, str):
        if scene.lstrip().startswith("{"):
            return scene, None
        return None, scene
    raise TypeError(
        f"scene must be a path, a JSON string or a dict, not {type(scene).__name__}"
    )


class Run:
    """A finished run.

    Attributes:
        summary: the dict `summary.json` holds (`status`, `reason`,
            `events`, `final_state`, `method`, `max_energy_error`, ...).
        events: a dict of NumPy arrays, one per field of the event log:
            `t` (float64), `seq` (uint64), `guard`, `mode_before`,
            `mode_after` (str), `before` and `after` (float64, shape
            `(n, len(state_names))`, NaN where an event's mode has no such
            state), `energy_before`, `energy_after` (float64, NaN without an
            energy), `shadow` (bool: the event comes past the run's
            horizon, in a run that goes past it: asked to, or a chain's),
            and the labels the
            model gives (`unit` as int64, `rel_velocity`, `x`) where it has
            them. None if the run was asked for no events.
        state_names: the columns of `before` and `after`.
        trace: for chains and continua, a dict of float64 arrays `t`,
            `energy`, `momentum`, `right_end` at the scene's sample times;
            else None.
        profiles: for chains and continua, a list of dicts (`t`, and arrays
            `x`, `strain`, `displacement`, `velocity`) at the snapshot
            times; else None.
        samples: for a run given `t_eval`, a dict of float64 arrays: `t`,
            one per state, and `bound` (each sample's error bound), from
            the method's own dense output; a sample at an event's time
            holds the state before the reset. Else None.
        fields: everything a chain or continuum reports (the two above, the
            classical string beside them, the momentum), or None.
    """

    def __init__(self, raw: Dict[str, Any]):
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        self.fields: Optional[Dict[str, Any]] = raw["fields"]
        self.trace = self.fields["trace"] if self.fields else None
        self.profiles = self.fields["profiles"] if self.fields else None
        self.samples: Optional[Dict[str, np.ndarray]] = raw["samples"]
        columns = raw["events"]
        if columns is None:
            self.events = None
            self.state_names: List[str] = []
            return
        names = np.asarray(columns["names"] or [""], dtype=str)
        self.state_names = list(columns["state_names"])
        events = {
            "seq": columns["seq"],
            "t": columns["t"],
            "guard": names[columns["guard"]],
            "mode_before": names[columns["mode_before"]],
            "mode_after": names[columns["mode_after"]],
            "energy_before": columns["energy_before"],
            "energy_after": columns["energy_after"],
            "before": columns["before"],
            "after": columns["after"],
            "shadow": columns["shadow"],
        }
        for name, values, counts in columns["labels"]:
            whole = counts and not np.isnan(values).any()
            events[name] = values.astype(np.int64) if whole else values
        self.events: Optional[Dict[str, np.ndarray]] = events

    @property
    def status(self) -> str:
        """The run's status: `completed`, `zeno`, `failed` or `interrupted`."""
        return self.summary["status"]

    def plot(self, x: Optional[str] = None, y: Optional[str] = None, ax=None):
        """Draw the run's samples (take them with `t_eval=`): every state
        over time, events ticked on the time axis, or `y` against `x`, each
        reset a dashed jump; sliding stretches in red. Returns the
        matplotlib Axes (drawn into `ax` if given). Needs matplotlib."""
        from .plotting import plot

        return plot(self, x, y, ax)

    def to_pandas(self, samples: bool = False):
        """The events as a pandas DataFrame: one row per event, one column
        per field, `before.NAME` and `after.NAME` for each state; or with
        `samples=True`, the samples (`t`, each state, `bound`), one row per
        time. Needs pandas."""
        import pandas as pd

        if samples:
            if self.samples is None:
                raise ValueError("this run took no samples (run it with t_eval=...)")
            return pd.DataFrame(self.samples)

        if self.events is None:
            raise ValueError("this run kept no events (run it with events=True)")
        data = {}
        for key, values in self.events.items():
            if key in ("before", "after"):
                for k, name in enumerate(self.state_names):
                    data[f"{key}.{name}"] = values[:, k]
            else:
                data[key] = values
        return pd.DataFrame(data)

    def __repr__(self) -> str:
        s = self.summary
        return (
            f"<flicker.Run {s['model']} {s['status']} at t = {s['t_reached']} "
            f"of {s['t_end']}, {s['events']} events, method {s['method']}>"
        )


def run(
    scene: Scene,
    *,
    t_end: Optional[float] = None,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    step: Optional[float] = None,
    log: Optional[Union[str, "os.PathLike[str]"]] = None,
    events: bool = True,
    sensitivities: Optional[Sequence[str]] = None,
    t_eval: Optional[Sequence[float]] = None,
    past_horizon: bool = False,
) -> Run:
    """Run a scene and return its `Run`.

    Args:
        scene: a path to a scene file, a JSON string, or a dict.
        t_end: the simulated time to stop at, replacing the scene's.
        method: `exact`, `linear`, `taylor`, `dopri5`, `dop853` or
            `verlet`, replacing the scene's (default: the cheapest exact
            description of the model).
        rtol, atol: tolerances (`dopri5`, `dop853`, `taylor`).
        step: the fixed step (`verlet`).
        log: a file to stream the event log to (JSON Lines, as
            `flicker run` writes `events.jsonl`); none is written otherwise.
        events: keep the events as arrays (`Run.events`).
        sensitivities: directions (a parameter's name, or `initial.STATE`)
            to carry the derivatives of the state and of every event time
            along (any model with a finite state: the mechanism, the chain,
            automata): the summary's `sensitivities`, and
            `d{state}/d{direction}`, `dt/d{direction}` among the events'
            states.
        t_eval: times (from 0 to t_end) at which to keep the state, with
            its error bound: `Run.samples` (automata and the mechanism), a
            row per time in the order given, repeats included (a run that
            stops early has no rows for the times it did not reach).
        past_horizon: go on past the run's horizon (where its error
            reaches 1e-3 of its state, or its bound can no longer decide
            what happens) as a pseudo-orbit, instead of stopping where it
            cannot decide: the run completes, its summary states `horizon`
            and no bound, and every event from the horizon on is flagged
            (`events["shadow"]`).

    Raises:
        SceneError: the scene or an argument is refused; `field` and
            `reason` say where and why.
    """
    text, path = _source(scene)
    asked = None if t_eval is None else np.asarray(t_eval, dtype=np.float64).ravel()
    raw = _flicker.run(
        text,
        path,
        t_end=t_end,
        method=method,
        rtol=rtol,
        atol=atol,
        step=step,
        log=None if log is None else os.fspath(log),
        events=events,
        sensitivities=None if sensitivities is None else list(sensitivities),
        t_eval=None if asked is None else [float(t) for t in asked],
        past_horizon=bool(past_horizon),
    )
    run = Run(raw)
    if asked is not None and run.samples is not None:
        run.samples = _as_asked(run.samples, asked)
    return run


def _as_asked(samples: Dict[str, np.ndarray], asked: np.ndarray) -> Dict[str, np.ndarray]:
    """The samples (taken in increasing time, each time once) in the order
    `t_eval` asked for them, a row per time asked; the times a run that
    stopped early did not reach are left out."""
    taken = samples["t"]
    at = np.searchsorted(taken, asked)
    reached = at < len(taken)
    reached[reached] = taken[at[reached]] == asked[reached]
    rows = at[reached]
    return {name: values[rows] for name, values in samples.items()}


def check(scene: Scene) -> List[str]:
    """What `flicker check` says of a scene or a sweep, a line each: that it
    is valid, its model, and what the model describes (for an automaton:
    its modes, guards and the method it would run). Raises `SceneError`
    where it is not valid."""
    text, path = _source(scene)
    return _flicker.check(text, path)


def compare(
    scene: Scene,
    *,
    methods: Optional[Sequence[str]] = None,
    tolerances: Optional[Sequence[float]] = None,
    steps: Optional[Sequence[float]] = None,
) -> Dict[str, Any]:
    """`flicker compare`: every method (default: all the scene's model
    runs) over the tolerances or steps, each measured against the exact
    answer. Returns `{"reference": what the answer is, "rows": columns}`,
    the columns of `compare.csv` (`method`, `status` as lists of str; the
    rest float64 arrays, NaN where a value does not apply)."""
    text, path = _source(scene)
    return _flicker.compare(
        text,
        path,
        methods=None if methods is None else list(methods),
        tolerances=None if tolerances is None else [float(t) for t in tolerances],
        steps=None if steps is None else [float(h) for h in steps],
    )


def sweep(sweep_file: Scene, *, threads: Optional[int] = None) -> Dict[str, Any]:
    """`flicker sweep`: every point of a sweep (a path, a JSON string or a
    dict with `scene` and `grid`), in parallel on `threads` threads
    (default: one per core). Returns a dict of columns, as `flicker sweep`
    writes them: `point`, each axis, `status` (list of str), `events`,
    `first_impact`, `impact_period`, `exact_period`, `period_error`,
    `energy_error`, `t_reached`, `horizon` (NaN where a value is missing).
    A sweep with `"past_horizon": true` runs each point on past its
    horizon, as `run(..., past_horizon=True)` does."""
    text, path = _source(sweep_file)
    return _flicker.sweep(text, path, threads=threads)


def orbit(
    scene: Scene,
    section: str,
    *,
    events: int = 1,
    settle: float = 0.0,
    forcing_period: Optional[float] = None,
    wall: float = 600.0,
) -> Dict[str, Any]:
    """`flicker orbit`: a periodic orbit through the Poincare section of the
    events of transition `section` (`events` of them per period), by
    Newton shooting from the scene's start after `settle`; for an
    automaton that reads the clock, its period a whole number of
    `forcing_period`. Returns what `orbit.json` holds: `status`,
    `converged`, `period`, `section_state`, `multipliers` (`[re, im]`, the
    trivial 1 first), `stable`, `residual` (recomputed by a plain run),
    `iterations`. A search that does not converge, or is still running
    after `wall` seconds (the whole search, transient included), returns,
    saying why in `status`."""
    text, path = _source(scene)
    return json.loads(
        _flicker.orbit(
            text,
            path,
            section=section,
            events=events,
            settle=float(settle),
            forcing_period=forcing_period,
            wall=float(wall),
        )
    )


def lyapunov(
    scene: Scene,
    *,
    exponents: Optional[int] = None,
    transient: float = 0.0,
    t_end: Optional[float] = None,
    interval: Optional[float] = None,
    wall: float = 600.0,
) -> Dict[str, Any]:
    """`flicker lyapunov`: the Lyapunov spectrum of any model with a finite
    state, through its events (Benettin's method: tangents carried by the
    variational equations and each event's saltation matrix,
    re-orthonormalised every `interval`, default a quarter of the scene's
    time scale), averaged over `t_end` (default the scene's) after
    `transient`. Returns what `lyapunov.json` holds: `exponents` (largest
    first; a forced system's clock gives one 0), `sum`, `t_span`,
    `events`, `history` (rows of `t` and `exponents`), `method`, and
    `status` (`completed`, or why it stopped short: Ctrl-C, or past `wall`
    seconds)."""
    text, path = _source(scene)
    return json.loads(
        _flicker.lyapunov(
            text,
            path,
            exponents=exponents,
            transient=float(transient),
            t_end=None if t_end is None else float(t_end),
            interval=None if interval is None else float(interval),
            wall=float(wall),
        )
    )


def continuation(
    scene: Scene,
    section: str,
    param: str,
    to: float,
    *,
    events: int = 1,
    settle: float = 0.0,
    forcing_period: Optional[float] = None,
    points: int = 200,
    max_step: float = 0.05,
    wall: float = 600.0,
) -> Dict[str, Any]:
    """`flicker continue`: the orbit `orbit` finds, followed in parameter
    `param` to `to` by pseudo-arclength continuation (at most `points`
    orbits, the longest step `max_step` of the way). Returns the branch as
    columns: `parameter`, `period`, each state at the section (float64
    arrays), `largest_multiplier`, `stable` and `label` (`fold`, `period
    doubling`, `torus`, `grazing`, `end` or empty), and `ended`, why the
    branch ended (past `wall` seconds of wall time among the reasons)."""
    text, path = _source(scene)
    return _flicker.continuation(
        text,
        path,
        section=section,
        param=param,
        to=float(to),
        events=events,
        settle=float(settle),
        forcing_period=forcing_period,
        points=points,
        max_step=float(max_step),
        wall=float(wall),
    )


def diagram(
    scene: Scene,
    param: str,
    start: float,
    stop: float,
    *,
    section: str,
    points: int = 100,
    transient: Optional[float] = None,
    record: int = 50,
    span: Optional[float] = None,
    follow: bool = False,
    past_horizon: bool = False,
    wall: float = 3600.0,
) -> Dict[str, Any]:
    """`flicker diagram`: a brute-force bifurcation diagram. At each of
    `points` values of `param` from `start` to `stop`, the scene runs
    `transient` (default: its `t_end`), then records the state just after
    each of the next `record` events of the guard `section`, running at most
    `span` past the transient (default: its `t_end`). `follow` starts each
    value from where the one before ended (the clock continuing);
    `past_horizon` lets chaotic runs go on as pseudo-orbits.

    Returns a dict: `param`, `t` and each state as float64 arrays, a row per
    record, and `ended_short`: a list of dicts (`param`, `status`, `reason`,
    `records`), one per value that ended at a Zeno point, failed or was
    interrupted (the diagram goes on past them). `diagram_frame` makes a
    pandas DataFrame of it, `diagram_plot` draws it."""
    text, path = _source(scene)
    return _flicker.diagram(
        text,
        path,
        param=param,
        start=float(start),
        stop=float(stop),
        points=int(points),
        section=section,
        transient=None if transient is None else float(transient),
        record=int(record),
        span=None if span is None else float(span),
        follow=bool(follow),
        past_horizon=bool(past_horizon),
        wall=float(wall),
    )


def diagram_frame(found: Dict[str, Any]):
    """The records of a `diagram` as a pandas DataFrame: `param`, `t`, each
    state. Needs pandas."""
    import pandas as pd

    return pd.DataFrame({k: v for k, v in found.items() if k != "ended_short"})


def basins(
    scene: Scene,
    grid: Dict[str, Tuple[float, float, int]],
    *,
    transient: Optional[float] = None,
    section: Optional[str] = None,
    record: int = 64,
    tolerance: float = 1e-6,
    forcing_period: Optional[float] = None,
    past_horizon: bool = False,
    wall: float = 3600.0,
) -> Dict[str, Any]:
    """`flicker basins`: basins of attraction. `grid` gives two states'
    starting values, `{"x": (start, stop, count), "v": (...)}` (the other
    states from the scene); each point runs `transient` (default: its
    `t_end`) and is named by the attractor it reaches: an equilibrium (the
    state settles to `tolerance`), a periodic orbit (the states after the
    `section` guard's events repeat within `record` of them), a chaotic
    attractor (no repeat, a positive largest exponent; `past_horizon` lets
    its runs go on), a Zeno point, or unresolved (said, with why). A
    periodic orbit is refined by the orbit finder (period, multipliers,
    stability); a model that reads the clock needs `forcing_period` for it.

    Returns a dict: the two states' starting values and `attractor` (the id
    each point reaches) as arrays, a row per point, and `attractors`, a
    list of dicts (`id`, `kind`, `state` as a dict, `points`, and `period`
    and `cycle` for an orbit, with `period_time`, `multipliers` (complex)
    and `stable` where refined, `exponent` where measured, `reason` where
    unresolved)."""
    if len(grid) != 2:
        raise ValueError("grid: give two states, {name: (start, stop, count), ...}")
    axes = [f"{name}={float(a)!r}:{float(b)!r}:{int(n)}" for name, (a, b, n) in grid.items()]
    text, path = _source(scene)
    found = _flicker.basins(
        text,
        path,
        grid=axes,
        transient=None if transient is None else float(transient),
        section=section,
        record=int(record),
        tolerance=float(tolerance),
        forcing_period=None if forcing_period is None else float(forcing_period),
        past_horizon=bool(past_horizon),
        wall=float(wall),
    )
    for attractor in found["attractors"]:
        if "multipliers" in attractor:
            attractor["multipliers"] = [complex(re, im) for re, im in attractor["multipliers"]]
    return found
