"""field_H and field_B at arbitrary points against the analytic dipole."""
import json
import math

import numpy as np

MOMENT = np.array([0.3, -0.2, 8.0])  # A m^2
AT = np.array([0.01, 0.02, -0.03])


def lone_magnet(magsim):
    scene = {"options": {"ground": False, "gravity": [0, 0, 0]},
             "bodies": [{"name": "magnet", "type": "static", "position": AT.tolist(), "magnet": True,
                         "shapes": [{"kind": "box", "size": [0.005, 0.005, 0.005]}],
                         "moments": [{"permanent": True, "volume": 1e-6, "moment": MOMENT.tolist()}]}]}
    return magsim.Simulation(magsim.Scene.from_json(json.dumps(scene)))


def test_far_field_is_the_dipole(magsim):
    sim = lone_magnet(magsim)
    rng = np.random.default_rng(1)
    d = rng.normal(size=(50, 3))
    pts = AT + d / np.linalg.norm(d, axis=1)[:, None] * rng.uniform(1.0, 100.0, size=(50, 1))
    r = pts - AT
    n = np.linalg.norm(r, axis=1)[:, None]
    rhat = r / n
    want = (3 * rhat * (rhat @ MOMENT)[:, None] - MOMENT) / (4 * math.pi * n**3)
    got = sim.field_H(pts)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    np.testing.assert_allclose(sim.field_B(pts), 4e-7 * math.pi * want, rtol=1e-12, atol=0)


def test_points_are_checked(magsim):
    sim = lone_magnet(magsim)
    import pytest
    with pytest.raises(ValueError):
        sim.field_H(np.zeros((2, 2)))
    with pytest.raises(ValueError):
        sim.field_H([[math.nan, 0, 0]])
