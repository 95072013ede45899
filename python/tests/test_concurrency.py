"""Runs release the GIL: runs in Python threads give the results they give
one after another; and Ctrl-C (SIGINT) stops a long run within a second,
returning it with status `interrupted` instead of raising."""

import json
import os
import signal
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import flicker
from conftest import MODELS

SCENES = [
    MODELS / "mechanism_impacting.json",
    MODELS / "automata" / "impact_oscillator.json",
    MODELS / "automata" / "rocking_block.json",
    MODELS / "chain_cradle.json",
]


def test_runs_in_threads_give_the_results_of_runs_one_after_another():
    alone = [flicker.run(s) for s in SCENES * 2]
    with ThreadPoolExecutor(4) as pool:
        together = list(pool.map(flicker.run, SCENES * 2))
    for a, b in zip(alone, together):
        assert a.summary["final_state"] == b.summary["final_state"]
        assert np.array_equal(a.events["t"], b.events["t"])
        assert np.array_equal(a.events["after"], b.events["after"])


def _sigint_in(seconds):
    """Send this process SIGINT `seconds` from now; the list gets the time
    it was sent."""
    sent = []

    def interrupt():
        time.sleep(seconds)
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt, daemon=True).start()
    return sent


def test_ctrl_c_stops_a_long_run_within_a_second():
    # A forced oscillator: the mechanism's exactly periodic orbit would be
    # jumped over whole periods (no events kept) and end at once.
    scene = json.loads((MODELS / "automata" / "impact_oscillator.json").read_text())
    scene["t_end"] = 1e12
    scene["max_events"] = 10**15
    sent = _sigint_in(0.5)
    run = flicker.run(scene, events=False)
    returned = time.perf_counter()
    assert sent, "the run ended before the signal"
    assert run.status == "interrupted", run.summary
    assert returned - sent[0] < 1.0
    assert 0 < run.summary["t_reached"] < 1e12


def _interrupted_within_a_second(call):
    """Send SIGINT 0.5 s into `call()`: it must raise KeyboardInterrupt
    within a second of the signal (it ignored Ctrl-C until done)."""
    sent = _sigint_in(0.5)
    with pytest.raises(KeyboardInterrupt):
        call()
    returned = time.perf_counter()
    assert sent, "the call ended before the signal"
    assert returned - sent[0] < 1.0


def _endless_mechanism():
    scene = json.loads((MODELS / "mechanism_impacting.json").read_text())
    scene["t_end"] = 1e12
    scene["max_events"] = 10**15
    return scene


def test_a_periodic_orbit_run_without_events_is_jumped_over():
    # 2.3e7 impacts: seconds fired one by one, microseconds jumped.
    scene = _endless_mechanism()
    scene["t_end"] = 1e8
    run = flicker.run(scene, events=False)
    assert run.status == "completed", run.summary
    jumped = run.summary["fast_forward"]
    assert jumped["periods"] + 5 >= run.summary["events"] > 2e7
    assert run.summary["wall_seconds"] < 1.0


def test_ctrl_c_stops_a_sweep():
    sweep = {"scene": _endless_mechanism(),
             "grid": [{"key": "eta", "from": 1.1, "to": 1.3, "count": 4}]}
    _interrupted_within_a_second(lambda: flicker.sweep(sweep))


def test_ctrl_c_stops_a_comparison():
    _interrupted_within_a_second(
        lambda: flicker.compare(_endless_mechanism(), methods=["exact", "dop853"]))


def test_ctrl_c_stops_an_orbit_search_and_a_continuation():
    """Long transients (seconds here before their own errors stop them):
    the transient is what Ctrl-C ends."""
    mechanism = json.loads((MODELS / "automata/mechanism.json").read_text())
    mechanism["t_end"] = 1e13
    mechanism["max_events"] = 10**15
    _interrupted_within_a_second(lambda: flicker.orbit(mechanism, "impact", settle=1e8))
    table = json.loads((MODELS / "automata/vibrating_table.json").read_text())
    table["t_end"] = 1e9
    table["max_events"] = 10**15
    _interrupted_within_a_second(
        lambda: flicker.continuation(table, "impact", "A", 0.16, settle=1e7,
                                     forcing_period=2 * np.pi / 10))


def test_orbit_searches_and_continuations_keep_their_wall_budget():
    """`wall` bounds the whole search in seconds, as `--wall` does: the
    search returns, saying why, once it is spent; a budget that is not a
    time > 0 is refused, naming `wall`. The budget is short: carrying
    `eta`, the continuation's transient stops on its own near t = 2.2e5
    (its error bound, grown with the parameter's, cannot tell a graze from
    an impact: honest, by design). Since periodic stretches are jumped over
    it gets there in about 0.07 s, so a 0.05 s budget raced it (and lost on
    a CI machine); 1 ms reaches about t = 2e3, a hundredth of the way."""
    mechanism = json.loads((MODELS / "automata/mechanism.json").read_text())
    mechanism["t_end"] = 1e13
    mechanism["max_events"] = 10**15
    for call, why in (
        (lambda wall: flicker.orbit(mechanism, "impact", settle=1e8, wall=wall),
         lambda found: found["status"]),
        (lambda wall: flicker.continuation(mechanism, "impact", "eta", 0.9, settle=1e8, wall=wall),
         lambda branch: branch["ended"]),
    ):
        started = time.perf_counter()
        said = why(call(1e-3))
        assert time.perf_counter() - started < 2.0
        assert "wall-time budget" in said, said
        with pytest.raises(Exception, match="wall"):
            call(-1.0)
