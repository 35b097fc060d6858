"""A bad argument is named as the Python caller spelled it: the library's messages name the
command line's flags (`--sample-rate`, `--lambda`, `--force`), which the binding renames to the
keyword arguments (`sample_rate`, `lambda_`, `force=True`); a negative count is a `GvsromError`
naming the argument, not pyo3's bare `OverflowError`."""

import re

import numpy as np
import pytest

import gvsrom
from conftest import run_cli


@pytest.fixture(scope="module")
def dataset(gvsrom_bin, tmp_path_factory):
    out = tmp_path_factory.mktemp("ds") / "sweep"
    p = run_cli(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:0",
                "--samples", "4", "--out", str(out))
    assert p.returncode == 0, p.stderr
    return out


def message(call) -> str:
    with pytest.raises(gvsrom.GvsromError) as e:
        call()
    text = str(e.value)
    assert not re.search(r"(^|[\s`(])--[a-z]", text), f"a command-line flag in: {text}"
    return text


def test_simulation_options_are_named_as_keyword_arguments():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    assert "`duration`: -1" in message(lambda: robot.simulate(-1.0))
    assert "`sample_rate`: 0" in message(lambda: robot.simulate(0.1, sample_rate=0.0))
    assert "`fixed_step`: 0" in message(lambda: robot.simulate(0.1, fixed_step=0.0))
    assert "`rtol`" in message(lambda: robot.simulate(0.1, rtol=-1.0))
    assert "count `0`" in message(lambda: robot.modes(count=0))
    # looser than the coordinates themselves: refused, not a motion off by the rod's length
    assert "`atol`: 100" in message(lambda: robot.simulate(0.1, atol=100.0))
    # a seed is a whole number ≥ 0 here as everywhere, not pyo3's bare OverflowError
    assert "`seed` = -1" in message(lambda: robot.simulate(0.02, steps=[-1, 0, 0.01], seed=-1))
    assert "`seed` = 1180591620717411303424" in message(
        lambda: robot.simulate(0.02, steps=[-1, 0, 0.01], seed=2**70))


def test_a_start_state_no_rod_holds_is_refused_naming_q0_before_anything_runs():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    text = message(lambda: robot.simulate(0.05, q0=np.full(robot.n_dof, 1e3)))
    assert "`q0`" in text and "no state of an elastic rod" in text, text


def test_dataset_options_are_named_as_keyword_arguments(tmp_path, dataset):
    beam = gvsrom.Scenario.preset("single-tendon")
    plan = dict(sweep=["tendons.0.tension=-6:0"], samples=3)
    assert message(lambda: gvsrom.dataset(beam, tmp_path / "a", **{**plan, "samples": 0})
                   ).startswith("samples 0")
    assert message(lambda: gvsrom.dataset(beam, tmp_path / "b", **plan, chunk_size=0)
                   ).startswith("chunk_size 0")
    assert message(lambda: gvsrom.dataset(beam, tmp_path / "c", **plan, threads=0)
                   ).startswith("threads 0")
    assert "`sample_rate`" in message(
        lambda: gvsrom.dataset(beam, tmp_path / "d", duration=0.1, sample_rate=0.0))
    # the way out of an existing output is the keyword, as Python spells it
    assert "pass force=True to replace it" in message(lambda: gvsrom.dataset(beam, dataset, **plan))


def test_training_options_are_named_as_keyword_arguments(tmp_path, dataset):
    def train(**kw):
        return lambda: gvsrom.train(dataset, tmp_path / "m", latent=1, epochs=2, **kw)

    assert "invalid `lambda_`" in message(train(lambda_=-1.0))
    assert "invalid `learning_rate`" in message(train(learning_rate=0.0))
    assert "invalid `lr_decay`" in message(train(lr_decay=2.0))
    assert "invalid `rate_weight`" in message(train(rate_weight=-1.0))
    assert "invalid `kinetic_weight`" in message(train(kinetic_weight=-1.0))
    assert "invalid `sample_weighting`" in message(train(sample_weighting="per-row"))
    # a floor outside (0, 1] is refused; with the uniform weighting, which would ignore it, any
    assert "invalid `relative_floor`: -1" in message(
        train(sample_weighting="relative", relative_floor=-1.0))
    assert "invalid `relative_floor`: applies to the relative weighting only" in message(
        train(relative_floor=0.5))
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize("name, least", [("patience", 0), ("lbfgs_iterations", 0),
                                         ("lr_reductions", 0), ("batch_size", 1), ("epochs", 1),
                                         ("seed", 0), ("latent", 1), ("hidden_layers", 1)])
