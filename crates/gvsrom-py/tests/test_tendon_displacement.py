"""Tendons driven by their displacement through the Python API (``Robot.statics(displacement=…)``
and a scenario's ``tendons[k].displacement``): the tendon is wound in by exactly that length, the
tension found makes the same rod when given back as ``u``, a paid-out tendon goes slack, and the
commands that drive tendons by tension only refuse a displacement."""

import numpy as np
import pytest

import gvsrom

#: the drive's length tolerance: 1e-9 of the IV-A arm's 0.25 m
TOL = 2.5e-10


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def test_a_tendon_wound_in_is_that_much_shorter_and_its_tension_makes_the_same_rod(robot):
    eq = robot.statics(displacement=0.005)
    wound = eq.tendon_rest_lengths - eq.tendon_lengths
    assert abs(wound[0] - 0.005) < TOL
    assert eq.slack.dtype == np.bool_ and not eq.slack[0]
    assert eq.drive_iterations >= 1
    assert eq.u[0] < -1.0
    by_tension = robot.statics(u=eq.u)
    np.testing.assert_allclose(by_tension.tip_position, eq.tip_position, atol=1e-9)
    assert by_tension.drive_iterations == 0 and not by_tension.slack.any()
    # the robot itself stays tension-driven
    assert robot.statics().drive_iterations == 0


def test_a_tendon_paid_out_past_its_path_is_slack_and_the_rod_hangs_as_without_it(robot):
    # the arm sagging under gravity lengthens the path of its upper tendon
    free = robot.statics(u=0.0)
    path = (free.tendon_rest_lengths - free.tendon_lengths)[0]
    assert path < -1e-4, "the sag lengthens the tendon's path"
    eq = robot.statics(displacement=path - 0.001)
    assert eq.slack[0] and eq.u[0] == 0.0
    np.testing.assert_allclose(eq.tip_position, free.tip_position, atol=1e-12)
    # paid out 1 mm less than the sag needs, it holds the arm up
    eq = robot.statics(displacement=path + 0.001)
    assert not eq.slack[0] and eq.u[0] < 0.0
    assert eq.tip_position[2] > free.tip_position[2]


def test_a_scenario_driven_by_displacement_solves_so_and_refuses_dynamics():
    s = (
        gvsrom.Scenario.preset("single-tendon")
        .set("tendons.0.tension", 0)
        .set("tendons.0.displacement", 0.004)
    )
    robot = s.build()
    eq = robot.statics()
    assert abs((eq.tendon_rest_lengths - eq.tendon_lengths)[0] - 0.004) < TOL
    with pytest.raises(gvsrom.GvsromError, match=r"tendons\[0\]\.displacement.*simulate drives tendons by their tension only"):
        robot.simulate(duration=0.01)
    # modes hold the taut tendon at its length: one mode fewer than the free arm's
    held = robot.modes()
    free = gvsrom.Scenario.preset("single-tendon").build().modes(u=eq.u)
    assert held["held_tendons"] == [0]
    assert len(held["all_frequencies_hz"]) == len(free["all_frequencies_hz"]) - 1
    assert held["all_frequencies_hz"][0] > free["all_frequencies_hz"][0]
    assert free["held_tendons"] == []
    # given tensions drive by tension, as --tension does
    assert robot.statics(u=eq.u).drive_iterations == 0
    # the robot has no tension for the driven tendon until a statics finds it
    assert np.isnan(robot.tensions[0]) and robot.displacements[0] == 0.004
    with pytest.raises(gvsrom.GvsromError, match=r"tendons\[0\] is driven by its displacement.*robot.statics\(\).u"):
        robot.statics_residual(eq.q)
    np.testing.assert_allclose(robot.statics_residual(eq.q, u=eq.u), 0.0, atol=1e-9)


def test_tension_and_displacement_together_or_impossible_are_refused(robot):
    with pytest.raises(gvsrom.GvsromError, match="`u` and `displacement` both given"):
        robot.statics(u=-1.0, displacement=0.001)
    with pytest.raises(gvsrom.GvsromError, match=r"tendons\[0\]\.displacement.*rest length"):
        robot.statics(displacement=0.3)
    with pytest.raises(gvsrom.GvsromError, match="2 displacements given for 1 tendon"):
        robot.statics(displacement=[0.001, 0.002])
