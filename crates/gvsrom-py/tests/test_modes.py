"""modes: the numbers of `gvsrom modes --json`, as arrays; each shape solves the generalized
eigenproblem with the model quantities."""

import json

import numpy as np
import pytest

import gvsrom
from conftest import cli_error, run_cli


def cli_modes(bin_path, tmp_path, *args):
    out = tmp_path / "modes.json"
    p = run_cli(bin_path, "modes", *args, "--json", str(out), "--force")
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


@pytest.mark.parametrize("preset,tension", [("single-tendon", "-4"), ("six-tendon", None)])
def test_modes_equal_the_cli_json(gvsrom_bin, tmp_path, preset, tension):
    args = [f"--tension={tension}"] if tension else []
    cli = cli_modes(gvsrom_bin, tmp_path, preset, *args, "--count", "4")
    robot = gvsrom.Scenario.preset(preset).build()
    m = robot.modes(4, u=[float(tension)]) if tension else robot.modes(4)
    assert len(m["frequency_hz"]) == 4 == len(cli["modes"])
    for name in ["frequency_hz", "omega_squared", "shape", "strain_energy_share", "tip_displacement",
                 "tip_rotation", "strain", "centerline_shape"]:
        expected = np.array([mode[name] for mode in cli["modes"]])
        np.testing.assert_allclose(m[name], expected, rtol=0, atol=1e-12 * max(1.0, np.abs(expected).max()),
                                   err_msg=name)
    assert m["dominant_strain"] == [mode["dominant_strain"] for mode in cli["modes"]]
    for name in ["all_frequencies_hz", "q0", "u", "strain_x", "equilibrium_tip_position", "centerline_x",
                 "centerline"]:
        np.testing.assert_allclose(m[name], cli[name], rtol=0, atol=1e-12 * max(1.0, np.abs(cli[name]).max()),
                                   err_msg=name)


def test_each_mode_solves_k_phi_equals_omega_squared_m_phi():
    robot = gvsrom.Scenario.preset("single-tendon").build()
    m = robot.modes(3)
    q0 = m["q0"]
    M = robot.mass_matrix(q0)
    J = robot.statics_jacobian(q0)
    # tendon friction: K_T is not symmetric, and the modes are the eigenpairs of M⁻¹ K_T itself
    KT = -J
    assert np.abs(KT - KT.T).max() > 1e-3 * np.abs(KT).max()
    for w2, phi in zip(m["omega_squared"], m["shape"]):
        assert phi @ M @ phi == pytest.approx(1.0, rel=1e-9)
        np.testing.assert_allclose(KT @ phi, w2 * (M @ phi), rtol=0, atol=1e-7 * np.abs(KT @ phi).max())
    assert np.all(np.diff(m["frequency_hz"]) >= 0)
    # the centreline's modal displacement is the position Jacobian times the shape
    _, Jp = robot.position_jacobian(q0, m["centerline_x"])
    np.testing.assert_allclose(m["centerline_shape"], np.einsum("can,kn->kca", Jp, m["shape"]),
                               rtol=0, atol=1e-12 * np.abs(m["centerline_shape"]).max())


def test_a_count_below_one_is_refused_with_the_cli_message(gvsrom_bin):
    expected = cli_error(gvsrom_bin, "modes", "single-tendon", "--count", "0")
    with pytest.raises(gvsrom.GvsromError) as e:
        gvsrom.Scenario.preset("single-tendon").build().modes(0)
    assert str(e.value) == expected
