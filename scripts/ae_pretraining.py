#!/usr/bin/env python3
"""IV-B at r = 1: two homotopies towards the paper's 7-hidden-layer code (JAX + optax, float64).

A trained r = 1 autoencoder of IV-B's 2-D family settles early on a code of a few passes and does
not add more (docs/assumptions.md). Two standard ways of reaching a network gradually, each ending
in eq. (15) on the whole dataset with `scripts/ae_reference.py`'s network, loss (`physical`: one
common scale, λ/n Σ‖W‖²), Adam, batches of 64 and a rate decaying from `--learning-rate` to 3 % of
it:

- `curriculum`: the family grown by the pulse's centre: the network is trained on the snapshots
  whose centre is at most c₁ < c₂ < … < 0.8 m in turn (`--stages`, from `--c0`, `--stage-epochs`
  each at the constant rate), then on all of them (`--epochs`); a new band of centres should need
  only new passes at the end of the code;
- `stacked`: greedy layer-wise pretraining (stacked autoencoders, the classic workflow of MATLAB's
  `trainAutoencoder` + `stack`): 148-74-148 on the data, 74-37-74 on its codes, 37-18-37, 18-1-18
  (`--pre-epochs` each; a tanh code but for the innermost, linear), stacked into the whole network,
  then `--epochs` on eq. (15).

Prints one line per stage and a JSON line with the RMSE over the dataset (Table I's) and over
`TEST`, a second draw never trained on:

    .venv/bin/python scripts/ae_pretraining.py DATASET TEST --mode curriculum
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np

import jax
import jax.numpy as jnp
import optax

import ae_reference as R

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("dataset", type=Path)
ap.add_argument("test", type=Path)
ap.add_argument("--mode", choices=["curriculum", "stacked"], required=True)
ap.add_argument("--stages", type=int, default=8)
ap.add_argument("--c0", type=float, default=0.1, help="the first stage's largest centre [m]")
ap.add_argument("--stage-epochs", type=int, default=600)
ap.add_argument("--pre-epochs", type=int, default=300)
ap.add_argument("--epochs", type=int, default=2000)
ap.add_argument("--learning-rate", type=float, default=1e-3)
ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
ap.add_argument("--seed", type=int, default=0)
a = ap.parse_args()

x = R.load(a.dataset)
centre = np.load(a.dataset / "inputs.npy")[np.load(a.dataset / "status.npy") == 0, 0]
xt = R.load(a.test)
n = x.shape[1]
mu, s = x.mean(0), np.sqrt(np.mean(x.std(0) ** 2))
y, yt = (x - mu) / s, (xt - mu) / s
sizes = R.architecture(n, 1, 7)
half = len(sizes) // 2
flags = [k + 1 < half for k in range(half)] * 2
rng = np.random.default_rng(a.seed)
key = jax.random.PRNGKey(a.seed)
t0 = time.time()


def train(params, tanh, inputs, targets, epochs, decay):
    """Adam on `‖f(inputs) − targets‖²/n + λ/n Σ‖W‖²` over batches of 64."""
    inputs, targets = jnp.asarray(inputs), jnp.asarray(targets)
    m = targets.shape[1]
    steps = epochs * -(-len(inputs) // 64)
    rate = optax.exponential_decay(a.learning_rate, steps, 0.03) if decay else a.learning_rate
    opt = optax.adam(rate)
    state = opt.init(params)

    def loss(p, b, t):
        rec = jnp.mean((R.forward(p, b, tanh) - t) ** 2)
        return rec + a.lam / m * sum(jnp.sum(w * w) for w, _ in p)

    @jax.jit
    def step(p, st, b, t):
        upd, st = opt.update(jax.grad(loss)(p, b, t), st, p)
        return optax.apply_updates(p, upd), st

    for _ in range(epochs):
        perm = rng.permutation(len(inputs))
        for j in range(0, len(inputs), 64):
            i = perm[j : j + 64]
            params, state = step(params, state, inputs[i], targets[i])
    return params


def rmse(p, d) -> float:
    return float(np.sqrt(np.mean((np.asarray(R.forward(p, jnp.asarray(d), flags)) - d) ** 2))) * s


if a.mode == "curriculum":
    params = R.init(sizes, key)
    for k, c_max in enumerate(np.linspace(a.c0, 0.8, a.stages)[:-1]):
        rows = y[centre <= c_max + 1e-12]
        params = train(params, flags, rows, rows, a.stage_epochs, decay=False)
        print(
            f"stage {k}: centres <= {c_max:.3f} m ({len(rows)} rows): RMSE over them"
            f" {rmse(params, rows):.3f}, over all {rmse(params, y):.3f}  {time.time() - t0:.0f} s",
            flush=True,
        )
else:
    enc, dec, h = [], [], y
    for k in range(half):
        key, sub = jax.random.split(key)
        tanh = [k + 1 < half, k > 0]  # the code's activation; the reconstruction's (of a tanh layer)
        p = train(R.init([sizes[k], sizes[k + 1], sizes[k]], sub), tanh, h, h, a.pre_epochs, True)
        rec = np.asarray(R.forward(p, jnp.asarray(h), tanh))
        print(
            f"layer {k}: {sizes[k]}-{sizes[k + 1]}-{sizes[k]}, relative error"
            f" {np.sqrt(np.mean((rec - h) ** 2) / np.mean(h**2)):.4f}  {time.time() - t0:.0f} s",
            flush=True,
        )
        enc.append(p[0])
        dec.insert(0, p[1])
        h = np.asarray(R.forward([p[0]], jnp.asarray(h), [tanh[0]]))
    params = enc + dec
    print(f"stacked: RMSE over the dataset {rmse(params, y):.3f}", flush=True)
params = train(params, flags, y, y, a.epochs, decay=True)
out = {"mode": a.mode, "rmse_full": rmse(params, y), "rmse_test": rmse(params, yt)}
print(json.dumps(out | {"seconds": time.time() - t0, "args": {k: str(v) for k, v in vars(a).items()}}))
