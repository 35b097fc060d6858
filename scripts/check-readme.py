#!/usr/bin/env python3
"""Runs every command that README.md shows and fails if one fails.

Every line of a ```sh block is run with bash, in order, in one scratch directory (a copy of
`examples/` is placed there, so the README's paths resolve), with `gvsrom` on the PATH. The
exceptions are stated here and nowhere else:

- `cargo …` lines are the build and the tests themselves, which `.ci/run` runs; they are skipped.
- `export PATH=…` lines only put the binary on the PATH, which this script does.
- `scripts/check-readme.py` is this check.

Every ```python block is run with the Python interpreter given by `--python` (default: this one;
CI passes the venv of the Python package, which has NumPy and `gvsrom`)
after the shell blocks before it, in the same directory. If that interpreter has no NumPy the
Python blocks are reported as not run and the check fails, unless `--skip-python` is given.

A command may say in a trailing comment that the check runs it at a reduced size:
`… --samples 20000 --out x   # checked with --samples 400` replaces the option's value (or adds
the option) before running. The README shows the full command; the check states its size.

Usage: scripts/check-readme.py [--bin PATH/TO/gvsrom] [--keep DIR] [--python PY] [--skip-python]
The binary defaults to target/release/gvsrom, else target/debug/gvsrom (built by `cargo test`).
"""

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FENCE = re.compile(r"^```(\w*)\s*$")
CHECKED_WITH = re.compile(r"#\s*checked with\s+(.*)$")


def blocks(readme: str):
    """(language, first line number, lines) of every fenced block."""
    out, lang, start, body = [], None, 0, []
    for n, line in enumerate(readme.splitlines(), 1):
        m = FENCE.match(line)
        if lang is None and m:
            lang, start, body = m.group(1), n + 1, []
        elif lang is not None and line.strip() == "```":
            out.append((lang, start, body))
            lang = None
        elif lang is not None:
            body.append(line)
    if lang is not None:
        sys.exit(f"README.md: the block opened at line {start - 1} is never closed")
    return out


def shell_commands(start: int, lines):
    """(line number, command) of a sh block: continuation lines joined, comments dropped."""
    cmds, cur, first = [], "", start
    for k, line in enumerate(lines):
        if not cur:
            first = start + k
        stripped = line.rstrip()
        if stripped.endswith("\\"):
            cur += stripped[:-1] + " "
            continue
        cur += stripped
        if cur.strip() and not cur.lstrip().startswith("#"):
            cmds.append((first, cur.strip()))
        cur = ""
    if cur.strip():
        cmds.append((first, cur.strip()))
    return cmds


def strip_comment(cmd: str):
    """The command without its trailing `# …` comment (outside quotes), and the comment."""
    quote = None
    for i, c in enumerate(cmd):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or cmd[i - 1].isspace()):
            return cmd[:i].rstrip(), cmd[i:]
    return cmd, ""


def reduce_size(cmd: str, comment: str) -> str:
    """Applies `# checked with --opt value …` to `cmd`."""
    m = CHECKED_WITH.search(comment)
    if not m:
        return cmd
    words = shlex.split(cmd)
    new = shlex.split(m.group(1))
    i = 0
    while i < len(new):
        opt = new[i]
        value = new[i + 1] if i + 1 < len(new) and not new[i + 1].startswith("--") else None
        i += 2 if value is not None else 1
        if opt in words:
            j = words.index(opt)
            if value is not None:
                words[j + 1] = value
        else:
            words += [opt] + ([value] if value is not None else [])
    return shlex.join(words)


def find_binary(given):
    if given:
        return Path(given).resolve()
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "gvsrom"
        if p.is_file():
            return p
    sys.exit("no gvsrom binary: build it (cargo build --release) or pass --bin")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", help="the gvsrom binary to run")
    ap.add_argument("--keep", help="run in this new directory and keep it")
    ap.add_argument("--python", default=sys.executable, help="interpreter for the python blocks")
    ap.add_argument("--skip-python", action="store_true", help="do not run the python blocks")
    ap.add_argument("--readme", default=str(ROOT / "README.md"), help="the file to check")
    args = ap.parse_args()

    binary = find_binary(args.bin)
    # the blocks run in the scratch directory: a relative interpreter path is made absolute (not
    # resolved: a venv's python is a link that must stay the venv's)
    if os.sep in args.python:
        args.python = os.path.abspath(args.python)
    readme = Path(args.readme).read_text()
    if args.keep:
        work = Path(args.keep).resolve()
        work.mkdir(parents=True)
    else:
        work = Path(tempfile.mkdtemp(prefix="gvsrom-readme-"))
    bindir = work / ".bin"
    bindir.mkdir()
    (bindir / "gvsrom").symlink_to(binary)
    shutil.copytree(ROOT / "examples", work / "examples")
    env = dict(os.environ, PATH=f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}")

    has_numpy = (
        not args.skip_python
        and subprocess.run(
            [args.python, "-c", "import numpy"], capture_output=True
        ).returncode
        == 0
    )
    ran, skipped, failed = 0, [], []
    t_all = time.monotonic()
    for lang, start, lines in blocks(readme):
        if lang == "sh":
            for line_no, cmd in shell_commands(start, lines):
                cmd, comment = strip_comment(cmd)
                if not cmd:
                    continue
                if cmd.startswith("cargo "):
                    skipped.append((line_no, cmd, "cargo: run by .ci/run itself"))
                    continue
                if cmd.startswith("scripts/check-readme.py"):
                    skipped.append((line_no, cmd, "the check itself"))
                    continue
                if cmd.startswith("export PATH="):
                    skipped.append((line_no, cmd, "the check puts gvsrom on the PATH"))
                    continue
                cmd = reduce_size(cmd, comment)
                t0 = time.monotonic()
                r = subprocess.run(
                    ["bash", "-euo", "pipefail", "-c", cmd],
                    cwd=work, env=env, capture_output=True, text=True,
                )
                dt = time.monotonic() - t0
                ran += 1
                status = "ok" if r.returncode == 0 else f"FAILED (exit {r.returncode})"
                print(f"README.md:{line_no}: {status} in {dt:.1f} s: {cmd}", flush=True)
                if r.returncode != 0:
                    failed.append(line_no)
                    sys.stdout.write(r.stdout[-2000:])
                    sys.stdout.write(r.stderr[-2000:])
        elif lang == "python":
            if args.skip_python:
                skipped.append((start, "python block", "--skip-python"))
                continue
            if not has_numpy:
                print(f"README.md:{start}: FAILED: {args.python} has no NumPy (use --python or --skip-python)")
                failed.append(start)
                continue
            t0 = time.monotonic()
            r = subprocess.run(
                [args.python, "-c", "\n".join(lines)],
                cwd=work, env=env, capture_output=True, text=True,
            )
            ran += 1
            status = "ok" if r.returncode == 0 else f"FAILED (exit {r.returncode})"
            print(f"README.md:{start}: {status} in {time.monotonic() - t0:.1f} s: python block", flush=True)
            if r.returncode != 0:
                failed.append(start)
                sys.stdout.write(r.stdout[-2000:])
                sys.stdout.write(r.stderr[-2000:])
    for line_no, cmd, why in skipped:
        print(f"README.md:{line_no}: not run ({why}): {cmd}")
    print(
        f"{ran} commands run in {time.monotonic() - t_all:.0f} s, {len(failed)} failed, "
        f"{len(skipped)} not run; in {work}"
    )
    if not args.keep and not failed:
        shutil.rmtree(work)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
