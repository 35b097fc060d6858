#!/usr/bin/env python3
"""Copies the docstrings of the compiled module into the hand-kept stubs
(`python/gvsrom/__init__.pyi`), so that IDEs that read only the stubs (Pylance, PyCharm) show
them on hover. From the repository root, with the Python `gvsrom` is installed in:

    target/py-venv/bin/python crates/gvsrom-py/scripts/sync_stub_docs.py          # rewrites them
    target/py-venv/bin/python crates/gvsrom-py/scripts/sync_stub_docs.py --check  # 1 if stale

Every module-level function and class of the stubs, and every method, static/class method and
property of those classes, whose runtime object (`gvsrom.X`, `vars(gvsrom.C)[name]`; for a
property the descriptor's) has a non-empty `__doc__`, gets that docstring (`inspect.cleandoc`) as
the first statement of its body: it replaces the stub's docstring or its `...` body (a one-line
`def f(...) -> T: ...` becomes a def with the docstring on the next line). Only those docstrings
change; the rest of the file is kept byte for byte, and a run on synced stubs changes nothing.
`--check` writes nothing: it lists the items whose stub docstring differs from the runtime's
(`ast.get_docstring(node)` against `inspect.cleandoc(obj.__doc__)`) and exits 1 if there are any.
Items with no runtime docstring, or not in the module, are left as they are and listed as notes.

Overloads: the docstring goes on the last `@overload` only, and the others must carry none. A
stub has no implementation to take it from, so Pylance (pyright) takes it from the overloads:
hovering the name shows the first docstring found among them, and (recent Pylance) hovering a
call, or the active signature of the signature help, borrows a sibling overload's when the matched
one has none; only the inactive entries of the signature help show nothing. One copy is thus
enough, and it sits where the implementation's would be in a `.py` file.

Attribute annotations (`x: int`) are not touched: they have no runtime object of their own.
"""

from __future__ import annotations

import argparse
import ast
import inspect
import sys
import types
import unicodedata
from pathlib import Path
from typing import Any, Iterator, NamedTuple, Optional, Union

STUB = Path(__file__).resolve().parent.parent / "python" / "gvsrom" / "__init__.pyi"
RUN = "python crates/gvsrom-py/scripts/sync_stub_docs.py"

_Def = Union[ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef]
_MISSING = object()


class _Item(NamedTuple):
    name: str  # "presets", "Scenario", "Scenario.preset", "Statics.u"
    node: _Def
    doc: Optional[str]  # the docstring the stub must carry; None: none (an overload but the last)


def _decorator_names(node: _Def) -> list[str]:
    names = []
    for d in node.decorator_list:
        if isinstance(d, ast.Call):
            d = d.func
        if isinstance(d, ast.Name):
            names.append(d.id)
        elif isinstance(d, ast.Attribute):
            names.append(d.attr)
    return names


def _runtime_doc(obj: Any) -> tuple[Optional[str], Optional[str]]:
    """The cleaned docstring of a runtime object, or why there is none to take."""
    if obj is _MISSING:
        return None, "not in the module at runtime"
    if isinstance(obj, (staticmethod, classmethod)):
        obj = obj.__func__
    if not (
        isinstance(obj, type)
        or inspect.isroutine(obj)
        or isinstance(obj, (property, types.GetSetDescriptorType, types.MemberDescriptorType))
    ):
        # e.g. a plain value, whose __doc__ would be its type's
        return None, f"a {type(obj).__name__} at runtime, not a class, routine or property"
    doc = obj.__doc__
    if not isinstance(doc, str) or not doc.strip():
        return None, "no docstring at runtime"
    return inspect.cleandoc(doc), None


def _functions(
    body: list[ast.stmt], owner: str, lookup: Any, notes: list[str]
) -> Iterator[_Item]:
    """The items of the function definitions directly in `body`; `lookup(name)` gives the runtime
    object (or _MISSING)."""
    groups: dict[str, list[Union[ast.FunctionDef, ast.AsyncFunctionDef]]] = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            groups.setdefault(node.name, []).append(node)
    for name, nodes in groups.items():
        qualname = f"{owner}.{name}" if owner else name
        # a property's setter and deleter: Pylance shows the getter's docstring
        nodes = [
            n for n in nodes if not {"setter", "deleter", "getter"} & set(_decorator_names(n))
        ]
        if not nodes:
            continue
        overloads = [n for n in nodes if "overload" in _decorator_names(n)]
        targets = [overloads[-1]] if overloads else nodes
        doc, why = _runtime_doc(lookup(name))
        if doc is None:
            notes.append(f"{qualname}: {why}")
        for n in nodes:
            if n in targets:
                if doc is not None:
                    yield _Item(qualname, n, doc)
            elif n in overloads:
                yield _Item(f"{qualname} (overload of line {n.lineno})", n, None)


