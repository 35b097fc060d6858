"""linearize: the numbers of `gvsrom linearize --json`, as arrays; A and B against central
differences of `Robot.accelerations` (another entry to the engine) about a moving state; the static
gain against differences of `Robot.statics`; a POD model's 2r states; errors."""

import json

import numpy as np
import pytest

import gvsrom
from conftest import load_example, run_cli


def cli_linearize(bin_path, tmp_path, *args):
    out = tmp_path / "linearize.json"
    p = run_cli(bin_path, "linearize", *args, "--json", str(out), "--force")
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


def test_linearize_equals_the_cli_json(gvsrom_bin, tmp_path):
    cli = cli_linearize(gvsrom_bin, tmp_path, "six-tendon", "--tension=-2,0,0,-1,0,0")
    lin = gvsrom.Scenario.preset("six-tendon").build().linearize(u=[-2, 0, 0, -1, 0, 0])
    for name, key in [("A", "a"), ("B", "b"), ("C", "c"), ("static_gain", "static_gain")]:
        expected = np.array(cli[key])
        np.testing.assert_allclose(lin[name], expected, rtol=0, atol=1e-12 * np.abs(expected).max(),
                                   err_msg=name)
    np.testing.assert_allclose(lin["x0"], cli["q"] + cli["qd"], rtol=0, atol=1e-14)
    poles = np.array([complex(p["re"], p["im"]) for p in cli["poles"]])
    assert lin["poles"].dtype == np.complex128
    np.testing.assert_allclose(lin["poles"], poles, rtol=1e-12)
    assert lin["about"] == "equilibrium" and lin["unstable_poles"] == 0
    assert lin["A"].shape == (56, 56) and lin["B"].shape == (56, 6) and lin["C"].shape == (3, 56)
    np.testing.assert_array_equal(lin["D"], np.zeros((3, 6)))


def accelerations_fd(robot, q, qd, u, h=1e-4):
    """Central differences of [q̇; q̈(q, q̇, u)] in x = [q; q̇] and in u. Each q̈ is a solve with M
    (IV-A's order-10 basis makes it ill-conditioned), so its rounding grows in the difference as
    1/h: at h = 1e-4 (relative) these differences are good to ~5e-7 of ‖A‖ on IV-A, at 1e-6 only
    to ~7e-5 (measured). `linearize` differences the residual before the solve, and is not
    affected."""
    n = len(q)

    def f(x, uu):
        return np.concatenate([x[n:], robot.accelerations(x[:n], x[n:], uu)])

    x = np.concatenate([q, qd])
    A = np.empty((2 * n, 2 * n))
    for j in range(2 * n):
        s = h * (1 + abs(x[j]))
        e = np.zeros(2 * n)
        e[j] = s
        A[:, j] = (f(x + e, u) - f(x - e, u)) / (2 * s)
    B = np.empty((2 * n, len(u)))
    for k in range(len(u)):
        e = np.zeros(len(u))
        e[k] = 1e-4
        B[:, k] = (f(x, u + e) - f(x, u - e)) / 2e-4
    return A, B


def test_a_and_b_about_a_moving_state_are_the_derivatives_of_the_accelerations():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    q0 = robot.statics(u=[-3.0]).q
    rng = np.random.default_rng(7)
    q = q0 + 0.02 * np.abs(q0).max() * rng.standard_normal(len(q0))
    qd = 2.0 * np.abs(q0).max() * rng.standard_normal(len(q0))
    u = np.array([-2.5])
    lin = robot.linearize(u=u, q=q, qd=qd)
    assert lin["about"] == "state" and lin["static_gain"] is None
    A, B = accelerations_fd(robot, q, qd, u)
    assert np.linalg.norm(lin["A"] - A) < 2e-6 * np.linalg.norm(A)
    assert np.linalg.norm(lin["B"] - B) < 2e-6 * np.linalg.norm(B)
    np.testing.assert_allclose(lin["xdot"][len(q):], robot.accelerations(q, qd, u), rtol=1e-12)
    # the tip output matrix is the tip Jacobian's translation, rotated to the world
    R = robot.forward(q)["rotation"][-1]
    J = robot.jacobian(q, -1)
    np.testing.assert_allclose(lin["C"][:, :len(q)], R @ J[3:], rtol=0, atol=1e-12 * np.abs(J).max())
    np.testing.assert_array_equal(lin["C"][:, len(q):], 0.0)


