"""simulate(out=…): the trajectory written as `gvsrom simulate --out` writes it (the same arrays,
byte for byte), recording how the run was made, ready for `plot`; written even when the run ends
early; the output rules of the command line (no overwrite without force, never a foreign path)."""

import json

import numpy as np
import pytest

import gvsrom
from conftest import run_cli

ARRAYS = ["t", "q", "qd", "u", "tip_position", "tip_rotation", "strain", "strain_x", "centerline",
          "tendon_paths", "tendon_lengths"]


@pytest.fixture(scope="module")
def robot():
    return gvsrom.Scenario.preset("single-tendon").build()


def test_the_files_are_the_command_lines_and_plot_draws_them(gvsrom_bin, robot, tmp_path):
    rows = np.array([[0.0, -2.0], [0.05, -4.0]])
    csv = tmp_path / "u.csv"
    csv.write_text("0,-2\n0.05,-4\n")
    tr = robot.simulate(0.1, sample_rate=100, input=rows, out=tmp_path / "py")
    assert tr["out"] == tmp_path / "py" or str(tr["out"]) == str(tmp_path / "py")
    p = run_cli(gvsrom_bin, "simulate", "single-tendon", "--duration", "0.1", "--input", str(csv),
                "--out", str(tmp_path / "cli"))
    assert p.returncode == 0, p.stderr
    for name in ARRAYS:
        a, b = (tmp_path / d / f"{name}.npy" for d in ("py", "cli"))
        assert a.read_bytes() == b.read_bytes(), name
        np.testing.assert_array_equal(np.load(a), np.load(b))
    np.testing.assert_array_equal(np.load(tmp_path / "py" / "q.npy"), tr["q"])
    meta = json.loads((tmp_path / "py" / "meta.json").read_text())
    assert meta["complete"] is True and meta["sample_rate"] == 100
    prov = meta["provenance"]
    assert prov["scenario"]["source"] == "preset" and prov["scenario"]["name"] == "single-tendon"
    assert prov["input"]["signal"] == "rows" and prov["integrator"]["method"]
    figures = gvsrom.plot(tmp_path / "py", tmp_path / "figs")
    assert figures["figures"], figures


def test_a_controllers_run_records_its_rate_and_a_run_ended_early_is_written(robot, tmp_path):
    robot.simulate(0.1, sample_rate=100, controller=lambda t, q, qd: -2.0, control_rate=50,
                   out=tmp_path / "ctrl")
    meta = json.loads((tmp_path / "ctrl" / "meta.json").read_text())
    assert meta["provenance"]["input"]["signal"] == "controller"
    assert meta["provenance"]["input"]["control_rate"] == 50

    class Stop(Exception):
        pass

    def gives_up(t, q, qd):
        if t > 0.05:
            raise Stop("controller gave up")
        return -2.0

    with pytest.raises(Stop):
        robot.simulate(0.1, sample_rate=100, controller=gives_up, out=tmp_path / "partial")
    meta = json.loads((tmp_path / "partial" / "meta.json").read_text())
    assert meta["complete"] is False, meta
    assert meta["t_reached"] == 0.05 and meta["reason"].startswith("the controller raised") and \
        meta["reason"].endswith("Stop: controller gave up"), meta
    t = np.load(tmp_path / "partial" / "t.npy")
    np.testing.assert_allclose(t, np.arange(6) / 100, rtol=0, atol=1e-15)


def test_the_output_rules_of_the_command_line(robot, tmp_path):
    d = tmp_path / "run"
    robot.simulate(0.02, out=d)
    with pytest.raises(gvsrom.GvsromError,
                       match=r"^out `.*`: exists \(a gvsrom trajectory output\); pass force=True"):
        robot.simulate(0.02, out=d)
    robot.simulate(0.02, out=d, force=True)
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    with pytest.raises(gvsrom.GvsromError, match=r"^out `.*`: .*not .*gvsrom"):
        robot.simulate(0.02, out=foreign, force=True)
    assert (foreign / "notes.txt").read_text() == "keep me"
    with pytest.raises(gvsrom.GvsromError, match=r"`force` replaces an earlier output at `out`"):
        robot.simulate(0.02, force=True)


