"""Scenario: presets, TOML text and files, `set` with the paths and errors of `--set`."""

import numpy as np
import pytest

import gvsrom
from conftest import cli_error


def test_presets_lists_the_built_in_scenarios():
    names = gvsrom.presets()
    assert "single-tendon" in names and "six-tendon" in names
    assert all(isinstance(v, str) and v for v in names.values())


def test_preset_builds_the_paper_robot_with_its_sizes():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    assert (robot.n_dof, robot.n_actuators, robot.length) == (33, 1, 0.25)
    assert robot.point_x.shape == (robot.n_points,)
    assert robot.section_inertia.shape == (robot.n_points, 6)


def test_unknown_preset_is_a_value_error_naming_the_presets():
    with pytest.raises(ValueError, match="unknown preset `nope`.*single-tendon"):
        gvsrom.Scenario.preset("nope")


def test_set_uses_the_paths_and_toml_values_of_the_command_line():
    s = gvsrom.Scenario.preset("six-tendon")
    s.set("tendons.0.tension", -2).set("tendons.1.tension", "-3.5").set("loads.gravity", [0, 0, -1.5])
    assert s.tensions[:2] == [-2.0, -3.5]
    assert s.overrides == ["tendons.0.tension=-2", "tendons.1.tension=-3.5", "loads.gravity=[0, 0, -1.5]"]
    tomllib = pytest.importorskip("tomllib")
    assert tomllib.loads(s.to_toml())["loads"]["gravity"] == [0.0, 0.0, -1.5]


def test_a_rejected_set_leaves_the_scenario_unchanged():
    s = gvsrom.Scenario.preset("single-tendon")
    before = s.to_toml()
    with pytest.raises(gvsrom.GvsromError):
        s.set("tendons.5.tension", 1.0)
    assert s.to_toml() == before and s.overrides == []


def test_to_toml_parses_back_to_the_same_scenario():
    text = gvsrom.Scenario.preset("soft-beam").set("divisions.0.basis.elements", 10).to_toml()
    assert gvsrom.Scenario.from_toml(text).to_toml() == text


def test_from_toml_reads_a_file_given_as_path_or_str(tmp_path):
    text = gvsrom.Scenario.preset("single-tendon").to_toml()
    f = tmp_path / "arm.toml"
    f.write_text(text)
    assert gvsrom.Scenario.from_toml(f).to_toml() == text
    assert gvsrom.Scenario.from_toml(str(f)).to_toml() == text


def test_missing_file_is_a_value_error():
    with pytest.raises(ValueError, match="not found"):
        gvsrom.Scenario.from_toml("no/such/file.toml")


def test_a_directory_given_as_str_is_refused_as_a_path_not_parsed_as_toml(tmp_path):
    # it was read as TOML text and failed with "<string>: not valid TOML … column 5"
    for given in (str(tmp_path), tmp_path):
        with pytest.raises(gvsrom.GvsromError, match=f"`{tmp_path}` is a directory"):
            gvsrom.Scenario.from_toml(given)


@pytest.mark.parametrize(
    "path, value, spec",
    [
        ("tendons.5.tension", 1.0, "tendons.5.tension=1.0"),
        ("material.colour", "red", "material.colour=red"),
        ("divisions.0.basis.order", "x", "divisions.0.basis.order=x"),
    ],
)
def test_set_errors_carry_the_message_of_the_command_line(gvsrom_bin, path, value, spec):
    expected = cli_error(gvsrom_bin, "check", "single-tendon", "--set", spec)
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.Scenario.preset("single-tendon").set(path, value)
    assert str(e.value) == expected


def test_build_errors_carry_the_message_of_the_command_line(gvsrom_bin):
    expected = cli_error(gvsrom_bin, "check", "single-tendon", "--set", "material.youngs_modulus=-1")
    s = gvsrom.Scenario.preset("single-tendon").set("material.youngs_modulus", -1)
    with pytest.raises(ValueError) as e:
        s.build()
    assert str(e.value) == expected


def test_copies_and_pickles_are_the_same_scenario_and_independent(tmp_path):
    import copy
    import pickle

    path = tmp_path / "beam.toml"
    path.write_text(gvsrom.Scenario.preset("soft-beam").to_toml())
    for original in [gvsrom.Scenario.preset("single-tendon").set("tendons.0.tension", -2.5),
                     gvsrom.Scenario.from_toml(path).set("material.density", 1100.0)]:
        for other in [copy.copy(original), copy.deepcopy(original), original.copy(),
                      pickle.loads(pickle.dumps(original))]:
            assert other.to_toml() == original.to_toml()
            assert (other.name, other.overrides) == (original.name, original.overrides)
            other.set("material.damping", 123.0)
            assert "123" not in original.to_toml().split("damping")[1].split("\n")[0]
    # a pickle holds the file's text as it was read, not the path
    from_file = gvsrom.Scenario.from_toml(path)
    blob = pickle.dumps(from_file)
    path.unlink()
    assert pickle.loads(blob).to_toml() == from_file.to_toml()


