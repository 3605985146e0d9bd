"""Shared fixtures of the magsim tests: the module, magsim-scene and the source tree."""
import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("MAGSIM_SOURCE_DIR", Path(__file__).resolve().parents[3]))
SCENE_BIN = os.environ.get("MAGSIM_SCENE_BIN", str(SOURCE / "build/release/tools/magsim-scene"))
TWO_BALLS = SOURCE / "scenes/examples/two_balls.json"
INPUTS = SOURCE / "tests/tools/cli/inputs"


def run_cli(*args, check=True):
    """magsim-scene with args; (exit code, stderr)."""
    p = subprocess.run([SCENE_BIN, *map(str, args)], capture_output=True, text=True, timeout=120)
    if check and p.returncode != 0:
        raise AssertionError(f"magsim-scene {args}: exit {p.returncode}: {p.stderr}")
    return p.returncode, p.stderr


def cli_summary(out_dir, *args):
    """Runs magsim-scene into out_dir without frames and returns its summary.json."""
    run_cli(*args, "--no-render", "--out", out_dir)
    return json.loads((Path(out_dir) / "summary.json").read_text())


def cli_error(stderr):
    """The message of magsim-scene's 'error: ...' line."""
    for line in stderr.splitlines():
        if line.startswith("error: "):
            return line[len("error: "):]
    return None


@pytest.fixture(scope="session")
def magsim():
    import magsim as m
    return m


@pytest.fixture
def small(magsim):
    """balls_up with 20 balls on one thread."""
    s = magsim.Scene.from_registry("balls_up", count=20)
    s.set_option("threads", 1)
    return s
