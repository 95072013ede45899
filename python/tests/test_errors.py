"""Every way flicker refuses a scene or an argument, from Python: a
SceneError (a ValueError) whose message is the command line's line and
whose field and reason are its parts; a run that cannot be trusted is not
an error but a summary that says so."""

import json

import pytest

import flicker
from conftest import MODELS


def ball():
    return json.loads((MODELS / "automata" / "bouncing_ball.json").read_text())


def test_a_bad_file_raises_what_the_command_line_prints(cli, tmp_path):
    scene = ball()
    scene["modes"]["flight"]["flow"]["v"] = "-gg"
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run(path)
    done, _ = cli("check", path)
    assert done.returncode == 2
    assert str(caught.value) == done.stderr.strip()
    assert caught.value.field == "modes.flight.flow.v"
    assert caught.value.reason.startswith("unknown name `gg` (did you mean `g`?)")
    assert isinstance(caught.value, ValueError)
    with pytest.raises(flicker.SceneError):
        flicker.check(path)


@pytest.mark.parametrize(
    "change, field, words",
    [
        (lambda s: s.update(t_end=-1), "t_end", "> 0"),
        (lambda s: s.update(colour=1), "colour", "not a known key"),
        (lambda s: s["modes"]["flight"]["transitions"][0].update(to="nowhere"), "modes.flight.transitions[0].to", "no mode"),
        (lambda s: s.update(states=["y", "y"]), "states[1]", "listed twice"),
        (lambda s: s.update(model="pendulum"), "model", "automaton"),
    ],
)
def test_bad_scenes_name_the_field_and_the_reason(change, field, words):
    scene = ball()
    change(scene)
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run(scene)
    assert caught.value.field == field, str(caught.value)
    assert words in caught.value.reason
    assert str(caught.value).startswith("flicker: ")


def test_bad_arguments_are_refused_before_anything_runs(tmp_path):
    path = MODELS / "mechanism_impacting.json"
    for kwargs, field in [
        ({"t_end": -5.0}, "t_end"),
        ({"t_end": float("nan")}, "t_end"),
        ({"method": "rk4"}, "method/rtol/atol/step"),
        ({"method": "dopri5", "rtol": -1.0}, "method/rtol/atol/step"),
        ({"log": tmp_path / "no" / "such" / "folder" / "log.jsonl"}, "log"),
    ]:
        with pytest.raises(flicker.SceneError) as caught:
            flicker.run(path, **kwargs)
        assert caught.value.field == field, (kwargs, str(caught.value))
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run(MODELS / "no_such_scene.json")
    assert "cannot be read" in caught.value.reason and caught.value.field is None
    with pytest.raises(flicker.SceneError) as caught:
        flicker.run("{not json")
    assert "not valid JSON" in caught.value.reason
    with pytest.raises(TypeError):
        flicker.run(42)
    with pytest.raises(flicker.SceneError) as caught:
        flicker.compare(path, methods=["exact", "rk4"])
    assert caught.value.field == "methods" and "rk4" in caught.value.reason
    with pytest.raises(flicker.SceneError) as caught:
        flicker.compare(path, tolerances=[0.0])
    assert caught.value.field == "tolerances"
    with pytest.raises(flicker.SceneError) as caught:
        flicker.sweep(path)
    assert caught.value.field == "grid"


def test_a_run_that_cannot_be_trusted_returns_its_reason(cli, tmp_path):
    # The angle formulation without charts fails at theta = 0, on purpose.
    run = flicker.run(MODELS / "mechanism_angle_plain.json")
    assert run.status == "failed"
    assert "singular at theta = 0" in run.summary["reason"]
    done, _ = cli("run", MODELS / "mechanism_angle_plain.json", "--out", tmp_path / "o", "--quiet")
    assert done.returncode == 3
    assert run.summary["reason"] in done.stderr
