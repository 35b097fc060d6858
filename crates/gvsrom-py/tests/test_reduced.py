"""A tiny dataset (CLI) → POD and autoencoder (Python) → reduced statics, equal to the CLI's
`statics --model`; the reduced model's quantities checked as the full model's are."""

import json
import os
import signal
import threading

import numpy as np
import pytest

import gvsrom
from conftest import cli_error, cli_statics, run_cli


@pytest.fixture(scope="module")
def dataset(gvsrom_bin, tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "sweep"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:0",
                "--samples", "7", "--out", str(out))
    assert p.returncode == 0, p.stderr
    return out


@pytest.fixture(scope="module")
def pod_model(dataset, tmp_path_factory):
    return gvsrom.pod(dataset, 2, tmp_path_factory.mktemp("pod") / "model")


@pytest.fixture(scope="module")
def ae_model(dataset, tmp_path_factory):
    return gvsrom.train(dataset, tmp_path_factory.mktemp("ae") / "model", latent=1, hidden_layers=3,
                        epochs=40, patience=0, lbfgs_iterations=20, seed=3)


def test_pod_model_loads_with_its_size(pod_model):
    assert (pod_model.kind, pod_model.latent) == ("pod", 2)
    again = gvsrom.load_model(pod_model.path)
    assert (again.kind, again.latent) == ("pod", 2)