def test_output_points_stack_their_position_jacobians_in_c():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    q = robot.statics(u=[-3.0]).q
    fwd = robot.forward(q)
    i = 40  # a computational point inside the rod
    x = float(fwd["x"][i])
    lin = robot.linearize(u=[-3.0], q=q, outputs=[x, 0.1, 0.25])
    n = len(q)
    assert lin["C"].shape == (9, 2 * n)
    np.testing.assert_array_equal(lin["outputs"], [x, 0.1, 0.25])
    np.testing.assert_allclose(lin["output_positions"][0], fwd["position"][i], rtol=0, atol=1e-15)
    J = robot.jacobian(q, i)
    np.testing.assert_allclose(lin["C"][:3, :n], fwd["rotation"][i] @ J[3:], rtol=0,
                               atol=1e-12 * np.abs(J).max())
    # the tip's block is the default output, and one number is one output
    tip = robot.linearize(u=[-3.0], q=q)
    np.testing.assert_array_equal(lin["C"][6:], tip["C"])
    np.testing.assert_array_equal(robot.linearize(u=[-3.0], q=q, outputs=0.25)["C"], tip["C"])
    # between points: central differences of the state's position there, read as an output
    # position of states q ± h e_j
    h = 1e-6
    for j in [0, 5, 17]:
        e = np.zeros(n)
        e[j] = h
        at = [robot.linearize(u=[-3.0], q=q + s * e, outputs=[0.1])["output_positions"][0]
              for s in (1, -1)]
        np.testing.assert_allclose(lin["C"][3:6, j], (at[0] - at[1]) / (2 * h), rtol=0,
                                   atol=1e-6 * np.abs(lin["C"][3:6]).max())
    with pytest.raises(gvsrom.GvsromError, match=r"outputs `0.3`.*within \[0, 0.25\] m"):
        robot.linearize(outputs=[0.1, 0.3])
    with pytest.raises(gvsrom.GvsromError, match="outputs: no abscissa given"):
        robot.linearize(outputs=[])


def test_static_gain_is_the_equilibriums_derivative_in_the_tensions():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    u = np.array([-3.0, 0, 0, -1.0, 0, 0])
    lin = robot.linearize(u=u)
    G = lin["static_gain"]
    h = 0.01
    for k in [0, 3, 4]:
        e = np.zeros(6)
        e[k] = h
        fd = (robot.statics(u + e).tip_position - robot.statics(u - e).tip_position) / (2 * h)
        np.testing.assert_allclose(G[:, k], fd, rtol=0, atol=1e-5 * np.linalg.norm(fd))


@pytest.fixture(scope="module")
def pod_robot(gvsrom_bin, tmp_path_factory):
    ds = tmp_path_factory.mktemp("lin-ds") / "sweep"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:0",
            "--samples", "7", "--out", str(ds))
    assert p.returncode == 0, p.stderr
    model = gvsrom.pod(ds, 2, tmp_path_factory.mktemp("lin-pod") / "model")
    return gvsrom.Scenario.preset("single-tendon").build().with_model(model)


def test_a_reduced_models_linearization_has_2r_states(pod_robot):
    lin = pod_robot.linearize(u=[-3.0])
    assert lin["A"].shape == (4, 4) and lin["B"].shape == (4, 1) and lin["C"].shape == (3, 4)
    # its slow pole near the full model's (2 POD modes hold the first bending mode well)
    full = gvsrom.Scenario.preset("single-tendon").build().linearize(u=[-3.0])
    assert lin["natural_frequency_hz"][0] == pytest.approx(full["natural_frequency_hz"][0], rel=0.05)
    A, B = accelerations_fd(pod_robot, lin["x0"][:2], np.array([0.3, -0.2]), np.array([-3.0]))
    moving = pod_robot.linearize(u=[-3.0], q=lin["x0"][:2], qd=[0.3, -0.2])
    assert np.linalg.norm(moving["A"] - A) < 1e-6 * np.linalg.norm(A)


def test_bad_arguments_are_clear_errors():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match="`qd` without `q`"):
        robot.linearize(qd=np.zeros(robot.n_dof))
    with pytest.raises(gvsrom.GvsromError, match="q"):
        robot.linearize(q=np.zeros(3))
    with pytest.raises(gvsrom.GvsromError, match="density"):
        gvsrom.Scenario.preset("single-tendon").set("material.density", 0.0).build().linearize()