def _items(tree: ast.Module, module: Any, notes: list[str]) -> Iterator[_Item]:
    yield from _functions(tree.body, "", lambda name: getattr(module, name, _MISSING), notes)
    for node in tree.body:
        if not isinstance(node, ast.ClassDef):
            continue
        cls = getattr(module, node.name, _MISSING)
        doc, why = _runtime_doc(cls)
        if doc is None:
            notes.append(f"{node.name}: {why}")
        else:
            yield _Item(node.name, node, doc)
        if isinstance(cls, type):
            # the class's own members only: an inherited one's docstring is its base's
            members = vars(cls)
            yield from _functions(
                node.body, node.name, lambda name: members.get(name, _MISSING), notes
            )


def _escape(doc: str) -> str:
    """`doc` as the inside of a triple-double-quoted literal whose value is `doc`."""
    out = []
    quotes = 0  # unescaped double quotes just written
    for i, ch in enumerate(doc):
        if ch == '"':
            # never three in a row, nor one just before the closing quotes
            if quotes == 2 or i == len(doc) - 1:
                out.append('\\"')
                quotes = 0
            else:
                out.append('"')
                quotes += 1
            continue
        quotes = 0
        if ch == "\\":
            out.append("\\\\")
        elif ch != "\n" and unicodedata.category(ch) in ("Cc", "Zl", "Zp"):
            code = ord(ch)
            out.append(f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}")
        else:
            out.append(ch)
    return "".join(out)


def render(doc: str, indent: str, newline: str = "\n") -> str:
    """The docstring literal of `doc` (cleaned), for a body indented by `indent`: one line, or the
    text from the opening quotes on, its other lines indented, the closing quotes on their own."""
    lines = _escape(doc).split("\n")
    if len(lines) == 1:
        return f'"""{lines[0]}"""'
    rest = [indent + line if line else "" for line in lines[1:]]
    return '"""' + newline.join([lines[0], *rest, indent]) + '"""'


class _Source:
    """The stub's bytes, addressed as `ast` addresses them (line, UTF-8 byte column)."""

    def __init__(self, data: bytes):
        self.data = data
        self.newline = "\r\n" if b"\r\n" in data else "\n"
        self.starts = [0]
        for i, b in enumerate(data):
            if b == 0x0A:
                self.starts.append(i + 1)

    def offset(self, line: int, col: int) -> int:
        return self.starts[line - 1] + col

    def next_line(self, line: int) -> int:
        """The offset just after the line's newline (the end of the data for the last line)."""
        return self.starts[line] if line < len(self.starts) else len(self.data)

    def before(self, node: ast.stmt) -> bytes:
        """The bytes of the node's line before it."""
        return self.data[self.starts[node.lineno - 1] : self.offset(node.lineno, node.col_offset)]


def _is_docstring(stmt: ast.stmt) -> bool:
    return (
        isinstance(stmt, ast.Expr)
        and isinstance(stmt.value, ast.Constant)
        and isinstance(stmt.value.value, str)
    )


def _is_ellipsis(stmt: ast.stmt) -> bool:
    return (
        isinstance(stmt, ast.Expr)
        and isinstance(stmt.value, ast.Constant)
        and stmt.value.value is ...
    )