@pytest.mark.parametrize("which", ["pod_model", "ae_model"])
def test_reduced_statics_equals_the_cli_with_model(gvsrom_bin, tmp_path, request, which):
    model = request.getfixturevalue(which)
    cli = cli_statics(gvsrom_bin, tmp_path, "single-tendon", "--tension=-3", "--model", str(model.path))
    robot = gvsrom.Scenario.preset("single-tendon").build()
    eq = robot.statics(u=[-3.0], model=model)
    assert eq.n_dof == model.latent
    np.testing.assert_allclose(eq.q, cli["q"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq.tip_position, cli["tip_position"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(eq.strain, cli["strain"], rtol=0, atol=1e-12)
    same = robot.with_model(model).statics(u=[-3.0])
    np.testing.assert_array_equal(same.q, eq.q)


@pytest.mark.parametrize("which", ["pod_model", "ae_model"])
def test_an_attached_model_solves_other_tensions_as_a_scenario_built_with_them(request, which):
    # with_model keeps the attached model: statics(u) starts from its anchors at u without
    # building again, and equals the model passed per call (the scenario built at u and attached)
    model = request.getfixturevalue(which)
    base = gvsrom.Scenario.preset("single-tendon").build()
    robot = base.with_model(model)
    for u in ([-3.0], [-0.7], np.array([-5.25])):
        fast = robot.statics(u=u)
        built = base.statics(u=u, model=model)
        np.testing.assert_array_equal(fast.q, built.q)
        np.testing.assert_array_equal(fast.strain, built.strain)
        assert fast.iterations == built.iterations
    np.testing.assert_array_equal(robot.statics().q, base.statics(model=model).q)


def test_an_attached_model_refuses_tensions_outside_its_training_with_the_cli_message(
        gvsrom_bin, pod_model):
    expected = cli_error(gvsrom_bin, "statics", "single-tendon", "--tension=-20", "--model",
                         str(pod_model.path))
    assert "pass extrapolate=True to use it anyway" in expected
    robot = gvsrom.Scenario.preset("single-tendon").build().with_model(pod_model)
    with pytest.raises(gvsrom.GvsromError) as e:
        robot.statics(u=[-20.0])
    assert str(e.value) == expected


def test_a_combination_of_tensions_training_never_came_near_is_refused_with_the_cli_message(
        gvsrom_bin, tmp_path):
    # six tensions moved together: every tension of [-10, 0, 0, 0, 0, 0] lies in its range, the
    # combination far off the line the model saw
    data = tmp_path / "together"
    p = run_cli(gvsrom_bin, "dataset", "six-tendon-no-gravity", "--sweep", "tendons.*.tension=-10:0",
                "--samples", "11", "--out", str(data))
    assert p.returncode == 0, p.stderr
    model = gvsrom.pod(data, 2, tmp_path / "pod")
    expected = cli_error(gvsrom_bin, "statics", "six-tendon-no-gravity", "--tension=-10,0,0,0,0,0",
                         "--model", str(model.path))
    assert "never came near this combination" in expected
    # the preset's own tensions are that corner: the robot is built on the line
    scenario = gvsrom.Scenario.preset("six-tendon-no-gravity").set("tendons.*.tension", -2.0)
    assert scenario.tensions == [-2.0] * 6
    robot = scenario.build().with_model(model)
    robot.statics(u=[-4.5] * 6)
    with pytest.raises(gvsrom.GvsromError) as e:
        robot.statics(u=[-10.0, 0, 0, 0, 0, 0])
    assert str(e.value) == expected


def test_a_model_refused_for_the_scenarios_tensions_alone_says_how_to_attach_it(pod_model):
    # trained on [-6, 0] N: a scenario holding -20 N is refused, and told to set its tensions
    far = gvsrom.Scenario.preset("single-tendon").set("tendons.*.tension", -20.0)
    with pytest.raises(gvsrom.GvsromError) as e:
        far.build().with_model(pod_model)
    message = str(e.value)
    assert "tendons.0.tension = -20" in message and "extrapolate=True" in message, message
    assert "set tensions inside the training inputs above before attaching it" in message, message
    robot = far.set("tendons.*.tension", -3.0).build().with_model(pod_model)
    assert robot.tensions.tolist() == [-3.0]
    # a scenario outside the training in more than its tensions gets no such advice
    soft = far.set("material.youngs_modulus", 1e5)
    with pytest.raises(gvsrom.GvsromError) as e:
        soft.build().with_model(pod_model)
    assert "material.youngs_modulus" in str(e.value)
    assert "set tensions inside the training" not in str(e.value)


@pytest.mark.parametrize("which", ["pod_model", "ae_model"])
def test_a_batch_on_a_reduced_model_is_its_statics_row_by_row(request, which):
    model = request.getfixturevalue(which)
    robot = gvsrom.Scenario.preset("single-tendon").build().with_model(model)
    U = np.array([[-1.0], [-3.0], [-5.5]])
    batch = robot.statics_batch(U)
    assert batch.q.shape == (3, robot.n_dof)
    for k, u in enumerate(U):
        one = robot.statics(u=u)
        np.testing.assert_array_equal(batch.q[k], one.q)
        np.testing.assert_array_equal(batch.tip_position[k], one.tip_position)
        np.testing.assert_array_equal(batch.strain[k], one.strain)
    # a row outside the training is refused as statics(u) refuses it, named
    with pytest.raises(gvsrom.GvsromError) as one:
        robot.statics(u=[-20.0])
    with pytest.raises(gvsrom.GvsromError) as many:
        robot.statics_batch([[-2.0], [-20.0]])
    assert str(many.value) == "U[1]: " + str(one.value)
    # extrapolating, the rows outside are named in a warning, and solved
    loose = gvsrom.Scenario.preset("single-tendon").build().with_model(model, extrapolate=True)
    with pytest.warns(UserWarning, match=r"rows \[1\] lie outside the model's training"):
        far = loose.statics_batch([[-2.0], [-7.0]])
    with pytest.warns(UserWarning, match="lies outside the training inputs"):
        np.testing.assert_array_equal(far.q[1], loose.statics(u=[-7.0]).q)


def test_reduced_model_quantities_hold_as_the_full_models(ae_model):
    robot = gvsrom.Scenario.preset("single-tendon").build().with_model(ae_model)
    assert robot.n_dof == 1 and robot.model == ae_model.path
    q = robot.statics(u=[-3.0]).q + 0.01
    M = robot.mass_matrix(q)
    assert M.shape == (1, 1) and M[0, 0] > 0
    # the decoder's second derivatives enter ∂R/∂q: compare with central differences
    h = 1e-6
    fd = (robot.statics_residual(q + h, [-3.0]) - robot.statics_residual(q - h, [-3.0])) / (2 * h)
    jac = robot.statics_jacobian(q, [-3.0])
    np.testing.assert_allclose(jac[:, 0], fd, rtol=1e-5, atol=1e-8 * np.abs(jac).max())


def test_a_model_outside_its_training_is_refused_with_the_cli_message(gvsrom_bin, pod_model):
    expected = cli_error(gvsrom_bin, "statics", "single-tendon", "--tension=-20", "--model",
                         str(pod_model.path))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.Scenario.preset("single-tendon").build().statics(u=[-20.0], model=pod_model)
    assert str(e.value) == expected


def test_load_model_of_a_non_model_is_a_value_error(tmp_path):
    with pytest.raises(ValueError):
        gvsrom.load_model(tmp_path)


QUANTITIES = [
    ("forward", lambda r, q, qd: r.forward(q)),
    ("jacobian", lambda r, q, qd: r.jacobian(q)),
    ("point_velocities", lambda r, q, qd: r.point_velocities(q, qd)),
    ("mass_matrix", lambda r, q, qd: r.mass_matrix(q)),
    ("statics_residual", lambda r, q, qd: r.statics_residual(q)),
    ("statics_jacobian", lambda r, q, qd: r.statics_jacobian(q)),
    ("elastic_force", lambda r, q, qd: r.elastic_force(q)),
    ("stiffness_matrix", lambda r, q, qd: r.stiffness_matrix(q)),
    ("damping_force", lambda r, q, qd: r.damping_force(q, qd)),
    ("damping_matrix", lambda r, q, qd: r.damping_matrix(q)),
    ("coriolis_force", lambda r, q, qd: r.coriolis_force(q, qd)),
    ("coriolis_matrix", lambda r, q, qd: r.coriolis_matrix(q, qd)),
    ("external_force", lambda r, q, qd: r.external_force(q)),
    ("actuation_matrix", lambda r, q, qd: r.actuation_matrix(q)),
    ("accelerations", lambda r, q, qd: r.accelerations(q, qd)),
    ("energy", lambda r, q, qd: r.energy(q, qd)),
]


def _flat(value):
    """A quantity's values as one array (dicts of arrays or numbers in key order)."""
    if isinstance(value, dict):
        return np.concatenate([_flat(value[k]) for k in sorted(value)])
    return np.asarray(value, dtype=float).ravel()


@pytest.mark.parametrize("reduced", [False, True])
def test_quantities_do_not_depend_on_the_calls_before_them(ae_model, reduced):
    # a robot keeps its model's workspace between calls: every quantity, asked after all the
    # others at other states, must be bit for bit what a new robot's first call gives
    base = gvsrom.Scenario.preset("single-tendon").build()
    make = (lambda: base.with_model(ae_model)) if reduced else (lambda: base)
    robot = make()
    q0 = robot.statics(u=[-3.0]).q
    rng = np.random.default_rng(5)
    states = [(q0 + 0.02 * rng.standard_normal(robot.n_dof), rng.standard_normal(robot.n_dof))
              for _ in range(3)]
    for name, f in QUANTITIES:
        for q, qd in states:
            f(robot, q, qd)
    for name, f in QUANTITIES:
        for q, qd in states:
            first = _flat(f(make(), q, qd))
            again = _flat(f(robot, q, qd))
            np.testing.assert_array_equal(again, first, err_msg=f"{name} after other calls")


def test_pod_encode_decode_is_the_projection_onto_the_stored_modes(dataset, pod_model):
    x = gvsrom.load_dataset(dataset).strain
    v = pod_model.arrays["modes"]
    assert pod_model.features == x.shape[1] == v.shape[0]
    q = pod_model.encode(x)
    np.testing.assert_allclose(q, x @ v, rtol=0, atol=1e-12 * np.abs(x).max())
    np.testing.assert_allclose(pod_model.decode(q), q @ v.T, rtol=0, atol=1e-12 * np.abs(x).max())
    np.testing.assert_array_equal(pod_model.reconstruct(x), pod_model.decode(q))
    # one snapshot in, one out: the dimensions follow the input
    assert pod_model.encode(x[3]).shape == (2,)
    assert pod_model.decode(q[3]).shape == (x.shape[1],)


def test_energy_pod_encodes_by_the_projection_in_its_norm(dataset, pod_model, tmp_path):
    x = gvsrom.load_dataset(dataset).strain
    model = gvsrom.pod(dataset, 2, tmp_path / "energy", norm="energy")
    assert model.meta["pod_norm"] == "energy"
    v, w = model.arrays["modes"], model.arrays["norm_weights"]
    assert w.shape == (x.shape[1],) and (w > 0).all()
    np.testing.assert_allclose(v.T @ (w[:, None] * v), np.eye(2), atol=1e-10)
    q = model.encode(x)
    np.testing.assert_allclose(q, (x * w) @ v, rtol=0, atol=1e-10 * np.abs(q).max())
    # the closer fit in the energy norm than the plain POD's, the looser in the plain norm
    def errors(m):
        d = m.reconstruct(x) - x
        return (w * d * d).sum(), (d * d).sum()
    (energy_w, energy_plain), (plain_w, plain_plain) = errors(model), errors(pod_model)
    assert energy_w < plain_w and plain_plain < energy_plain
    with pytest.raises(gvsrom.GvsromError, match="invalid `norm`: `kinetic` .*plain, energy"):
        gvsrom.pod(dataset, 2, tmp_path / "bad", norm="kinetic")
    assert not (tmp_path / "bad").exists()


def test_autoencoder_reconstruction_is_its_network_from_the_stored_weights(dataset, ae_model):
    x = gvsrom.load_dataset(dataset).strain
    a = ae_model.arrays

    def mlp(prefix, y):
        k = 0
        while f"{prefix}.{k}.weight" in a:
            y = y @ a[f"{prefix}.{k}.weight"].T + a[f"{prefix}.{k}.bias"]
            if f"{prefix}.{k + 1}.weight" in a:
                y = np.tanh(y)
            k += 1
        return y

    mu, s = a["scaling.mean"], a["scaling.scale"]
    z = mlp("encoder", (x - mu) / s)
    np.testing.assert_allclose(ae_model.encode(x), z, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(ae_model.reconstruct(x), mlp("decoder", z) * s + mu,
                               rtol=1e-12, atol=1e-12 * np.abs(x).max())


def test_codes_far_outside_the_training_encodings_are_refused_unless_extrapolating(pod_model):
    lo, hi = pod_model.latent_range[0]
    far = np.array([hi + 2 * (hi - lo), 0.5 * sum(pod_model.latent_range[1])])
    with pytest.raises(gvsrom.GvsromError, match=r"q_r\[0\].*far outside"):
        pod_model.decode(far)
    assert pod_model.decode(far, extrapolate=True).shape == (pod_model.features,)
    # a huge code is named in exponent form, not in 300 digits
    with pytest.raises(gvsrom.GvsromError, match=r"q_r\[0\] = 1e300 lies far outside") as e:
        pod_model.decode(np.array([1e300, 0.0]))
    assert len(str(e.value)) < 400
    with pytest.raises(gvsrom.GvsromError, match=r"`strain` has shape \(5,\)"):
        pod_model.encode(np.zeros(5))
    bad = np.zeros((2, pod_model.features))
    bad[1, 1] = np.nan
    with pytest.raises(gvsrom.GvsromError, match="row 1, entry 1 is NaN"):
        pod_model.encode(bad)


def test_a_snapshot_far_larger_than_any_trained_is_refused_by_the_encoder(dataset, ae_model,
                                                                          pod_model):
    # A tanh encoder saturates on a snapshot 1000× a training one and returns a code inside its
    # training encodings, so the code cannot tell; the snapshot's norm against the largest
    # training snapshot's (recorded in the model) does.
    x = gvsrom.load_dataset(dataset).strain
    norms = np.linalg.norm(x, axis=1)
    largest = x[np.argmax(norms)][None, :]
    big = 1000 * largest
    assert ae_model.meta["snapshot_norm_max"] == pytest.approx(norms.max(), rel=1e-12)
    lo, hi = ae_model.latent_range[0]
    code = ae_model.encode(big, extrapolate=True)[0, 0]
    assert lo - 0.5 * (hi - lo) <= code <= hi + 0.5 * (hi - lo), "the code alone looks ordinary"
    for model in (ae_model, pod_model):
        for snapshot in (big, np.full((1, model.features), 1e300)):
            with pytest.raises(gvsrom.GvsromError,
                               match=r"row 0: the snapshot's norm ‖x‖ = .*× the largest training "
                                     r"snapshot's .*accepted: ‖x‖ ≤ 2 × that, or "
                                     r"extrapolate=True$"):
                model.reconstruct(snapshot)
    # within the margin it is encoded as before
    np.testing.assert_array_equal(ae_model.encode(1.9 * largest),
                                  ae_model.encode(1.9 * largest, extrapolate=True))


def test_a_reduced_run_starts_inside_the_training_encodings_but_not_far_outside_them(ae_model):
    # q0 is in the reduced model's coordinates: a code inside the autoencoder's training encodings
    # is a valid start (the run's first sample is that code), one far outside them is refused — its
    # decoder would extrapolate (a POD basis is linear: only its inputs are bounded)
    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -3.0).build()
    reduced = robot.with_model(ae_model)
    lo, hi = ae_model.latent_range[0]
    inside = np.array([0.5 * (lo + hi)])
    tr = reduced.simulate(0.02, sample_rate=100, q0=inside)
    np.testing.assert_array_equal(tr["q"][0], inside)
    assert tr["q"].shape == (3, 1)
    with pytest.raises(gvsrom.GvsromError, match=r"q0.*q_r\[0\].*far outside"):
        reduced.simulate(0.02, q0=np.array([hi + 2 * (hi - lo)]))
    with pytest.raises(gvsrom.GvsromError, match=r"q0.*2 values given: expected 1.*reduced"):
        reduced.simulate(0.02, q0=np.zeros(2))
    # the model quantities at such a code say so too, rather than return the saturated decoder's
    # numbers (they once did), and answer when attached with extrapolate=True
    far = np.array([hi + 2 * (hi - lo)])
    for quantity in (reduced.mass_matrix, reduced.elastic_force, reduced.forward, reduced.statics_residual):
        with pytest.raises(gvsrom.GvsromError, match=r"`q`: q_r\[0\].*far outside.*extrapolate=True"):
            quantity(far)
    np.testing.assert_array_equal(reduced.mass_matrix(inside), reduced.mass_matrix(inside))
    bold = robot.with_model(ae_model, extrapolate=True)
    assert np.isfinite(bold.mass_matrix(far)).all()


def test_a_reduced_run_checks_each_input_signal_against_the_training_tensions(pod_model):
    # the model was trained on tensions in [-6, 0] N: a signal inside runs (twice: the scenario
    # built for signals is kept between runs), one that leaves the range is refused, and the next
    # inside one still runs — each run checks its own signal
    robot = gvsrom.Scenario.preset("single-tendon").build().with_model(pod_model)
    inside = np.array([[0.0, -2.0], [0.01, -5.0]])
    first = robot.simulate(0.02, sample_rate=100, input=inside)
    again = robot.simulate(0.02, sample_rate=100, input=inside)
    np.testing.assert_array_equal(first["q"], again["q"])
    with pytest.raises(gvsrom.GvsromError, match="not trained for this input"):
        robot.simulate(0.02, sample_rate=100, input=np.array([[0.0, -2.0], [0.01, -20.0]]))
    np.testing.assert_array_equal(robot.simulate(0.02, sample_rate=100, input=inside)["q"], first["q"])


def test_several_datasets_make_one_model_of_their_stacked_snapshots(gvsrom_bin, dataset, tmp_path):
    # a second dataset of the same scenario: POD of both is the POD of the stacked snapshots, whose
    # squared singular values are the eigenvalues of X_Aᵀ X_A + X_Bᵀ X_B (numpy's eigvalsh)
    other = tmp_path / "random"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--random", "tendons.0.tension=-2:2.5",
                "--samples", "5", "--seed", "2", "--out", str(other))
    assert p.returncode == 0, p.stderr
    a, b = gvsrom.load_dataset(dataset), gvsrom.load_dataset(other)
    xa, xb = a.strain.reshape(len(a.strain), -1), b.strain.reshape(len(b.strain), -1)
    model = gvsrom.pod([dataset, str(other)], 3, tmp_path / "pod")
    eig = np.sort(np.linalg.eigvalsh(xa.T @ xa + xb.T @ xb))[::-1][:3]
    sigma = model.arrays["singular_values"][:3]
    np.testing.assert_allclose(sigma**2, eig, rtol=0, atol=1e-9 * eig[0])
    assert model.meta["more_datasets"][0]["rows"] == 5
    lo = min(a.inputs.min(), b.inputs.min())
    hi = max(a.inputs.max(), b.inputs.max())
    assert model.meta["input_range"][0]["min"] == lo and model.meta["input_range"][0]["max"] == hi
    ae = gvsrom.train((a, other), tmp_path / "ae", latent=1, hidden_layers=3, epochs=5,
                      lbfgs_iterations=0)
    assert ae.meta["dataset"]["rows"] == 7 and ae.meta["more_datasets"][0]["rows"] == 5
    with pytest.raises(TypeError, match=r"invalid `dataset`: got a int"):
        gvsrom.pod(3, 2, tmp_path / "never")
    with pytest.raises(TypeError, match=r"invalid `dataset`: got a float"):
        gvsrom.pod([dataset, 2.5], 2, tmp_path / "never")


def test_datasets_of_other_physics_are_refused_naming_the_field(gvsrom_bin, dataset, tmp_path):
    other = tmp_path / "stiffer"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--set", "material.youngs_modulus=2e6",
                "--random", "tendons.0.tension=-2:0", "--samples", "3", "--out", str(other))
    assert p.returncode == 0, p.stderr
    with pytest.raises(ValueError, match=r"invalid `dataset`.*material\.youngs_modulus"):
        gvsrom.pod([dataset, other], 2, tmp_path / "pod")


def test_reconstruction_of_its_own_data_is_what_pod_discards(dataset, pod_model, tmp_path, gvsrom_bin):
    # POD-2 on its own snapshots: the squared error is the energy of the discarded singular values
    ds = gvsrom.load_dataset(dataset)
    x = ds.strain.reshape(len(ds.strain), -1)
    sigma = pod_model.arrays["singular_values"]
    r = pod_model.reconstruction(ds)
    assert r.rows == len(x) and r.outside == 0
    assert (r.unseen_inputs, r.inputs_note, r.other_physics) == (0, None, None)
    np.testing.assert_allclose(r.rmse, np.sqrt((sigma[2:] ** 2).sum() / x.size), rtol=1e-9)
    np.testing.assert_allclose(r.relative, np.sqrt((sigma[2:] ** 2).sum() / (sigma**2).sum()),
                               rtol=1e-9)
    norms = np.linalg.norm(x, axis=1)
    assert r.largest_norm == pytest.approx(norms.max(), rel=1e-12)
    row, ratio, norm = r.worst
    assert norm == pytest.approx(norms[row], rel=1e-12) and 0 < ratio < 1
    # the directory gives the same numbers; another layout is refused naming both
    same = pod_model.reconstruction(str(dataset))
    assert (same.rmse, same.worst) == (r.rmse, r.worst)
    beam = tmp_path / "beam"
    p = run_cli(gvsrom_bin, "dataset", "soft-beam", "--random", "loads.distributed.0.magnitude=-1:1",
                "--samples", "2", "--out", str(beam))
    assert p.returncode == 0, p.stderr
    with pytest.raises(ValueError, match=r"invalid `dataset`.*soft-beam.*single-tendon"):
        pod_model.reconstruction(beam)
    # tensions beyond the training's [-6, 0] N on a stiffer rod: the inputs and the physics named
    beyond = tmp_path / "beyond"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-9:-3",
                "--samples", "3", "--set", "material.youngs_modulus=2e6", "--out", str(beyond))
    assert p.returncode == 0, p.stderr
    r = pod_model.reconstruction(beyond)
    assert r.unseen_inputs == 1 and r.inputs_note is None, r
    assert r.other_physics.startswith("material.youngs_modulus is 2000000.0 in the dataset's"), r