def test_zero_order_hold_predicts_one_held_sample_of_the_nonlinear_simulation():
    # From the equilibrium at u0, tensions u0 ± δu held for one sample h: the simulated state after
    # h (integrator at rtol 1e-8) differs by 2 B_d δu + O(δu³); from a perturbed state x0 ± δx
    # with u0 held, by 2 A_d δx. The central difference removes the quadratic terms. Measured:
    # 2.8e-7 relative for B_d at rtol 1e-6 … 1e-8 (2026-12-06); an Euler step B h is 4e4 × off.
    robot = gvsrom.Scenario.preset("single-tendon").build()
    u0, h = -3.0, 0.02
    lin = robot.linearize(u=[u0], dt=h)
    assert lin["Ad"].shape == (66, 66) and lin["Bd"].shape == (66, 1) and lin["dt"] == h
    assert 0 < lin["spectral_radius"] < 1
    n = robot.n_dof
    q0 = lin["x0"][:n]

    def after(q, qd, u):
        tr = robot.simulate(h, sample_rate=1 / h, input=np.array([[0.0, u]]), q0=q, qd0=qd,
                            rtol=1e-8, atol=1e-11)
        assert tr["t"][-1] == pytest.approx(h)
        return np.concatenate([tr["q"][-1], tr["qd"][-1]])

    du = 0.01
    bd = (after(q0, np.zeros(n), u0 + du) - after(q0, np.zeros(n), u0 - du)) / (2 * du)
    assert np.linalg.norm(lin["Bd"][:, 0] - bd) < 1e-5 * np.linalg.norm(bd)
    # a velocity kick along the first mode's shape
    phi = robot.modes(1, u=[u0])["shape"][0]
    dx = 1e-3 * phi
    ad_dx = (after(q0, dx, u0) - after(q0, -dx, u0)) / 2
    pred = lin["Ad"][:, n:] @ dx
    assert np.linalg.norm(pred - ad_dx) < 1e-5 * np.linalg.norm(ad_dx)


def test_a_bad_sample_time_is_refused_naming_dt():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    for bad in [0.0, -0.01, float("nan"), float("inf"), 1e300]:
        with pytest.raises(gvsrom.GvsromError, match="^dt `"):
            robot.linearize(dt=bad)


@pytest.fixture(scope="module")
def ae_robot(gvsrom_bin, tmp_path_factory):
    ds = tmp_path_factory.mktemp("lin-ae-ds") / "sweep"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:0",
                "--samples", "7", "--out", str(ds))
    assert p.returncode == 0, p.stderr
    model = gvsrom.train(ds, tmp_path_factory.mktemp("lin-ae") / "model", latent=1, hidden_layers=3,
                         epochs=40, patience=0, lbfgs_iterations=20, seed=3)
    return gvsrom.Scenario.preset("single-tendon").build().with_model(model)


def test_an_autoencoders_linearization_is_the_derivative_of_its_accelerations(ae_robot):
    # the decoder's path of the engine (Ψ(q) nonlinear, M(q) varying with the code)
    eq = ae_robot.linearize(u=[-3.0])
    assert eq["A"].shape == (2, 2) and eq["B"].shape == (2, 1)
    q = eq["x0"][:1]
    for qd in [0.0, 0.5]:
        lin = ae_robot.linearize(u=[-3.0], q=q, qd=[qd])
        A, B = accelerations_fd(ae_robot, q, np.array([qd]), np.array([-3.0]))
        assert np.linalg.norm(lin["A"] - A) < 2e-6 * np.linalg.norm(A), (lin["A"], A)
        assert np.linalg.norm(lin["B"] - B) < 2e-6 * np.linalg.norm(B)


# crates/gvsrom-py/examples/lqr_tip.py's Riccati iteration is the tests'
discrete_lqr = load_example("lqr_tip").discrete_lqr


def test_an_lqr_designed_on_the_linearization_damps_the_nonlinear_arm():
    # IV-A at −3 N, its tip kicked at 0.5 m/s along the first mode: a discrete LQR on (Ad, Bd) with
    # the tip position weighted (C), applied every 10 ms to the nonlinear model (`simulate` with
    # the LQR as its `controller`, the tension held over each period), against the tension held
    # at −3 N. Measured over 1 s (2026-12-07): tip error RMS 12.2 → 1.10 mm, at 0.5 s
    # 6.7 mm → 3.8 µm, tensions in [−8.12, −2.81] N (the tendon only pulls). Checked here over
    # the first 0.5 s.
    robot = gvsrom.Scenario.preset("single-tendon").build()
    u0, h, steps = -3.0, 0.01, 50
    lin = robot.linearize(u=[u0], dt=h)
    Ad, Bd, C, x0 = lin["Ad"], lin["Bd"], lin["C"], lin["x0"]
    K = discrete_lqr(Ad, Bd, 1e4 * C.T @ C + 1e-8 * np.eye(len(x0)), np.array([[1e-3]]))
    assert max(abs(np.linalg.eigvals(Ad - Bd @ K))) < lin["spectral_radius"]
    n = robot.n_dof
    phi = robot.modes(1, u=[u0])["shape"][0]
    qd_kick = 0.5 * phi / np.abs(C[:, :n] @ phi).max()
    tip0 = lin["tip_position"]

    def run(control):
        law = lambda t, q, qd: u0 - (K @ (np.concatenate([q, qd]) - x0))[0] if control else u0  # noqa: E731
        tr = robot.simulate(h * steps, sample_rate=1 / h, controller=law, q0=x0[:n], qd0=qd_kick)
        err = np.linalg.norm(tr["tip_position"][1:] - tip0, axis=1)
        return err, tr["u"][:-1, 0]

    open_err, _ = run(False)
    closed_err, us = run(True)
    rms = lambda e: np.sqrt((e ** 2).mean())  # noqa: E731
    assert rms(closed_err) < 0.2 * rms(open_err), (rms(closed_err), rms(open_err))
    assert closed_err[-1] < 0.01 * open_err[-1], (closed_err[-1], open_err[-1])
    assert (us < 0).all(), "the controller asked the tendon to push"


