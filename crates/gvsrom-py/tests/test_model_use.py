"""A reduced model used outside what it was trained on says so everywhere a Python caller reaches
it (a callable input, the model quantities, the results); a loaded model or dataset is the one
used, never a directory written again since; a state no rod holds is refused, not answered with
NaN."""

import os
import warnings

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    return gvsrom.dataset("single-tendon", tmp_path_factory.mktemp("ds") / "sweep",
                          sweep="tendons.0.tension=-6:0", samples=7)


@pytest.fixture(scope="module")
def pod(dataset, tmp_path_factory):
    return gvsrom.pod(dataset, 2, tmp_path_factory.mktemp("pod") / "model")


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def outside_message(excinfo):
    return str(excinfo.value)


def test_a_callable_input_outside_the_training_is_refused_as_rows_are(robot, pod):
    rom = robot.with_model(pod)
    with pytest.raises(gvsrom.GvsromError) as rows:
        rom.simulate(0.05, input=[[0.0, -30.0]])
    with pytest.raises(gvsrom.GvsromError) as function:
        rom.simulate(0.05, input=lambda t: -30.0)
    # the same verdict: the tension, its value, the time and the training range
    for e in (rows, function):
        assert "tendons.0.tension reaches -30 at t = 0 s, outside the training inputs [-6, 0]" \
            in str(e.value), str(e.value)
    # inside, it runs and nothing is marked
    run = rom.simulate(0.05, input=lambda t: -3.0)
    assert run["model_extrapolated"] == []


def test_a_callable_input_that_leaves_the_training_later_is_refused_there(robot, pod):
    rom = robot.with_model(pod)
    with pytest.raises(gvsrom.GvsromError, match=r"reaches -20 at t = 0\.0[2-3]"):
        rom.simulate(0.05, input=lambda t: -3.0 if t < 0.02 else -20.0)


