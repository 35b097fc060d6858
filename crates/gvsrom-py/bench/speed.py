"""Speed of the Python package against the command line and the Rust library, in one run
(the figures of docs/speed.md, "From Python").

From the repository root, in the virtualenv the package is installed in (release build):

    cargo build --release -p gvsrom
    maturin develop --release -m crates/gvsrom-py/Cargo.toml
    python crates/gvsrom-py/bench/speed.py            # --help for the options

It prints two comparisons, each timed several times, interleaved, with medians:

1. ``robot.statics_batch(U)`` of the 1000 IV-A tensions against ``gvsrom dataset single-tendon
   --sweep tendons.0.tension=-6:3 --samples 1000`` (U: that dataset's own inputs), both on
   ``--threads`` threads: the ratio Python / CLI, against the command's wall time (process and
   files included) and against the solve time it prints. Target: ≤ 1.2. Also
   ``statics_batch(U, warm_start=False)`` (every row from straight, as ``statics(U[k])``).
2. One AE-ROM equilibrium at u = −2.7 N, ``robot.with_model(model).statics(u)`` (timeit), against
   the same calls from Rust (``cargo bench -p gvsrom --bench rom_statics``, criterion's median),
   on the same model: the difference per call. Target: ≤ 10 µs. The model (r = 1, 7 hidden
   layers, 300 epochs on 200 IV-A equilibria) is made once with ``gvsrom dataset`` and
   ``gvsrom train`` under ``<target>/bench-data/iv-a-ae``. Also ``robot.statics(u, model=model)``,
   which builds the scenario at u and attaches the model on every call.

Timings depend on the machine and its load: read the ratios and differences, not the times.
"""

import argparse
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
TENSION = -2.7


def parse_args() -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--gvsrom", type=Path, default=TARGET / "release" / "gvsrom",
                   help="the command-line binary (release build)")
    p.add_argument("--threads", type=int, default=2, help="threads of the batch and the dataset")
    p.add_argument("--repeat", type=int, default=5, help="timings of each batch contender")
    p.add_argument("--samples", type=int, default=1000, help="IV-A tensions of the batch")
    p.add_argument("--calls", type=int, default=200, help="ROM solves per Python timing sample")
    p.add_argument("--only", choices=["batch", "rom"], help="run one comparison only")
    p.add_argument("--skip-rust", action="store_true",
                   help="do not run the Rust bench (comparison 2 then shows Python alone)")
    return p.parse_args()


def run(*cmd: str, **kw) -> subprocess.CompletedProcess:
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    if p.returncode != 0:
        sys.exit(f"failed: {' '.join(map(str, cmd))}\n{p.stdout}\n{p.stderr}")
    return p


def median(xs):
    return statistics.median(xs)


def batch_comparison(args) -> None:
    import numpy as np

    work = Path(tempfile.mkdtemp(prefix="gvsrom-speed-"))
    plan = ["single-tendon", "--sweep", "tendons.0.tension=-6:3", "--samples", str(args.samples),
            "--threads", str(args.threads)]

    def cli():
        out = work / "ds"
        t0 = time.perf_counter()
        p = run(args.gvsrom, "dataset", *plan, "--out", out, "--force")
        wall = time.perf_counter() - t0
        m = re.search(r"solved .* in ([0-9.]+) s on (\d+) threads", p.stdout)
        if not m or int(m.group(2)) != args.threads:
            sys.exit(f"unexpected `gvsrom dataset` summary:\n{p.stdout}")
        return wall, float(m.group(1))

    cli()  # warm the file cache; its inputs are the batch's rows
    U = np.load(work / "ds" / "inputs.npy").reshape(-1, 1)
    q_cli = np.load(work / "ds" / "q.npy")
    robot = gvsrom.Scenario.preset("single-tendon").build()
    first = robot.statics_batch(U)
    same = np.array_equal(first.q, q_cli)

    walls, solves, warm, cold = [], [], [], []
    for _ in range(args.repeat):
        w, s = cli()
        walls.append(w)
        solves.append(s)
        t0 = time.perf_counter()
        robot.statics_batch(U)
        warm.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        robot.statics_batch(U, warm_start=False)
        cold.append(time.perf_counter() - t0)
    shutil.rmtree(work)

    cw, cs, pw, pc = median(walls), median(solves), median(warm), median(cold)
    print(f"1. statics_batch of {len(U)} IV-A tensions vs `gvsrom dataset` of the same plan, "
          f"{args.threads} threads, medians of {args.repeat} interleaved runs")
    print(f"   gvsrom dataset             wall {cw * 1e3:8.1f} ms   (solves, as it prints: {cs * 1e3:.1f} ms)")
    print(f"   statics_batch(U)                {pw * 1e3:8.1f} ms   ratio {pw / cw:.2f} to the wall time, "
          f"{pw / cs:.2f} to the solves   (target <= 1.2)")
    print(f"   statics_batch(U, warm_start=False) {pc * 1e3:5.1f} ms   ratio {pc / cw:.2f} to the wall time")
    print(f"   q equal to the dataset's q.npy: {same}")


