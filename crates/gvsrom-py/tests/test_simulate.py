"""simulate: the trajectory of `gvsrom simulate --out`, as arrays in memory; Ctrl-C stops it."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import gvsrom
from conftest import run_cli

ARRAYS = ["t", "q", "qd", "u", "tip_position", "tip_rotation", "strain", "centerline", "tendon_paths"]


def test_simulate_equals_the_cli_trajectory(gvsrom_bin, tmp_path):
    out = tmp_path / "run"
    p = run_cli(gvsrom_bin, "simulate", "single-tendon", "--duration", "0.05", "--sample-rate", "200",
                "--from-equilibrium", "--tension=-4", "--out", str(out))
    assert p.returncode == 0, p.stderr
    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -4).build()
    tr = robot.simulate(0.05, sample_rate=200, from_equilibrium=True)
    for name in ARRAYS:
        cli = np.load(out / f"{name}.npy")
        assert tr[name].shape == cli.shape, name
        np.testing.assert_allclose(tr[name], cli, rtol=0, atol=1e-12, err_msg=name)
    np.testing.assert_array_equal(tr["strain_x"], np.load(out / "strain_x.npy"))


def test_an_input_array_holds_each_row():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    rows = np.array([[0.0, 0.0], [0.01, -3.0]])
    tr = robot.simulate(0.02, sample_rate=500, input=rows)
    u = tr["u"][:, 0]
    t = tr["t"]
    np.testing.assert_array_equal(u[t < 0.01], 0.0)
    np.testing.assert_array_equal(u[t >= 0.01], -3.0)
    assert tr["centerline"].shape == (len(t), len(tr["centerline_x"]), 3)


def test_an_input_of_the_wrong_width_or_start_is_a_value_error():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match="columns"):
        robot.simulate(0.01, input=np.zeros((2, 3)))
    with pytest.raises(gvsrom.GvsromError, match="starts at t = 0.5"):
        robot.simulate(0.01, input=[[0.5, -1.0]])
    with pytest.raises(gvsrom.GvsromError, match="`duration`"):
        robot.simulate(-1.0)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_interrupts_a_long_simulation(sigint_raises):
    robot = gvsrom.Scenario.preset("single-tendon").build()
    # a tension switching every 10 ms for 1000 s keeps the integrator's steps short
    t = np.arange(0.0, 1000.0, 0.01)
    rows = np.stack([t, np.where(np.arange(len(t)) % 2 == 0, -5.0, 0.0)], axis=1)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        robot.simulate(1000.0, sample_rate=1, input=rows)
    assert time.monotonic() - t0 < 30