def test_a_negative_count_of_train_is_a_value_error_naming_it(tmp_path, dataset, name, least):
    # the least value the argument accepts, not a generic "≥ 0" where 0 is refused next
    kw = {"latent": 1, "epochs": 2, name: -1}
    text = message(lambda: gvsrom.train(dataset, tmp_path / "m", **kw))
    assert text == f"`{name}` = -1: expected a whole number ≥ {least}"


def test_an_int_beyond_64_bits_in_a_scenario_is_checked_as_the_number_it_is():
    # not a bare OverflowError: 10**30 is the number 1e30, refused by the field's own range
    def preset():
        return gvsrom.Scenario.preset("single-tendon")
    text = message(lambda: preset().set("material.youngs_modulus", 10**30).build())
    assert "material.youngs_modulus" in text and "1e30" in text and "[1, 1e13] Pa" in text, text
    text = message(lambda: preset().set("tendons.0.tension", 10**400))
    assert text.startswith("`tendons.0.tension`: the int 1000") and "±1.8e308" in text, text


def test_a_negative_count_elsewhere_is_a_value_error_naming_it(tmp_path, dataset):
    beam = gvsrom.Scenario.preset("single-tendon")
    plan = dict(sweep=["tendons.0.tension=-6:0"], samples=3)
    assert message(lambda: gvsrom.pod(dataset, -2, tmp_path / "p")).startswith("`modes` = -2")
    for name, least in [("samples", 1), ("seed", 0), ("chunk_size", 1), ("threads", 1)]:
        text = message(lambda: gvsrom.dataset(beam, tmp_path / "d", **{**plan, name: -1}))
        assert text == f"`{name}` = -1: expected a whole number ≥ {least}", text
    assert message(lambda: gvsrom.reproduce("iv-a", tmp_path / "r", jobs=-1)
                   ).startswith("`jobs` = -1")
    assert "≤ 18446744073709551615" in message(
        lambda: gvsrom.dataset(beam, tmp_path / "e", **plan, seed=2**64))


def test_an_int_past_any_rust_integer_says_what_is_accepted(tmp_path, dataset):
    # pyo3's own conversion raises a bare OverflowError "int too big to convert"
    robot = gvsrom.Scenario.preset("single-tendon").build()
    q = np.zeros(robot.n_dof)
    for call, name in [(lambda: robot.jacobian(q, point=2**200), "point"),
                       (lambda: robot.modes(count=-(2**130)), "count"),
                       (lambda: gvsrom.train(dataset, tmp_path / "m", latent=1, epochs=2**130), "epochs"),
                       (lambda: gvsrom.pod(dataset, 2**300, tmp_path / "p"), "modes")]:
        with pytest.raises(gvsrom.GvsromError) as e:
            call()
        assert re.fullmatch(r"-?\d{39,}: too large, expected a whole number ≤ 18446744073709551615",
                            str(e.value)), str(e.value)
        assert f"while processing '{name}'" in e.value.__notes__
    # the largest index that fits is range-checked as before
    with pytest.raises(gvsrom.GvsromError, match=r"`point` = 9223372036854775808 is out of range"):
        robot.jacobian(q, point=2**63)
    assert not (tmp_path / "m").exists() and not (tmp_path / "p").exists()


@pytest.mark.parametrize("given, got", [
    (lambda n: np.zeros((n, 1)), r"an array of shape \(\d+, 1\)"),
    (lambda n: np.zeros(n) + 0j, r"values of dtype complex128"),
    (lambda n: [1.0, None] + [0.0] * (n - 2), r"values of dtype object"),
    (lambda n: "abc", r"values of dtype <U3"),
    (lambda n: 0.5, r"a single number \(a 0-D array\)"),
    (lambda n: [[0.0], [0.0, 1.0]], r"a `list` \(ValueError: .*inhomogeneous"),
])
def test_an_array_of_the_wrong_shape_or_kind_is_a_type_error_naming_the_argument(given, got):
    # numpy's own conversion says "dimensionality mismatch: from=2, to=1", or casts complex values
    # to real with only a ComplexWarning
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(TypeError, match="expected a 1-D array-like of real numbers; got " + got) as e:
        robot.mass_matrix(given(robot.n_dof))
    assert "while processing 'q'" in e.value.__notes__


