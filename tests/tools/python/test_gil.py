"""step(n) releases the GIL, and Ctrl-C stops it after a whole step."""
import os
import signal
import threading
import time

import pytest


def test_other_threads_run_during_step(magsim, small):
    sim = magsim.Simulation(small)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(sim.steps)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        sim.step(2000)
    finally:
        done.set()
        t.join()
    assert len(ticks) > 20
    assert len(set(ticks)) > 5  # it saw the steps advance while step(400) ran


def test_a_second_stepper_is_refused(magsim, small):
    sim = magsim.Simulation(small)
    errors = []

    def other():
        while sim.steps == 0:
            time.sleep(0.001)
        try:
            sim.step(1)
        except RuntimeError as e:
            errors.append(str(e))

    t = threading.Thread(target=other)
    t.start()
    sim.step(4000)
    t.join()
    assert errors and "busy" in errors[0]


def test_sigint_stops_after_a_whole_step(magsim):
    scene = magsim.Scene.from_registry("balls_up", count=200)
    scene.set_option("threads", 1)
    sim = magsim.Simulation(scene)
    ref = magsim.Simulation(scene)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        sim.step(10**6)
    sent = t0 + 0.3
    assert time.monotonic() - sent < 1.0
    n = sim.steps
    assert n > 0
    ref.step(n)
    assert ref.state_hash() == sim.state_hash()  # whole steps only


def test_sigint_ends_magsim_run_with_whole_outputs(magsim, tmp_path):
    import json
    scene = magsim.Scene.from_registry("balls_up", count=200)
    scene.set_option("threads", 1)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        magsim.run(scene, tmp_path, seconds=100, fps=100, render=False)
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["interrupted"] and s["signal"] == "SIGINT" and 0 < s["steps"] < 100000
    rows = (tmp_path / "states.csv").read_text().splitlines()
    assert len(rows) - 1 == s["frames"] * s["bodies"]
