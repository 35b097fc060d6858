"""The hand-kept stubs (`__init__.pyi`) match the compiled module, and every public item has a
docstring."""

import subprocess
import sys

import pytest

import gvsrom


def test_stubs_match_the_module():
    pytest.importorskip("mypy")
    p = subprocess.run([sys.executable, "-m", "mypy.stubtest", "gvsrom"], capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr


def test_every_public_class_method_and_function_has_a_docstring():
    missing = []
    for name in gvsrom.__all__:
        obj = getattr(gvsrom, name)
        if name.startswith("__"):
            continue
        if not (obj.__doc__ or "").strip():
            missing.append(name)
        if isinstance(obj, type) and not issubclass(obj, Exception):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and not (getattr(member, "__doc__", "") or "").strip():
                    missing.append(f"{name}.{attr}")
    assert missing == []
