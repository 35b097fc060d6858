"""Robot.stepper: a run advanced one control period per `step(u)` (a loop the user drives), the
same integration as `simulate(controller=…)`; its errors, its end, its horizon."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def law(t, q, qd):
    return min(-1.0 - 0.5 * (q[0] + 2.0) - 0.05 * qd[0], 0.0)


@pytest.mark.parametrize("kw", [{}, {"fixed_step": 0.005}])
def test_the_steps_are_the_controllers_run(robot, kw):
    dt, k = 0.02, 8
    tr = robot.simulate(dt * k, sample_rate=1 / dt, controller=law, **kw)
    with robot.stepper(dt, **kw) as env:
        assert env.t == 0.0 and env.running
        np.testing.assert_array_equal(env.q, tr["q"][0])
        for i in range(k):
            u = law(env.t, env.q, env.qd)
            q, qd = env.step(u)
            assert env.t == pytest.approx((i + 1) * dt, abs=1e-12)
            # the same integration: the same numbers
            np.testing.assert_array_equal(q, tr["q"][i + 1], err_msg=f"step {i}")
            np.testing.assert_array_equal(qd, tr["qd"][i + 1], err_msg=f"step {i}")
    assert not env.running
    with pytest.raises(gvsrom.GvsromError, match=r"has ended at t = 0.16 s: closed"):
        env.step(-1.0)


def test_bad_arguments_and_values_are_clear_errors(robot):
    for dt in [0.0, -0.01, float("nan")]:
        with pytest.raises(gvsrom.GvsromError, match=r"invalid value for `dt`"):
            robot.stepper(dt)
    with pytest.raises(gvsrom.GvsromError, match=r"invalid value for `horizon`: 0.001 .*≥ dt = 0.01"):
        robot.stepper(0.01, horizon=0.001)
    env = robot.stepper(0.01)
    with pytest.raises(gvsrom.GvsromError, match=r"`u`: .*2 tensions given for 1 tendon"):
        env.step([-1.0, -2.0])
    with pytest.raises(gvsrom.GvsromError, match=r"`u\[0\]` = NaN: expected finite"):
        env.step(float("nan"))
    # refused before the run used them: the run goes on
    q, _ = env.step(-1.0)
    assert env.running and env.t == pytest.approx(0.01)
    # a tension far beyond the elastic range is refused, naming it, and the run goes on as it was
    with pytest.raises(gvsrom.GvsromError, match=r"`step\(u\)` at t = 0.01 s: tendons\[0\].tension.*the run goes on"):
        env.step(-1e9)
    assert env.running and env.t == pytest.approx(0.01)
    q2, _ = env.step(-1.0)
    assert env.t == pytest.approx(0.02) and np.all(np.isfinite(q2))
    env.close()


def test_the_horizon_ends_the_run(robot):
    env = robot.stepper(0.01, horizon=0.03, fixed_step=0.01)
    for _ in range(3):
        env.step(-1.0)
    with pytest.raises(gvsrom.GvsromError, match=r"has ended at t = 0.03 s: it reached its horizon"):
        env.step(-1.0)


def test_a_reduced_model_steps_in_its_coordinates_and_checks_its_training(gvsrom_bin, tmp_path):
    from conftest import run_cli

    ds = tmp_path / "sweep"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:0",
                "--samples", "7", "--out", str(ds))
    assert p.returncode == 0, p.stderr
    rom = gvsrom.Scenario.preset("single-tendon").build().with_model(gvsrom.pod(ds, 2, tmp_path / "pod"))
    with rom.stepper(0.01) as env:
        q, qd = env.step(-3.0)
        assert q.shape == (2,) and qd.shape == (2,)
        with pytest.raises(gvsrom.GvsromError, match=r"`step\(u\)` at t = 0.01 s: .*outside the training"):
            env.step(-20.0)
        # refused before the run used it: an agent's bad action does not end its environment
        assert env.running and env.t == pytest.approx(0.01)
        env.step(-3.0)
        assert env.t == pytest.approx(0.02)


def test_the_default_horizon_suits_a_small_period_and_a_long_one_is_refused_naming_it(robot):
    # 100 000 periods at dt = 1e-4 (10 s), where an hour would lay out 36 million sample times
    with robot.stepper(1e-4, fixed_step=1e-4) as env:
        env.step(-1.0)
        assert env.t == pytest.approx(1e-4)
    with pytest.raises(gvsrom.GvsromError, match=r"invalid value for `horizon`: 3600 .*at most 9999998 periods"):
        robot.stepper(1e-4, horizon=3600.0)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_during_a_step_stops_the_run_at_once(robot, sigint_raises):
    # a step of 10 s at a tiny fixed step takes far longer than the signal's 0.3 s
    env = robot.stepper(10.0, horizon=10.0, fixed_step=1e-5)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        env.step(-1.0)
    assert time.monotonic() - t0 < 3.0
    assert not env.running and env.t == 0.0
    with pytest.raises(gvsrom.GvsromError, match=r"has ended at t = 0 s: interrupted"):
        env.step(-1.0)


def test_a_rod_without_tendons_steps_its_free_motion_with_no_tensions():
    # `u = np.zeros(robot.n_actuators)` is the generic call, also where there are no tendons
    beam = gvsrom.Scenario.preset("soft-beam").build()
    assert beam.n_actuators == 0
    np.testing.assert_array_equal(beam.statics(u=np.zeros(0)).q, beam.statics().q)
    with beam.stepper(0.01, fixed_step=0.01) as env:
        q, qd = env.step(np.zeros(beam.n_actuators))
        assert env.t == pytest.approx(0.01) and q.shape == (beam.n_dof,)
        with pytest.raises(gvsrom.GvsromError, match=r"no tendons"):
            env.step([-1.0])
        assert env.running
