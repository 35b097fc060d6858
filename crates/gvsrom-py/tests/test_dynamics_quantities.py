"""The terms of the equations of motion `M q̈ + C q̇ + D₁ + K₁ = B u + F`, each checked against
another quantity: the Coriolis force against finite differences of M, K₁ and F against the
gradients of the elastic and gravitational energies, B against the statics residual's change with
u, and all of them against the residual and the integrators' accelerations."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def robot():
    # gravity, friction 0.88 on its tendon, damping: every term is non-zero
    return gvsrom.Scenario.preset("single-tendon").build()


@pytest.fixture(scope="module")
def state(robot):
    rng = np.random.default_rng(7)
    q = robot.statics(u=[-3.0]).q + 0.05 * rng.standard_normal(robot.n_dof)
    qd = rng.standard_normal(robot.n_dof)
    return q, qd


def central(f, x, h):
    """Central differences of f at x along every coordinate, as columns."""
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h
        cols.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.stack(cols, axis=-1)


def test_coriolis_force_is_mdot_qd_minus_half_the_gradient_of_qd_m_qd(robot, state):
    # C(q, q̇) q̇ = Ṁ q̇ − ½ ∂/∂q (q̇ᵀ M(q) q̇)  (Lagrange's equations with T = ½ q̇ᵀ M q̇)
    q, qd = state
    h = 1e-6
    mdot = (robot.mass_matrix(q + h * qd) - robot.mass_matrix(q - h * qd)) / (2 * h)
    grad = central(lambda x: qd @ robot.mass_matrix(x) @ qd, q, h)
    expected = mdot @ qd - 0.5 * grad
    c = robot.coriolis_force(q, qd)
    # central differences: O(h²) truncation plus round-off ε‖M‖‖q̇‖²/h
    np.testing.assert_allclose(c, expected, rtol=0, atol=1e-6 * np.abs(expected).max())
    np.testing.assert_allclose(robot.coriolis_matrix(q, qd) @ qd, c, rtol=0, atol=1e-10 * np.abs(c).max())


def test_mdot_minus_two_c_is_skew_symmetric(robot, state):
    q, qd = state
    h = 1e-6
    mdot = (robot.mass_matrix(q + h * qd) - robot.mass_matrix(q - h * qd)) / (2 * h)
    s = mdot - 2 * robot.coriolis_matrix(q, qd)
    np.testing.assert_allclose(s, -s.T, rtol=0, atol=1e-6 * np.abs(mdot).max())


def test_elastic_force_is_the_gradient_of_the_elastic_energy_and_k_q(robot, state):
    q, _ = state
    k1 = robot.elastic_force(q)
    grad = central(lambda x: robot.energy(x)["elastic"], q, 1e-6)
    np.testing.assert_allclose(k1, grad, rtol=0, atol=1e-6 * np.abs(k1).max())
    # the HOM's basis is linear: K₁ = K q with the constant K, symmetric
    K = robot.stiffness_matrix(q)
    np.testing.assert_array_equal(K, robot.stiffness_matrix(np.zeros(robot.n_dof)))
    np.testing.assert_allclose(K, K.T, rtol=0, atol=1e-12 * np.abs(K).max())
    np.testing.assert_allclose(K @ q, k1, rtol=0, atol=1e-12 * np.abs(k1).max())


def test_elastic_force_is_minus_the_residual_without_tension_and_gravity(state):
    q, _ = state
    robot = gvsrom.Scenario.preset("single-tendon").set("loads.gravity", [0.0, 0.0, 0.0]).build()
    np.testing.assert_array_equal(robot.elastic_force(q), -robot.statics_residual(q, u=[0.0]))
    np.testing.assert_array_equal(robot.external_force(q), 0.0)


def test_external_force_of_gravity_is_minus_the_gradient_of_its_energy(robot, state):
    q, _ = state
    f = robot.external_force(q)
    grad = central(lambda x: robot.energy(x)["gravitational"], q, 1e-6)
    np.testing.assert_allclose(f, -grad, rtol=0, atol=1e-6 * np.abs(f).max())


def test_frictionless_tendons_force_is_minus_the_gradient_of_their_potential():
    # V = −Σ u ℓ(q), the `tendons` term of energy(u=…): B u = −∂V/∂q for frictionless tendons
    # (six-tendon: six of them, three ending mid-way, in two divisions)
    robot = gvsrom.Scenario.preset("six-tendon").build()
    rng = np.random.default_rng(3)
    u = np.array([-4.0, -1.0, 0.0, -7.0, -2.5, -0.5])
    q = robot.statics(u).q + 0.02 * rng.standard_normal(robot.n_dof)
    e = robot.energy(q, u=u)
    assert e["tendons"] == pytest.approx(-(u @ robot.tendon_lengths(q)), rel=1e-14)
    assert e["total"] == pytest.approx(e["kinetic"] + e["elastic"] + e["gravitational"] + e["tendons"],
                                       rel=1e-14)
    force = robot.actuation_matrix(q) @ u
    grad = central(lambda x: robot.energy(x, u=u)["tendons"], q, 1e-6)
    np.testing.assert_allclose(force, -grad, rtol=0, atol=1e-6 * np.abs(force).max())
    # without u, no tendon term (as before)
    assert "tendons" not in robot.energy(q)


def test_actuation_matrix_is_the_residuals_derivative_in_u(robot, state):
    q, _ = state
    B = robot.actuation_matrix(q)
    assert B.shape == (robot.n_dof, robot.n_actuators)
    # R is affine in u (the friction factor depends on q only): one difference is exact to round-off
    du = 1.0
    fd = (robot.statics_residual(q, u=[-2.0 + du]) - robot.statics_residual(q, u=[-2.0])) / du
    scale = np.abs(robot.statics_residual(q, u=[-2.0])).max() + np.abs(B).max()
    np.testing.assert_allclose(B[:, 0], fd, rtol=0, atol=1e-12 * scale)


def test_terms_add_up_to_the_residual_and_the_accelerations(robot, state):
    q, qd = state
    u = np.array([-4.0])
    k1, f, B = robot.elastic_force(q), robot.external_force(q), robot.actuation_matrix(q)
    r = robot.statics_residual(q, u=u)
    scale = max(np.abs(k1).max(), np.abs(B @ u).max())
    np.testing.assert_allclose(-k1 + f + B @ u, r, rtol=0, atol=1e-12 * scale)
    # M q̈ = B u + F − K₁ − D₁ − C q̇ with q̈ from the integrators' forward dynamics
    d1 = robot.damping_force(q, qd)
    np.testing.assert_allclose(d1, robot.damping_matrix(q) @ qd, rtol=0, atol=1e-12 * np.abs(d1).max())
    tau = r - d1 - robot.coriolis_force(q, qd)
    qdd = robot.accelerations(q, qd, u=u)
    M = robot.mass_matrix(q)
    # a backward-stable solve: ‖M q̈ − τ‖ ~ ε ‖M‖ ‖q̈‖ (however ill-conditioned M is)
    np.testing.assert_allclose(M @ qdd, tau, rtol=0,
                               atol=1e-9 * (np.abs(tau).max() + np.abs(M).max() * np.abs(qdd).max()))


def test_energy_is_kinetic_plus_potential(robot, state):
    q, qd = state
    e = robot.energy(q, qd)
    assert e["kinetic"] == pytest.approx(0.5 * qd @ robot.mass_matrix(q) @ qd, rel=1e-12)
    assert e["total"] == pytest.approx(e["kinetic"] + e["elastic"] + e["gravitational"], rel=1e-14)


def test_bad_states_name_the_argument(robot):
    n = robot.n_dof
    with pytest.raises(gvsrom.GvsromError, match=r"`qd` has 2 entries, the model has 33 coordinates"):
        robot.coriolis_force(np.zeros(n), [0.0, 1.0])
    q = np.zeros(n)
    q[4] = np.nan
    with pytest.raises(gvsrom.GvsromError, match=r"`q\[4\]` = NaN: expected a finite number"):
        robot.elastic_force(q)
    with pytest.raises(gvsrom.GvsromError, match="tension"):
        robot.accelerations(np.zeros(n), np.zeros(n), u=[1.0, 2.0, 3.0])
    # every quantity refuses a non-finite state or tension, none returns NaN (the kinematic and
    # statics ones once did)
    at_q = [robot.forward, robot.jacobian, robot.mass_matrix, robot.statics_residual,
            robot.statics_jacobian, robot.elastic_force, robot.external_force,
            lambda q: robot.position_jacobian(q, 0.1), robot.tendon_lengths,
            robot.tendon_length_jacobian]
    for f in at_q:
        with pytest.raises(gvsrom.GvsromError, match=r"`q\[4\]` = NaN: expected a finite number"):
            f(q)
    with pytest.raises(gvsrom.GvsromError, match=r"`qd\[4\]` = inf: expected a finite number"):
        robot.point_velocities(np.zeros(n), np.where(np.arange(n) == 4, np.inf, 0.0))
    for f in (robot.statics_residual, robot.statics_jacobian):
        with pytest.raises(gvsrom.GvsromError, match=r"`u\[0\]` = NaN: expected a finite number"):
            f(np.zeros(n), u=[np.nan])


def test_a_massless_rod_has_no_accelerations_said_as_simulate_says_it():
    # it was "the mass matrix is not positive semi-definite (pivot 0 = 0e0)": the matrix is zero
    massless = gvsrom.Scenario.preset("single-tendon").set("material.density", 0).build()
    n = massless.n_dof
    expected = "invalid `material.density`: 0: a motion needs a rod with mass"
    with pytest.raises(gvsrom.GvsromError, match=expected):
        massless.accelerations(np.zeros(n), np.zeros(n))
    with pytest.raises(gvsrom.GvsromError, match=expected):
        massless.simulate(0.01)
    # its statics stand
    assert np.isfinite(massless.statics().tip_position).all()
