"""statics_batch: many equilibria in parallel, each equal to the single call."""

import numpy as np
import pytest

import gvsrom


def test_batch_rows_equal_single_solves():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    U = np.linspace(-8.0, 0.0, 9).reshape(-1, 1)
    batch = robot.statics_batch(U)
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


def test_batch_on_six_tendons_matches_single_solves():
    robot = gvsrom.Scenario.preset("six-tendon-no-gravity").build()
    rng = np.random.default_rng(0)
    U = rng.uniform(-3.0, 0.0, size=(6, 6))
    batch = robot.statics_batch(U)
    for k in range(6):
        np.testing.assert_array_equal(batch.q[k], robot.statics(U[k]).q)


def test_batch_of_the_wrong_width_is_a_value_error():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match="6 columns|has 2 columns"):
        robot.statics_batch(np.zeros((3, 2)))


def test_batch_names_the_row_that_fails():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(ValueError, match=r"U\[1\]: "):
        robot.statics_batch([[-1.0], [float("nan")]])
