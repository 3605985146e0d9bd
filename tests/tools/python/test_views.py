"""Views: read-only numpy arrays at one address for a simulation's life, and after it."""
import gc

import numpy as np
import pytest

VIEWS = ["positions", "quaternions", "velocities", "angular_velocities", "M", "moment_positions"]


def address(a):
    return a.__array_interface__["data"][0]


def test_views_keep_their_address(magsim, small):
    sim = magsim.Simulation(small)
    views = {v: getattr(sim, v) for v in VIEWS}
    before = {v: address(a) for v, a in views.items()}
    start = views["positions"].copy()
    st = sim.get_state()
    sim.step(3)
    assert not np.array_equal(views["positions"], start)  # they follow the state
    assert {v: address(getattr(sim, v)) for v in VIEWS} == before
    sim.set_state(st)
    np.testing.assert_array_equal(views["positions"], start)
    assert {v: address(getattr(sim, v)) for v in VIEWS} == before
    assert views["positions"].shape == (sim.nbody, 3) and views["quaternions"].shape == (sim.nbody, 4)
    assert views["M"].shape == (sim.nmoment, 3)


def test_views_are_read_only(magsim, small):
    sim = magsim.Simulation(small)
    for v in VIEWS:
        a = getattr(sim, v)
        with pytest.raises(ValueError):
            a[0, 0] = 1.0
        with pytest.raises(ValueError):
            a.flags.writeable = True


def test_view_survives_the_simulation(magsim, small):
    sim = magsim.Simulation(small)
    sim.step(2)
    p = sim.positions
    expected = p.copy()
    del sim
    gc.collect()
    np.testing.assert_array_equal(p, expected)


def test_copies_and_names(magsim, small):
    sim = magsim.Simulation(small)
    assert sim.body_names[sim.body_index(sim.body_names[3])] == sim.body_names[3]
    with pytest.raises(KeyError):
        sim.body_index("no such body")
    np.testing.assert_array_equal(sim.forces(), 0.0)  # before the first step
    sim.step(2)
    f = sim.forces()
    assert f.shape == (sim.nbody, 3) and f.flags.writeable and np.abs(f).max() > 0
    assert sim.torques().shape == (sim.nbody, 3)
    assert sim.H().shape == (sim.nmoment, 3)
    m = sim.metrics()
    assert m["steps"] == 2 and set(m) >= {"kinetic_energy", "attached", "held", "escaped"}
    e = sim.energy()
    assert {"kinetic", "total", "magnetic_energy", "guard"} <= set(e)