def test_a_scenario_given_as_text_is_recorded_as_text(tmp_path):
    text = gvsrom.Scenario.preset("single-tendon").to_toml()
    robot = gvsrom.Scenario.from_toml(text).build()
    robot.simulate(0.02, out=tmp_path / "run")
    prov = json.loads((tmp_path / "run" / "meta.json").read_text())["provenance"]
    assert prov["scenario"]["source"] == "text" and "path" not in prov["scenario"], prov["scenario"]
    assert prov["scenario_toml"] == gvsrom.Scenario.from_toml(text).to_toml()


def test_a_refused_controller_value_is_the_recorded_reason(robot, tmp_path):
    with pytest.raises(gvsrom.GvsromError, match=r"`controller\(0, q, qd\)`.*tendons\[0\]"):
        robot.simulate(0.05, sample_rate=100, controller=lambda t, q, qd: -1e9, out=tmp_path / "far")
    meta = json.loads((tmp_path / "far" / "meta.json").read_text())
    assert meta["complete"] is False
    assert "`controller(0, q, qd)`" in meta["reason"] and "tendons[0]" in meta["reason"], meta["reason"]


def test_a_constant_tension_is_named_in_a_note_instead_of_a_figure(robot, tmp_path):
    robot.simulate(0.03, sample_rate=100, controller=lambda t, q, qd: -2.0, out=tmp_path / "run")
    figures = gvsrom.plot(tmp_path / "run", tmp_path / "figs")
    assert "tensions: held at -2 N over the run (not drawn)" in figures["notes"], figures["notes"]
    assert not any(f.startswith("tensions") for f in figures["figures"])



_EULER_COLUMN = """
name = "euler-column"
[material]
youngs_modulus = 1e6
poisson_ratio = 0.45
density = 1000.0
damping = 0
[[divisions]]
length = 0.5
radius = 0.01
basis = { kind = "legendre", modes = ["bend_y", "bend_z", "elongation", "shear_y", "shear_z"], order = 4 }
[loads]
gravity = [0, 0, 0]
[[loads.point]]
x = 0.5
force = [-5.0, 0, 0]
frame = "global"
"""


def test_a_run_from_a_diverging_equilibrium_warns_and_records_it(tmp_path):
    # 5 N along the axis, 64× the Euler load π² EI / 4L² = 0.078 N: the straight equilibrium is
    # the one found, and it diverges
    robot = gvsrom.Scenario.from_toml(_EULER_COLUMN).build()
    with pytest.warns(UserWarning, match=r"the equilibrium the run starts from diverges"):
        tr = robot.simulate(0.05, from_equilibrium=True, out=tmp_path / "run")
    assert tr["start_divergence"] < 0
    meta = json.loads((tmp_path / "run" / "meta.json").read_text())
    assert meta["start_divergence"] == tr["start_divergence"]
    assert "start_divergence" not in robot.simulate(0.05)


def test_compare_measures_a_run_as_the_command_line_does(gvsrom_bin, robot, tmp_path):
    fine = robot.simulate(0.1, sample_rate=100, input=np.array([[0.0, -3.0]]), rtol=1e-8, out=tmp_path / "fine")
    loose = robot.simulate(0.1, sample_rate=100, input=np.array([[0.0, -3.0]]), rtol=1e-2, out=tmp_path / "loose")
    c = gvsrom.compare(tmp_path / "fine", tmp_path / "loose")
    p = run_cli(gvsrom_bin, "compare", str(tmp_path / "fine"), str(tmp_path / "loose"), "--json",
                str(tmp_path / "c.json"))
    assert p.returncode == 0, p.stderr
    cli = json.loads((tmp_path / "c.json").read_text())
    assert c["comparison"] == cli["comparison"] and c["differ"] == cli["differ"] == []
    # the tip error in % of the length, against the arrays themselves
    tip = np.linalg.norm(fine["tip_position"] - loose["tip_position"], axis=1) / 0.25 * 100
    assert abs(c["comparison"]["tip_max"] - tip.max()) < 1e-9 * max(1.0, tip.max())
    assert c["comparison"]["samples"] == len(fine["t"]) == 11
    # runs of other inputs are refused, naming the Python arguments, unless allowed
    robot.simulate(0.1, sample_rate=100, input=np.array([[0.0, -2.0]]), out=tmp_path / "other")
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.compare(tmp_path / "fine", tmp_path / "other")
    text = str(e.value)
    assert "invalid `run`" in text and "allow_different=True" in text, text
    anyway = gvsrom.compare(tmp_path / "fine", tmp_path / "other", allow_different=True)
    assert anyway["differ"], anyway
