"""dataset / load_dataset / reproduce: the files of `gvsrom dataset` (bit-identical for the same
plan and seed), read back as arrays; a Python dataset → POD and autoencoder → reduced statics;
bad input refused with the command line's message; Ctrl-C keeps the finished samples."""

import os
import signal
import threading
import warnings

import numpy as np
import pytest

import gvsrom
from conftest import cli_error, run_cli

FILES = ["inputs", "strain", "q", "tip_position", "tip_rotation", "status", "iterations", "residual",
         "strain_x", "tendon_lengths"]


def cli_dataset(bin_path, out, *args):
    p = run_cli(bin_path, "dataset", *args, "--out", str(out))
    assert p.returncode == 0, p.stderr
    return out


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    out = tmp_path_factory.mktemp("py") / "sweep"
    return gvsrom.dataset("single-tendon", out, sweep="tendons.0.tension=-6:0", samples=7)


@pytest.mark.parametrize("plan", [["--sweep", "tendons.0.tension=-6:0", "--samples", "7"],
                                  ["--random", "tendons.0.tension=-5:-1", "--samples", "5", "--seed", "3",
                                   "--set", "solver.ramp_steps=3"]])
def test_a_python_dataset_is_bit_identical_to_the_cli_dataset(gvsrom_bin, tmp_path, plan):
    cli = cli_dataset(gvsrom_bin, tmp_path / "cli", "single-tendon", *plan)
    opts = dict(zip(plan[::2], plan[1::2]))
    ds = gvsrom.dataset(
        "single-tendon", tmp_path / "py",
        sweep=opts.get("--sweep"), random=opts.get("--random"), samples=int(opts["--samples"]),
        seed=int(opts["--seed"]) if "--seed" in opts else None, set=[opts["--set"]] if "--set" in opts else None,
    )
    for name in FILES:
        assert (ds.path / f"{name}.npy").read_bytes() == (cli / f"{name}.npy").read_bytes(), name


def test_a_dynamic_dataset_is_bit_identical_to_the_cli_dataset(gvsrom_bin, tmp_path):
    args = ["--duration", "0.02", "--sample-rate", "200", "--steps=-3,0,0.01", "--seed", "2"]
    cli = cli_dataset(gvsrom_bin, tmp_path / "cli", "single-tendon", *args)
    ds = gvsrom.dataset("single-tendon", tmp_path / "py", duration=0.02, sample_rate=200,
                        steps=[-3, 0, 0.01], seed=2)
    assert ds.kind == "dynamics" and ds.t is not None
    for name in FILES + ["t"]:
        assert (ds.path / f"{name}.npy").read_bytes() == (cli / f"{name}.npy").read_bytes(), name


def test_load_dataset_reads_the_files_and_the_metadata(sweep):
    ds = gvsrom.load_dataset(sweep.path)
    assert len(ds) == 7 and ds.complete and ds.kind == "statics"
    assert ds.parameters == ["tendons.0.tension"]
    for name in FILES:
        np.testing.assert_array_equal(getattr(ds, name), np.load(ds.path / f"{name}.npy"), err_msg=name)
    # the iteration counts as int64, as StaticsBatch's (the file's u32 would wrap in arithmetic)
    assert ds.status.dtype == np.uint8 and ds.iterations.dtype == np.int64
    assert (ds.iterations - 1000 < 0).all()
    assert ds.strain.shape == (7, ds.n_points * len(ds.components))
    np.testing.assert_array_equal(ds.inputs[:, 0], np.linspace(-6, 0, 7))
    assert ds.meta["samples"] == 7 and ds.meta["counts"]["ok"] == 7
    assert ds.t is None
    # the tendon's lengths are its length at each row's q, as the robot computes it
    robot = gvsrom.Scenario.preset("single-tendon").build()
    assert ds.tendon_lengths.shape == (7, 1) and ds.meta["n_tendons"] == 1
    for k in range(7):
        np.testing.assert_allclose(ds.tendon_lengths[k], robot.tendon_lengths(ds.q[k]), rtol=1e-14)
    # pulled harder (−6 N first), shorter
    assert np.all(np.diff(ds.tendon_lengths[:, 0]) > 0)