def test_tendon_lengths_as_outputs_add_their_jacobian_rows_and_compliance():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    lin = robot.linearize(tendon_lengths=True)
    q = lin["x0"][: robot.n_dof]
    n, na = robot.n_dof, robot.n_actuators
    assert lin["C"].shape == (3 + na, 2 * n)
    np.testing.assert_array_equal(lin["C"][3:, :n], robot.tendon_length_jacobian(q))
    np.testing.assert_array_equal(lin["C"][3:, n:], 0.0)
    np.testing.assert_allclose(lin["output_tendon_lengths"], robot.tendon_lengths(q), rtol=1e-14)
    # frictionless tendons: the compliance ∂ℓ/∂u is symmetric (Maxwell–Betti)
    g = lin["static_gain"][3:]
    np.testing.assert_allclose(g, g.T, rtol=0, atol=1e-9 * np.abs(g).max())
    # the position rows are the default output's
    np.testing.assert_array_equal(lin["C"][:3], robot.linearize()["C"])
    assert robot.linearize()["output_tendon_lengths"].shape == (0,)
    bare = gvsrom.Scenario.preset("soft-beam").build()
    with pytest.raises(gvsrom.GvsromError, match=r"^tendon_lengths=True: the rod has no tendons"):
        bare.linearize(tendon_lengths=True)


def test_tip_orientation_rows_are_the_tip_angular_jacobian_in_world_axes():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    q = robot.statics(u=[-10.0, 0, 0, -4.0, 0, 0]).q
    n = robot.n_dof
    lin = robot.linearize(u=[-10.0, 0, 0, -4.0, 0, 0], q=q, tip_orientation=True)
    assert lin["C"].shape == (6, 2 * n)
    rot = robot.forward(q)["rotation"][-1]
    np.testing.assert_allclose(lin["output_tip_rotation"], rot, rtol=0, atol=1e-15)
    J = robot.jacobian(q, -1)
    np.testing.assert_allclose(lin["C"][3:, :n], rot @ J[:3], rtol=0, atol=1e-12 * np.abs(J).max())
    # against differences of the tip's rotation: δθ = vee(log(R(q + h e_j) R(q)ᵀ))
    h = 1e-6
    for j in (0, 7, 20):
        e = np.zeros(n)
        e[j] = h
        rp, rm = (robot.forward(q + s * e)["rotation"][-1] for s in (1, -1))
        d = (rp - rm) / (2 * h) @ rot.T  # the skew matrix [δθ]× per unit q_j
        dtheta = np.array([d[2, 1], d[0, 2], d[1, 0]])
        np.testing.assert_allclose(lin["C"][3:, j], dtheta, rtol=0,
                                   atol=1e-6 * np.abs(lin["C"][3:]).max())
    assert robot.linearize()["output_tip_rotation"] is None


def test_the_lqr_example_runs_and_prints_its_table(tmp_path):
    # crates/gvsrom-py/examples/lqr_tip.py, over a tenth of its second (the table's figures are
    # docs/linearize.md's over the full second)
    import subprocess
    import sys
    from pathlib import Path

    script = Path(__file__).parents[1] / "examples" / "lqr_tip.py"
    p = subprocess.run([sys.executable, str(script), str(tmp_path / "lqr"), "--duration", "0.1"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "closed-loop spectral radius 0.858 (open loop 0.966)" in p.stdout, p.stdout
    rows = [line for line in p.stdout.splitlines() if line.startswith("| held") or line.startswith("| lqr")]
    assert len(rows) == 2, p.stdout
    for name in ["held", "lqr"]:
        assert (tmp_path / "lqr" / name / "meta.json").exists()
        assert (tmp_path / "lqr" / f"{name}-figures" / "tip_position.png").exists()
    # the LQR's tension varies (drawn), the held one does not (a note instead)
    assert (tmp_path / "lqr" / "lqr-figures" / "tensions.png").exists()
    assert not (tmp_path / "lqr" / "held-figures" / "tensions.png").exists()