def _edit(src: _Source, item: _Item) -> Optional[tuple[int, int, bytes]]:
    """The replacement (start, end, bytes) that gives the item's node its docstring, or None if the
    node's body has no place for it."""
    node, first = item.node, item.node.body[0]
    start = src.offset(first.lineno, first.col_offset)
    end = src.offset(first.end_lineno or first.lineno, first.end_col_offset or 0)
    head = src.before(first)
    own_line = head.strip() == b""
    nl = src.newline
    if item.doc is None:  # an overload other than the last: `...` instead of its docstring
        line_end = src.next_line(first.end_lineno or first.lineno)
        if len(node.body) > 1 and own_line and src.data[end:line_end].strip() == b"":
            return src.starts[first.lineno - 1], line_end, b""  # its lines; what follows stays
        return start, end, b"..."
    if own_line:
        indent = head.decode()
    else:
        indent = src.before(node).decode() + "    "
    literal = render(item.doc, indent, nl)
    if _is_docstring(first) or _is_ellipsis(first):
        if own_line:
            return start, end, literal.encode()
        # `def f(...) -> T: ...  # comment`: the colon ends the line, the comment stays on it (a
        # `# type: ignore` applies to its line), the docstring follows on the next
        stripped = head.rstrip()
        line_end = src.next_line(first.end_lineno or first.lineno)
        tail = src.data[end:line_end].rstrip(b"\r\n")
        if not stripped.endswith(b":") or tail.strip()[:1] not in (b"", b"#"):
            return None  # e.g. `def f(): x; ...`
        cut = src.starts[first.lineno - 1] + len(stripped)
        keep = tail if tail.strip() else b""
        return cut, end + len(tail), keep + (nl + indent + literal).encode()
    if not own_line:
        return None
    blank = nl if isinstance(node, ast.ClassDef) else ""
    return start, start, (literal + nl + blank + indent).encode()


class Result(NamedTuple):
    text: bytes  # the stubs with the runtime's docstrings
    stale: list[str]  # the items whose docstring differs, and how
    notes: list[str]  # the items left as they are, and why


def sync_text(data: bytes, module: Any) -> Result:
    """The stub bytes `data` with the docstrings of `module`."""
    tree = ast.parse(data)
    src = _Source(data)
    stale: list[str] = []
    notes: list[str] = []
    edits: list[tuple[int, int, bytes]] = []
    for item in sorted(_items(tree, module, notes), key=lambda item: item.node.lineno):
        current = ast.get_docstring(item.node, clean=True)
        if current == item.doc:
            continue
        if item.doc is None:
            stale.append(f"{item.name}: carries a docstring; only the last overload may")
        elif current is None:
            stale.append(f"{item.name}: no docstring in the stubs")
        else:
            stale.append(f"{item.name}: the stub's docstring differs from the runtime's")
        edit = _edit(src, item)
        if edit is None:
            notes.append(f"{item.name}: its body has no place for a docstring; not changed")
        else:
            edits.append(edit)
    out = data
    for start, end, new in sorted(edits, reverse=True):
        out = out[:start] + new + out[end:]
    return Result(out, stale, notes)


def _module(module: Any) -> Any:
    if module is None:
        import gvsrom

        module = gvsrom
    return module


def check(path: Union[str, Path] = STUB, module: Any = None) -> list[str]:
    """The items of the stubs at `path` whose docstring differs from the runtime's (`module`,
    default `gvsrom`), each with how; empty when in sync."""
    return sync_text(Path(path).read_bytes(), _module(module)).stale


def sync(path: Union[str, Path] = STUB, module: Any = None) -> Result:
    """Writes the runtime's docstrings into the stubs at `path` (not if nothing changes)."""
    path = Path(path)
    data = path.read_bytes()
    result = sync_text(data, _module(module))
    if result.text != data:
        path.write_bytes(result.text)
    return result


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--check", action="store_true", help="list the stale docstrings, write nothing, exit 1 if any"
    )
    parser.add_argument("--stub", type=Path, default=STUB, help=f"the stub file (default: {STUB})")
    args = parser.parse_args(argv)
    if args.check:
        result = sync_text(args.stub.read_bytes(), _module(None))
    else:
        result = sync(args.stub)
    for note in result.notes:
        print(f"note: {note}", file=sys.stderr)
    if args.check:
        if result.stale:
            print(f"{len(result.stale)} stub docstrings differ from the module's (run `{RUN}`):")
            print("\n".join(f"  {s}" for s in result.stale))
            return 1
        print("stub docstrings match the module's")
        return 0
    if result.stale:
        print(f"{len(result.stale)} docstrings written to {args.stub}")
    else:
        print("stub docstrings already match the module's")
    return 0


if __name__ == "__main__":
    sys.exit(main())
