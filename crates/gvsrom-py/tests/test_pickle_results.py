"""Results pickle, for the return trip of `multiprocessing` and `concurrent.futures`: `Statics` and
`StaticsBatch` whole (every field equal after the round trip, every array bit for bit and read-only
again); `Dataset` and `Model` by directory and content, a directory written again or removed in
between refused naming it. And `with_model` / `statics(model=…)` take a model's directory as
`pod`, `train` and `reconstruction` do."""

import concurrent.futures
import copy
import multiprocessing
import pickle
import re
import shutil
import struct
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


def fields(obj):
    """The names of the public attributes of `obj`'s class (its getters), as the class declares
    them: what a round trip must keep, listed independently of the pickling code."""
    cls = vars(type(obj))
    return sorted(n for n, v in cls.items() if not n.startswith("_") and not callable(v))


def assert_same(a, b, where):
    """`a` and `b` equal as values: arrays of the same type, dtype and shape with the same bytes
    (NaN payloads and signed zeros included), the copy read-only as results' arrays are; floats bit
    for bit; containers item by item; anything else by type and `==`."""
    assert type(a) is type(b), (where, type(a), type(b))
    if isinstance(a, np.ndarray):
        assert (a.dtype, a.shape) == (b.dtype, b.shape), (where, a.dtype, b.dtype, a.shape, b.shape)
        assert a.tobytes() == b.tobytes(), where
        assert not b.flags.writeable, f"{where}: an unpickled result's array is writable"
    elif isinstance(a, float):
        assert struct.pack("<d", a) == struct.pack("<d", b), (where, a, b)
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), (where, len(a), len(b))
        for k, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{k}]")
    elif isinstance(a, dict):
        assert list(a) == list(b), (where, list(a), list(b))
        for k in a:
            assert_same(a[k], b[k], f"{where}[{k!r}]")
    else:
        assert a == b, (where, a, b)


def assert_same_fields(a, b, expected_some, skip=()):
    names = fields(a)
    # the listing finds the fields (an empty one would compare nothing)
    assert set(expected_some) <= set(names), names
    for name in names:
        if name not in skip:
            assert_same(getattr(a, name), getattr(b, name), name)


def test_statics_pickles_whole_every_field_bit_for_bit(robot, pod):
    loose = gvsrom.load_model(pod.path, extrapolate=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a list field that is not empty: the model used outside its training
        extrapolated = robot.statics(u=-30.0, model=loose)
    assert extrapolated.model_extrapolated
    for eq in (robot.statics(u=[-2.0]), extrapolated):
        again = pickle.loads(pickle.dumps(eq))
        assert type(again) is gvsrom.Statics
        assert_same_fields(eq, again, ["q", "tendon_paths", "divergence", "model_extrapolated",
                                       "solve_time_s"])
        assert_same(eq.to_dict(), again.to_dict(), "to_dict()")
        for c in (copy.copy(eq), copy.deepcopy(eq)):
            assert_same_fields(eq, c, ["q"])


def test_statics_batch_pickles_whole_every_field_bit_for_bit(robot):
    batch = robot.statics_batch([[-1.0], [-2.5], [-4.0]])
    # NaN marks the stable rows: its bits survive too
    assert np.isnan(batch.divergence).all()
    again = pickle.loads(pickle.dumps(batch))
    assert type(again) is gvsrom.StaticsBatch and len(again) == 3
    assert_same_fields(batch, again, ["q", "iterations", "divergence", "buckled", "solve_time_s"])
    for c in (copy.copy(batch), copy.deepcopy(batch)):
        assert_same_fields(batch, c, ["q"])


def test_a_dataset_pickles_by_directory_and_reads_the_same_content_back(dataset):
    again = pickle.loads(pickle.dumps(dataset))
    assert type(again) is gvsrom.Dataset
    assert_same_fields(dataset, again, ["path", "strain", "tendon_lengths", "meta", "seed"])
    assert copy.copy(dataset) is dataset and copy.deepcopy(dataset) is dataset


def test_a_model_pickles_by_directory_with_its_extrapolate(pod):
    for model in (pod, gvsrom.load_model(pod.path, extrapolate=True)):
        again = pickle.loads(pickle.dumps(model))
        assert type(again) is gvsrom.Model
        assert_same_fields(model, again, ["path", "arrays", "extrapolate", "meta", "rest"])
        assert copy.copy(model) is model and copy.deepcopy(model) is model
    assert pickle.loads(pickle.dumps(gvsrom.load_model(pod.path, extrapolate=True))).extrapolate


def _statics(robot, u):
    return robot.statics(u=[u])


def test_statics_come_back_from_worker_processes(robot):
    # the README's multiprocessing use: the robot goes out, its results come back
    ctx = multiprocessing.get_context("spawn")
    tensions = [-1.0, -2.0]
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=ctx) as pool:
        results = list(pool.map(_statics, [robot] * len(tensions), tensions, timeout=120))
    for u, eq in zip(tensions, results):
        assert type(eq) is gvsrom.Statics
        # the same solve here: the same numbers, all but its own wall-clock time
        assert_same_fields(robot.statics(u=[u]), eq, ["q", "tip_position"], skip=["solve_time_s"])