def test_tensions_and_rows_of_the_wrong_kind_say_what_is_accepted():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(TypeError, match=r"expected tensions \[N\]: one real number for every tendon, "
                                        r"or a 1-D array-like of one per tendon; got values of dtype complex128"):
        robot.statics(u=-1 + 2j)
    with pytest.raises(TypeError, match=r"expected a 2-D array-like of real numbers \(rows\); "
                                        r"got an array of shape \(3,\)") as e:
        robot.statics_batch(np.zeros(3))
    assert "while processing 'U'" in e.value.__notes__
    # every real kind NumPy users pass is still taken, a 1-element array of tensions included
    tip = robot.statics(-1.0).tip_position
    for u in [-1, np.float32(-1.0), np.array(-1.0), np.array([-1.0]), [-1], (-1.0,)]:
        np.testing.assert_array_equal(robot.statics(u).tip_position, tip)
    m = robot.mass_matrix(np.zeros(robot.n_dof))
    for q in [np.zeros(robot.n_dof, dtype=int), np.zeros(robot.n_dof, dtype=np.float32),
              [0] * robot.n_dof, np.zeros(2 * robot.n_dof)[::2]]:
        np.testing.assert_array_equal(robot.mass_matrix(q), m)


def test_a_command_quoted_for_the_shell_keeps_its_flags():
    # the translation every message goes through, on messages costly to provoke
    from gvsrom._gvsrom import _python_spelling as spell

    scaled = ("no step can be taken from there. Simulate with a plain decoder "
              "(`gvsrom train --decoder plain`), or start from another state")
    assert spell(scaled) == scaled
    assert spell("--tension `-3`: give --extrapolate or --from-equilibrium") == (
        "u `-3`: give extrapolate=True or from_equilibrium=True")
    # a flag with no Python argument, a word with a dash inside and a bare `--` stay as they are
    assert spell("--json x, well-known--set, a -- b, --") == "--json x, well-known--set, a -- b, --"
    assert spell("`--lambda`; `--lr-reductions`") == "`lambda_`; `lr_reductions`"
    # a positional argument's value name is the Python argument's, whole words only
    assert spell("invalid `DATASET`: no dataset given; the input DATASET `d`, INPUT `x`") == (
        "invalid `dataset`: no dataset given; the input dataset `d`, output `x`")
    assert spell("`SCENARIO`, MODEL_X, DATASETS, `gvsrom pod DATASET --modes 2`") == (
        "`scenario`, MODEL_X, DATASETS, `gvsrom pod DATASET --modes 2`")
    assert spell("invalid `--load-schedule`: a directory") == "invalid `load_schedule`: a directory"
    # never inside a path or a file name, quoted or not; a sentence's full stop is not a name
    for kept in ["cannot read `/home/u/INPUT.csv`", "dataset `/runs/DATASET`", "`C:\\DATASET`"]:
        assert spell(kept) == kept
    assert spell("INPUT `/data/INPUT/run.json`: no such file") == (
        "output `/data/INPUT/run.json`: no such file")
    assert spell("`SCENARIO.toml`, data/DATASET, DATASET.npy") == "`SCENARIO.toml`, data/DATASET, DATASET.npy"
    assert spell("give a DATASET.") == "give a dataset."


def test_integrator_tolerances_of_a_static_dataset_are_refused(tmp_path):
    beam = gvsrom.Scenario.preset("single-tendon")
    plan = dict(sweep=["tendons.0.tension=-6:0"], samples=3)
    for kw in [{"rtol": 1e-20}, {"atol": 1e-9}]:
        name = next(iter(kw))
        assert message(lambda: gvsrom.dataset(beam, tmp_path / "d", **plan, **kw)) == (
            f"`{name}` is an option of a dynamic dataset: give `duration` too")
    assert not (tmp_path / "d").exists()


def test_an_input_array_of_the_wrong_kind_says_what_it_got():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    for bad, got in [(np.array([0.0, -1.0]), "shape (2,)"), (np.zeros((1, 1, 2)), "shape (1, 1, 2)"),
                     (np.array([[0, -1 + 1j]]), "dtype complex128")]:
        with pytest.raises(TypeError, match=r"`input` must be rows `t, u_1, …, u_1` \(1 \+ 1 "
                           r"columns: a 2-D array\) or a callable `u\(t\)`: expected a 2-D .*" + re.escape(got)):
            robot.simulate(0.01, input=bad)


def test_deepcopy_takes_its_memo_by_the_stubs_name():
    import copy
    s = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -2.0)
    assert s.__deepcopy__(memo={}).to_toml() == s.to_toml()
    assert copy.deepcopy(s).to_toml() == s.to_toml()