def test_a_training_from_a_model_continues_it_and_keeps_its_architecture(dataset, ae_model, tmp_path):
    # no latent, hidden_layers or seed given: the start model's (r = 1, 3 hidden layers, seed 3).
    # 200 epochs: in 40 at the default rate Adam's first steps climb out of the polished start's
    # minimum and never beat it, and only the L-BFGS polish from the start's weights gains (10 %)
    more = gvsrom.train(dataset, tmp_path / "more", epochs=200, patience=0, lbfgs_iterations=20,
                        init=ae_model)
    a, b = ae_model.meta["training"], more.meta["training"]
    assert more.latent == 1 and b["hidden_layers"] == 3 and b["loss"] == a["loss"]
    assert (b["seed"], b["validation_fraction"]) == (3, a["validation_fraction"])
    # from random weights the same seed would repeat the start model's training exactly
    assert b["final_train_loss"] < 0.9 * a["final_train_loss"], (a, b)
    assert more.meta["provenance"]["model"]["path"] == str(ae_model.path)
    with pytest.raises(gvsrom.GvsromError, match=r"latent.*2, but the start model.*has 1"):
        gvsrom.train(dataset, tmp_path / "never", latent=2, epochs=5, init=str(ae_model.path))
    with pytest.raises(TypeError, match=r"invalid `init`: got a int"):
        gvsrom.train(dataset, tmp_path / "never", epochs=5, init=3)


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_reaches_python_when_the_stopped_training_then_fails(dataset, ae_model, tmp_path,
                                                                     sigint_raises):
    # at this rate the weights never move, so no epoch beats the start model's validation loss and
    # the run Ctrl-C stops ends in "not improved on": the KeyboardInterrupt, taken from Python's
    # queue during the run, must still be raised
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        gvsrom.train(dataset, tmp_path / "stopped", init=ae_model, epochs=10**7, learning_rate=1e-300,
                     patience=0, lbfgs_iterations=0, validation_fraction=0.3)
    assert not (tmp_path / "stopped").exists()


