"""Shared fixtures: the `gvsrom` binary the Python results are compared with (GVSROM_BIN)."""

import json
import os
import signal
import subprocess
from pathlib import Path

import pytest

PRESETS = [
    "single-tendon",
    "soft-beam",
    "six-tendon",
    "soft-beam-peak",
    "six-tendon-no-gravity",
    "six-tendon-hanging",
]


@pytest.fixture(scope="session")
def gvsrom_bin() -> Path:
    """The command-line binary (`cargo build -p gvsrom`), from GVSROM_BIN."""
    path = os.environ.get("GVSROM_BIN")
    if not path or not Path(path).is_file():
        pytest.skip("GVSROM_BIN is not set to the gvsrom binary")
    return Path(path)


@pytest.fixture
def sigint_raises():
    """SIGINT raises KeyboardInterrupt for the test's duration, whatever the runner inherited: a
    shell's background job (`pytest … &`) starts with SIGINT ignored, and Python then installs no
    handler, so a test's Ctrl-C to itself would be lost and its long run never stopped."""
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)


def run_cli(bin_path: Path, *args: str) -> subprocess.CompletedProcess:
    """Runs `gvsrom ARGS`, returning the completed process (not checked)."""
    return subprocess.run([str(bin_path), *args], capture_output=True, text=True, timeout=600)


def cli_error(bin_path: Path, *args: str) -> str:
    """The message of a failing `gvsrom ARGS` as Python raises it: its stderr without the
    `error: ` prefix, the flags renamed to the keyword arguments as the binding renames them in
    every message (`--count` → `count`; test_argument_errors checks the renaming itself)."""
    from gvsrom._gvsrom import _python_spelling

    p = run_cli(bin_path, *args)
    assert p.returncode == 1, p.stdout + p.stderr
    line = p.stderr.strip().splitlines()[-1]
    assert line.startswith("error: "), line
    return _python_spelling(line[len("error: "):])


def cli_statics(bin_path: Path, tmp_path: Path, *args: str) -> dict:
    """`gvsrom statics ARGS --json F`, read back."""
    out = tmp_path / "statics.json"
    p = run_cli(bin_path, "statics", *args, "--json", str(out), "--force")
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text())


def load_example(name: str):
    """crates/gvsrom-py/examples/NAME.py as a module, for the tests that run it or use its parts."""
    import importlib.util

    path = Path(__file__).parents[1] / "examples" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
