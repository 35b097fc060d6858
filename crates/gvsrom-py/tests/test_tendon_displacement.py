"""Tendons driven by their displacement through the Python API (``Robot.statics(displacement=…)``
and a scenario's ``tendons[k].displacement``): the tendon is wound in by exactly that length, the
tension found makes the same rod when given back as ``u``, a paid-out tendon goes slack, a run
on an elastic thread settles where statics puts it, and the commands that drive tendons by
tension only refuse a displacement."""

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


def test_a_scenario_driven_by_displacement_solves_so_and_needs_a_thread_to_move():
    s = (
        gvsrom.Scenario.preset("single-tendon")
        .set("tendons.0.tension", 0)
        .set("tendons.0.displacement", 0.004)
    )
    robot = s.build()
    eq = robot.statics()
    assert abs((eq.tendon_rest_lengths - eq.tendon_lengths)[0] - 0.004) < TOL
    # an inextensible tendon held at its length is a constraint the integrators do not impose
    with pytest.raises(gvsrom.GvsromError, match=r"tendons\[0\]\.axial_stiffness.*missing.*EA in N"):
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


def test_a_run_on_an_elastic_thread_settles_where_statics_puts_it():
    """The IV-A arm's thread with EA = 200 N wound in by 4 mm: the run's tensions follow the
    stretch (all 4 mm of it at the straight start, ``u = −δ EA / ℓ_rest``) and settle, with the
    tip, on the statics drive of the same thread; an ``input`` column of a driven tendon is its
    displacement, ramped here from 0 to 4 mm over the first second to the same end."""
    robot = (
        gvsrom.Scenario.preset("single-tendon")
        .set("tendons.0.tension", 0)
        .set("tendons.0.displacement", 0.004)
        .set("tendons.0.axial_stiffness", 200.0)
        .build()
    )
    eq = robot.statics()
    run = robot.simulate(4.0, sample_rate=10)
    rest = robot.tendon_rest_lengths[0]
    assert run["u"][0, 0] == pytest.approx(-0.004 * 200.0 / rest, rel=1e-9)
    assert run["u"][-1, 0] == pytest.approx(eq.u[0], rel=1e-4)
    np.testing.assert_allclose(run["tip_position"][-1], eq.tip_position, atol=1e-6 * 0.25)
    ramp = robot.simulate(4.0, sample_rate=10, input=[[0.0, 0.0], [1.0, 0.004]], interpolate=True)
    assert ramp["u"][0, 0] == 0.0, "no displacement yet: the thread is at its length"
    # the commanded displacements are kept: the ramp, then held
    np.testing.assert_allclose(ramp["displacement"][:11, 0], np.linspace(0.0, 0.004, 11), atol=1e-15)
    assert (ramp["displacement"][10:, 0] == 0.004).all()
    np.testing.assert_allclose(ramp["tip_position"][-1], eq.tip_position, atol=1e-6 * 0.25)
    # a displacement past the tendon's length is refused before the run
    with pytest.raises(gvsrom.GvsromError, match=r"tendon 0.s displacement at t = 0.5 s.*rest length"):
        robot.simulate(1.0, input=[[0.0, 0.0], [0.5, 0.3]])
    # a callable's displacement the rod cannot take ends the run where the thread pulls past
    # the rod's elastic range (20 cm of a 200 N thread: 160 N at once)
    with pytest.raises(gvsrom.IntegrationError, match=r"tendons\[0\]\.displacement: at t = 0 s its thread pulls.*beyond the tension limit"):
        robot.simulate(0.2, input=lambda t: [0.2])
    # linearized, the driven tendon's input is its displacement: the settled tip rises per metre
    lin = robot.linearize()
    assert lin["displacement_channels"] == [0]
    assert lin["static_gain"][2, 0] > 1.0, "a millimetre wound in lifts the tip by more"
    # the stepper's entry for the driven tendon is its displacement too
    stepper = robot.stepper(0.1)
    with pytest.raises(gvsrom.GvsromError, match=r"u\[0\].*rest length"):
        stepper.step([0.3])
    for _ in range(40):
        q, _ = stepper.step([0.004])
    assert np.linalg.norm(q - eq.q) < 1e-4 * np.linalg.norm(eq.q)
    stepper.close()
