"""Robot.stepper: a run advanced one control period per `step(u)` (a loop the user drives), the
same integration as `simulate(controller=…)`; its errors, its end, its horizon."""

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
    # a tension far beyond the elastic range ends the run, naming it
    with pytest.raises(gvsrom.GvsromError, match=r"`step\(u\)` at t = 0.01 s: tendons\[0\].tension"):
        env.step(-1e9)
    assert not env.running
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
