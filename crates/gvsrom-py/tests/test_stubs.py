"""The hand-kept stubs (`__init__.pyi`) match the compiled module, every public item has a
docstring, and the stubs carry the module's docstrings (for IDEs that read only the stubs)."""

import ast
import importlib.util
import subprocess
import sys
from pathlib import Path

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


def _sync_stub_docs():
    path = Path(__file__).resolve().parent.parent / "scripts" / "sync_stub_docs.py"
    spec = importlib.util.spec_from_file_location("sync_stub_docs", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_stub_docstrings_are_the_modules():
    sync = _sync_stub_docs()
    stale = sync.check(sync.STUB, gvsrom)
    assert stale == [], (
        f"{len(stale)} docstrings of {sync.STUB.name} differ from the module's; run `{sync.RUN}`:\n"
        + "\n".join(stale)
    )


def test_stub_docstring_check_finds_a_changed_docstring(tmp_path):
    # a scratch copy of the stubs with one docstring changed: the check names it, --check exits 1,
    # and a sync gives back the stubs as they are
    sync = _sync_stub_docs()
    text = sync.STUB.read_text(encoding="utf-8")
    tree = ast.parse(text)
    scenario = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Scenario")
    tensions = next(
        n for n in scenario.body if isinstance(n, ast.FunctionDef) and n.name == "tensions"
    )
    doc = tensions.body[0]
    assert ast.get_docstring(tensions) is not None
    lines = text.splitlines(keepends=True)
    lines[doc.lineno - 1 : doc.end_lineno] = [" " * doc.col_offset + '"""Something else."""\n']
    stub = tmp_path / "__init__.pyi"
    stub.write_text("".join(lines), encoding="utf-8")

    assert sync.check(stub, gvsrom) == [
        "Scenario.tensions: the stub's docstring differs from the runtime's"
    ]
    p = subprocess.run(
        [sys.executable, sync.__file__, "--check", "--stub", str(stub)],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 1 and "Scenario.tensions" in p.stdout, p.stdout + p.stderr
    sync.sync(stub, gvsrom)
    assert stub.read_text(encoding="utf-8") == text
