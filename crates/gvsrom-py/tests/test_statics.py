"""Statics from Python equals `gvsrom statics --json` on every preset, bit for bit."""

import numpy as np
import pytest

import gvsrom
from conftest import PRESETS, cli_error, cli_statics

# the same code on the same inputs: identical up to the JSON round trip of f64 (exact with
# serde_json's float_roundtrip); 1e-12 leaves room for nothing else
TOL = 1e-12

TENSIONS = {
    "single-tendon": [-5.0],
    "six-tendon": [-4.0, 0.0, -2.0, 0.0, -1.0, 0.0],
    "six-tendon-no-gravity": [-3.0, -1.0, 0.0, 0.0, -2.0, 0.0],
    "six-tendon-hanging": [-4.0, 0.0, -2.0, 0.0, -1.0, 0.0],
}


def assert_same(py: gvsrom.Statics, cli: dict) -> None:
    np.testing.assert_allclose(py.q, cli["q"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.u, cli["u"], rtol=0, atol=0)
    np.testing.assert_allclose(py.tip_position, cli["tip_position"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.tip_rotation, cli["tip_rotation"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.centerline_x, cli["centerline_x"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.centerline, cli["centerline"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.strain_x, cli["strain_x"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.strain, cli["strain"], rtol=0, atol=TOL)
    np.testing.assert_allclose(py.strain_reference, cli["strain_reference"], rtol=0, atol=0)
    assert len(py.tendon_paths) == len(cli.get("tendon_paths", []))
    for a, b in zip(py.tendon_paths, cli.get("tendon_paths", [])):
        np.testing.assert_allclose(a, b, rtol=0, atol=TOL)
    assert py.iterations == cli["iterations"]
    assert py.load_stages == cli["load_stages"]
    assert py.residual_norm == pytest.approx(cli["residual_norm"], rel=0, abs=TOL)
    assert py.scenario == cli["scenario"]


@pytest.mark.parametrize("name", PRESETS)
def test_statics_equals_the_cli_json_on_each_preset(gvsrom_bin, tmp_path, name):
    cli = cli_statics(gvsrom_bin, tmp_path, name)
    eq = gvsrom.Scenario.preset(name).build().statics()
    assert_same(eq, cli)
    assert eq.q.shape == (eq.n_dof,) and eq.strain.shape == (eq.n_points, 6)
    assert eq.solve_time_s > 0


@pytest.mark.parametrize("name", sorted(TENSIONS))
def test_statics_under_tensions_equals_the_cli_with_tension(gvsrom_bin, tmp_path, name):
    u = TENSIONS[name]
    cli = cli_statics(gvsrom_bin, tmp_path, name, "--tension=" + ",".join(map(str, u)))
    eq = gvsrom.Scenario.preset(name).build().statics(u=np.array(u))
    assert_same(eq, cli)


def test_statics_after_set_equals_the_cli_with_set(gvsrom_bin, tmp_path):
    sets = ["tendons.0.tension=-7", "solver.ramp_steps=3"]
    cli = cli_statics(gvsrom_bin, tmp_path, "single-tendon", *[a for s in sets for a in ("--set", s)])
    s = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -7).set("solver.ramp_steps", 3)
    assert_same(s.build().statics(), cli)


def test_one_tension_is_given_to_every_tendon():
    robot = gvsrom.Scenario.preset("six-tendon-no-gravity").build()
    a = robot.statics(u=[-1.5])
    b = robot.statics(u=[-1.5] * 6)
    np.testing.assert_array_equal(a.q, b.q)
    # one number for all, as the docstrings say: a float, an int, a NumPy scalar or 0-d array
    for one in (-1.5, np.float64(-1.5), np.array(-1.5)):
        np.testing.assert_array_equal(robot.statics(one).q, b.q)
    np.testing.assert_array_equal(robot.statics(-2).q, robot.statics([-2.0] * 6).q)
    np.testing.assert_array_equal(robot.statics_residual(b.q, u=-1.5), robot.statics_residual(b.q, u=[-1.5] * 6))
    np.testing.assert_array_equal(robot.modes(2, u=-1.5)["frequency_hz"],
                                  robot.modes(2, u=[-1.5] * 6)["frequency_hz"])


def test_wrong_tension_count_is_a_value_error(gvsrom_bin):
    robot = gvsrom.Scenario.preset("six-tendon").build()
    expected = cli_error(gvsrom_bin, "statics", "six-tendon", "--tension=-1,-2")
    with pytest.raises(ValueError) as e:
        robot.statics(u=[-1.0, -2.0])
    # named as the argument `u` where the command line names its option and the scenario's
    # `tendons`; the same account of what is wrong
    text = str(e.value)
    assert text.startswith("`u`: ") and expected.endswith(text[len("`u`: "):]), (text, expected)
    assert expected.startswith("u: invalid `tendons`: 2 tensions given for 6 tendons"), expected


def test_non_convergence_raises_with_iterations_and_residual(gvsrom_bin):
    sets = ["solver.max_iterations=1", "solver.ramp_steps=1", "tendons.0.tension=-10"]
    expected = cli_error(gvsrom_bin, "statics", "single-tendon", *[a for s in sets for a in ("--set", s)])
    s = gvsrom.Scenario.preset("single-tendon")
    for spec in sets:
        path, value = spec.split("=")
        s.set(path, value)
    with pytest.raises(gvsrom.ConvergenceError) as e:
        s.build().statics()
    assert str(e.value) == expected
    assert e.value.iterations >= 1 and e.value.residual_norm > 0
    assert f"after {e.value.iterations} iterations" in str(e.value)
    assert isinstance(e.value, ValueError)


def test_tendon_paths_start_at_the_offsets_and_follow_the_rod():
    # single-tendon: the tendon runs from (0, 0, 0.01) at the base to 3 mm above the tip's axis;
    # at the tip it is the tip pose applied to its end offset (0, 0, 0.003)
    robot = gvsrom.Scenario.preset("single-tendon").build()
    eq = robot.statics(u=[-3.0])
    (path,) = eq.tendon_paths
    assert path.shape == (len(eq.centerline_x), 3)
    np.testing.assert_allclose(path[0], [0.0, 0.0, 0.01], atol=1e-15)
    np.testing.assert_allclose(path[-1], eq.tip_position + eq.tip_rotation @ [0.0, 0.0, 0.003],
                               atol=1e-12)
    # and it stays within the section's radius (12.5 → 5 mm) of the centreline
    gap = np.linalg.norm(path - eq.centerline, axis=1)
    assert np.all(gap <= 0.0125 + 1e-9) and np.all(gap > 0.0029)


SOFT_CANTILEVER = """
name = "soft-cantilever"
[material]
youngs_modulus = 3.3e5
poisson_ratio = 0.5
density = 1000.0
[[divisions]]
length = 1.0
radius = 0.01
basis = { kind = "legendre", modes = ["torsion","bend_y","bend_z","elongation","shear_y","shear_z"], order = 3 }
[loads]
gravity = [0.0, 0.0, -9.81]
"""


def test_a_soft_cantilever_under_gravity_hangs_down_and_is_stable():
    # one full-load step from straight lands on an equilibrium curled up above the clamp, which
    # diverges; the solver then follows the equilibria from the straight rod to the hanging one
    s = gvsrom.Scenario.from_toml(SOFT_CANTILEVER).build().statics()
    assert s.tip_position[2] < -0.9 and s.divergence is None
    assert s.to_dict()["divergence"] is None


def test_an_unstable_equilibrium_warns_and_reports_its_divergence():
    # the same rod with continuation forbidden (solver.min_increment = 1): the curled equilibrium
    scenario = gvsrom.Scenario.from_toml(SOFT_CANTILEVER).set("solver.min_increment", 1.0)
    with pytest.warns(UserWarning, match="unstable.*divergence"):
        s = scenario.build().statics()
    assert s.tip_position[2] > 0.1 and s.divergence < -1e3


def test_a_batch_row_on_an_unstable_equilibrium_warns_and_reports_its_divergence():
    # the soft cantilever with a slack tendon: each row a full-load solve from straight
    text = SOFT_CANTILEVER + "[[tendons]]\noffset_start = [0.0, 0.005]\noffset_end = [0.0, 0.005]\ntension = 0.0\n"
    robot = gvsrom.Scenario.from_toml(text).set("solver.min_increment", 1.0).build()
    # continuation forbidden: the curled equilibrium
    with pytest.warns(UserWarning, match=r"rows \[0\] are unstable"):
        b = robot.statics_batch(np.zeros((1, 1)), warm_start=False)
    assert b.divergence.shape == (1,) and b.divergence[0] < -1e3
    # the default solver: stable, NaN
    b = gvsrom.Scenario.from_toml(text).build().statics_batch(np.zeros((1, 1)))
    assert np.isnan(b.divergence[0]) and b.tip_position[0, 2] < -0.9


def test_a_soft_cantilever_reached_by_continuation_says_so_and_did_not_buckle():
    s = gvsrom.Scenario.from_toml(SOFT_CANTILEVER).build().statics()
    assert s.continued and s.buckled is None
    assert s.to_dict()["continued"] is True and s.to_dict()["buckled"] is None


def test_six_tendon_pushed_on_every_tendon_buckles_onto_an_equilibrium_numpy_finds_stable():
    # +30 N on every tendon: the path from the straight rod stays in the arm's plane of symmetry
    # (y = 0) and ends on an equilibrium that diverges with two modes; released, the arm leaves
    # that plane and settles beside it
    robot = gvsrom.Scenario.preset("six-tendon").build()
    u = np.full(6, 30.0)
    s = robot.statics(u)
    assert s.divergence is None and s.buckled is not None and s.buckled < -1e3
    assert abs(s.tip_position[1]) > 0.005
    # an equilibrium: ‖R‖∞ at the tolerance of the solve's own test
    assert np.max(np.abs(robot.statics_residual(s.q, u))) < 1e-7
    # and stable, judged here by NumPy: every eigenvalue of M⁻¹K_T, K_T = −∂R/∂q, has Re > 0
    k_t = -robot.statics_jacobian(s.q, u)
    w2 = np.linalg.eigvals(np.linalg.solve(robot.mass_matrix(s.q), k_t))
    assert w2.real.min() > 1.0, w2.real.min()
    # the in-plane equilibrium it left is one too, but diverges
    straight = gvsrom.Scenario.preset("six-tendon").set("solver.min_increment", 1.0).build()
    with pytest.warns(UserWarning, match="unstable"):
        flat = straight.statics(u)
    assert abs(flat.tip_position[1]) < 1e-5
    k_t = -robot.statics_jacobian(flat.q, u)
    w2 = np.linalg.eigvals(np.linalg.solve(robot.mass_matrix(flat.q), k_t))
    assert w2.real.min() < -1e3


def test_a_batch_row_that_buckled_says_so_and_matches_the_single_solve():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    U = np.array([np.zeros(6), np.full(6, 30.0)])
    b = robot.statics_batch(U, warm_start=False)
    assert np.isnan(b.buckled[0]) and b.buckled[1] < -1e3
    assert np.all(np.isnan(b.divergence))
    single = robot.statics(U[1])
    np.testing.assert_allclose(b.tip_position[1], single.tip_position, atol=1e-9)
