"""Renderer(w, h).render(sim): an (H, W, 3) uint8 image of the simulation's state."""
import numpy as np
import pytest


def test_render(magsim, small):
    if not magsim.HAVE_RENDER:
        pytest.skip("built without the renderer (MAGSIM_RENDER=OFF)")
    sim = magsim.Simulation(small)
    r = magsim.Renderer(96, 64)
    img = r.render(sim)
    assert img.shape == (64, 96, 3) and img.dtype == np.uint8
    assert img.std() > 1  # something was drawn
    sim.step(50)
    assert not np.array_equal(r.render(sim), img)
    with pytest.raises(ValueError):
        magsim.Renderer(8, 8)


def test_run_renders_frames(magsim, tmp_path, small):
    if not magsim.HAVE_RENDER:
        pytest.skip("built without the renderer (MAGSIM_RENDER=OFF)")
    s = magsim.run(small, tmp_path, steps=20, fps=100, render=True, width=64, height=48)
    pngs = sorted(p.name for p in tmp_path.glob("frame_*.png"))
    assert s["rendered_frames"] == len(pngs) >= 2 and pngs[0] == "frame_000000.png"
