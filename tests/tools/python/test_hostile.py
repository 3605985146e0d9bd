"""Scene.from_json on the CLI's hostile inputs: the CLI's message and exit class as an
exception (1: SceneError/ValueError, 2: SimulationError, 3: OSError), never a crash."""
import pytest

from conftest import INPUTS, cli_error, run_cli

CASES = sorted(p for p in INPUTS.rglob("*.json") if not p.stem.endswith("_magsolve"))
STEPS = 30


def python_outcome(magsim, path):
    """(exit class, message) of reading, building and stepping the scene from Python."""
    try:
        scene = magsim.Scene.from_json(path.read_text(errors="surrogateescape"), origin=str(path))
        sim = magsim.Simulation(scene)
        sim.step(STEPS)
    except magsim.SimulationError as e:
        return 2, str(e)
    except ValueError as e:
        return 1, str(e)
    except OSError as e:
        return 3, str(e)
    return 0, None


@pytest.mark.parametrize("path", CASES, ids=[str(p.relative_to(INPUTS)) for p in CASES])
def test_like_the_cli(magsim, tmp_path, path):
    code, err = run_cli(path, "--steps", STEPS, "--no-render", "--out", tmp_path, check=False)
    got = python_outcome(magsim, path)
    assert got == (code, cli_error(err))