def test_meta_is_the_verified_meta_json(dataset, ae_model):
    # the dict is the file's content as the loader checked it (not a second, unchecked read)
    for loaded, d in ((gvsrom.load_model(ae_model.path), ae_model.path),
                      (gvsrom.load_dataset(dataset), dataset)):
        with open(os.path.join(d, "meta.json")) as f:
            assert loaded.meta == json.load(f)

def test_meta_tells_adam_epochs_from_fine_tuning_iterations(ae_model):
    # 40 Adam epochs without early stopping (patience 0), then at most 20 L-BFGS iterations
    t = ae_model.meta["training"]
    fine = t["fine_tune_iterations_run"]
    assert 1 <= fine <= 20, t
    assert t["epochs_run"] - fine == 40, t


def _cli_defaults(gvsrom_bin, command):
    """`gvsrom COMMAND --help`'s options with a plain `[default: V]`: option name → V."""
    p = run_cli(gvsrom_bin, command, "--help")
    assert p.returncode == 0, p.stderr
    defaults, option = {}, None
    for line in p.stdout.splitlines():
        s = line.strip()
        if s.startswith("--"):
            option = s.split()[0].lstrip("-")
        elif option and s.startswith("[default: ") and s.endswith("]"):
            defaults[option] = s[len("[default: "):-1]
    return defaults


