"""simulate: the trajectory of `gvsrom simulate --out`, as arrays in memory; Ctrl-C stops it."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import gvsrom
from conftest import run_cli

ARRAYS = ["t", "q", "qd", "u", "tip_position", "tip_rotation", "strain", "centerline", "tendon_paths"]


def test_simulate_equals_the_cli_trajectory(gvsrom_bin, tmp_path):
    out = tmp_path / "run"
    p = run_cli(gvsrom_bin, "simulate", "single-tendon", "--duration", "0.05", "--sample-rate", "200",
                "--from-equilibrium", "--tension=-4", "--out", str(out))
    assert p.returncode == 0, p.stderr
    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -4).build()
    tr = robot.simulate(0.05, sample_rate=200, from_equilibrium=True)
    for name in ARRAYS:
        cli = np.load(out / f"{name}.npy")
        assert tr[name].shape == cli.shape, name
        np.testing.assert_allclose(tr[name], cli, rtol=0, atol=1e-12, err_msg=name)
    np.testing.assert_array_equal(tr["strain_x"], np.load(out / "strain_x.npy"))


@pytest.mark.parametrize("options", [
    ["--method", "galpha", "--rho-inf", "1", "--error-norm", "mass"],
    ["--method", "ndf", "--max-order", "2", "--fd-jacobian"],
])
def test_the_integrators_options_equal_the_clis(gvsrom_bin, tmp_path, options):
    out = tmp_path / "run"
    p = run_cli(gvsrom_bin, "simulate", "single-tendon", "--duration", "0.05", "--sample-rate", "200",
                "--tension=-4", *options, "--out", str(out))
    assert p.returncode == 0, p.stderr
    kw = {}
    it = iter(options)
    for flag in it:
        name = flag[2:].replace("-", "_")
        if name == "fd_jacobian":
            kw[name] = True
        else:
            value = next(it)
            kw[name] = {"rho_inf": float, "max_order": int}.get(name, str)(value)
    robot = gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -4).build()
    tr = robot.simulate(0.05, sample_rate=200, **kw)
    np.testing.assert_allclose(tr["q"], np.load(out / "q.npy"), rtol=0, atol=1e-12)
    assert tr["steps"] == json.loads((out / "meta.json").read_text())["steps"]


def test_bad_integrator_options_are_named_as_keyword_arguments():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match=r"`error_norm`: `l2` \(accepted: componentwise, mass\)"):
        robot.simulate(0.01, error_norm="l2")
    with pytest.raises(gvsrom.GvsromError, match=r"max_order"):
        robot.simulate(0.01, method="ndf", max_order=7)
    with pytest.raises(gvsrom.GvsromError, match=r"rho_inf"):
        robot.simulate(0.01, method="galpha", rho_inf=2.0)
    with pytest.raises(gvsrom.GvsromError, match=r"rho_inf"):
        robot.simulate(0.01, method="ndf", rho_inf=0.5)
    with pytest.raises(gvsrom.GvsromError, match=r"max_order` = -1"):
        robot.simulate(0.01, max_order=-1)


def test_an_input_array_holds_each_row():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    rows = np.array([[0.0, 0.0], [0.01, -3.0]])
    tr = robot.simulate(0.02, sample_rate=500, input=rows)
    u = tr["u"][:, 0]
    t = tr["t"]
    np.testing.assert_array_equal(u[t < 0.01], 0.0)
    np.testing.assert_array_equal(u[t >= 0.01], -3.0)
    assert tr["centerline"].shape == (len(t), len(tr["centerline_x"]), 3)


def test_an_input_of_the_wrong_width_or_start_is_a_value_error():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match="columns"):
        robot.simulate(0.01, input=np.zeros((2, 3)))
    with pytest.raises(gvsrom.GvsromError, match="starts at t = 0.5"):
        robot.simulate(0.01, input=[[0.5, -1.0]])
    with pytest.raises(gvsrom.GvsromError, match="`duration`"):
        robot.simulate(-1.0)


def test_a_non_finite_input_entry_is_named_by_its_index_in_the_array():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    with pytest.raises(gvsrom.GvsromError, match=r"`input\[1, 1\]` = NaN: .*column 1 is the tension u_1 of tendon 0 in N"):
        robot.simulate(0.01, input=np.array([[0.0, -1.0], [0.005, np.nan]]))
    with pytest.raises(gvsrom.GvsromError, match=r"`input\[1, 0\]` = inf: .*the time t in s"):
        robot.simulate(0.01, input=np.array([[0.0, -1.0], [np.inf, -1.0]]))


@pytest.mark.skipif(os.name != "posix", reason="SIGINT to self")
def test_ctrl_c_interrupts_a_long_simulation(sigint_raises):
    robot = gvsrom.Scenario.preset("single-tendon").build()
    # a tension switching every 10 ms for 1000 s keeps the integrator's steps short
    t = np.arange(0.0, 1000.0, 0.01)
    rows = np.stack([t, np.where(np.arange(len(t)) % 2 == 0, -5.0, 0.0)], axis=1)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt) as e:
        robot.simulate(1000.0, sample_rate=100, input=rows)
    assert time.monotonic() - t0 < 30
    # the samples computed before come with it
    tr = e.value.trajectory
    assert tr["t"][0] == 0.0 and tr["t"][-1] < 1000.0 and tr["q"].shape == (len(tr["t"]), robot.n_dof)


EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "..", "examples")


def test_a_load_schedule_release_equals_the_cli(gvsrom_bin, tmp_path):
    # the release of examples/undamped-release.toml: held at its tip-loaded equilibrium, the load
    # dropped to zero at t = 0 by the schedule
    scenario = os.path.join(EXAMPLES, "undamped-release.toml")
    schedule = os.path.join(EXAMPLES, "release-zero.csv")
    out = tmp_path / "release"
    p = run_cli(gvsrom_bin, "simulate", scenario, "--duration", "0.05", "--sample-rate", "200",
                "--from-equilibrium", "--load-schedule", schedule, "--out", str(out))
    assert p.returncode == 0, p.stderr
    robot = gvsrom.Scenario.from_toml(scenario).build()
    tr = robot.simulate(0.05, sample_rate=200, from_equilibrium=True, load_schedule=schedule)
    for name in ["t", "q", "qd", "tip_position"]:
        np.testing.assert_allclose(tr[name], np.load(out / f"{name}.npy"), rtol=0, atol=1e-12,
                                   err_msg=name)
    # it moves: the tip rises from its loaded deflection once the load is gone
    assert tr["tip_position"][-1, 2] > tr["tip_position"][0, 2] + 1e-4
    # a schedule does work: no energy balance
    assert "energy_balance" not in tr
    with pytest.raises(gvsrom.GvsromError, match="load_schedule|load-schedule|cannot read"):
        robot.simulate(0.05, from_equilibrium=True, load_schedule=str(tmp_path / "missing.csv"))


def falling_rod():
    """The undamped rod of examples/undamped-release.toml without its tip force, falling under
    gravity, on 4 elements."""
    return (gvsrom.Scenario.from_toml(os.path.join(EXAMPLES, "undamped-release.toml"))
            .set("loads.point.0.force", [0.0, 0.0, 0.0])
            .set("loads.gravity", [0.0, 0.0, -9.81])
            .set("divisions.0.basis.elements", 4)
            .set("divisions.0.quadrature.elements", 4)
            .build())


def test_a_conservative_run_reports_its_energy_balance():
    robot = falling_rod()
    tr = robot.simulate(0.3, sample_rate=50, rtol=1e-6, atol=1e-9)
    b = tr["energy_balance"]
    assert b["kinetic_max"] > 0.01
    assert b["largest_gain"] < 0.01 * b["kinetic_max"] and b["largest_loss"] < 0.01 * b["kinetic_max"]
    # E at the last sample, from the energies Robot.energy gives, the tendon-free rod's total
    e = robot.energy(tr["q"][-1], tr["qd"][-1])
    assert abs(e["total"] - b["last"]) < 1e-12 * max(1.0, abs(b["last"])) + 1e-12
    # a damped preset: none
    assert "energy_balance" not in gvsrom.Scenario.preset("single-tendon").build().simulate(0.01)


def test_the_energy_a_run_keeps_under_constant_tensions_is_robot_energy_with_u():
    # undamped, frictionless tendons pulling from rest: E = T + V_e + V_g − Σ u ℓ is conserved,
    # and Robot.energy(q, qd, u) is the E the run's balance reports at its last sample
    robot = (gvsrom.Scenario.preset("six-tendon-no-gravity").set("material.damping", 0.0)
             .set("tendons.0.tension", -2.0).set("tendons.3.tension", -1.0).build())
    tr = robot.simulate(0.1, sample_rate=100, rtol=1e-7, atol=1e-10)
    b = tr["energy_balance"]
    assert b["kinetic_max"] > 1e-4, b
    assert b["largest_gain"] < 0.01 * b["kinetic_max"] and b["largest_loss"] < 0.01 * b["kinetic_max"]
    e = robot.energy(tr["q"][-1], tr["qd"][-1], u=robot.tensions)
    assert abs(e["total"] - b["last"]) < 1e-9 * max(1.0, abs(b["last"])), (e, b)
    # without the tendons' potential the total is not kept: the pull turned it into motion
    no_u = robot.energy(tr["q"][-1], tr["qd"][-1])["total"]
    assert abs(no_u - b["initial"]) > 0.5 * b["kinetic_max"], (no_u, b)


def test_random_steps_and_babbling_equal_the_cli(gvsrom_bin, tmp_path):
    robot = gvsrom.Scenario.preset("six-tendon").build()
    for option, values in [("--steps", [-15.0, 0.0, 0.1]), ("--babble", [-15.0, 0.0, 0.05, 0.1])]:
        out = tmp_path / option.strip("-")
        p = run_cli(gvsrom_bin, "simulate", "six-tendon", "--duration", "0.3", "--sample-rate", "100",
                    f"{option}={','.join(map(str, values))}", "--seed", "3", "--out", str(out))
        assert p.returncode == 0, p.stderr
        tr = robot.simulate(0.3, **{option.strip("-"): values}, seed=3)
        for name in ["t", "u", "q", "tip_position"]:
            np.testing.assert_allclose(tr[name], np.load(out / f"{name}.npy"), rtol=0, atol=1e-12,
                                       err_msg=f"{option} {name}")
        # the tensions change within the run, inside [lo, hi]
        assert len(np.unique(tr["u"][:, 0])) > 1
        assert tr["u"].min() >= -15.0 and tr["u"].max() <= 0.0
    # without a seed, both draw the same signal (the command line's default seed, 1)
    out = tmp_path / "default-seed"
    p = run_cli(gvsrom_bin, "simulate", "six-tendon", "--duration", "0.3", "--steps=-15,0,0.1",
                "--out", str(out))
    assert p.returncode == 0, p.stderr
    np.testing.assert_array_equal(robot.simulate(0.3, steps=[-15.0, 0.0, 0.1])["u"],
                                  np.load(out / "u.npy"))
    with pytest.raises(gvsrom.GvsromError, match="at most one"):
        robot.simulate(0.1, input=np.zeros((1, 7)), steps=[-1.0, 0.0, 0.1])
    with pytest.raises(gvsrom.GvsromError, match="steps"):
        robot.simulate(0.1, steps=[-1.0, 0.0])


def test_an_undamped_run_the_integrator_damps_strongly_warns_with_the_balance():
    # an undamped rod falling from horizontal, at a loose tolerance: the L-stable SDIRK4 damps the
    # whip's vibrations its steps do not resolve (the CLI measured 40 % of the largest kinetic
    # energy; it also gained 3.8 %, warned of as well); the result's energy_balance shows it and
    # a warning names the option to tighten, in Python's spelling
    robot = falling_rod()
    with pytest.warns(UserWarning) as caught:
        tr = robot.simulate(2.0, sample_rate=50, method="sdirk", rtol=1e-2)
    messages = [str(w.message) for w in caught]
    assert any("dissipated" in m and "tighten rtol" in m for m in messages), messages
    b = tr["energy_balance"]
    assert b["largest_loss"] > 0.1 * b["kinetic_max"] > 0.0


def test_rows_that_change_nothing_restart_nothing():
    # 5000 held rows of one value are the 2-row run exactly, rows on one line interpolated the
    # ramp between its ends (the integrator restarts only where the input jumps or bends: 20 000 such rows took > 60 s)
    robot = gvsrom.Scenario.preset("single-tendon").build()
    t = np.linspace(0.0, 0.3, 5000)
    held = robot.simulate(0.3, input=np.c_[t, -np.ones_like(t)])
    two = robot.simulate(0.3, input=np.array([[0.0, -1.0], [0.3, -1.0]]))
    np.testing.assert_array_equal(held["q"], two["q"])
    ramp = robot.simulate(0.3, input=np.c_[t, -10 * t], interpolate=True)
    ends = robot.simulate(0.3, input=np.array([[0.0, 0.0], [0.3, -3.0]]), interpolate=True)
    # the same steps; u between the rows rounds otherwise than between the ends (2e-10 in q)
    np.testing.assert_allclose(ramp["q"], ends["q"], rtol=0, atol=1e-8 * np.abs(ends["q"]).max())
    assert (held["steps"], ramp["steps"]) == (two["steps"], ends["steps"])