def test_an_extrapolating_model_marks_every_result(robot, pod):
    loose = gvsrom.load_model(pod.path, extrapolate=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = robot.with_model(loose).simulate(0.05, input=lambda t: -30.0)
        eq = robot.statics(u=-30.0, model=loose)
        modes = robot.with_model(loose).modes(2, u=-30.0)
    assert run["model_extrapolated"] and "-30" in run["model_extrapolated"][0]
    assert eq.model_extrapolated == ["tendons.0.tension = -30 lies outside the training inputs [-6, 0]"]
    assert eq.to_dict()["model_extrapolated"] == eq.model_extrapolated
    assert modes["model_extrapolated"] == eq.model_extrapolated
    # warned in Python's spelling, not the command line's
    messages = [str(w.message) for w in caught]
    assert messages and all("--extrapolate" not in m for m in messages), messages
    assert any("extrapolate=True" in m for m in messages), messages
    # a full-model solve is never marked
    assert robot.statics(u=-30.0).model_extrapolated == []


def test_with_model_takes_the_models_own_extrapolate_unless_told(robot, pod):
    loose = gvsrom.load_model(pod.path, extrapolate=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert robot.with_model(loose).statics(u=-30.0).model_extrapolated
    with pytest.raises(gvsrom.GvsromError, match="extrapolate=True"):
        robot.with_model(loose, extrapolate=False).statics(u=-30.0)


def test_model_quantities_refuse_tensions_outside_the_training(robot, pod):
    rom = robot.with_model(pod)
    rest = pod.rest
    for f in (lambda u: rom.accelerations(rest, np.zeros(2), u=u),
              lambda u: rom.statics_residual(rest, u=u),
              lambda u: rom.statics_jacobian(rest, u=u)):
        with pytest.raises(gvsrom.GvsromError, match=r"-30 lies outside the training inputs \[-6, 0\]"):
            f(-30.0)
        assert np.all(np.isfinite(f(-3.0)))


def test_a_model_directory_written_again_is_refused_not_read_silently(tmp_path, dataset, robot):
    path = tmp_path / "model"
    loaded = gvsrom.pod(dataset, 2, path)
    gvsrom.pod(dataset, 1, path, force=True)
    with pytest.raises(gvsrom.GvsromError, match="changed since `load_model` read it"):
        robot.with_model(loaded)
    with pytest.raises(gvsrom.GvsromError, match="changed since `load_model` read it"):
        robot.statics(model=loaded)
    assert robot.with_model(gvsrom.load_model(path)).n_dof == 1


def test_a_dataset_directory_written_again_is_refused_not_read_silently(tmp_path):
    path = tmp_path / "ds"
    loaded = gvsrom.dataset("single-tendon", path, sweep="tendons.0.tension=-6:0", samples=5)
    gvsrom.dataset("single-tendon", path, sweep="tendons.0.tension=-6:0", samples=4, force=True)
    for f in (lambda: gvsrom.pod(loaded, 1, tmp_path / "pod"),
              lambda: gvsrom.pod([loaded], 1, tmp_path / "pod")):
        with pytest.raises(gvsrom.GvsromError, match="no longer holds what `load_dataset` read"):
            f()
    assert not (tmp_path / "pod").exists()
    assert len(gvsrom.load_dataset(path)) == 4


def test_a_model_loaded_by_a_relative_path_survives_a_change_of_directory(tmp_path, dataset, robot,
                                                                          monkeypatch):
    gvsrom.pod(dataset, 2, tmp_path / "model")
    monkeypatch.chdir(tmp_path)
    loaded = gvsrom.load_model("model")
    assert loaded.path == tmp_path / "model"
    monkeypatch.chdir(os.path.dirname(tmp_path))
    assert robot.with_model(loaded).n_dof == 2


def test_a_state_no_rod_holds_is_refused_not_answered_with_nan(robot):
    n = robot.n_dof
    q = np.zeros(n)
    q[0] = 1e24
    for f in (robot.mass_matrix, robot.elastic_force, robot.forward, robot.external_force,
              lambda q: robot.position_jacobian(q, 0.1), robot.tendon_lengths,
              robot.tendon_length_jacobian):
        with pytest.raises(gvsrom.GvsromError, match="`q` is no state of an elastic rod"):
            f(q)
    fast = np.full(n, 1e200)
    # quadratic in q̇: overflows (linear ones, as the point velocities or C(q, q̇), stay finite)
    for f in (robot.coriolis_force, robot.accelerations, lambda q, qd: robot.energy(q, qd)):
        with pytest.raises(gvsrom.GvsromError, match="`qd`"):
            f(np.zeros(n), fast)
    # a large but physical state is answered
    q[0] = 0.5
    assert np.all(np.isfinite(robot.mass_matrix(q)))


def test_a_pod_run_that_leaves_its_training_encodings_says_so_once(robot, pod):
    # A POD basis is linear and defined everywhere, so the run goes on; but no snapshot checked
    # the motion there, and the result (and a warning) says where it left them.
    reduced = robot.with_model(pod)
    lo, hi = pod.latent_range[0]
    inside = np.array([0.5 * (lo + hi), 0.5 * sum(pod.latent_range[1])])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # (a model of equilibria says so in every motion: its own test, below)
        warnings.filterwarnings("ignore", message=".*made from equilibria only")
        tr = reduced.simulate(0.02, sample_rate=100, q0=inside)
    assert tr["model_extrapolated"] == []
    far = inside.copy()
    far[0] = hi + 2 * (hi - lo)
    with pytest.warns(UserWarning, match=r"left the training encodings at t = 0\.0000 s: q_r\[0\]"):
        tr = reduced.simulate(0.02, sample_rate=100, q0=far)
    notes = [n for n in tr["model_extrapolated"] if "left the training encodings" in n]
    assert len(notes) == 1 and "its basis is linear" in notes[0], tr["model_extrapolated"]
    assert tr["t"][-1] == pytest.approx(0.02)


def test_pod_quantities_far_outside_the_data_say_so_and_answer(robot, pod):
    # A POD basis is linear: its quantities are defined everywhere and answered, but far from
    # the snapshots a UserWarning says no snapshot checked them (as a simulation notes it)
    reduced = robot.with_model(pod)
    inside = np.array([0.5 * sum(r) for r in pod.latent_range])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        reduced.mass_matrix(inside)
        reduced.tendon_lengths(inside)
    lo, hi = pod.latent_range[0]
    far = inside.copy()
    far[0] = hi + 2 * (hi - lo)
    for f in (reduced.mass_matrix, reduced.tendon_lengths, reduced.elastic_force):
        with pytest.warns(UserWarning, match=r"`q`: q_r\[0\] = .* lies far outside the range of the training data.*no snapshot checked"):
            assert np.all(np.isfinite(f(far)))
    # attached with extrapolate=True the user said so: no warning
    loose = robot.with_model(pod, extrapolate=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        loose.mass_matrix(far)


def test_a_results_strains_become_the_datasets_snapshot_rows_and_encode(robot, dataset, pod):
    # a dataset row is ξ − ξ* of the basis's components, point-major: `snapshot` of the statics'
    # absolute strains under the same tension gives it (to the solver's tolerance)
    ds = dataset
    for k in (0, 3, 6):
        eq = robot.statics(u=ds.inputs[k])
        row = robot.snapshot(eq.strain)
        assert row.shape == (ds.strain.shape[1],)
        np.testing.assert_allclose(row, ds.strain[k], rtol=0, atol=1e-7 * np.abs(ds.strain[k]).max())
    # the layout spelled out independently: elongation is 1 at rest, so its snapshot value is ξ₄ − 1
    names = ["torsion", "bend_y", "bend_z", "elongation", "shear_y", "shear_z"]
    cols = [names.index(c) for c in ds.components]
    by_hand = (eq.strain - eq.strain_reference)[:, cols].reshape(-1)
    np.testing.assert_array_equal(robot.snapshot(eq.strain), by_hand)
    # a trajectory's strains, sample by sample, and its reference strain as the statics' has it
    run = robot.simulate(0.02, sample_rate=100)
    np.testing.assert_array_equal(run["strain_reference"], robot.strain_reference)
    rows = robot.snapshot(run["strain"])
    assert rows.shape == (3, ds.strain.shape[1])
    np.testing.assert_array_equal(rows[1], robot.snapshot(run["strain"][1]))
    # Model.encode of a result: through snapshot, and the raw strains refused with that hint
    np.testing.assert_allclose(pod.encode(robot.snapshot(eq.strain)), pod.encode(ds.strain[6]),
                               rtol=0, atol=1e-6)
    with pytest.raises(gvsrom.GvsromError, match=r"converts to snapshot rows with `Robot.snapshot`"):
        pod.encode(eq.strain)
    with pytest.raises(gvsrom.GvsromError, match=r"`strain` has shape \(3, 6\); expected \(102, 6\)"):
        robot.snapshot(np.zeros((3, 6)))


def test_snapshot_rows_of_six_components_on_two_divisions(tmp_path):
    # the six-tendon arm: every strain component active, two divisions (a junction's points)
    ds = gvsrom.dataset("six-tendon", tmp_path / "ds6", random="tendons.*.tension=-10:0", samples=3)
    arm = gvsrom.Scenario.preset("six-tendon").build()
    assert len(ds.components) == 6 and ds.strain.shape == (3, 6 * arm.n_points)
    for k in range(3):
        row = arm.snapshot(arm.statics(u=ds.inputs[k]).strain)
        np.testing.assert_allclose(row, ds.strain[k], rtol=0, atol=1e-7 * np.abs(ds.strain[k]).max())


def test_pod_modes_and_singular_values_are_numpys_svd_of_the_snapshots(dataset, pod):
    # an independent SVD (LAPACK through NumPy) of the snapshot matrix, rows = snapshots, not centred
    X = dataset.strain
    _, S, Vt = np.linalg.svd(X, full_matrices=False)
    modes, sigma = pod.arrays["modes"], pod.arrays["singular_values"]
    k = pod.latent
    np.testing.assert_allclose(sigma, S[:len(sigma)], rtol=1e-10, atol=1e-12 * S[0])
    V = modes if modes.shape[0] == X.shape[1] else modes.T
    # each mode is numpy's up to its sign
    overlap = np.abs(Vt[:k] @ V)
    np.testing.assert_allclose(overlap, np.eye(k), rtol=0, atol=1e-9)
    np.testing.assert_allclose(pod.meta["captured_energy"], (S[:k] ** 2).sum() / (S ** 2).sum(),
                               rtol=1e-12)


def test_a_model_of_equilibria_only_warns_in_motion_not_in_statics(robot, pod):
    rom = robot.with_model(pod)
    for run in (lambda: rom.simulate(0.02), lambda: rom.stepper(dt=0.01).close(),
                lambda: rom.modes(1), lambda: rom.linearize()):
        with pytest.warns(UserWarning, match="made from equilibria only"):
            run()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rom.statics([-3.0])
