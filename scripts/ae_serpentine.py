#!/usr/bin/env python3
"""Can the paper's 1-D decoder hold a code that folds K times through the IV-B family? (JAX, float64)

IV-B's strain is linear in the moment: x(c, M) = M g(c) (c the pulse's centre, M its total moment).
A natural 1-D code of this 2-D family is a serpentine: K bands of the magnitude, each swept along
the centre, alternately up and down. With every sample at the centre of its band the RMSE is that of
quantizing M to K levels — printed as the bound `exact`. This script fits the paper's 7-layer decoder
(r = 1: 1-18-37-74-n, tanh, linear output, eq. (15) with λ/n) to the snapshots *given* their
serpentine codes z ∈ [-1, 1] (no encoder), to see whether the architecture can hold such a curve:

    .venv/bin/python scripts/ae_serpentine.py DATASET --bands 10 --epochs 3000 --learning-rate 3e-3 \
        --first-layer-scale 10

DATASET is `gvsrom dataset soft-beam --random loads.distributed.0.center=0:0.8 --random
loads.distributed.0.magnitude=-5:5 --samples 5000 --seed 1` (or `reproduce iv-b`'s). Its inputs
must be (centre, magnitude) in that order.

`--whole` trains the whole autoencoder instead (the encoder 148-74-37-18-1 too): the loss is eq. (15)
of `D(E(x))`, plus `--code-weight` × the mean squared distance of `E(x)` from the serpentine code,
plus the decoder's error on the given codes; its `--lbfgs` phase minimises the same loss, and
`--release N` more L-BFGS iterations minimise eq. (15) alone. `rmse_ae` is the autoencoder's
RMSE, `rmse` the decoder's on the given codes. `--first-layer-scale` multiplies the Glorot bound of the
decoder's first layer (larger: more folds at the start). RMSE over the whole dataset, physical units.
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path)
    ap.add_argument("--bands", type=int, default=10)
    ap.add_argument("--epochs", type=int, default=3000)
    ap.add_argument("--learning-rate", type=float, default=3e-3)
    ap.add_argument("--first-layer-scale", type=float, default=1.0)
    ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--lbfgs", type=int, default=0,
                    help="then this many full-batch L-BFGS iterations (scipy) from Adam's weights")
    ap.add_argument("--whole", action="store_true", help="train an encoder too (see above)")
    ap.add_argument("--code-weight", type=float, default=1.0)
    ap.add_argument("--release", type=int, default=0,
                    help="--whole: then this many L-BFGS iterations of eq. (15) alone")
    a = ap.parse_args()
    t0 = time.time()

    x = np.load(a.dataset / "strain.npy")
    x = x.reshape(x.shape[0], -1)
    u = np.load(a.dataset / "inputs.npy")
    ok = np.load(a.dataset / "status.npy") == 0
    x, u = x[ok], u[ok]
    rows, n = x.shape
    c = (u[:, 0] - u[:, 0].min()) / np.ptp(u[:, 0])
    m_lo, m_hi = u[:, 1].min(), u[:, 1].max()
    k = a.bands
    band = np.minimum(((u[:, 1] - m_lo) / (m_hi - m_lo) * k).astype(int), k - 1)
    t = np.where(band % 2 == 0, c, 1.0 - c)
    z = jnp.asarray(((band + t) / k * 2.0 - 1.0)[:, None])
    # the bound: every magnitude moved to its band's centre, x = M g(c) scaled accordingly
    centre = m_lo + (band + 0.5) * (m_hi - m_lo) / k
    exact = float(np.sqrt(np.mean((x - x * (centre / u[:, 1])[:, None]) ** 2)))

    s = float(np.sqrt(np.mean(x.std(0) ** 2)))
    y = jnp.asarray(x / s)
    sizes = [1] + [max(n >> j, 2) for j in (3, 2, 1)] + [n]
    key = jax.random.PRNGKey(a.seed)

    def glorot(sizes, first_scale):
        nonlocal key
        ps = []
        for i, (p, q) in enumerate(zip(sizes[:-1], sizes[1:])):
            key, sub = jax.random.split(key)
            lim = np.sqrt(6.0 / (p + q)) * (first_scale if i == 0 else 1.0)
            ps.append((jax.random.uniform(sub, (p, q), minval=-lim, maxval=lim), jnp.zeros(q)))
        return ps

    params = glorot(sizes, a.first_layer_scale)
    if a.whole:
        params = {"dec": params, "enc": glorot(sizes[::-1], 1.0)}

    def decode(ps, h):
        for i, (w, b) in enumerate(ps):
            h = h @ w + b
            if i + 1 < len(ps):
                h = jnp.tanh(h)
        return h

    def penalty(layers):
        return a.lam / n * sum(jnp.sum(w * w) for w, _ in layers)

    def loss(ps, idx, mu=a.code_weight):
        if not a.whole:
            return jnp.mean((decode(ps, z[idx]) - y[idx]) ** 2) + penalty(ps)
        e = decode(ps["enc"], y[idx])
        out = jnp.mean((decode(ps["dec"], e) - y[idx]) ** 2) + penalty(ps["enc"] + ps["dec"])
        if mu > 0:
            out = out + mu * jnp.mean((e - z[idx]) ** 2)
            out = out + jnp.mean((decode(ps["dec"], z[idx]) - y[idx]) ** 2)
        return out

    batches = -(-rows // 64)
    opt = optax.adam(optax.exponential_decay(a.learning_rate, a.epochs * batches, 0.03))
    state = opt.init(params)

    @jax.jit
    def step(ps, st, idx):
        g = jax.grad(loss)(ps, idx)
        upd, st = opt.update(g, st, ps)
        return optax.apply_updates(ps, upd), st

    rng = np.random.default_rng(a.seed)
    for _ in range(a.epochs):
        perm = rng.permutation(rows)
        for j in range(0, rows, 64):
            params, state = step(params, state, perm[j : j + 64])
    t_adam = time.time() - t0
    def rmse_of(ps):
        dec = ps["dec"] if a.whole else ps
        return float(np.sqrt(np.mean((np.asarray(decode(dec, z)) * s - x) ** 2)))

    def rmse_ae(ps):
        xr = np.asarray(decode(ps["dec"], decode(ps["enc"], y))) * s
        return float(np.sqrt(np.mean((xr - x) ** 2)))

    out = {"sizes": sizes, "bands": k, "exact": exact, "rmse_adam": rmse_of(params)}
    if a.whole:
        out["rmse_ae_adam"] = rmse_ae(params)

    def lbfgs(params, iterations, mu):
        from scipy.optimize import minimize

        flat, unravel = jax.flatten_util.ravel_pytree(params)
        every = jnp.arange(rows)
        fg = jax.jit(jax.value_and_grad(lambda f: loss(unravel(f), every, mu)))

        def fun(f):
            v, g = fg(jnp.asarray(f))
            return float(v), np.asarray(g)

        res = minimize(fun, np.asarray(flat), jac=True, method="L-BFGS-B",
                       options={"maxiter": iterations, "maxcor": 20, "gtol": 0, "ftol": 0})
        return unravel(jnp.asarray(res.x)), int(res.nit)

    if a.lbfgs > 0:
        params, out["lbfgs_iterations"] = lbfgs(params, a.lbfgs, a.code_weight)
    out["rmse"] = rmse_of(params)
    if a.whole:
        out["rmse_ae"] = rmse_ae(params)
        if a.release > 0:
            params, out["release_iterations"] = lbfgs(params, a.release, 0.0)
            out["rmse_ae_released"] = rmse_ae(params)
    out["seconds_adam"], out["seconds"] = t_adam, time.time() - t0
    print(json.dumps({**vars(a), **out}, default=str))


if __name__ == "__main__":
    main()
