"""statics_batch: many equilibria in parallel, as `gvsrom dataset` solves them (warm starts along
a chain) or each as the single call."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import gvsrom
from conftest import run_cli


def test_batch_rows_equal_single_solves_without_warm_starts():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    U = np.linspace(-8.0, 0.0, 9).reshape(-1, 1)
    batch = robot.statics_batch(U, warm_start=False)
    assert len(batch) == 9
    assert batch.q.shape == (9, robot.n_dof)
    assert batch.tip_rotation.shape == (9, 3, 3)
    assert batch.strain.shape == (9, robot.n_points, 6)
    for k, u in enumerate(U):
        one = robot.statics(u)
        np.testing.assert_array_equal(batch.q[k], one.q)
        np.testing.assert_array_equal(batch.tip_position[k], one.tip_position)
        np.testing.assert_array_equal(batch.centerline[k], one.centerline)
        np.testing.assert_array_equal(batch.strain[k], one.strain)
        assert batch.iterations[k] == one.iterations
    np.testing.assert_array_equal(batch.u, U)


def test_warm_started_rows_equal_single_solves_to_the_solver_tolerance():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    U = np.linspace(-8.0, 0.0, 9).reshape(-1, 1)
    batch = robot.statics_batch(U)
    for k, u in enumerate(U):
        one = robot.statics(u)
        # both stop at ‖R‖∞ ≤ 1e-10-level residuals; the tip moves by far less than 1e-9 L
        np.testing.assert_allclose(batch.tip_position[k], one.tip_position, rtol=0, atol=1e-10)
        np.testing.assert_allclose(batch.q[k], one.q, rtol=0, atol=1e-7 * np.abs(one.q).max())
        assert batch.residual_norm[k] <= max(one.residual_norm, 1e-9)
    # a warm start from the neighbour's solution needs fewer iterations than the ramp
    assert batch.iterations.sum() < sum(robot.statics(u).iterations for u in U)


def test_batch_equals_the_dataset_of_the_same_tensions(gvsrom_bin, tmp_path):
    out = tmp_path / "ds"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:3",
                "--samples", "150", "--out", str(out))
    assert p.returncode == 0, p.stderr
    U = np.load(out / "inputs.npy").reshape(-1, 1)
    batch = gvsrom.Scenario.preset("single-tendon").build().statics_batch(U)
    # two chunks of 128 and 22 rows, each along the same chain from the same starts
    np.testing.assert_array_equal(batch.q, np.load(out / "q.npy"))
    np.testing.assert_array_equal(batch.tip_position, np.load(out / "tip_position.npy"))


def test_batch_on_six_tendons_matches_single_solves():
    robot = gvsrom.Scenario.preset("six-tendon-no-gravity").build()
    rng = np.random.default_rng(0)
    U = rng.uniform(-3.0, 0.0, size=(6, 6))
    batch = robot.statics_batch(U, warm_start=False)
    for k in range(6):
        np.testing.assert_array_equal(batch.q[k], robot.statics(U[k]).q)
    warm = robot.statics_batch(U)
    np.testing.assert_allclose(warm.tip_position, batch.tip_position, rtol=0, atol=1e-10)


def test_batch_of_the_wrong_width_is_a_value_error():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match="6 columns|has 2 columns"):
        robot.statics_batch(np.zeros((3, 2)))


def test_batch_names_the_row_that_fails():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(ValueError, match=r"U\[1\]: "):
        robot.statics_batch([[-1.0], [float("nan")]])


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
@pytest.mark.parametrize("warm_start", [True, False])
def test_ctrl_c_stops_a_batch(sigint_raises, warm_start):
    # 20 000 equilibria take minutes in a debug build: Ctrl-C after 0.5 s must end the call soon
    robot = gvsrom.Scenario.preset("single-tendon").build()
    U = np.linspace(-8.0, 0.0, 20000).reshape(-1, 1)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        robot.statics_batch(U, warm_start=warm_start)
    assert time.monotonic() - t0 < 10.0


@pytest.mark.parametrize("warm_start", [True, False])
def test_a_row_that_does_not_converge_is_a_convergence_error_naming_it(warm_start):
    robot = gvsrom.Scenario.preset("single-tendon").set("solver.max_iterations", 1).build()
    with pytest.raises(gvsrom.ConvergenceError, match=r"^U\[\d\]: statics did not converge") as e:
        robot.statics_batch(np.array([[-1.0], [-5.0]]), warm_start=warm_start)
    assert e.value.iterations >= 1 and e.value.residual_norm > 0
