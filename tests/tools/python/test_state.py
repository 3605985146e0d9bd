"""get_state / set_state round trips, through pickle too; foreign and non-finite states."""
import math
import pickle
import struct

import pytest


def test_restore_repeats_the_run(magsim, small):
    sim = magsim.Simulation(small)
    sim.step(5)
    st = sim.get_state()
    sim.step(10)
    h = sim.state_hash()
    sim.set_state(st)
    assert sim.steps == 5
    sim.step(10)
    assert sim.state_hash() == h
    sim.set_state(pickle.loads(pickle.dumps(st)))
    sim.step(10)
    assert sim.state_hash() == h
    # and into a fresh simulation of the same scene
    other = magsim.Simulation(small)
    other.set_state(pickle.loads(pickle.dumps(st)))
    other.step(10)
    assert other.state_hash() == h


def test_state_of_another_scene(magsim, small):
    st = magsim.Simulation(magsim.Scene.from_registry("balls_up", count=21)).get_state()
    with pytest.raises(ValueError, match="another scene"):
        magsim.Simulation(small).set_state(st)


def test_non_finite_state(magsim, small):
    sim = magsim.Simulation(small)
    sim.step(1)
    raw = bytearray(sim.get_state().__getstate__())
    # the first position's x, after the magic, the fingerprint, the step and the count
    raw[32:40] = struct.pack("<d", math.nan)
    bad = magsim.State.__new__(magsim.State)
    bad.__setstate__(bytes(raw))
    h = sim.state_hash()
    with pytest.raises(ValueError, match="non-finite|position"):
        sim.set_state(bad)
    assert sim.state_hash() == h  # untouched


def test_garbage_bytes(magsim):
    st = magsim.State.__new__(magsim.State)
    with pytest.raises(ValueError):
        st.__setstate__(b"not a state")