def test_set_while_another_thread_builds_is_not_refused():
    # build() held the scenario borrowed while it built without the GIL: a set() from another
    # thread then raised pyo3's "RuntimeError: Already borrowed"
    import threading

    import time

    s = gvsrom.Scenario.preset("six-tendon")
    errors = []
    built = [0]
    done = threading.Event()

    def builds():
        try:
            while not done.is_set():
                s.build()
                built[0] += 1
        except Exception as e:  # noqa: BLE001 - any error fails the test below
            errors.append(e)

    t = threading.Thread(target=builds)
    t.start()
    # set while the other thread builds, until both have run a while (however the machine's load
    # schedules the two threads: a fixed number of builds could end before the first set)
    k = 0
    deadline = time.monotonic() + 60.0
    while (k < 200 or built[0] < 5) and not errors and time.monotonic() < deadline:
        s.set("tendons.0.tension", -1.0 - (k % 5))
        k += 1
    done.set()
    t.join()
    assert errors == [] and k >= 200 and built[0] >= 5, (errors, k, built[0])


def test_a_tendon_the_basis_cannot_hold_is_warned_about_at_build():
    # a helical tendon on the planar single-tendon basis would twist the rod, which the basis lacks
    s = gvsrom.Scenario.preset("single-tendon").set("tendons.0.turns", 0.5)
    with pytest.warns(UserWarning, match=r"tendons\[0\] also loads torsion, bend_z, shear_y, which the "
                                         r"basis of division 0 lacks"):
        s.build()
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gvsrom.Scenario.preset("single-tendon").build()


def test_a_precurved_rod_records_its_reference_strain_and_rests_on_it():
    straight = gvsrom.Scenario.preset("single-tendon").build()
    assert np.array_equal(straight.strain_reference,
                          np.tile([0.0, 0.0, 0.0, 1.0, 0.0, 0.0], (straight.n_points, 1)))
    robot = (gvsrom.Scenario.preset("single-tendon")
             .set("divisions.0.reference_strain", [0, 3, 0, 1, 0, 0])
             .set("loads.gravity", [0, 0, 0]).set("tendons.0.tension", 0).build())
    star = robot.strain_reference
    assert star.shape == (robot.n_points, 6)
    assert np.array_equal(star, np.tile([0.0, 3.0, 0.0, 1.0, 0.0, 0.0], (robot.n_points, 1)))
    # unloaded, the rod rests at q = 0 on its arc: its strain is ξ* (a deviation of zero)
    eq = robot.statics()
    assert np.abs(eq.q).max() < 1e-12
    assert np.abs(eq.strain - star).max() < 1e-12


def test_a_divisions_own_material_sets_its_sections():
    # six-tendon: two divisions of 0.3 m, E = 1 MPa, ν = ½, ρ = 1000; the second at E = 5 MPa
    # and ρ = 2000: its sections' stiffness and inertia follow, the first division's do not
    base = gvsrom.Scenario.preset("six-tendon")
    robot = (base.copy().set("divisions.1.material.youngs_modulus", 5e6)
             .set("divisions.1.material.density", 2000.0).build())
    plain = base.build()
    second = robot.point_x > 0.3 + 1e-12
    first = robot.point_x < 0.3 - 1e-12
    np.testing.assert_array_equal(robot.section_stiffness[first], plain.section_stiffness[first])
    np.testing.assert_allclose(robot.section_stiffness[second], 5 * plain.section_stiffness[second],
                               rtol=1e-15)
    np.testing.assert_allclose(robot.section_inertia[second], 2 * plain.section_inertia[second],
                               rtol=1e-15)
    np.testing.assert_array_equal(robot.section_inertia[first], plain.section_inertia[first])
    # at the junction, two points: the first division's end, of its material, then the second's
    # start, of the second's
    at = np.flatnonzero(np.abs(robot.point_x - 0.3) < 1e-12)
    assert len(at) == 2, robot.point_x
    np.testing.assert_array_equal(robot.section_stiffness[at[0]], plain.section_stiffness[at[0]])
    np.testing.assert_allclose(robot.section_stiffness[at[1]], 5 * plain.section_stiffness[at[1]],
                               rtol=1e-15)
    assert "material" in robot.scenario.to_toml().split("[[divisions]]")[2]
    with pytest.raises(gvsrom.GvsromError, match=r"divisions\[1\]\.material\.poisson_ratio"):
        base.copy().set("divisions.1.material.poisson_ratio", 0.7).build()