@pytest.mark.parametrize("command", ["train", "pod"])
def test_the_python_defaults_are_the_command_lines(gvsrom_bin, command):
    import inspect

    cli = _cli_defaults(gvsrom_bin, command)
    params = inspect.signature(getattr(gvsrom, command)).parameters
    compared = []
    for name, p in params.items():
        option = name.rstrip("_").replace("_", "-")
        if option not in cli or p.default is inspect.Parameter.empty:
            continue
        value = cli[option]
        if isinstance(p.default, bool) or isinstance(p.default, str):
            assert str(p.default) == value, (name, p.default, value)
        else:
            assert p.default == type(p.default)(float(value)), (name, p.default, value)
        compared.append(name)
    # every plain default of the command line has its Python counterpart (not a vacuous test)
    assert len(compared) == len(cli), (sorted(compared), sorted(cli))


def test_a_failed_reduced_run_raises_with_the_samples_it_computed(ae_model):
    # a step to the largest trained tension from rest: the undamped-enough swing overshoots the
    # training encodings and the run stops there; the samples before are on the exception, as
    # simulate returns them
    reduced = (gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -6.0).build()
               .with_model(ae_model))
    with pytest.raises(gvsrom.IntegrationError, match=r"left the training region at t = ([0-9.]+) s"
                       r".* \((\d+) samples computed: the exception's `trajectory`\)") as e:
        reduced.simulate(0.5, sample_rate=100)
    assert isinstance(e.value, gvsrom.GvsromError)
    tr = e.value.trajectory
    k = len(tr["t"])
    assert f"({k} samples computed" in str(e.value)
    assert 0 < k < 51
    t_stop = float(str(e.value).split("at t = ")[1].split(" s")[0])
    assert tr["t"][-1] <= t_stop
    np.testing.assert_allclose(np.diff(tr["t"]), 0.01, rtol=1e-12)
    assert tr["q"].shape == (k, 1) and tr["tip_position"].shape == (k, 3)
    assert np.isfinite(tr["q"]).all()
    lo, hi = ae_model.latent_range[0]
    span = hi - lo
    assert (tr["q"][:, 0] >= lo - span).all() and (tr["q"][:, 0] <= hi + span).all()
    assert "energy_balance" not in tr
    assert tr["reason"] == "the reduced model left its training region"