def model_dir(args) -> Path:
    data = TARGET / "bench-data"
    model = data / "iv-a-ae"
    try:
        gvsrom.load_model(model)
        return model
    except ValueError:
        pass
    data.mkdir(parents=True, exist_ok=True)
    print(f"   (making the model {model}: dataset and training, about a minute)")
    run(args.gvsrom, "dataset", "single-tendon", "--sweep", "tendons.0.tension=-6:3",
        "--samples", "200", "--out", data / "iv-a-200", "--force")
    run(args.gvsrom, "train", data / "iv-a-200", "--latent", "1", "--hidden-layers", "7",
        "--epochs", "300", "--out", model, "--force")
    return model


def python_rom_calls(robot, u, calls, timer) -> list:
    """The time per call [s] of 25 timeit samples of `calls` calls each (criterion's samples
    likewise hold many calls each), by `timer`."""
    t = timeit.repeat(lambda: robot.statics(u), number=calls, repeat=25, timer=timer)
    return [x / calls for x in t]


def rust_rom_call(model: Path) -> tuple:
    """criterion's median time of the library calls of one solve [s] (bench `rom_statics`), in
    wall-clock and in CPU time."""
    env = dict(os.environ, GVSROM_BENCH_MODEL=str(model), CARGO_TARGET_DIR=str(TARGET))
    run("cargo", "bench", "-p", "gvsrom", "--bench", "rom_statics", "--", "--noplot",
        "rom_statics/ae_r1_solve_under", cwd=ROOT, env=env)

    def estimate(name):
        path = TARGET / "criterion" / f"rom_statics_{name}" / "new" / "estimates.json"
        return json.loads(path.read_text())["median"]["point_estimate"] * 1e-9

    return estimate("ae_r1_solve_under"), estimate("ae_r1_solve_under_cpu")


def rom_comparison(args) -> None:
    import numpy as np

    model = model_dir(args)
    m = gvsrom.load_model(model)
    base = gvsrom.Scenario.preset("single-tendon").build()
    robot = base.with_model(m)
    u = np.array([TENSION])
    one = robot.statics(u)
    assert one.n_dof == 1
    clocks = {"wall": time.perf_counter, "cpu": time.process_time}
    before = {k: python_rom_calls(robot, u, args.calls, c) for k, c in clocks.items()}
    rust = dict(zip(clocks, rust_rom_call(model))) if not args.skip_rust else None
    after = {k: python_rom_calls(robot, u, args.calls, c) for k, c in clocks.items()}
    rebuild = median(timeit.repeat(lambda: base.statics(u, model=m), number=20, repeat=5)) / 20
    print(f"2. one AE-ROM equilibrium (r = 1, {model}) at u = {TENSION} N: "
          f"{one.iterations} iteration(s), {one.residual_evaluations} residuals; medians of "
          f"criterion's samples and of 25 × {args.calls} Python calls before and after the bench")
    for k in clocks:
        py = median(before[k] + after[k])
        line = (f"   {k:4} Python {py * 1e6:7.1f} µs (before {median(before[k]) * 1e6:.1f}, "
                f"after {median(after[k]) * 1e6:.1f})")
        if rust is not None:
            line += (f"   Rust {rust[k] * 1e6:7.1f} µs   difference {(py - rust[k]) * 1e6:+.1f} µs"
                     "   (target <= +10 µs)")
        print(line)
    print(f"   wall Python robot.statics(u, model=m) {rebuild * 1e6:8.1f} µs   (builds the scenario and "
          "attaches the model at every call)")


if __name__ == "__main__":
    args = parse_args()
    # the extension's thread pool reads this when it starts
    os.environ["RAYON_NUM_THREADS"] = str(args.threads)
    import gvsrom  # noqa: E402

    if not args.gvsrom.is_file():
        sys.exit(f"{args.gvsrom}: no such binary (cargo build --release -p gvsrom, or --gvsrom)")
    print(f"gvsrom {gvsrom.__file__}; CLI {args.gvsrom}; {os.cpu_count()} cores")
    if args.only != "rom":
        batch_comparison(args)
    if args.only != "batch":
        rom_comparison(args)
