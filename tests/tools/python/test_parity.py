"""The module and magsim-scene agree: state hashes, positions, scene files and output files."""
import csv

import numpy as np
import pytest

from conftest import TWO_BALLS, cli_summary, run_cli


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("which", ["file", "balls_up"])
def test_state_hash_matches_cli(magsim, tmp_path, which, threads):
    steps = 40
    if which == "file":
        scene = magsim.Scene.from_file(str(TWO_BALLS))
        args = [TWO_BALLS]
    else:
        scene = magsim.Scene.from_registry("balls_up", count=20)
        args = ["balls_up", "--count", 20]
    scene.set_option("threads", threads)
    summary = cli_summary(tmp_path, *args, "--threads", threads, "--steps", steps)
    sim = magsim.Simulation(scene)
    sim.step(steps)
    assert f"{sim.state_hash():016x}" == summary["state_hash"]
    assert sim.steps == steps and sim.time == pytest.approx(summary["seconds"])


def test_positions_match_states_csv(magsim, tmp_path, small):
    cli_summary(tmp_path, "balls_up", "--count", 20, "--threads", 1, "--steps", 50, "--fps", 200)
    rows = list(csv.DictReader(open(tmp_path / "states.csv")))
    frames = sorted({int(r["frame"]) for r in rows})
    sim = magsim.Simulation(small)
    for f in frames:
        fr = [r for r in rows if int(r["frame"]) == f]
        target = round(float(fr[0]["time"]) / 1e-3)
        sim.step(target - sim.steps)
        csv_pos = np.array([[float(r["x"]), float(r["y"]), float(r["z"])] for r in fr])
        csv_q = np.array([[float(r[k]) for k in ("qw", "qx", "qy", "qz")] for r in fr])
        # states.csv prints 10 significant digits
        np.testing.assert_allclose(sim.positions, csv_pos, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(sim.quaternions, csv_q, rtol=1e-9, atol=1e-9)
    assert len(frames) >= 5


@pytest.mark.parametrize("which", ["file", "balls_up"])
def test_to_json_is_write_scene(magsim, tmp_path, which):
    out = tmp_path / "scene.json"
    if which == "file":
        run_cli(TWO_BALLS, "--write-scene", out)
        scene = magsim.Scene.from_file(str(TWO_BALLS))
    else:
        run_cli("balls_up", "--count", 20, "--strength", 1.5, "--write-scene", out)
        scene = magsim.Scene.from_registry("balls_up", count=20, strength=1.5)
    assert scene.to_json() == out.read_text()
    # and it reads back to the same scene
    assert magsim.Scene.from_json(scene.to_json()).to_json() == scene.to_json()


@pytest.mark.parametrize("which", ["file", "balls_up"])
def test_run_writes_the_cli_files(magsim, tmp_path, which):
    if which == "file":
        scene, args = magsim.Scene.from_file(str(TWO_BALLS)), [TWO_BALLS]
    else:
        scene, args = magsim.Scene.from_registry("balls_up", count=20), ["balls_up", "--count", 20]
    scene.set_option("threads", 1)
    cli = cli_summary(tmp_path / "cli", *args, "--threads", 1, "--seconds", 0.05, "--fps", 100)
    py = magsim.run(scene, tmp_path / "py", seconds=0.05, fps=100, render=False)
    for name in ("states.csv", "moments.csv"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert py["state_hash"] == cli["state_hash"]
    for key in ("source", "params", "options", "steps", "frames", "final", "series"):
        if key != "series":
            assert py[key] == cli[key], key
    assert py["series"]["time"] == cli["series"]["time"]


def test_options_table_is_the_clis(magsim):
    import json
    import subprocess
    from conftest import SCENE_BIN
    cli = json.loads(subprocess.run([SCENE_BIN, "--options-json"], capture_output=True, text=True, check=True).stdout)
    assert magsim.options_table() == cli
    assert [o["key"] for o in cli] == magsim.option_keys()
    # every option's default is what a fresh scene file gets
    opts = magsim.Scene.from_json('{"bodies": []}').options
    for o in cli:
        at = opts
        for part in o["key"].split("."):
            at = at[part]
        assert at == o["default"], o["key"]


def test_run_writes_the_clis_gltf(magsim, tmp_path):
    """magsim.run(gltf=...) writes magsim-scene's --gltf file: the same glb, byte for byte,
    but for the asset's extras that name nothing run-specific beyond the outcome."""
    scene = magsim.Scene.from_file(str(TWO_BALLS))
    scene.set_option("threads", 1)
    cli_summary(tmp_path / "cli", TWO_BALLS, "--threads", 1, "--seconds", 0.05, "--fps", 100,
                "--gltf", tmp_path / "cli.glb", "--gltf-channels", "m_norm,speed")
    py = magsim.run(scene, tmp_path / "py", seconds=0.05, fps=100, render=False,
                    gltf=tmp_path / "py.glb", gltf_channels="m_norm,speed")
    assert py["gltf"]["bytes"] == (tmp_path / "py.glb").stat().st_size
    assert (tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    with pytest.raises(ValueError, match=r"\.glb"):
        magsim.run(scene, tmp_path / "bad", seconds=0.01, render=False, gltf=tmp_path / "x.gltf")
    with pytest.raises(ValueError, match="needs --gltf"):
        magsim.run(scene, tmp_path / "bad2", seconds=0.01, render=False, gltf_channels="speed")