def test_a_bool_is_no_tension_nor_count_and_a_whole_float_is_a_count():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    # True is 1 to Python: as a tension it would pull +1 N, as a point index take point 1
    for bad in (True, np.bool_(False)):
        with pytest.raises(TypeError, match=r"tensions \[N\].*got a `bool`"):
            robot.statics(bad)
        with pytest.raises(TypeError, match=r"whole number; got a `bool`"):
            robot.modes(bad)
    with pytest.raises(TypeError, match=r"whole number; got 2\.5"):
        robot.modes(2.5)
    # a float of a whole value is that count
    assert len(robot.modes(2.0)["frequency_hz"]) == 2


def test_booleans_are_no_tensions_states_or_times_in_any_container():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    for bad in ([True], np.array([True]), np.array(True)):
        with pytest.raises(TypeError, match=r"bool"):
            robot.statics(bad)
    with pytest.raises(TypeError, match=r"bool"):
        robot.mass_matrix(np.zeros(robot.n_dof, dtype=bool))
    with pytest.raises(TypeError, match=r"real number; got a `bool`"):
        robot.simulate(True)
    with pytest.raises(TypeError, match=r"real number; got a `bool`"):
        robot.stepper(True)
    with pytest.raises(TypeError, match=r"real number; got a `bool`"):
        robot.stepper(0.01, horizon=True)
    with pytest.raises(gvsrom.GvsromError, match=r"returned `\[True\]`: expected 1 tension"):
        robot.simulate(0.02, input=lambda t: [True])
    # integers are numbers
    assert robot.statics(np.array([-2])).u.tolist() == [-2.0]


def test_tensions_far_beyond_the_elastic_range_are_refused_by_every_quantity():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    n, z = robot.n_dof, np.zeros(robot.n_dof)
    expected = message(lambda: robot.statics([1e300] * 6))
    assert "far beyond the rod's elastic range" in expected
    for call in (lambda: robot.statics_residual(z, [1e300] * 6),
                 lambda: robot.statics_jacobian(z, [-1e300] * 6),
                 lambda: robot.energy(z, z, [1.7e308] * 6),
                 lambda: robot.accelerations(z, z, [-1e300] * 6)):
        assert "far beyond the rod's elastic range" in message(call)
    # within the range, a quantity answers
    assert np.isfinite(robot.statics_residual(z, [-5.0] * 6)).all()


def test_a_steppers_period_and_step_are_named_as_given():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    for dt in (1e-300, 1e300):
        assert "`dt`" in message(lambda: robot.stepper(dt))
    assert "`fixed_step`: 0.02 (expected a step ≤ dt = 0.01 s" in message(
        lambda: robot.stepper(0.01, fixed_step=0.02))
    for h in (0.0, float("nan")):
        assert "`fixed_step`" in message(lambda: robot.stepper(0.01, fixed_step=h))


def test_random_inputs_are_named_as_python_arguments():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    text = message(lambda: robot.simulate(0.02, steps=[-1, 0, 0.01], babble=[-1, 0, 0.01, 0.02]))
    assert "give at most one" in text and "`steps`" in text and "`babble`" in text, text
    text = message(lambda: robot.simulate(0.02, steps=[-1, 0]))
    assert "`steps` takes 3 values [lo, hi, period], got 2" in text, text
    text = message(lambda: gvsrom.dataset("single-tendon", "never", duration=0.1, babble=[-1, 0]))
    assert "`babble` takes 4 values [lo, hi, hold_min, hold_max], got 2" in text, text


def test_a_reconstruction_of_no_dataset_says_what_is_accepted(tmp_path, dataset):
    model = gvsrom.pod(dataset, 1, tmp_path / "pod")
    with pytest.raises(TypeError, match=r"invalid `dataset`: got a NoneType; accepted: a Dataset"):
        model.reconstruction(None)
    assert model.reconstruction(dataset).rows == 4


def test_tensions_of_the_wrong_count_or_not_finite_are_named_u_everywhere():
    robot = gvsrom.Scenario.preset("six-tendon").build()
    z = np.zeros(robot.n_dof)
    for call in (lambda u: robot.statics(u), lambda u: robot.statics_residual(z, u),
                 lambda u: robot.linearize(u=u)):
        assert message(lambda: call([-1.0] * 5)).startswith(
            "`u`: 5 tensions given for 6 tendons"), call
        assert message(lambda: call([np.nan] * 6)).startswith("`u[0]` = NaN"), call
