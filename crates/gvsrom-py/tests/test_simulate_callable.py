"""simulate with a Python callable `u(t)` as input: the trajectory of the same input given as rows,
its exceptions propagated, its bad values refused."""

import time

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def test_a_callable_gives_the_trajectory_of_the_same_rows(robot):
    # a linear ramp: rows interpolated linearly, and the same function of t
    rows = np.array([[0.0, 0.0], [0.02, -4.0], [1.0, -4.0]])
    by_rows = robot.simulate(0.03, sample_rate=500, input=rows, interpolate=True)
    calls = []

    def u(t):
        calls.append(t)
        return [np.interp(t, rows[:, 0], rows[:, 1])]

    by_function = robot.simulate(0.03, sample_rate=500, input=u)
    assert calls, "the callable was never called"
    # the rows' knot at 0.02 s is a breakpoint (the integrator restarts there), the callable has
    # none: the two runs take different steps, equal within the integrator's tolerance
    for name in ["t", "u"]:
        np.testing.assert_allclose(by_function[name], by_rows[name], rtol=0, atol=1e-12, err_msg=name)
    tip = by_rows["tip_position"]
    np.testing.assert_allclose(by_function["tip_position"], tip, rtol=0, atol=2e-3 * np.abs(tip).max())


def test_a_held_callable_equals_held_rows_exactly(robot):
    # a constant input: no breakpoint either way, the same steps, the same numbers
    by_rows = robot.simulate(0.02, sample_rate=500, input=[[0.0, -2.5]])
    by_function = robot.simulate(0.02, sample_rate=500, input=lambda t: -2.5)
    for name in ["t", "q", "qd", "u", "tip_position"]:
        np.testing.assert_array_equal(by_function[name], by_rows[name], err_msg=name)


def test_an_exception_in_the_callable_propagates(robot):
    class Stop(Exception):
        pass

    def u(t):
        if t > 0.005:
            raise Stop("controller gave up")
        return [-1.0]

    with pytest.raises(Stop, match="controller gave up"):
        robot.simulate(0.02, sample_rate=500, input=u)


def test_bad_values_of_the_callable_are_value_errors(robot):
    with pytest.raises(gvsrom.GvsromError, match=r"`input\(0\)`: .*3 tensions given for 1 tendon \("):
        robot.simulate(0.01, input=lambda t: [1.0, 2.0, 3.0])
    with pytest.raises(gvsrom.GvsromError, match=r"u\[0\] = NaN: expected finite values \(tensions"):
        robot.simulate(0.01, input=lambda t: [float("nan")])
    with pytest.raises(gvsrom.GvsromError, match=r"returned `'strong'`: expected 1 tension \[N\]"):
        robot.simulate(0.01, input=lambda t: "strong")
    with pytest.raises(gvsrom.GvsromError, match="`interpolate`"):
        robot.simulate(0.01, input=lambda t: -1.0, interpolate=True)
    # without an input there is nothing to interpolate: refused, as `gvsrom simulate --interpolate`
    # without --input is, rather than ignored
    with pytest.raises(gvsrom.GvsromError, match="`interpolate` applies to an `input` of rows"):
        robot.simulate(0.01, interpolate=True)


def test_a_tension_far_beyond_the_elastic_range_stops_the_run_at_once(robot, gvsrom_bin, tmp_path):
    # the same bound as the command line's check of a signal's tensions before a run
    from conftest import cli_error

    expected = cli_error(gvsrom_bin, "simulate", "single-tendon", "--duration", "0.1",
                         "--steps=-1e6,-1e6,0.05", "--out", str(tmp_path / "run"))
    assert "far beyond the rod's elastic range" in expected
    # the command line names its signal and when it reaches the tension; the bound's own sentence
    # is what the callable's check gives too
    assert expected.startswith("invalid `steps`: u(t) random steps") and "at t = 0 s" in expected
    expected = expected[expected.index("tendons[0].tension"):]
    for late in [False, True]:
        # from the start, or only after 0.05 s of a moderate pull (once integrated past it)
        def u(t):
            return [-1e6] if (t >= 0.05 or not late) else [-2.0]

        t0 = time.monotonic()
        with pytest.raises(gvsrom.GvsromError) as e:
            robot.simulate(0.1, input=u)
        assert time.monotonic() - t0 < 5.0  # ran on for minutes before
        at = str(e.value).split("`: ")[0]
        # after the start, the samples computed before come with it (an IntegrationError)
        before = ""
        if late:
            assert isinstance(e.value, gvsrom.IntegrationError)
            n = len(e.value.trajectory["t"])
            before = f" ({n} samples computed before: the exception's `trajectory`)"
        assert str(e.value) == f"{at}`: {expected}{before}", str(e.value)
        assert float(at.removeprefix("`input(")[:-1]) >= (0.05 if late else 0.0)
    # up to the bound the run goes on as before
    assert robot.simulate(0.05, input=lambda t: [-5.0])["t"][-1] == pytest.approx(0.05)
