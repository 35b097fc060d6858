"""crates/gvsrom-py/examples/rom_tracking.py: a reduced model's statics in the control loop."""

from conftest import load_example


def test_the_roms_inverse_statics_tracks_the_tip_as_the_full_models_does(tmp_path, capsys):
    # Over half the reference's period (1.5 s; the example's default run is 6 s), measured
    # 2026-12-07: the AE-1's inverse statics within 5.7e-3 N of the full model's over the
    # reference; tip error RMS 2.96 % L with the ROM's feedforward alone, 0.322 % L with the PI,
    # and 0.322 % L with the full model's statics instead of the ROM's; 1.95 equilibria per call,
    # 1.96 Newton iterations per call for the ROM and 20.2 for the full model
    rows, du = load_example("rom_tracking").main([str(tmp_path / "run"), "--duration", "1.5"])
    table = capsys.readouterr().out
    assert "| rom+pi |" in table and "| hom+pi |" in table, table
    # the ROM's equilibria put the tip where the full model's do: the tensions agree within
    # 0.02 N, a tenth of a percent of the 6 N range (a model off by its training error's tenfold
    # would miss it)
    assert du < 0.02, du
    # feedback on the measured tip removes most of the feedforward's lag ...
    assert rows["rom+pi"]["rms"] < 0.2 * rows["rom"]["rms"], rows
    # ... and the ROM in the loop tracks as the full model in the loop does
    assert abs(rows["rom+pi"]["rms"] - rows["hom+pi"]["rms"]) < 0.05 * rows["hom+pi"]["rms"], rows
    assert rows["rom+pi"]["max"] < 0.01, rows  # below 1 % L
    # the secant warm-started from the last period: about two equilibria per call, each reached
    assert all(r["solves"] < 3.0 and r["unconverged"] == 0 for r in rows.values()), rows
    # the reduced model starts each equilibrium from its training anchors (one Newton iteration
    # or two), the full model from the straight rod (about ten)
    assert rows["rom+pi"]["newton"] < 0.3 * rows["hom+pi"]["newton"], rows
    for name in ["rom", "rom+pi", "hom+pi"]:
        assert (tmp_path / "run" / name / "meta.json").exists()
