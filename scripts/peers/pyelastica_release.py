#!/usr/bin/env python3
"""PyElastica side of the peer comparison (docs/speed.md, "Against open peers").

The common problem: a uniform cantilever, 0.5 m long, solid circular section of radius 0.01 m,
E = 10 MPa, Poisson ratio 0.5 (G = E/3), density 1000 kg/m^3, no damping, clamped at the origin
along world +x, straight and at rest at t = 0, released under gravity (9.81 m/s^2 along -z) for
1 s. gvsrom's scenario of the same problem is `scripts/peers/gravity-release.toml`.

PyElastica (`pip install pyelastica`) discretizes the rod into `--elements` straight elements
(a discrete Cosserat rod: shear, extension, bending and twist, rotational inertia, lumped nodal
masses) and integrates with its explicit symplectic Position Verlet at the fixed step `--dt`.
Its shear stiffness is alpha_c G A with alpha_c = 27/28 (Kaneko); gvsrom's is G A, so the script
hands PyElastica G' = (28/27) G to model the same rod. Gravity: `GravityForces`; the clamp:
`OneEndFixedBC` on node 0 and director 0.

Writes DIR/t.npy (101,), DIR/tip_position.npy (101, 3) at 100 Hz and DIR/timing.json: the
numba compilation measured apart (a 20-step run of a fresh system first), then the median wall
time of `--repeat` full runs.

    python scripts/peers/pyelastica_release.py --elements 50 --dt 8e-5 --out pe50
"""
import argparse
import importlib.metadata
import json
import pathlib
import statistics
import time

import numpy as np
import elastica as ea

L, RADIUS, E, NU, RHO, G_ACC, T_END, RATE = 0.5, 0.01, 1e7, 0.5, 1000.0, 9.81, 1.0, 100


class Release(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.CallBacks):
    pass


class TipRecorder(ea.CallBackBaseClass):
    def __init__(self, every, out):
        super().__init__()
        self.every, self.out = every, out

    def make_callback(self, system, time, current_step):
        if current_step % self.every == 0:
            self.out.append((time, system.position_collection[:, -1].copy()))


def build(elements, every, out):
    sim = Release()
    g = E / (2.0 * (1.0 + NU))
    rod = ea.CosseratRod.straight_rod(
        elements,
        np.zeros(3),
        np.array([1.0, 0.0, 0.0]),  # direction: along +x
        np.array([0.0, 0.0, 1.0]),  # normal: +z, the plane of the sag
        L,
        RADIUS,
        RHO,
        youngs_modulus=E,
        shear_modulus=g * 28.0 / 27.0,  # alpha_c G' = G, gvsrom's G A
    )
    sim.append(rod)
    sim.constrain(rod).using(
        ea.OneEndFixedBC, constrained_position_idx=(0,), constrained_director_idx=(0,)
    )
    sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, 0.0, -G_ACC]))
    sim.collect_diagnostics(rod).using(TipRecorder, every=every, out=out)
    sim.finalize()
    return sim


def run(elements, dt, steps, every):
    out = []
    sim = build(elements, every, out)
    start = time.perf_counter()
    ea.integrate(ea.PositionVerlet(), sim, steps * dt, steps, progress_bar=False)
    return time.perf_counter() - start, out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, default=50)
    ap.add_argument("--dt", type=float, default=8e-5)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    every = round(1.0 / (RATE * a.dt))
    if abs(every * a.dt * RATE - 1.0) > 1e-9:
        ap.error(f"--dt {a.dt} must divide the output period 1/{RATE} s")
    steps = every * round(T_END * RATE)
    start = time.perf_counter()
    run(a.elements, a.dt, 20, every)
    compile_s = time.perf_counter() - start
    times = []
    for _ in range(a.repeat):
        wall, out = run(a.elements, a.dt, steps, every)
        times.append(wall)
    t = np.array([s[0] for s in out])
    tip = np.array([s[1] for s in out])
    if len(t) != round(T_END * RATE) + 1 or not np.all(np.isfinite(tip)):
        raise SystemExit(f"run failed or unstable: {len(t)} samples, finite: {np.all(np.isfinite(tip))}")
    d = pathlib.Path(a.out)
    d.mkdir(parents=True, exist_ok=False)
    np.save(d / "t.npy", t)
    np.save(d / "tip_position.npy", tip)
    info = {
        "peer": "pyelastica",
        "version": importlib.metadata.version("pyelastica"),
        "settings": {"elements": a.elements, "dt": a.dt, "steps": steps, "integrator": "PositionVerlet"},
        "summary": f"{a.elements} elements, Position Verlet dt {a.dt:g}, {steps} steps",
        "compile_s": compile_s,
        "run_s": statistics.median(times),
        "runs_s": times,
    }
    (d / "timing.json").write_text(json.dumps(info, indent=1))
    print(json.dumps(info))


if __name__ == "__main__":
    main()