def test_a_python_dataset_trains_models_whose_arrays_and_statics_hold(sweep, tmp_path):
    pod = gvsrom.pod(sweep.path, 2, tmp_path / "pod")
    modes = pod.arrays["modes"]
    assert modes.shape == (sweep.strain.shape[1], 2)
    np.testing.assert_allclose(modes.T @ modes, np.eye(2), rtol=0, atol=1e-12)
    assert np.all(np.diff(pod.arrays["singular_values"]) <= 0)
    assert pod.latent_range.shape == (2, 2) and pod.rest.shape == (2,)
    assert pod.meta["kind"] == "pod"
    robot = gvsrom.Scenario.preset("single-tendon").build()
    full, reduced = robot.statics(u=[-3.0]), robot.statics(u=[-3.0], model=pod)
    # two POD modes of a 1-parameter sweep reproduce its tip to well within 1 % of L = 0.25 m
    np.testing.assert_allclose(reduced.tip_position, full.tip_position, rtol=0, atol=2.5e-3)

    ae = gvsrom.train(sweep.path, tmp_path / "ae", latent=1, hidden_layers=3, epochs=20, patience=0,
                      lbfgs_iterations=10, seed=1)
    w = ae.arrays
    assert w["encoder.0.weight"].shape[1] == sweep.strain.shape[1]
    assert w["decoder.1.weight"].shape[0] == sweep.strain.shape[1]
    lo, hi = ae.latent_range[0]
    assert lo < hi and ae.meta["training"]["epochs"] == 20
    # the reduced model's quantities at its rest: M > 0, and C q̇ = Ṁ q̇ − ½ ∂(q̇ M q̇)/∂q in 1 DOF
    rom = robot.with_model(ae)
    q, qd, h = ae.rest + 0.1 * (hi - lo), np.array([0.3]), 1e-6
    m = lambda x: rom.mass_matrix(np.array([x]))[0, 0]
    dm = (m(q[0] + h) - m(q[0] - h)) / (2 * h)
    np.testing.assert_allclose(rom.coriolis_force(q, qd), [0.5 * dm * qd[0] ** 2], rtol=1e-5)
    k1, f = rom.elastic_force(q), rom.external_force(q)
    scale = max(np.abs(k1).max(), np.abs(f).max())
    np.testing.assert_allclose(k1, f - rom.statics_residual(q, u=[0.0]), rtol=0, atol=1e-12 * scale)


