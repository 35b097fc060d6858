"""simulate with a sampled-data controller `controller(t, q, qd)`: called at the control instants
with the state there, its tensions held between them; the closed loop is the run of the held rows
of what it returned, and the loop of one `simulate` call per period; its errors are clear."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def pd(calls):
    # a PD law on the first bending coordinate, pulls only; keeps what it was called with
    def controller(t, q, qd):
        u = min(-1.0 - 0.5 * (q[0] + 2.0) - 0.05 * qd[0], 0.0)
        calls.append((t, q.copy(), qd.copy(), u))
        return u

    return controller


def test_the_closed_loop_is_the_run_of_the_held_rows_of_what_it_returned(robot):
    calls = []
    tr = robot.simulate(0.2, sample_rate=100, controller=pd(calls), control_rate=50)
    t = tr["t"]
    # at 0, 0.02, …, 0.2 s: every second sample, with the state the run delivered there
    np.testing.assert_array_equal([c[0] for c in calls], t[::2])
    for (tk, q, qd, u), i in zip(calls, range(0, len(t), 2)):
        np.testing.assert_array_equal(q, tr["q"][i], err_msg=f"q handed at {tk}")
        np.testing.assert_array_equal(qd, tr["qd"][i], err_msg=f"qd handed at {tk}")
        assert tr["u"][i, 0] == u, "a sample's tension is the one the controller just returned"
    us = np.array([c[3] for c in calls])
    assert np.ptp(us) > 0.05, us
    # held between calls
    np.testing.assert_array_equal(tr["u"][1::2, 0], us[:-1])
    # the open loop of the same held tensions (the last call applies to no step)
    rows = np.column_stack([[c[0] for c in calls[:-1]], us[:-1]])
    by_rows = robot.simulate(0.2, sample_rate=100, input=rows)
    np.testing.assert_allclose(tr["q"], by_rows["q"], rtol=0, atol=1e-12 * np.abs(by_rows["q"]).max())


def test_the_closed_loop_is_the_loop_of_one_simulate_call_per_period(robot):
    # what a user writes without `controller`: the same restarts at each period, the same numbers
    # to the Newton tolerance (each call starts from the state the last one delivered and renews
    # the Jacobian, which one run keeps)
    h = 0.02
    tr = robot.simulate(0.2, sample_rate=1 / h, controller=pd([]), fixed_step=2e-3)
    n = robot.n_dof
    q, qd = np.zeros(n), np.zeros(n)
    law = pd([])
    for k in range(10):
        u = law(k * h, q, qd)
        step = robot.simulate(h, sample_rate=1 / h, input=np.array([[0.0, u]]), q0=q, qd0=qd,
                              fixed_step=2e-3)
        q, qd = step["q"][-1], step["qd"][-1]
        np.testing.assert_allclose(q, tr["q"][k + 1], rtol=0, atol=1e-6 * np.abs(q).max(),
                                   err_msg=f"period {k}")


def test_an_exception_in_the_controller_propagates_and_bad_values_are_named(robot):
    class Stop(Exception):
        pass

    def gives_up(t, q, qd):
        if t > 0.005:
            raise Stop("controller gave up")
        return -1.0

    with pytest.raises(Stop, match="controller gave up"):
        robot.simulate(0.05, sample_rate=500, controller=gives_up)
    with pytest.raises(gvsrom.GvsromError,
                       match=r"`controller\(0, q, qd\)` returned u\[0\] = NaN: expected finite"):
        robot.simulate(0.01, controller=lambda t, q, qd: float("nan"))
    with pytest.raises(gvsrom.GvsromError, match=r"`controller\(0, q, qd\)`: .*2 tensions given for 1 tendon \("):
        robot.simulate(0.01, controller=lambda t, q, qd: [1.0, 2.0])
    with pytest.raises(gvsrom.GvsromError, match=r"`controller\(0, q, qd\)`.*tendons\[0\]"):
        robot.simulate(0.01, controller=lambda t, q, qd: -1e9)


def test_bad_arguments_are_clear_errors(robot):
    law = lambda t, q, qd: -1.0  # noqa: E731
    with pytest.raises(gvsrom.GvsromError, match=r"^invalid value for `control_rate`: 30 \(expected a whole fraction of sample_rate 100 Hz"):
        robot.simulate(0.1, sample_rate=100, controller=law, control_rate=30)
    with pytest.raises(gvsrom.GvsromError, match=r"control_rate.*a finite number > 0"):
        robot.simulate(0.1, controller=law, control_rate=-5)
    with pytest.raises(gvsrom.GvsromError, match=r"`control_rate` is the rate of a `controller`"):
        robot.simulate(0.1, control_rate=50)
    with pytest.raises(gvsrom.GvsromError, match=r"`input` and `controller` both give the tensions"):
        robot.simulate(0.1, input=[[0.0, -1.0]], controller=law)
    with pytest.raises(gvsrom.GvsromError, match=r"`controller`, `steps` and `babble`"):
        robot.simulate(0.1, controller=law, steps=[-1.0, 0.0, 0.05])
    with pytest.raises(TypeError, match=r"`controller` must be a callable.*got `3`"):
        robot.simulate(0.1, controller=3)


def test_a_run_the_controller_stops_hands_back_the_samples_before(robot):
    class Stop(Exception):
        pass

    def gives_up(t, q, qd):
        if t > 0.025:
            raise Stop("controller gave up")
        return -1.0

    with pytest.raises(Stop) as e:
        robot.simulate(0.05, sample_rate=100, controller=gives_up)
    np.testing.assert_allclose(e.value.trajectory["t"], [0.0, 0.01, 0.02], rtol=0, atol=1e-15)
    assert any("its 3 samples before" in n for n in e.value.__notes__)
    # a refused value after the start: an IntegrationError (a GvsromError) with the samples
    with pytest.raises(gvsrom.IntegrationError,
                       match=r"`controller\(0.02, q, qd\)` returned u\[0\] = NaN.*2 samples computed before"
                       ) as e:
        robot.simulate(0.05, sample_rate=100,
                       controller=lambda t, q, qd: float("nan") if t > 0.015 else -1.0)
    assert e.value.trajectory["q"].shape == (2, robot.n_dof)
    # a returned array of the wrong shape says its shape
    with pytest.raises(gvsrom.GvsromError, match=r"returned `array\(\[\[-3.\]\]\)` of shape \(1, 1\): "
                                                 r"expected 1 tension \[N\] \(a 1-D array"):
        robot.simulate(0.01, controller=lambda t, q, qd: np.array([[-3.0]]))


def test_an_error_the_users_own_code_raises_keeps_its_type_and_no_zero_tension_is_delivered(robot):
    # a GvsromError from the user's own call inside the controller is the user's: not rewrapped
    def law(t, q, qd):
        if t > 0.015:
            raise gvsrom.GvsromError("mine")
        return -1.0

    with pytest.raises(gvsrom.GvsromError) as e:
        robot.simulate(0.05, sample_rate=100, controller=law)
    assert type(e.value) is gvsrom.GvsromError and str(e.value) == "mine"
    assert len(e.value.trajectory["t"]) == 2
    # an input callable that fails mid-step: the samples handed back all carry its tensions, none
    # the zeros the step evaluated after the failure
    with pytest.raises(gvsrom.IntegrationError) as e:
        robot.simulate(0.05, sample_rate=100, input=lambda t: -2.0 if t < 0.025 else float("nan"))
    u = e.value.trajectory["u"]
    assert len(u) >= 2 and (u == -2.0).all(), u
