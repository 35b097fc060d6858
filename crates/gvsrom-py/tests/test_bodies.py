"""Rigid bodies (``[[bodies]]``) through the Python API: the mass matrix is the sections' plus
``Σ J_bᵀ Mb J_b``, ``Mb`` gives the kinetic energy of the body's centre of mass and spin, and the
gravitational energy holds the body's weight at its centre of mass."""

import numpy as np
import pytest

import gvsrom

PAYLOAD_ARM = """
name = "payload arm"
[material]
youngs_modulus = 0.617e6
poisson_ratio = 0.5
density = 1121
[[divisions]]
length = 0.25
radius_start = 0.0125
radius_end = 0.005
basis = { kind = "legendre", modes = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 2 }
[[tendons]]
offset_start = [0, 0.01]
offset_end = [0, 0.003]
tension = -2
[[bodies]]
x = 0.25
mass = 0.02
center = [0.01, 0.004, 0.0]
inertia = [[2e-6, 1e-7, 0], [1e-7, 1.5e-6, 0], [0, 0, 1.2e-6]]
"""


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.from_toml(PAYLOAD_ARM).build()


@pytest.fixture(scope="module")
def state(robot):
    """The equilibrium under the scenario's tension, perturbed, and a velocity."""
    rng = np.random.default_rng(3)
    q = robot.statics().q + 0.05 * rng.standard_normal(robot.n_dof)
    return q, rng.standard_normal(robot.n_dof)


def test_the_payload_is_where_its_x_is_and_its_inertia_is_the_spatial_one(robot):
    (b,) = robot.body_points
    assert robot.point_x[b] == pytest.approx(0.25)
    mb = robot.body_inertia[0]
    m, c = 0.02, np.array([0.01, 0.004, 0.0])
    ct = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
    inertia = np.array([[2e-6, 1e-7, 0], [1e-7, 1.5e-6, 0], [0, 0, 1.2e-6]])
    np.testing.assert_allclose(mb[:3, :3], inertia - m * ct @ ct, rtol=1e-14, atol=1e-20)
    np.testing.assert_allclose(mb[3:, 3:], m * np.eye(3))
    np.testing.assert_allclose(mb[:3, 3:], m * ct)


def test_mass_matrix_adds_each_body_at_its_point(robot, state):
    q, qd = state
    J = robot.jacobian(q)
    sections = np.einsum("p,pan,pa,pam->nm", robot.point_weights, J, robot.section_inertia, J)
    bodies = sum(J[b].T @ mb @ J[b] for b, mb in zip(robot.body_points, robot.body_inertia))
    M = robot.mass_matrix(q)
    np.testing.assert_allclose(M, sections + bodies, rtol=0, atol=1e-10 * np.abs(M).max())
    # the body's share of ½ q̇ᵀ M q̇ is ½ m |v_c|² + ½ ωᵀ I ω, its centre of mass moving at v − c̃ ω
    (b,) = robot.body_points
    eta = robot.point_velocities(q, qd)[b]
    w, v = eta[:3], eta[3:]
    c = np.array([0.01, 0.004, 0.0])
    inertia = np.array([[2e-6, 1e-7, 0], [1e-7, 1.5e-6, 0], [0, 0, 1.2e-6]])
    t_body = 0.5 * 0.02 * np.sum((v + np.cross(w, c)) ** 2) + 0.5 * w @ inertia @ w
    assert 0.5 * qd @ bodies @ qd == pytest.approx(t_body, rel=1e-10)


def test_gravitational_energy_weighs_the_body_at_its_centre_of_mass(robot, state):
    q, _ = state
    bare = gvsrom.Scenario.from_toml(PAYLOAD_ARM.split("[[bodies]]")[0]).build()
    pose = robot.forward(q)
    (b,) = robot.body_points
    centre = pose["position"][b] + pose["rotation"][b] @ np.array([0.01, 0.004, 0.0])
    expected = bare.energy(q)["gravitational"] + 0.02 * 9.81 * centre[2]
    assert robot.energy(q)["gravitational"] == pytest.approx(expected, rel=1e-12)


def test_a_robot_without_bodies_has_empty_body_arrays():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    assert robot.body_points.shape == (0,) and robot.body_points.dtype == np.int64
    assert robot.body_inertia.shape == (0, 6, 6)


def test_statics_and_simulate_return_where_the_payload_is(robot):
    eq = robot.statics()
    assert eq.body_positions.shape == (1, 2, 3)
    section, centre = eq.body_positions[0]
    np.testing.assert_allclose(section, eq.tip_position, rtol=0, atol=1e-15)
    rotation = eq.tip_rotation
    np.testing.assert_allclose(centre, section + rotation @ [0.01, 0.004, 0.0], rtol=0, atol=1e-15)
    run = robot.simulate(duration=0.02)
    assert run["body_positions"].shape == (len(run["t"]), 1, 2, 3)
    np.testing.assert_allclose(run["body_positions"][:, 0, 0], run["tip_position"], rtol=0, atol=1e-15)
