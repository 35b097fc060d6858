#!/usr/bin/env python3
"""IV-B at r = 1 with a fan-shaped code: which half of the autoencoder limits Table I? (JAX, float64)

IV-B's strain is linear in the moment, x(c, M) = M g(c): in the plane of the first two POD
coefficients every centre c is a line through the origin (M > 0 on one side, M < 0 on the other),
and the angle of the line grows with c. A "fan" code of the 2-D family cuts the angle into K bins of
equal count and, inside bin k, runs along the signed radius (the moment), alternately outwards and
inwards, so that consecutive passes meet at the outer end:

    z = (k + (1 ± ρ/ρ_max)/2) / K · 2 − 1        (+ for even k, − for odd k; z in [−1, 1])

Each pass is one straight line M g(c_k) through the origin, so the decoder must hold K ramps of
fixed shape — not K moving steps, as a serpentine of magnitude bands swept along the centre
(`scripts/ae_serpentine.py`) asks. The script measures each half of the paper's 7-hidden-layer
autoencoder (148-74-37-18-1 and back, tanh, linear code and output, eq. (15) with λ/n, the physical
loss: one common scale) in turn:

1. the decoder alone fitted to the fan codes (`--dec-epochs` Adam epochs at 3e-3 decaying to 3 %,
   then `--dec-lbfgs` full-batch L-BFGS iterations), its first layer's Glorot bound times
   `--first-layer-scale` (K passes need a steep first layer); `decoder` is its RMSE on the given
   codes, `projection` the RMSE of the nearest point of its curve to each snapshot (a grid of 4001
   codes): what a perfect encoder would give with this decoder;
2. the encoder fitted to those nearest codes (regression, the same schedule);
3. the encoder trained on eq. (15) of D(E(x)) with the decoder frozen (`--enc-ae-epochs` at 3e-4,
   then `--enc-ae-lbfgs`);
4. the whole autoencoder from there by `--whole-lbfgs` L-BFGS iterations of eq. (15).

RMSE over every value of every snapshot, physical units (Table I's measure), one JSON line:

    .venv/bin/python scripts/ae_fan_code.py DATASET --bands 16

DATASET is `gvsrom dataset soft-beam --random loads.distributed.0.center=0:0.8 --random
loads.distributed.0.magnitude=-5:5 --samples 5000 --seed 1` (`reproduce iv-b`'s).
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np

import jax
import jax.flatten_util

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402
import optax  # noqa: E402
from scipy.optimize import minimize  # noqa: E402

from ae_reference import load  # noqa: E402


def fan_codes(y: np.ndarray, bands: int) -> np.ndarray:
    """The fan code of every row of the centred, scaled snapshots `y` (module docs)."""
    _, _, vt = np.linalg.svd(y, full_matrices=False)
    a = y @ vt[:2].T
    # the axis of the double cone: half the mean doubled angle
    phi = 0.5 * np.arctan2(np.mean(2 * a[:, 0] * a[:, 1]), np.mean(a[:, 0] ** 2 - a[:, 1] ** 2))
    e = np.array([np.cos(phi), np.sin(phi)])
    f = np.array([-e[1], e[0]])
    side = np.where(a @ e < 0, -1.0, 1.0)
    folded = a * side[:, None]
    angle = np.arctan2(folded @ f, folded @ e)
    radius = side * np.linalg.norm(a, axis=1)
    band = np.searchsorted(np.quantile(angle, np.linspace(0, 1, bands + 1)[1:-1]), angle)
    t = radius / np.abs(radius).max()
    along = np.where(band % 2 == 0, (1 + t) / 2, (1 - t) / 2)
    return ((band + along) / bands * 2 - 1)[:, None]


def physical_scaling(x: np.ndarray) -> tuple[np.ndarray, float]:
    """The snapshots centred and divided by one common scale (the physical loss's), and the scale:
    the root mean of the values' variances."""
    scale = float(np.sqrt(np.mean(x.std(0) ** 2)))
    return (x - x.mean(0)) / scale, scale


def nearest(dec, y: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, float]:
    """The nearest of the decoder's points `D(grid)` to each row of `y`: its code, and the mean
    squared distance per value over all rows (scaled units)."""
    g = np.asarray(forward(dec, jnp.asarray(grid)))
    d = (y**2).sum(1)[:, None] - 2 * y @ g.T + (g**2).sum(1)[None]
    best = d.argmin(1)
    return grid[best], float(np.maximum(d[np.arange(len(y)), best], 0).mean() / y.shape[1])


def glorot(sizes, key, first_scale=1.0):
    layers = []
    for i, (p, q) in enumerate(zip(sizes[:-1], sizes[1:])):
        key, sub = jax.random.split(key)
        lim = np.sqrt(6.0 / (p + q)) * (first_scale if i == 0 else 1.0)
        layers.append((jax.random.uniform(sub, (p, q), minval=-lim, maxval=lim), jnp.zeros(q)))
    return layers


def forward(layers, h):
    for i, (w, b) in enumerate(layers):
        h = h @ w + b
        if i + 1 < len(layers):
            h = jnp.tanh(h)
    return h


def squares(layers):
    return sum(jnp.sum(w * w) for w, _ in layers)


def fit(params, loss, index, epochs, iterations, rate, rng):
    """Adam on batches of 64 of the rows `index` (the rate decaying to 3 %), then full-batch L-BFGS
    (scipy, no tolerance stop) on them; `loss(params, rows)`."""
    if epochs:
        opt = optax.adam(optax.exponential_decay(rate, epochs * -(-len(index) // 64), 0.03))
        state = opt.init(params)

        @jax.jit
        def step(p, st, idx):
            upd, st = opt.update(jax.grad(loss)(p, idx), st, p)
            return optax.apply_updates(p, upd), st

        for _ in range(epochs):
            perm = rng.permutation(len(index))
            for j in range(0, len(index), 64):
                params, state = step(params, state, jnp.asarray(index[perm[j : j + 64]]))
    if iterations:
        flat, unravel = jax.flatten_util.ravel_pytree(params)
        every = jnp.asarray(index)
        fg = jax.jit(jax.value_and_grad(lambda f: loss(unravel(f), every)))

        def fun(f):
            v, g = fg(jnp.asarray(f))
            return float(v), np.asarray(g)

        res = minimize(fun, np.asarray(flat), jac=True, method="L-BFGS-B",
                       options={"maxiter": iterations, "maxfun": 2 * iterations,
                                "gtol": 0, "ftol": 0})
        params = unravel(jnp.asarray(res.x))
    return params


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("--bands", type=int, default=16)
    ap.add_argument("--first-layer-scale", type=float, default=30.0)
    ap.add_argument("--dec-epochs", type=int, default=200)
    ap.add_argument("--dec-lbfgs", type=int, default=3000)
    ap.add_argument("--enc-epochs", type=int, default=200)
    ap.add_argument("--enc-lbfgs", type=int, default=2000)
    ap.add_argument("--enc-ae-epochs", type=int, default=100)
    ap.add_argument("--enc-ae-lbfgs", type=int, default=2000)
    ap.add_argument("--whole-lbfgs", type=int, default=3000)
    ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    t0 = time.time()

    y_np, scale = physical_scaling(load(a.dataset))
    rows, n = y_np.shape
    y = jnp.asarray(y_np)
    lam = a.lam / n
    rng = np.random.default_rng(a.seed)
    enc_sizes = [n, n // 2, n // 4, n // 8, 1]
    k_dec, k_enc = jax.random.split(jax.random.PRNGKey(a.seed))
    dec = glorot(enc_sizes[::-1], k_dec, a.first_layer_scale)
    enc = glorot(enc_sizes, k_enc)

    def rmse(pred) -> float:
        return float(np.sqrt(np.mean((np.asarray(pred) - y_np) ** 2)) * scale)

    grid = jnp.linspace(-1.2, 1.2, 4001)[:, None]

    def project(dec):
        """The nearest point of the decoder's curve to each snapshot: codes and RMSE."""
        codes, ms = nearest(dec, y_np, np.asarray(grid))
        return codes, float(np.sqrt(ms) * scale)

    out = {"bands": a.bands, "rows": rows}
    all_rows = np.arange(rows)
    z = jnp.asarray(fan_codes(y_np, a.bands))
    dec = fit(dec, lambda p, i: jnp.mean((forward(p, z[i]) - y[i]) ** 2) + lam * squares(p),
              all_rows, a.dec_epochs, a.dec_lbfgs, 3e-3, rng)
    out["decoder"] = rmse(forward(dec, z))
    nearest_codes, out["projection"] = project(dec)
    out["seconds_decoder"] = time.time() - t0

    z = jnp.asarray(nearest_codes)
    enc = fit(enc, lambda p, i: jnp.mean((forward(p, y[i]) - z[i]) ** 2) + lam * squares(p),
              all_rows, a.enc_epochs, a.enc_lbfgs, 3e-3, rng)
    out["ae_encoder_regressed"] = rmse(forward(dec, forward(enc, y)))
    enc = fit(enc, lambda p, i: jnp.mean((forward(dec, forward(p, y[i])) - y[i]) ** 2)
              + lam * squares(p), all_rows, a.enc_ae_epochs, a.enc_ae_lbfgs, 3e-4, rng)
    out["ae_decoder_frozen"] = rmse(forward(dec, forward(enc, y)))

    def whole(p, i):
        rec = forward(p[1], forward(p[0], y[i]))
        return jnp.mean((rec - y[i]) ** 2) + lam * (squares(p[0]) + squares(p[1]))

    enc, dec = fit((enc, dec), whole, all_rows, 0, a.whole_lbfgs, 0.0, rng)
    out["ae_whole"] = rmse(forward(dec, forward(enc, y)))
    out["projection_whole"] = project(dec)[1]
    out["seconds"] = time.time() - t0
    print(json.dumps({**vars(a), **out}, default=str))


if __name__ == "__main__":
    main()
