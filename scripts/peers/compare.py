#!/usr/bin/env python3
"""Tip error and wall time of peer runs against a reference run (docs/speed.md, "Against open peers").

    python scripts/peers/compare.py [--figure PNG] REF LABEL=DIR [LABEL=DIR ...] [LABEL=COARSE+FINE ...]

Every DIR holds `t.npy` and `tip_position.npy` (101 samples of the 1 s release at 100 Hz) and its
timing: gvsrom's `meta.json` (`wall_time_s`, the integrator's wall time) or a peer script's
`timing.json` (`run_s`, the median of the timed runs after compilation). The tip error is
|p - p_ref| over the run, in % of the rod's length, mean and max. `COARSE+FINE` (two runs of a
first-order method, the second with half the element length and step) compares the Richardson
extrapolation `2 p_fine - p_coarse` instead, the limit the method converges to. Prints a Markdown
table. `A|B|C` (runs of the same settings, one trajectory) times by the median of their wall times.
`--figure PNG` (a new file; needs matplotlib) also draws the tip's height against time for
the reference and the coarsest and finest run of each code (the label's text before the first
comma names the code), and every run's mean tip error against its wall time.
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


def figure(path, t_ref, ref, runs):
    """Tip height against time, and mean tip error against wall time, one colour per code."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    codes = list(dict.fromkeys(label.split(",")[0] for label, *_ in runs))
    colour = {c: f"C{i}" for i, c in enumerate(codes)}
    fig, (ax_t, ax_e) = plt.subplots(1, 2, figsize=(12, 4.8))
    ax_t.plot(t_ref, ref[:, 2], color="k", lw=2.5, label="reference (gvsrom, order 10)")
    for code in codes:
        own = [r for r in runs if r[0].split(",")[0] == code and "extrapolat" not in r[0]]
        for k, (label, t, tip, _, _) in enumerate([own[0], own[-1]] if len(own) > 1 else own):
            ax_t.plot(t, tip[:, 2], color=colour[code], ls="--" if k == 0 else "-", lw=1.2, label=label)
    ax_t.set(xlabel="t [s]", ylabel="tip height z [m]", title="Tip of the released cantilever")
    low, high = ax_t.get_ylim()
    ax_t.set_ylim(low, high + 0.45 * (high - low))  # room above the curves for the legend
    ax_t.legend(fontsize=6.5, loc="upper center", ncol=2, framealpha=0.9)
    for code in codes:
        own = [r for r in runs if r[0].split(",")[0] == code and "extrapolat" not in r[0]]
        ax_e.loglog([r[3] for r in own], [r[4] for r in own], "o-", color=colour[code], label=code)
        for label, _, _, wall, err in own:
            ax_e.annotate(label.split(", ", 1)[-1], (wall, err), fontsize=6, xytext=(3, 3),
                          textcoords="offset points")
    ax_e.set(xlabel="wall time of 1 s simulated [s]", ylabel="mean tip error [% L]",
             title="Accuracy against cost (lower left is better)")
    ax_e.grid(True, which="both", alpha=0.3)
    ax_e.legend(fontsize=8)
    fig.tight_layout()
    path = pathlib.Path(path)
    if path.exists():
        raise SystemExit(f"--figure {path} exists; give a new file")
    fig.savefig(path, dpi=130)


def main():
    args = sys.argv[1:]
    fig_path = None
    if args[:1] == ["--figure"]:
        fig_path, args = args[1], args[2:]
    if len(args) < 2:
        raise SystemExit(__doc__)
    runs = []
    t_ref, ref, _, _ = load(args[0])
    print("| run | settings | tip error mean / max [% L] | wall time [s] |")
    print("|---|---|---|---|")
    for arg in args[1:]:
        label, _, d = arg.partition("=")
        if "+" in d:
            coarse, fine = d.split("+")
            t, tip_c, _, _ = load(coarse)
            _, tip_f, wall, settings = load(fine)
            tip = 2.0 * tip_f - tip_c
            names = f"{pathlib.Path(coarse).name} and {pathlib.Path(fine).name}"
            settings = f"Richardson extrapolation of {names}"
        elif "|" in d:
            loaded = [load(x) for x in d.split("|")]
            t, tip, _, settings = loaded[0]
            if any(np.max(np.abs(other[1] - tip)) > 0.0 for other in loaded[1:]):
                raise SystemExit(f"{label}: the repeated runs differ")
            wall = float(np.median([x[2] for x in loaded]))
            settings += f" (median of {len(loaded)} runs)"
        else:
            t, tip, wall, settings = load(d)
        if t.shape != t_ref.shape or np.max(np.abs(t - t_ref)) > 1e-9:
            raise SystemExit(f"{d}: its samples are not at the reference's times")
        err = np.linalg.norm(tip - ref, axis=1) / LENGTH * 100
        print(f"| {label} | {settings} | {err.mean():.3g} / {err.max():.3g} | {wall:.3g} |")
        runs.append((label, t, tip, wall, err.mean()))
    if fig_path:
        figure(fig_path, t_ref, ref, runs)


if __name__ == "__main__":
    main()