def test_a_relative_sample_weighting_is_recorded_and_a_bad_one_refused_as_the_cli_does(
        gvsrom_bin, sweep, tmp_path):
    ae = gvsrom.train(sweep.path, tmp_path / "rel", latent=1, hidden_layers=3, epochs=5, patience=0,
                      lbfgs_iterations=0, sample_weighting="relative", relative_floor=0.2)
    assert ae.meta["training"]["sample_weighting"] == "relative"
    assert ae.meta["training"]["relative_floor"] == 0.2
    expected = cli_error(gvsrom_bin, "train", str(sweep.path), "--sample-weighting", "relative",
                         "--relative-floor", "0", "--out", str(tmp_path / "cli"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.train(sweep.path, tmp_path / "py", sample_weighting="relative", relative_floor=0.0)
    assert str(e.value) == expected
    with pytest.raises(gvsrom.GvsromError, match="`sample_weighting`.*accepted: uniform, relative"):
        gvsrom.train(sweep.path, tmp_path / "py", sample_weighting="per-row")


def test_a_scaled_decoder_is_recorded_its_rest_is_z1_zero_and_a_bad_form_refused(sweep, tmp_path):
    ae = gvsrom.train(sweep.path, tmp_path / "scaled", latent=1, hidden_layers=3, epochs=5,
                      patience=0, lbfgs_iterations=0, decoder="scaled")
    assert ae.meta["training"]["decoder"] == "scaled"
    assert ae.rest[0] == 0.0
    with pytest.raises(gvsrom.GvsromError, match="`decoder`.*`cone`.*accepted: plain, scaled"):
        gvsrom.train(sweep.path, tmp_path / "py", decoder="cone")


def test_a_rate_weight_is_recorded_and_refused_on_equilibria_as_the_cli_does(
        gvsrom_bin, sweep, tmp_path):
    traj = gvsrom.dataset("single-tendon", tmp_path / "traj", duration=0.2, sample_rate=100,
                          steps=[-3, 0, 0.05], seed=2)
    ae = gvsrom.train(traj, tmp_path / "rated", latent=1, hidden_layers=3, epochs=5, patience=0,
                      lbfgs_iterations=0, rate_weight=0.5)
    assert ae.meta["training"]["rate_weight"] == 0.5
    expected = cli_error(gvsrom_bin, "train", str(sweep.path), "--rate-weight", "0.1",
                         "--out", str(tmp_path / "cli"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.train(sweep.path, tmp_path / "py", rate_weight=0.1)
    assert str(e.value) == expected
    assert "static equilibria" in expected and not (tmp_path / "py").exists()
    kinetic = gvsrom.train(traj, tmp_path / "kinetic", latent=1, hidden_layers=3, epochs=5,
                           patience=0, lbfgs_iterations=0, rate_weight=0.5, kinetic_weight=1.0)
    assert kinetic.meta["training"]["kinetic_weight"] == 1.0
    expected = cli_error(gvsrom_bin, "train", str(traj.path), "--kinetic-weight", "1",
                         "--out", str(tmp_path / "cli-k"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.train(traj, tmp_path / "py-k", kinetic_weight=1.0)
    assert str(e.value) == expected
    assert "`rate_weight` > 0" in expected and not (tmp_path / "py-k").exists()


def test_a_learning_rate_decay_is_recorded_and_a_bad_factor_refused_as_the_cli_does(
        gvsrom_bin, sweep, tmp_path):
    ae = gvsrom.train(sweep, tmp_path / "decayed", latent=1, hidden_layers=3, epochs=5,
                      lr_decay=0.05)
    assert ae.meta["training"]["lr_decay"] == 0.05
    expected = cli_error(gvsrom_bin, "train", str(sweep.path), "--lr-decay", "1.5",
                         "--out", str(tmp_path / "cli"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.train(sweep.path, tmp_path / "py", lr_decay=1.5)
    assert str(e.value) == expected
    assert "`lr_decay`" in expected and not (tmp_path / "py").exists()


def test_bad_plans_are_refused_with_the_cli_message(gvsrom_bin, tmp_path):
    expected = cli_error(gvsrom_bin, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6",
                         "--samples", "3", "--out", str(tmp_path / "cli"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.dataset("single-tendon", tmp_path / "py", sweep="tendons.0.tension=-6", samples=3)
    assert str(e.value) == expected
    expected = cli_error(gvsrom_bin, "dataset", "no-such-preset", "--sweep", "tendons.0.tension=-6:0",
                         "--samples", "3", "--out", str(tmp_path / "cli"))
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.dataset("no-such-preset", tmp_path / "py", sweep={"tendons.0.tension": (-6, 0)}, samples=3)
    assert str(e.value) == expected
    with pytest.raises(gvsrom.GvsromError, match="`sample_rate` is an option of a dynamic dataset"):
        gvsrom.dataset("single-tendon", tmp_path / "py", sweep="tendons.0.tension=-6:0", samples=3,
                       sample_rate=100)
    assert not (tmp_path / "py").exists()


def test_load_dataset_of_a_non_dataset_is_a_value_error(tmp_path):
    with pytest.raises(gvsrom.GvsromError):
        gvsrom.load_dataset(tmp_path)


def test_an_unknown_study_is_refused_naming_it_and_the_accepted(tmp_path):
    with pytest.raises(gvsrom.GvsromError,
                       match=r"unknown study `iv-z` \(accepted: iv-a, iv-b, iv-c1, iv-c2, v, noise, all\)"):
        gvsrom.reproduce("iv-z", tmp_path / "run")
    with pytest.raises(gvsrom.GvsromError, match=r"noise 2: expected a number in \[0, 1\]"):
        gvsrom.reproduce(["v"], tmp_path / "run", noise=2.0)
    with pytest.raises(gvsrom.GvsromError, match=r"noise 0.5: only the noise study reads it"):
        gvsrom.reproduce(["v"], tmp_path / "run", noise=0.5)
    assert not (tmp_path / "run").exists()


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_stops_a_dataset_and_keeps_its_finished_chunks(tmp_path, sigint_raises):
    timer = threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(KeyboardInterrupt, match="interrupted by SIGINT; the .* finished samples were written"):
        gvsrom.dataset("single-tendon", tmp_path / "big", sweep="tendons.0.tension=-6:0", samples=20000,
                       chunk_size=8, threads=1)
    ds = gvsrom.load_dataset(tmp_path / "big")
    assert not ds.complete and 0 < np.sum(ds.status == 0) < 20000


def test_reproduce_runs_the_steps_the_cli_then_reuses(gvsrom_bin, tmp_path):
    # the smallest study at test sizes (~7 s): the command line on the same directory finds every
    # step's key unchanged, i.e. Python ran the same configuration
    done = gvsrom.reproduce("v", tmp_path / "run", test_sizes=True, jobs=1)
    assert [d["study"] for d in done] == ["v"]
    assert done[0]["steps"] > 0 and done[0]["reused"] == 0
    assert (done[0]["dir"] / "results.json").is_file()
    p = run_cli(gvsrom_bin, "reproduce", "v", "--test-sizes", "--jobs", "1", "--out", str(tmp_path / "run"))
    assert p.returncode == 0, p.stderr
    steps = done[0]["steps"]
    assert f"({steps} steps, {steps} reused)" in p.stdout


def test_a_dataset_of_a_tendon_the_basis_cannot_hold_warns(tmp_path):
    s = gvsrom.Scenario.preset("single-tendon").set("tendons.0.turns", 0.5)
    with pytest.warns(UserWarning, match=r"tendons\[0\] also loads torsion, bend_z, shear_y"):
        gvsrom.dataset(s, tmp_path / "h", sweep="tendons.0.tension=-2:0", samples=2)


def test_a_seed_with_a_plan_that_draws_nothing_is_refused(tmp_path):
    with pytest.raises(gvsrom.GvsromError, match=r"seed 3: this plan draws nothing \(a sweep, grid or input\); seed applies to random"):
        gvsrom.dataset("single-tendon", tmp_path / "s", sweep="tendons.0.tension=-2:0", samples=2, seed=3)
    assert not (tmp_path / "s").exists()
    # a random plan takes it, and the default is 0
    a = gvsrom.dataset("single-tendon", tmp_path / "a", random="tendons.0.tension=-2:0", samples=2)
    b = gvsrom.dataset("single-tendon", tmp_path / "b", random="tendons.0.tension=-2:0", samples=2, seed=0)
    np.testing.assert_array_equal(a.inputs, b.inputs)


def test_failed_samples_are_warned_of_by_dataset_and_left_out_by_pod_with_a_warning(tmp_path):
    # one solver iteration: most equilibria fail; the command line lists them, Python warns
    beam = gvsrom.Scenario.preset("single-tendon").set("solver.max_iterations", 1)
    with pytest.warns(UserWarning, match=r"(\d+) of the 12 samples failed \(sample \d+: .*\); their "
                      r"rows are NaN with status 1, and pod and train leave them out") as caught:
        ds = gvsrom.dataset(beam, tmp_path / "d", sweep="tendons.0.tension=-6:0", samples=12)
    failed = int((ds.status == 1).sum())
    assert 0 < failed < 12
    assert any(f"{failed} of the 12 samples failed" in str(w.message) for w in caught)
    assert np.isnan(ds.strain[ds.status == 1]).all()
    with pytest.warns(UserWarning, match=rf"dataset `.*`: {failed} of its 12 samples are left out, "
                      r"failed or not computed \(sample \d+: failed: "):
        model = gvsrom.pod(ds, 1, tmp_path / "pod")
    assert model.kind == "pod"
    # a dataset without failures: no such warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gvsrom.dataset("single-tendon", tmp_path / "ok", sweep="tendons.0.tension=-6:0", samples=3)


def test_a_single_override_may_be_a_str(tmp_path):
    one = gvsrom.dataset("single-tendon", tmp_path / "a", sweep="tendons.0.tension=-6:0", samples=2,
                         set="loads.gravity=[0, 0, 0]")
    listed = gvsrom.dataset("single-tendon", tmp_path / "b", sweep="tendons.0.tension=-6:0",
                            samples=2, set=["loads.gravity=[0, 0, 0]"])
    np.testing.assert_array_equal(one.strain, listed.strain)
    with pytest.raises(TypeError, match=r"`set`: expected a str or a list of str; got int"):
        gvsrom.dataset("single-tendon", tmp_path / "c", sweep="tendons.0.tension=-6:0", samples=2,
                       set=3)



def test_a_value_set_with_the_plan_that_varies_it_is_refused_but_a_scenarios_own_is_its_base(
        tmp_path):
    # set= beside a sweep of the same value would be replaced at every sample: refused
    with pytest.raises(gvsrom.GvsromError, match=r"set tendons.0.tension=-1: the plan varies"):
        gvsrom.dataset("single-tendon", tmp_path / "both", sweep="tendons.0.tension=-6:0",
                       samples=2, set=["tendons.0.tension=-1"])
    # a Scenario carrying a tension is the base its plan varies
    base = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -1.0)
    ds = gvsrom.dataset(base, tmp_path / "base", sweep="tendons.0.tension=-6:0", samples=2)
    assert ds.inputs[:, 0].tolist() == [-6.0, 0.0]
