"""Model quantities, each checked against another: the residual Jacobian against finite
differences of the residual, the geometric Jacobians against finite differences of the forward
kinematics, M against the kinetic energy of the section twists."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module", params=["single-tendon", "six-tendon"])
def robot(request):
    return gvsrom.Scenario.preset(request.param).build()


@pytest.fixture(scope="module")
def state(robot):
    """A bent state (the equilibrium under the scenario's tensions plus a perturbation) and a
    velocity."""
    rng = np.random.default_rng(1)
    q = robot.statics(u=[-3.0]).q + 0.05 * rng.standard_normal(robot.n_dof)
    qd = rng.standard_normal(robot.n_dof)
    return q, qd


def test_residual_vanishes_at_the_equilibrium(robot):
    eq = robot.statics()
    r = robot.statics_residual(eq.q)
    assert np.abs(r).max() == pytest.approx(eq.residual_norm, rel=1e-6, abs=1e-9)


def test_statics_jacobian_matches_central_differences_of_the_residual(robot, state):
    q, _ = state
    u = [-2.0]
    jac = robot.statics_jacobian(q, u)
    h = 1e-6
    fd = np.empty_like(jac)
    for j in range(robot.n_dof):
        e = np.zeros(robot.n_dof)
        e[j] = h
        fd[:, j] = (robot.statics_residual(q + e, u) - robot.statics_residual(q - e, u)) / (2 * h)
    # central differences: error O(h²)·R''' plus round-off ~ ε·‖R‖/h
    scale = np.abs(jac).max()
    np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-6 * scale)


def test_geometric_jacobian_matches_differences_of_the_forward_kinematics(robot, state):
    q, qd = state
    J = robot.jacobian(q)
    h = 1e-6
    plus, minus, at = robot.forward(q + h * qd), robot.forward(q - h * qd), robot.forward(q)
    R = at["rotation"]
    # body twist: ω̂ = Rᵀ Ṙ, v = Rᵀ ṙ
    Rdot = (plus["rotation"] - minus["rotation"]) / (2 * h)
    rdot = (plus["position"] - minus["position"]) / (2 * h)
    W = np.einsum("pji,pjk->pik", R, Rdot)
    omega = np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], axis=1)
    v = np.einsum("pji,pj->pi", R, rdot)
    eta = np.einsum("pan,n->pa", J, qd)
    scale = np.abs(eta).max()
    np.testing.assert_allclose(eta[:, :3], omega, rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose(eta[:, 3:], v, rtol=0, atol=1e-6 * scale)
    np.testing.assert_array_equal(robot.jacobian(q, point=-1), J[-1])


def test_position_jacobian_is_the_point_jacobian_at_points_and_the_positions_derivative_between(
        robot, state):
    q, qd = state
    n = robot.n_dof
    fwd = robot.forward(q)
    i = robot.n_points // 2
    p, J = robot.position_jacobian(q, float(fwd["x"][i]))
    assert p.shape == (3,) and J.shape == (3, n)
    np.testing.assert_allclose(p, fwd["position"][i], rtol=0, atol=1e-15)
    Jb = robot.jacobian(q, i)
    np.testing.assert_allclose(J, fwd["rotation"][i] @ Jb[3:], rtol=0, atol=1e-12 * np.abs(Jb).max())
    # between points: the derivative of the interpolated position along q̇
    xs = 0.5 * (fwd["x"][1:4] + fwd["x"][2:5])
    P, Js = robot.position_jacobian(q, xs)
    assert P.shape == (3, 3) and Js.shape == (3, 3, n)
    h = 1e-6
    fd = (robot.position_jacobian(q + h * qd, xs)[0] - robot.position_jacobian(q - h * qd, xs)[0]) / (2 * h)
    np.testing.assert_allclose(Js @ qd, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    # the rows linearize stacks into C
    C = robot.linearize(q=q, outputs=xs)["C"]
    np.testing.assert_array_equal(C[:, :n], Js.reshape(9, n))
    # a 1-element array is an array (not one number); a bool, a string or a 2-D array is refused
    P1, J1 = robot.position_jacobian(q, np.array([xs[0]]))
    assert P1.shape == (1, 3) and J1.shape == (1, 3, n)
    np.testing.assert_array_equal(robot.position_jacobian(q, np.float64(xs[0]))[1], J1[0])
    for bad in [True, "0.1", [[0.1]]]:
        with pytest.raises(TypeError, match="one abscissa .m. or a 1-D array-like of them"):
            robot.position_jacobian(q, bad)
    length = robot.length
    for bad in [-0.01, length * 1.01, float("nan")]:
        with pytest.raises(gvsrom.GvsromError, match=r"^x `.*`: expected abscissae .*within \[0, "):
            robot.position_jacobian(q, [0.0, bad])


def test_point_velocities_are_the_jacobians_times_qd(robot, state):
    q, qd = state
    eta = robot.point_velocities(q, qd)
    np.testing.assert_allclose(eta, np.einsum("pan,n->pa", robot.jacobian(q), qd), rtol=1e-10, atol=1e-12)


def test_mass_matrix_is_symmetric_positive_definite(robot, state):
    q, _ = state
    M = robot.mass_matrix(q)
    assert M.shape == (robot.n_dof, robot.n_dof)
    np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-14 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0


def test_mass_matrix_gives_the_kinetic_energy_of_the_section_twists(robot, state):
    # T = ½ q̇ᵀ M q̇ = ½ ∫ ηᵀ Ms η dX = ½ Σ W_i η_iᵀ Ms_i η_i with η from the velocity recursion
    q, qd = state
    M = robot.mass_matrix(q)
    eta = robot.point_velocities(q, qd)
    T = 0.5 * np.sum(robot.point_weights[:, None] * robot.section_inertia * eta**2)
    assert 0.5 * qd @ M @ qd == pytest.approx(T, rel=1e-10)
    # and M = Σ W Jᵀ Ms J
    J = robot.jacobian(q)
    M_ref = np.einsum("p,pan,pa,pam->nm", robot.point_weights, J, robot.section_inertia, J)
    np.testing.assert_allclose(M, M_ref, rtol=0, atol=1e-10 * np.abs(M).max())


def test_q_of_the_wrong_length_is_a_value_error(robot):
    with pytest.raises(gvsrom.GvsromError, match="`q` has 2 entries"):
        robot.mass_matrix([0.0, 0.0])
