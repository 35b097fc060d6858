"""plot: the figures of gvsrom outputs drawn from Python as `gvsrom plot` draws them — a
linearization written by the CLI, a POD model made from Python; the files are the CLI's, the
PNGs decode; bad input is a GvsromError naming what is wrong."""

import json
import struct

import pytest

import gvsrom
from conftest import run_cli


def png_size(path):
    """Width and height from a PNG's IHDR chunk (a PNG must start with its signature)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", data[16:24])


def test_a_linearization_and_a_model_are_drawn_as_the_cli_draws_them(gvsrom_bin, tmp_path):
    lin = tmp_path / "lin.json"
    p = run_cli(gvsrom_bin, "linearize", "six-tendon", "--output-at", "0.3,0.6", "--json", str(lin))
    assert p.returncode == 0, p.stderr
    r = gvsrom.plot(lin, tmp_path / "figs")
    assert r["kind"] == "linearization"
    assert sorted(r["figures"]) == ["poles.png", "poles.svg", "static_gain.png", "static_gain.svg"]
    assert r["out"] == tmp_path / "figs"
    w, h = png_size(tmp_path / "figs" / "static_gain.png")
    assert w >= 600 and h >= 400
    assert json.loads((tmp_path / "figs" / "meta.json").read_text())["kind"] == "linearization"
    # the same figures as the command line's, byte for byte
    p = run_cli(gvsrom_bin, "plot", str(lin), "--out", str(tmp_path / "cli-figs"))
    assert p.returncode == 0, p.stderr
    for name in r["figures"]:
        assert (tmp_path / "figs" / name).read_bytes() == (tmp_path / "cli-figs" / name).read_bytes(), name

    # a model made from Python; one format
    ds = tmp_path / "ds"
    gvsrom.dataset("single-tendon", ds, sweep=["tendons.0.tension=-6:0"], samples=7)
    gvsrom.pod(ds, 2, tmp_path / "model")
    r = gvsrom.plot(tmp_path / "model", tmp_path / "model-figs", formats=["svg"])
    assert r["kind"] == "reduced model" and all(f.endswith(".svg") for f in r["figures"])
    # again: only with force
    with pytest.raises(gvsrom.GvsromError, match="force"):
        gvsrom.plot(tmp_path / "model", tmp_path / "model-figs")
    gvsrom.plot(tmp_path / "model", tmp_path / "model-figs", force=True)


def test_bad_input_is_a_clear_error(tmp_path):
    with pytest.raises(gvsrom.GvsromError, match="no such file"):
        gvsrom.plot(tmp_path / "missing.json", tmp_path / "out")
    (tmp_path / "x.json").write_text("{}")
    with pytest.raises(gvsrom.GvsromError, match="no gvsrom manifest"):
        gvsrom.plot(tmp_path / "x.json", tmp_path / "out")
    with pytest.raises(gvsrom.GvsromError, match=r"`formats`: unknown image format `jpg`"):
        gvsrom.plot(tmp_path / "x.json", tmp_path / "out", formats=["jpg"])
    # the input is named as Python names it, not as the command line's INPUT
    with pytest.raises(gvsrom.GvsromError, match=r"^output `.*missing.json`"):
        gvsrom.plot(tmp_path / "missing.json", tmp_path / "out")
    # one format as a str is a list of one; an empty list draws nothing and is refused, not taken
    # as the default; a list of something else is a TypeError naming `formats`
    with pytest.raises(gvsrom.GvsromError, match=r"`formats`: unknown image format `jpg`"):
        gvsrom.plot(tmp_path / "x.json", tmp_path / "out", formats="jpg")
    with pytest.raises(gvsrom.GvsromError, match=r"`formats`: an empty list draws nothing"):
        gvsrom.plot(tmp_path / "x.json", tmp_path / "out", formats=[])
    with pytest.raises(TypeError, match=r"`formats`: expected a str or a list of str; got int"):
        gvsrom.plot(tmp_path / "x.json", tmp_path / "out", formats=3)
    assert not (tmp_path / "out").exists()


def test_one_format_given_as_a_str_draws_only_it(tmp_path):
    ds = gvsrom.dataset("single-tendon", tmp_path / "ds", sweep="tendons.0.tension=-6:0", samples=4)
    r = gvsrom.plot(ds.path, tmp_path / "figs", formats="svg")
    assert r["figures"] and all(f.endswith(".svg") for f in r["figures"]), r["figures"]