def test_a_reduced_model_runs_a_tendon_driven_by_displacement(pod_model):
    # the thread of the IV-A arm (EA = 200 N) wound in by 4 mm: its tension found as the run goes
    # (−3.2 N at the straight start, inside the sweep's [−6, 0]) settles, with the tip, on the
    # reduced statics drive; 12 mm pulls −9.6 N at once, outside: the run stops there, or with
    # extrapolate goes on and says so
    driven = (gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", 0)
              .set("tendons.0.displacement", 0.004).set("tendons.0.axial_stiffness", 200.0).build())
    reduced = driven.with_model(pod_model)
    eq = reduced.statics()
    run = reduced.simulate(4.0, sample_rate=10)
    assert run["q"].shape == (41, 2)
    rest = driven.tendon_rest_lengths[0]
    assert run["u"][0, 0] == pytest.approx(-0.004 * 200.0 / rest, rel=1e-9)
    assert run["u"][-1, 0] == pytest.approx(eq.u[0], rel=1e-4)
    np.testing.assert_allclose(run["tip_position"][-1], eq.tip_position, atol=1e-5 * 0.25)
    assert not any("tension" in s for s in run["model_extrapolated"])
    with pytest.raises(gvsrom.IntegrationError, match=r"at t = 0\.0000 s the tensions found from the threads .* outside the model's training: "
                       r"tendons\.0\.tension = -9\.59.* \(found\) lies outside the training inputs \[-6, 0\]"):
        reduced.simulate(0.2, input=lambda t: [0.012])
    # the stepper refuses such a step before the run sees it, or with extrapolate warns of it
    stepper = reduced.stepper(0.05)
    with pytest.raises(gvsrom.GvsromError, match=r"`step\(u\)` at t = 0 s: the tensions found from the threads"
                       r".*tendons\.0\.tension = -9\.59.*the run goes on from there"):
        stepper.step([0.012])
    q, _ = stepper.step([0.004])
    assert stepper.t == pytest.approx(0.05)
    stepper.close()
    loose = driven.with_model(pod_model, extrapolate=True)
    with pytest.warns(UserWarning, match=r"at t = 0 s the tensions found from the threads.*-9\.59"):
        loose.stepper(0.05).step([0.012])
    far = loose.simulate(0.2, input=lambda t: [0.012])
    assert any("(found) lies outside the training inputs [-6, 0]" in s for s in far["model_extrapolated"])
    # in statics too: 20 mm of the inextensible tendon needs −8.7 N, answered with extrapolate
    # and said so
    inextensible = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.warns(UserWarning, match=r"the tensions the displacements need: tendons\.0\.tension = -8\."):
        eq = inextensible.with_model(pod_model, extrapolate=True).statics(displacement=[0.02])
    assert eq.u[0] < -6.0
    assert any(s.startswith("the tensions the displacements need: tendons.0.tension = -8.")
               for s in eq.model_extrapolated), eq.model_extrapolated
    # the same drive given by the scenario, solved with no arguments, says so too
    scenario_driven = (gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", 0)
                       .set("tendons.0.displacement", 0.02).build())
    again = scenario_driven.with_model(pod_model, extrapolate=True).statics()
    assert again.u[0] == pytest.approx(eq.u[0], rel=1e-9)
    assert again.model_extrapolated == eq.model_extrapolated


