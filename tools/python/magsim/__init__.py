"""magsim: inducible rigid magnets, stepped from Python.

    import magsim
    scene = magsim.Scene.from_registry("balls_up", count=20)
    scene.set_option("threads", 1)
    sim = magsim.Simulation(scene)
    sim.step(100)                 # the GIL is released; Ctrl-C stops after a whole step
    sim.positions                 # (nbody, 3) read-only view, same address across steps
    magsim.run(scene, "out/x", seconds=0.1, render=False)   # magsim-scene's files

Errors: SceneError(ValueError) for a bad scene, ValueError for a bad option or state,
SimulationError(RuntimeError) for a failed step, OSError for I/O.
"""

from magsim._errors import SceneError, SimulationError
from magsim._magsim import (HAVE_RENDER, Scene, Simulation, State, option_keys, options_table,
                            scene_names)
from magsim import _magsim

if HAVE_RENDER:
    from magsim._magsim import Renderer

__all__ = ["Scene", "Simulation", "State", "SceneError", "SimulationError", "scene_names",
           "option_keys", "options_table", "run", "HAVE_RENDER"] + (["Renderer"] if HAVE_RENDER else [])


def run(scene, out_dir, seconds=None, steps=None, fps=60.0, render=True, width=1280,
        height=720, samples=1, arrows=False, gltf=None, gltf_channels=None):
    """Runs `scene` as magsim-scene does and writes the same files into out_dir: summary.json,
    states.csv, moments.csv and (render=True, when built with the renderer) frame_*.png.

    seconds or steps (neither: the scene's default_seconds), fps and the frame size as
    magsim-scene's --seconds, --steps, --fps, --width, --height, --samples, --arrows; gltf
    (a path ending in .glb) and gltf_channels ("m_norm,speed") as its --gltf and
    --gltf-channels: the run as one binary glTF 2.0 file for Blender.
    Returns summary.json as a dict. ValueError for bad arguments (magsim-scene's exit 1),
    SimulationError when the run failed (summary.json holds the error and the last good
    state), OSError when a file could not be written; Ctrl-C ends the run after the step in
    progress, with its outputs whole, and raises KeyboardInterrupt.
    """
    import json
    import math
    import os

    if seconds is not None and steps is not None:
        raise ValueError("--seconds excludes --steps")
    if seconds is not None and not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"--seconds: must be a finite number > 0, got {seconds}")
    if steps is not None and not (isinstance(steps, int) and 1 <= steps <= 10_000_000):
        raise ValueError(f"--steps: must be in [1, 10000000], got {steps}")
    if not (isinstance(fps, (int, float)) and 1e-3 <= fps <= 1e9):
        raise ValueError(f"--fps: must be in [0.001, 1e9], got {fps}")
    for name, v in (("--width", width), ("--height", height)):
        if not (isinstance(v, int) and 16 <= v <= 8192 and v % 2 == 0):
            raise ValueError(f"{name}: must be even and in [16, 8192], got {v}")
    if samples not in (1, 2, 3, 4):
        raise ValueError(f"--samples: must be in [1, 4], got {samples}")
    out = os.fspath(out_dir)
    if not out:
        raise ValueError("--out: needs a non-empty path")
    if gltf_channels and not gltf:
        raise ValueError("--gltf-channels needs --gltf")
    _magsim._run(scene, out, steps or 0, float(seconds or 0.0), float(fps), bool(render), width,
                 height, samples, bool(arrows), os.fspath(gltf) if gltf else "", gltf_channels or "")
    with open(os.path.join(out, "summary.json")) as f:
        return json.load(f)
