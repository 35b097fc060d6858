"""A result object's arrays are its state, returned by every access: they are read-only, so a
write cannot change what the object reports; its dicts (`meta`, `arrays`) are new at each access."""

import numpy as np
import pytest

import gvsrom


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "sweep"
    return gvsrom.dataset(gvsrom.Scenario.preset("single-tendon"), out,
                          sweep=["tendons.0.tension=-6:0"], samples=4)


def assert_held(obj, names):
    for name in names:
        a = getattr(obj, name)
        before = np.array(a)
        with pytest.raises(ValueError, match="read-only"):
            a[(0,) * a.ndim] = 12345.0
        np.testing.assert_array_equal(getattr(obj, name), before)
        assert a.copy().flags.writeable, name


def test_statics_and_batches_hold_read_only_arrays():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    eq = robot.statics(u=[-3.0])
    assert_held(eq, ["u", "q", "tip_position", "tip_rotation", "centerline_x", "centerline",
                     "strain_x", "strain", "strain_reference"])
    for path in eq.tendon_paths:
        with pytest.raises(ValueError, match="read-only"):
            path[0, 0] = 1.0
    assert_held(robot.statics_batch([[-1.0], [-2.0]]),
                ["u", "q", "tip_position", "tip_rotation", "centerline_x", "centerline",
                 "strain_x", "strain", "iterations", "residual_norm", "solve_time_s"])
    # a method's result is the caller's own: writable
    assert robot.mass_matrix(np.zeros(robot.n_dof)).flags.writeable


def test_a_dataset_holds_read_only_arrays_and_a_fresh_meta(dataset):
    assert_held(dataset, ["inputs", "strain", "q", "tip_position", "tip_rotation", "status",
                          "iterations", "residual", "strain_x"])
    dataset.meta["samples"] = 99
    assert dataset.meta["samples"] == 4


def test_a_model_holds_read_only_arrays_and_fresh_dicts(dataset, tmp_path):
    model = gvsrom.pod(dataset, 2, tmp_path / "pod")
    assert_held(model, ["latent_range", "rest"])
    name = next(iter(model.arrays))
    weights = model.arrays[name]
    with pytest.raises(ValueError, match="read-only"):
        weights[(0,) * weights.ndim] = 1.0
    model.arrays[name] = np.zeros(3)
    assert model.arrays[name].shape == weights.shape
    model.meta["latent"] = 99
    assert model.meta["latent"] == 2 == model.latent
    # the model's own computation is untouched by all of the above
    x = dataset.strain[-1]
    np.testing.assert_allclose(model.reconstruct(x), model.reconstruct(x.copy()))