def test_a_dataset_written_again_or_removed_is_refused_on_unpickling(tmp_path):
    out = tmp_path / "d"
    made = gvsrom.dataset("single-tendon", out, sweep="tendons.0.tension=-2:0", samples=2)
    blob = pickle.dumps(made)
    gvsrom.dataset("single-tendon", out, sweep="tendons.0.tension=-3:0", samples=2, force=True)
    with pytest.raises(gvsrom.GvsromError, match="changed since it was pickled") as e:
        pickle.loads(blob)
    assert f"dataset `{out}`" in str(e.value) and "`load_dataset`" in str(e.value), str(e.value)
    blob = pickle.dumps(gvsrom.load_dataset(out))
    shutil.rmtree(out)
    with pytest.raises(gvsrom.GvsromError) as e:
        pickle.loads(blob)
    assert f"unpickling the dataset of `{out}`" in str(e.value), str(e.value)


def test_a_model_written_again_is_refused_on_unpickling(dataset, tmp_path):
    out = tmp_path / "m"
    blob = pickle.dumps(gvsrom.pod(dataset, 1, out))
    gvsrom.pod(dataset, 2, out, force=True)
    with pytest.raises(gvsrom.GvsromError, match="changed since it was pickled") as e:
        pickle.loads(blob)
    assert f"model `{out}`" in str(e.value) and "`load_model`" in str(e.value), str(e.value)


def test_with_model_and_statics_take_a_model_directory(robot, pod):
    by_model = robot.with_model(pod).statics(u=[-3.0])
    for path in (pod.path, str(pod.path)):
        attached = robot.with_model(path)
        assert attached.model == pod.path and attached.n_dof == 2
        assert_same_fields(by_model, attached.statics(u=[-3.0]), ["q"], skip=["solve_time_s"])
        assert_same_fields(robot.statics(u=[-3.0], model=pod), robot.statics(u=[-3.0], model=path),
                           ["q"], skip=["solve_time_s"])
    # loaded as load_model(path) loads it: without extrapolate, outside the training refused
    with pytest.raises(gvsrom.GvsromError, match="outside the training inputs"):
        robot.statics(u=-30.0, model=str(pod.path))


def test_a_model_argument_that_is_neither_a_model_nor_a_path_is_refused(robot, tmp_path):
    accepted = re.escape("accepted: a Model or a model directory (str or os.PathLike)")
    with pytest.raises(TypeError, match="invalid `model`: got a int; " + accepted):
        robot.with_model(3)
    with pytest.raises(TypeError, match="invalid `model`: got a list"):
        robot.statics(model=[1.0])
    # a directory that is no model: load_model's own refusal
    with pytest.raises(gvsrom.GvsromError) as by_path:
        robot.with_model(tmp_path)
    with pytest.raises(gvsrom.GvsromError) as by_load:
        gvsrom.load_model(tmp_path)
    assert str(by_path.value) == str(by_load.value)
