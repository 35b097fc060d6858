#!/usr/bin/env python3
"""IV-B at r = 1: how close can the paper's *decoder* of each depth come to the data? (JAX, float64)

Table I's r = 1 cells are the RMSE of `D(E(x))`. Whatever the encoder, that error is at least the
distance from each snapshot to the nearest point of the decoder's curve `{D(z)}`: a perfect
encoder would return that point's code. So the smallest such distance a decoder of the paper's
shape can reach is a floor under the cell at that depth (3, 5 or 7 hidden layers: decoders
1-74-148, 1-37-74-148 and 1-18-37-74-148 for IV-B's 148 values, tanh, linear output).

The floor is estimated as a principal curve (Hastie and Stuetzle) whose curve is the decoder:
start from the codes of a K-pass fan (`ae_fan_code.py`), fit the decoder to them, then alternate
(1) each snapshot's code := the nearest point of the decoder's curve (a grid of `--grid` codes) and
(2) the decoder refitted to those codes by `--lbfgs` full-batch L-BFGS iterations, for `--rounds`
rounds, keeping the best curve. With `--lambda 0` (the default) nothing penalises the weights, so
the estimate is a floor for eq. (15) with any λ — up to the local optimum the search finds, which
is why it runs over several K and seeds.

RMSE over every value of every snapshot, physical units (Table I's measure), one JSON line:

    .venv/bin/python scripts/ae_decoder_bound.py DATASET --hidden-layers 3 --bands 8
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

from ae_fan_code import fan_codes, fit, forward, glorot, nearest, physical_scaling, squares  # noqa: E402
from ae_reference import load  # noqa: E402


def decoder_sizes(n: int, hidden_layers: int) -> list[int]:
    """The decoder's layer sizes, latent first: the encoder's halving sizes reversed."""
    enc = [n]
    for _ in range((hidden_layers - 1) // 2):
        enc.append(enc[-1] // 2)
    return [1] + enc[::-1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("--hidden-layers", type=int, default=3)
    ap.add_argument("--bands", type=int, default=8)
    ap.add_argument("--first-layer-scale", type=float, default=10.0)
    ap.add_argument("--epochs", type=int, default=200, help="Adam epochs of the first fit")
    ap.add_argument("--lbfgs", type=int, default=1000, help="L-BFGS iterations per fit")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--grid", type=int, default=8001)
    ap.add_argument("--lambda", dest="lam", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    t0 = time.time()

    y_np, scale = physical_scaling(load(a.dataset))
    rows, n = y_np.shape
    y = jnp.asarray(y_np)
    lam = a.lam / n
    rng = np.random.default_rng(a.seed)
    sizes = decoder_sizes(n, a.hidden_layers)
    dec = glorot(sizes, jax.random.PRNGKey(a.seed), a.first_layer_scale)
    every = np.arange(rows)
    grid = np.linspace(-1.3, 1.3, a.grid)[:, None]

    def project(dec):
        """Each snapshot's nearest code on the grid, and the RMSE [physical units] there."""
        codes, ms = nearest(dec, y_np, grid)
        return codes, float(np.sqrt(ms) * scale)

    def refit(dec, z, epochs):
        z = jnp.asarray(z)
        return fit(dec, lambda p, i: jnp.mean((forward(p, z[i]) - y[i]) ** 2) + lam * squares(p),
                   every, epochs, a.lbfgs, 3e-3, rng)

    dec = refit(dec, fan_codes(y_np, a.bands), a.epochs)
    z, err = project(dec)
    history = [err]
    best = err
    for _ in range(a.rounds):
        dec = refit(dec, z, 0)
        z, err = project(dec)
        history.append(err)
        best = min(best, err)
    out = {"rows": rows, "decoder_sizes": sizes, "floor": best, "history": history,
           "sum_w2": float(squares(dec)), "seconds": time.time() - t0}
    print(json.dumps({**vars(a), **out}, default=str))


if __name__ == "__main__":
    main()
