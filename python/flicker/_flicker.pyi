"""Type stubs of flicker's native module (python/src/lib.rs): the functions
the package's own `run`, `check`, `compare` and `sweep` call."""

from typing import Any, Dict, List, Optional

class SceneError(ValueError):
    """A scene (or an argument) flicker refuses: `str(e)` is the command
    line's line, `field` the dotted key at fault (or None), `reason` what
    is wrong."""

    field: Optional[str]
    reason: str

def run(
    text: Optional[str] = None,
    path: Optional[str] = None,
    t_end: Optional[float] = None,
    method: Optional[str] = None,
    rtol: Optional[float] = None,
    atol: Optional[float] = None,
    step: Optional[float] = None,
    log: Optional[str] = None,
    events: bool = True,
    sensitivities: Optional[List[str]] = None,
    t_eval: Optional[List[float]] = None,
    past_horizon: bool = False,
) -> Dict[str, Any]: ...
def check(text: Optional[str] = None, path: Optional[str] = None) -> List[str]: ...
def compare(
    text: Optional[str] = None,
    path: Optional[str] = None,
    methods: Optional[List[str]] = None,
    tolerances: Optional[List[float]] = None,
    steps: Optional[List[float]] = None,
) -> Dict[str, Any]: ...
def sweep(
    text: Optional[str] = None, path: Optional[str] = None, threads: Optional[int] = None
) -> Dict[str, Any]: ...
def orbit(
    text: Optional[str] = None,
    path: Optional[str] = None,
    section: str = "",
    events: int = 1,
    settle: float = 0.0,
    forcing_period: Optional[float] = None,
) -> str: ...
def lyapunov(
    text: Optional[str] = None,
    path: Optional[str] = None,
    exponents: Optional[int] = None,
    transient: float = 0.0,
    t_end: Optional[float] = None,
    interval: Optional[float] = None,
    wall: float = 600.0,
) -> str: ...
def continuation(
    text: Optional[str] = None,
    path: Optional[str] = None,
    section: str = "",
    param: str = "",
    to: float = 0.0,
    events: int = 1,
    settle: float = 0.0,
    forcing_period: Optional[float] = None,
    points: int = 200,
    max_step: float = 0.05,
) -> Dict[str, Any]: ...
def diagram(
    text: Optional[str] = None,
    path: Optional[str] = None,
    param: str = "",
    start: float = 0.0,
    stop: float = 0.0,
    points: int = 100,
    section: str = "",
    transient: Optional[float] = None,
    record: int = 50,
    span: Optional[float] = None,
    follow: bool = False,
    past_horizon: bool = False,
    wall: float = 3600.0,
) -> Dict[str, Any]: ...
def basins(
    text: Optional[str] = None,
    path: Optional[str] = None,
    grid: List[str] = ...,
    transient: Optional[float] = None,
    section: Optional[str] = None,
    record: int = 64,
    tolerance: float = 1e-6,
    past_horizon: bool = False,
    wall: float = 3600.0,
) -> Dict[str, Any]: ...
