"""Tendon lengths for a controller that commands the actuators' positions: at rest the routed
line's length, `∂ℓ/∂q` against central differences and (frictionless) against the actuation
matrix, the same lengths in statics results, batches and trajectories, and through a reduced
model."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def arm():
    return gvsrom.Scenario.preset("single-tendon").build()


@pytest.fixture(scope="module")
def six():
    return gvsrom.Scenario.preset("six-tendon").build()


def central_differences(f, q, h=1e-6):
    cols = []
    for j in range(len(q)):
        e = np.zeros(len(q))
        e[j] = h
        cols.append((f(q + e) - f(q - e)) / (2 * h))
    return np.stack(cols, axis=-1)


def test_rest_length_is_the_routed_line(arm):
    # single-tendon: offset 10 mm → 3 mm over the 0.25 m arm, a straight line at rest
    line = np.hypot(0.25, 0.007)
    np.testing.assert_allclose(arm.tendon_rest_lengths, [line], rtol=1e-14)
    np.testing.assert_allclose(arm.tendon_lengths(np.zeros(arm.n_dof)), [line], rtol=1e-14)


def test_length_jacobian_is_the_gradient_and_frictionless_b_transposed(arm, six):
    for robot, frictionless in ((six, True), (arm, False)):
        q = robot.statics().q
        jac = robot.tendon_length_jacobian(q)
        assert jac.shape == (robot.n_actuators, robot.n_dof)
        fd = central_differences(robot.tendon_lengths, q)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-8 * np.abs(jac).max())
        b = robot.actuation_matrix(q)
        if frictionless:
            np.testing.assert_allclose(jac, b.T, rtol=0, atol=1e-13 * np.abs(b).max())
        else:
            # the capstan friction (μ = 0.88) attenuates the tension along the tendon: B < ∇ℓ
            assert np.abs(jac - b.T).max() > 0.05 * np.abs(b).max()


def test_results_carry_the_lengths_at_their_states(arm, six):
    st = six.statics()
    np.testing.assert_allclose(st.tendon_lengths, six.tendon_lengths(st.q), rtol=1e-14)
    np.testing.assert_array_equal(st.tendon_rest_lengths, six.tendon_rest_lengths)
    # tendons on the side bent toward are shorter than at rest, and the others longer
    pulled = st.tendon_rest_lengths - st.tendon_lengths
    assert pulled.max() > 1e-3 and pulled.min() < -1e-3, pulled
    batch = arm.statics_batch([[-1.0], [-3.0]])
    assert batch.tendon_lengths.shape == (2, 1)
    for k in range(2):
        np.testing.assert_allclose(batch.tendon_lengths[k], arm.tendon_lengths(batch.q[k]),
                                   rtol=1e-14)
    # gravity sags the arm away from its tendon (on top): at -1 N it is stretched; pulled at
    # -3 N the arm lifts and the tendon is shorter than at rest
    assert batch.tendon_lengths[1, 0] < arm.tendon_rest_lengths[0] < batch.tendon_lengths[0, 0]
    tr = arm.simulate(0.02, sample_rate=500, input=[[0.0, -2.0]])
    assert tr["tendon_lengths"].shape == (len(tr["t"]), 1)
    for k in (0, len(tr["t"]) // 2, -1):
        np.testing.assert_allclose(tr["tendon_lengths"][k], arm.tendon_lengths(tr["q"][k]),
                                   rtol=1e-14)


def test_a_reduced_model_reads_the_same_tendon(arm, tmp_path):
    ds = gvsrom.dataset("single-tendon", tmp_path / "ds", sweep="tendons.0.tension=-6:0",
                        samples=7)
    rom = arm.with_model(gvsrom.pod(ds, 2, tmp_path / "pod"))
    np.testing.assert_array_equal(rom.tendon_rest_lengths, arm.tendon_rest_lengths)
    st = rom.statics(u=[-3.0])
    full = arm.statics(u=[-3.0])
    np.testing.assert_allclose(st.tendon_lengths, rom.tendon_lengths(st.q), rtol=1e-14)
    # POD-2's equilibrium is the HOM's to its own accuracy: the tendon 7 mm shorter than at
    # rest in both, within 0.5 mm of each other (measured 0.21 mm)
    np.testing.assert_allclose(st.tendon_lengths, full.tendon_lengths, rtol=0, atol=5e-4)
    jac = rom.tendon_length_jacobian(st.q)
    assert jac.shape == (1, 2)
    # POD coordinates are of order 10–100 (q = [-60, 12] here): a step of 1e-2 keeps the
    # differences' round-off (ε ℓ / h) at 1e-11 of the entries (measured 5e-11)
    fd = central_differences(rom.tendon_lengths, st.q, h=1e-2)
    np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-8 * np.abs(jac).max())
