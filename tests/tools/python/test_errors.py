"""Each error maps to its Python exception with magsim-scene's one-line message."""
import json
import os
import re

import pytest

from conftest import INPUTS, cli_error, run_cli


def test_scene_error_names_the_json_path(magsim):
    with pytest.raises(magsim.SceneError, match=r"^mine: bodies\[0\]\.mass") as e:
        magsim.Scene.from_json('{"bodies": [{"name": "a", "mass": -1, "shapes": [{"kind": "sphere"}]}]}', origin="mine")
    assert isinstance(e.value, ValueError)
    with pytest.raises(magsim.SceneError, match="<json>"):
        magsim.Scene.from_json("{not json")


def test_missing_file_is_os_error(magsim, tmp_path):
    path = tmp_path / "none.json"
    code, err = run_cli(path, "--steps", 1, "--no-render", "--out", tmp_path / "o", check=False)
    with pytest.raises(OSError) as e:
        magsim.Scene.from_file(str(path))
    assert isinstance(e.value, FileNotFoundError) and code == 1
    assert str(e.value.strerror) == cli_error(err)


def test_bad_option_is_value_error(magsim, small):
    with pytest.raises(ValueError, match=r"^set_option: options\.magnetics\.tol: must be in \(0, 1\) \(got 1\.5\)$"):
        small.set_option("magnetics.tol", 1.5)
    with pytest.raises(ValueError, match=r"unknown method 'nope'"):
        small.set_option("magnetics.method", "nope")
    with pytest.raises(ValueError, match=r"options\.no_such_option: unknown key"):
        small.set_option("no_such_option", 1)
    with pytest.raises(ValueError, match="must be an integer"):
        small.set_option("threads", 1.5)
    small.set_option("bh_theta", 0.5)  # an older key
    assert small.options["magnetics"]["field"]["bh_theta"] == 0.5
    # the scene file's reader says the same
    text = json.loads(small.to_json())
    text["options"]["magnetics"]["tol"] = 1.5
    with pytest.raises(magsim.SceneError, match=r"options\.magnetics\.tol: must be in \(0, 1\) \(got 1\.5\)"):
        magsim.Scene.from_json(json.dumps(text))


def test_simulation_error_keeps_the_last_good_state(magsim, tmp_path):
    path = INPUTS / "blow_up.json"
    code, err = run_cli(path, "--steps", 50, "--no-render", "--out", tmp_path, check=False)
    assert code == 2
    sim = magsim.Simulation(magsim.Scene.from_file(str(path)))
    with pytest.raises(magsim.SimulationError) as e:
        sim.step(50)
    assert isinstance(e.value, RuntimeError)
    assert str(e.value) == cli_error(err)
    assert e.value.step == sim.steps + 1 and e.value.body == sim.body_index("ball_0")
    assert e.value.quantity and e.value.body_name == "ball_0"
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert f"{sim.state_hash():016x}" == summary["state_hash"]


def test_run_errors(magsim, tmp_path, small):
    not_a_dir = tmp_path / "file"
    not_a_dir.write_text("x")
    code, err = run_cli("balls_up", "--count", 20, "--steps", 1, "--no-render", "--out", not_a_dir, check=False)
    assert code == 3
    with pytest.raises(OSError, match="exists and is not a directory") as e:
        magsim.run(magsim.Scene.from_registry("balls_up", count=20), not_a_dir, steps=1, render=False)
    assert str(e.value) == cli_error(err)
    with pytest.raises(ValueError, match="--seconds"):
        magsim.run(small, tmp_path / "o", seconds=-1)
    with pytest.raises(magsim.SimulationError):
        magsim.run(magsim.Scene.from_file(str(INPUTS / "blow_up.json")), tmp_path / "b", steps=50, render=False)
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["error"]
    assert os.path.exists(tmp_path / "b" / "states.csv")


def test_a_count_that_cannot_fit_is_refused(magsim, tmp_path):
    code, err = run_cli("balls_up", "--count", 1000000000, "--steps", 1, "--no-render", "--out", tmp_path, check=False)
    assert code == 1
    with pytest.raises(ValueError) as e:
        magsim.Scene.from_registry("balls_up", count=1000000000)
    # the same message, but for the memory the machine has free at each moment
    free = re.compile(r"the [0-9.]+ GB available")
    assert free.search(str(e.value))
    assert free.sub("the N GB available", str(e.value)) == free.sub("the N GB available", cli_error(err))


def test_iron_curve_needs_a_converged_method(magsim, small):
    small.set_option("magnetics.field.near_field.curve", "iron")
    small.set_option("magnetics.method", "ours")
    with pytest.raises(magsim.SceneError, match=r"near_field\.curve: iron needs method anderson or exact"):
        magsim.Simulation(small)
    with pytest.raises(ValueError, match=r"unknown curve 'kim' \(tanh, iron\)"):
        small.set_option("magnetics.field.near_field.curve", "kim")
    small.set_option("magnetics.method", "anderson")
    sim = magsim.Simulation(small)
    sim.step(2)