def test_a_pickled_robot_is_the_same_robot_in_another_process(dataset, pod_model, tmp_path):
    # multiprocessing pickles what it sends: a robot is rebuilt from its scenario and its model's
    # directory; in a worker process it solves as it does here
    import concurrent.futures
    import multiprocessing
    import pickle

    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -2.0).build()
    reduced = robot.with_model(pod_model)
    for r in (robot, reduced):
        again = pickle.loads(pickle.dumps(r))
        assert repr(again) == repr(r)
        np.testing.assert_array_equal(again.statics().q, r.statics().q)
    ctx = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(1, mp_context=ctx) as pool:
        q = pool.submit(_reduced_statics_q, reduced).result(timeout=120)
    np.testing.assert_array_equal(q, reduced.statics().q)
    # a model directory written again between pickling and unpickling is refused, as with_model
    # refuses one changed since load_model
    copy = gvsrom.pod(dataset, 1, tmp_path / "m")
    blob = pickle.dumps(robot.with_model(copy))
    gvsrom.pod(dataset, 2, tmp_path / "m", force=True)
    with pytest.raises(gvsrom.GvsromError, match="changed since"):
        pickle.loads(blob)


def _reduced_statics_q(robot):
    return robot.statics().q


def test_a_controller_on_a_reduced_model_is_checked_against_its_training(pod_model):
    robot = gvsrom.Scenario.preset("single-tendon").build().with_model(pod_model)
    # inside the training tensions (−6 … 0 N): the closed loop runs in the model's coordinates
    seen = []

    def law(t, q, qd):
        seen.append(q.shape)
        return min(max(-3.0 - 0.05 * q[0], -5.5), -0.5)

    tr = robot.simulate(0.1, sample_rate=100, controller=law)
    assert tr["q"].shape == (11, 2) and set(seen) == {(2,)}, (tr["q"].shape, set(seen))
    # a tension far outside them stops the run with the model's verdict, naming the controller
    with pytest.raises(gvsrom.GvsromError, match=r"tendons.0.tension reaches -20 at t = 0.05 s, "
                                                 r"outside the training inputs \[-6, 0\]"):
        robot.simulate(0.1, sample_rate=100, controller=lambda t, q, qd: -3.0 if t < 0.05 else -20.0)
