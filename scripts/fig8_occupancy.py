#!/usr/bin/env python3
"""Fig. 8's measure for any r ≥ 3 autoencoder, through gvsrom's Python API: the share of the cells
of an n × n × n grid over the bounding box of the training codes' first three principal components
that hold at least one code (n = round((N/4)^(1/3)), as `gvsrom reproduce iv-c1` computes it).

    python scripts/fig8_occupancy.py DATASET MODEL [DATASET MODEL …]

e.g. the grid- and random-trained models of `reproduce iv-c1` (RUN/steps/iv-c1/fig8-grid with
fig8-ae-grid, fig8-random with fig8-ae-random) or others trained on the same datasets with
`gvsrom train DATASET --latent 6 --hidden-layers 7 --epochs 1000 --seed S --out M`.
"""

import sys

import numpy as np

import gvsrom


def occupancy(dataset: str, model: str) -> float:
    ds = gvsrom.load_dataset(dataset)
    x = ds.strain.reshape(len(ds.status), -1)[ds.status == 0]
    z = gvsrom.load_model(model, extrapolate=True).encode(x)
    c = z - z.mean(0)
    _, _, vt = np.linalg.svd(c, full_matrices=False)
    p = c @ vt[:3].T
    bins = max(int(round((len(p) / 4) ** (1 / 3))), 2)
    lo, hi = p.min(0), p.max(0)
    cell = np.minimum(((p - lo) / np.where(hi > lo, hi - lo, 1.0) * bins).astype(int), bins - 1)
    return len(np.unique((cell[:, 0] * bins + cell[:, 1]) * bins + cell[:, 2])) / bins**3


def main() -> None:
    args = sys.argv[1:]
    if not args or len(args) % 2:
        raise SystemExit(__doc__)
    for dataset, model in zip(args[::2], args[1::2]):
        print(f"{occupancy(dataset, model) * 100:.1f} %  {model} on {dataset}")


if __name__ == "__main__":
    main()
