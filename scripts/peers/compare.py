#!/usr/bin/env python3
"""Tip error and wall time of peer runs against a reference run (docs/speed.md, "Against open peers").

    python scripts/peers/compare.py REF LABEL=DIR [LABEL=DIR ...] [LABEL=COARSE+FINE ...]

Every DIR holds `t.npy` and `tip_position.npy` (101 samples of the 1 s release at 100 Hz) and its
timing: gvsrom's `meta.json` (`wall_time_s`, the integrator's wall time) or a peer script's
`timing.json` (`run_s`, the median of the timed runs after compilation). The tip error is
|p - p_ref| over the run, in % of the rod's length, mean and max. `COARSE+FINE` (two runs of a
first-order method, the second with half the element length and step) compares the Richardson
extrapolation `2 p_fine - p_coarse` instead, the limit the method converges to. Prints a Markdown
table.
"""
import json
import pathlib
import sys

import numpy as np

LENGTH = 0.5


def load(d):
    d = pathlib.Path(d)
    t, tip = np.load(d / "t.npy"), np.load(d / "tip_position.npy")
    if (d / "meta.json").exists():
        meta = json.loads((d / "meta.json").read_text())
        steps = f"{meta['steps']} steps ({meta['failed_steps']} failed)"
        return t, tip, meta["wall_time_s"], f"{meta['n_dof']} DOF, {steps}"
    info = json.loads((d / "timing.json").read_text())
    summary = info.get("summary") or ", ".join(f"{k} {v}" for k, v in info["settings"].items())
    return t, tip, info["run_s"], summary


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    t_ref, ref, _, _ = load(sys.argv[1])
    print("| run | settings | tip error mean / max [% L] | wall time [s] |")
    print("|---|---|---|---|")
    for arg in sys.argv[2:]:
        label, _, d = arg.partition("=")
        if "+" in d:
            coarse, fine = d.split("+")
            t, tip_c, _, _ = load(coarse)
            _, tip_f, wall, settings = load(fine)
            tip = 2.0 * tip_f - tip_c
            names = f"{pathlib.Path(coarse).name} and {pathlib.Path(fine).name}"
            settings = f"Richardson extrapolation of {names}"
        else:
            t, tip, wall, settings = load(d)
        if t.shape != t_ref.shape or np.max(np.abs(t - t_ref)) > 1e-9:
            raise SystemExit(f"{d}: its samples are not at the reference's times")
        err = np.linalg.norm(tip - ref, axis=1) / LENGTH * 100
        print(f"| {label} | {settings} | {err.mean():.3g} / {err.max():.3g} | {wall:.3g} |")


if __name__ == "__main__":
    main()
