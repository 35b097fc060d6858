"""simulate from a given state (`q0`, `qd0`): a controller's loop, one period per call with the
tensions held, lands where one run under the same held tensions does; bad starts are refused."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def test_stepping_one_period_at_a_time_follows_the_whole_run(robot):
    # tensions changed every 0.05 s: one run of held rows, and a loop that simulates each
    # period from the state the last one ended in (tight tolerances: compare the starts, not
    # the integrators' error)
    period, u = 0.05, [-2.0, -4.0, -1.0, -3.0]
    rows = np.array([[k * period, uk] for k, uk in enumerate(u)])
    tight = dict(rtol=1e-9, atol=1e-11)
    whole = robot.simulate(period * len(u), sample_rate=1 / period, input=rows, **tight)
    q, qd = np.zeros(robot.n_dof), np.zeros(robot.n_dof)
    for k, uk in enumerate(u):
        step = robot.simulate(period, sample_rate=1 / period, input=lambda t, uk=uk: [uk],
                              q0=q, qd0=qd, **tight)
        assert step["t"].shape == (2,)
        np.testing.assert_array_equal(step["q"][0], q)
        q, qd = step["q"][-1], step["qd"][-1]
        tip = step["tip_position"][-1]
        np.testing.assert_allclose(tip, whole["tip_position"][k + 1], rtol=0, atol=1e-9 * robot.length)
    np.testing.assert_allclose(q, whole["q"][-1], rtol=0, atol=1e-7 * np.abs(whole["q"][-1]).max())
    # the velocity carries over: restarting each period at rest goes elsewhere
    at_rest = robot.simulate(period, sample_rate=1 / period, input=lambda t: [u[-1]],
                             q0=whole["q"][-2], **tight)
    assert np.abs(at_rest["tip_position"][-1] - whole["tip_position"][-1]).max() > 1e-4 * robot.length


def test_a_bad_start_is_a_value_error_naming_the_argument(robot):
    n = robot.n_dof
    with pytest.raises(gvsrom.GvsromError, match=r"q0.*expected %d" % n):
        robot.simulate(0.01, q0=np.zeros(n - 1))
    with pytest.raises(gvsrom.GvsromError, match=r"qd0\[2\]"):
        robot.simulate(0.01, q0=np.zeros(n), qd0=np.array([0, 0, np.nan] + [0] * (n - 3)))
    with pytest.raises(gvsrom.GvsromError, match="from_equilibrium"):
        robot.simulate(0.01, q0=np.zeros(n), from_equilibrium=True)
    with pytest.raises(gvsrom.GvsromError, match="qd0.*without `q0`"):
        robot.simulate(0.01, qd0=np.zeros(n))


def test_a_fixed_step_run_converges_to_the_adaptive_one(robot):
    # `fixed_step` (the CLI's --fixed-step, BDF2): its error against a tight adaptive run of the
    # same held tension shrinks with the step
    rows = np.array([[0.0, -3.0]])
    ref = robot.simulate(0.2, sample_rate=50, input=rows, rtol=1e-9, atol=1e-11)
    err = {}
    for h in (4e-3, 1e-3):
        run = robot.simulate(0.2, sample_rate=50, input=rows, fixed_step=h)
        np.testing.assert_array_equal(run["t"], ref["t"])
        err[h] = np.abs(run["tip_position"] - ref["tip_position"]).max() / robot.length
    assert err[1e-3] < 1e-4, err
    assert err[1e-3] < 0.5 * err[4e-3], err
    with pytest.raises(gvsrom.GvsromError, match="`fixed_step`"):
        robot.simulate(0.1, fixed_step=-1.0)
    # a tolerance the fixed step would ignore is refused, as on the CLI
    for kw in ({"rtol": 1e-4}, {"atol": 1e-6}):
        with pytest.raises(gvsrom.GvsromError, match="not controlled"):
            robot.simulate(0.1, fixed_step=1e-3, **kw)
