#!/usr/bin/env python3
"""Six-tendon inputs of the IV-C2 kind with linear transitions instead of steps, as CSV for
`gvsrom dataset|simulate six-tendon --input FILE --interpolate`.

    python scripts/ramped_inputs.py babble 180 0.2 0 babble.csv   # holds U[0.5, 1] s per tendon
    python scripts/ramped_inputs.py steps 10 0.2 2 test2.csv       # every tendon changes each 1 s

Arguments: KIND (babble | steps), duration T [s], transition RAMP [s], SEED, output file. Values
are drawn uniformly in [-15, 0] N (the paper's range); the run starts from 0 N and reaches the
first values after RAMP. Draws come from NumPy's `default_rng(SEED)`, not from gvsrom's `--babble`
and `--steps`, so the sequences differ from those (the distribution is the same).
"""

import sys

import numpy as np


def main() -> None:
    if len(sys.argv) != 6 or sys.argv[1] not in ("babble", "steps"):
        raise SystemExit(__doc__)
    kind, duration, ramp = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
    seed, out = int(sys.argv[4]), sys.argv[5]
    if not 0.0 < ramp < 0.5:
        raise SystemExit(f"RAMP = {ramp}: expected 0 < RAMP < 0.5 s (shorter than a hold)")
    rng = np.random.default_rng(seed)
    tracks = []
    for _ in range(6):
        v = rng.uniform(-15.0, 0.0)
        t, pts = 0.0, [(0.0, 0.0), (ramp, v)]
        while True:
            t += rng.uniform(0.5, 1.0) if kind == "babble" else 1.0
            if t >= duration:
                break
            new = rng.uniform(-15.0, 0.0)
            pts += [(t, v), (min(t + ramp, duration), new)]
            v = new
        pts.append((duration, v))
        tracks.append(pts)
    times = sorted({p[0] for tr in tracks for p in tr})
    with open(out, "w") as f:
        f.write("t,u_1,u_2,u_3,u_4,u_5,u_6\n")
        for t in times:
            vals = [np.interp(t, [p[0] for p in tr], [p[1] for p in tr]) for tr in tracks]
            f.write(f"{t:.6f}," + ",".join(f"{v:.6f}" for v in vals) + "\n")


if __name__ == "__main__":
    main()
