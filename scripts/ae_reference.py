#!/usr/bin/env python3
"""Independent reference trainer for gvsrom's autoencoders (JAX + optax, float64).

The same network, loss and data as `gvsrom train`, written from the paper (Section III, eq. 15)
and not from gvsrom's code, to judge the Rust trainer against a standard stack:

- architecture: n → n/2 → … → r → … → n (the encoder halves the width per layer, the decoder
  mirrors it), tanh on every hidden layer, linear latent and output layers, Glorot-uniform weights,
  zero biases;
- loss: eq. (15), `‖x̂ − x‖² + λ Σ‖W‖²` with the squared error of a whole snapshot, averaged over
  the batch and divided by the number of features n: the mean squared error per entry in scaled
  units plus (λ/n) Σ‖W‖² (biases not regularised), λ = 1e-4;
- scaling: `standardized` (each feature by its own standard deviation), `physical` (one common
  scale: the plain physical MSE) or `raw` (none: the network sees and returns strains in 1/m, as a
  network trained without input normalisation would); `--input-gain G` multiplies the encoder's
  input by G (the decoder's target stays scaled), to test whether sharper first-layer units help;
  `--odd` drops the biases and the centring: the autoencoder is then an odd function, as IV-B's
  family is (`x(c, −M) = −x(c, M)`), so each half of the family is learnt once for both;
- `--init-gain G`: every layer's Glorot bound × G; above about 1 a deep tanh network is in its
  chaotic phase, where its function of the input folds many times (a test of whether the initial
  network's few folds are what keeps a trained r = 1 code of IV-B to a few passes);
- `--init nguyen-widrow`: MATLAB's default layer initialisation (`initnw`) instead of Glorot's:
  tanh units whose active regions tile the input range evenly, the decoder's one-input first
  layer then 18 steps of slope 12.6 at evenly spaced codes (a test of whether the paper's r = 1
  cell owes its many folds to the initialisation of a MATLAB network);
- `--log-gain`: the same network and loss, optimised in another parametrisation: each unit's
  weights are `W = e^g v` (a gain per unit, `g` from 0) and Adam moves `g`, `v` and `b`; the
  penalty is still on `W`. Adam moves a weight by about one learning rate per step, so a unit
  grows sharp only linearly in time; through `g` it grows geometrically (a test of whether the
  step bound is what keeps a trained r = 1 encoder from tearing IV-B's family sharply);
- Adam (optax defaults β = 0.9/0.999, ε = 1e-8), shuffled mini-batches, a fixed epoch budget and
  the weights with the lowest validation loss kept; the rate constant, or decaying exponentially
  to `--final-lr-factor` of itself over the run.

It prints the RMSE over the whole dataset in physical units (Table I's metric) and the mean wall
time of an epoch after the first (compiled) one.

    python -m venv .venv && .venv/bin/pip install numpy jax optax
    .venv/bin/python scripts/ae_reference.py DATASET --latent 2 --hidden-layers 7 --epochs 200

`--synthetic` replaces DATASET by the 1000 × 306 snapshots of `crates/rom/examples/ae_epoch_time.rs`
(the same SplitMix64 draws, so the same numbers), to compare epoch times with that example:

    .venv/bin/python scripts/ae_reference.py --synthetic --epochs 20

Without validation rows (`--validation-fraction 0`) the monitored loss is the mean of the epoch's
batch losses, as in gvsrom, so no extra pass over the data is timed.
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402
from jax.flatten_util import ravel_pytree  # noqa: E402
import optax  # noqa: E402


def load(dataset: Path) -> np.ndarray:
    """The solved snapshots (status 0) of a gvsrom dataset, rows × features."""
    x = np.load(dataset / "strain.npy")
    status = np.load(dataset / "status.npy")
    x = x.reshape(x.shape[0], -1)[status == 0]
    if not np.isfinite(x).all():
        raise SystemExit(f"{dataset}: non-finite strain in solved rows")
    return x


def synthetic(rows: int = 1000, n: int = 306) -> np.ndarray:
    """`x_j = sin(a X_j) + b X_j² + c cos(3 X_j)`, `X_j = j/(n−1)`, `(a, b, c)` drawn as the Rust
    example draws them (`SplitMix64::new(3).range(-1, 1)`)."""
    state, mask = 3, (1 << 64) - 1

    def uniform() -> float:
        nonlocal state
        state = (state + 0x9E3779B97F4A7C15) & mask
        z = state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        z ^= z >> 31
        return (z >> 11) / float(1 << 53)

    xj = np.arange(n) / (n - 1)
    out = np.empty((rows, n))
    for i in range(rows):
        a, b, c = (-1.0 + 2.0 * uniform() for _ in range(3))
        out[i] = np.sin(a * xj) + b * xj * xj + c * np.cos(3.0 * xj)
    return out


def architecture(n: int, r: int, hidden: int) -> list[int]:
    if hidden % 2 == 0:
        raise SystemExit(f"--hidden-layers {hidden}: expected odd")
    enc = [n] + [max(n >> k, r + 1) for k in range(1, (hidden - 1) // 2 + 1)]
    return enc + [r] + enc[::-1]


def init(sizes: list[int], key, gain: float = 1.0) -> list[tuple]:
    """Glorot-uniform weights (× `gain`), zero biases."""
    params = []
    for a, b in zip(sizes[:-1], sizes[1:]):
        key, sub = jax.random.split(key)
        lim = gain * np.sqrt(6.0 / (a + b))
        params.append((jax.random.uniform(sub, (a, b), minval=-lim, maxval=lim), jnp.zeros(b)))
    return params


def init_nguyen_widrow(sizes: list[int], flags: list[bool], key) -> list[tuple]:
    """MATLAB's default layer initialisation (`initnw`) for a network with inputs in [-1, 1].

    A tanh layer of S units on R inputs gets rows of norm `0.7 S^(1/R)` in random directions and
    biases spread evenly over `[-0.7 S^(1/R), 0.7 S^(1/R)]`, so the units' active regions tile the
    input range; a linear layer gets weights and biases uniform in [-1, 1] (`rands`). On the
    decoder's one-input first layer (R = 1, S = 18) the units are steps of slope 12.6 at 18 evenly
    spaced codes: a start that can fold the code many times.
    """
    params = []
    for (a, b), t in zip(zip(sizes[:-1], sizes[1:]), flags):
        key, k1, k2 = jax.random.split(key, 3)
        if t:
            mag = 0.7 * b ** (1.0 / a)
            w = jax.random.normal(k1, (a, b))
            w = mag * w / jnp.linalg.norm(w, axis=0, keepdims=True)
            bias = mag * jnp.linspace(-1.0, 1.0, b) * jnp.sign(w[0])
        else:
            w = jax.random.uniform(k1, (a, b), minval=-1.0, maxval=1.0)
            bias = jax.random.uniform(k2, (b,), minval=-1.0, maxval=1.0)
        params.append((w, bias))
    return params


def effective(params):
    """The network's `(W, b)` per layer: with `--log-gain` the layers are `(v, g, b)`, `W = e^g v`."""
    return [(p[0] * jnp.exp(p[1]), p[2]) if len(p) == 3 else p for p in params]


def forward(params, x, tanh_flags, odd=False):
    h = x
    for (w, b), t in zip(effective(params), tanh_flags):
        h = h @ w if odd else h @ w + b
        if t:
            h = jnp.tanh(h)
    return h


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dataset", type=Path, nargs="?")
    ap.add_argument(
        "--synthetic", action="store_true", help="the Rust example's 1000 × 306 snapshots"
    )
    ap.add_argument("--latent", type=int, default=1)
    ap.add_argument("--hidden-layers", type=int, default=7)
    ap.add_argument("--epochs", type=int, default=200)
    ap.add_argument("--batch-size", type=int, default=64)
    ap.add_argument("--learning-rate", type=float, default=1e-3)
    ap.add_argument(
        "--final-lr-factor",
        type=float,
        default=1.0,
        help="decay the rate exponentially to this fraction of itself over the epochs (1: constant)",
    )
    ap.add_argument("--lambda", dest="lam", type=float, default=1e-4)
    ap.add_argument("--validation-fraction", type=float, default=0.1)
    ap.add_argument(
        "--loss", choices=["standardized", "physical", "raw"], default="standardized"
    )
    ap.add_argument(
        "--input-gain", type=float, default=1.0, help="multiply the encoder's input by this"
    )
    ap.add_argument("--odd", action="store_true", help="no biases, no centring: an odd network")
    ap.add_argument(
        "--init-gain",
        type=float,
        default=1.0,
        help="every layer's Glorot bound × this (> 1: the chaotic phase of deep tanh networks)",
    )
    ap.add_argument(
        "--init",
        choices=["glorot", "nguyen-widrow"],
        default="glorot",
        help="Glorot-uniform weights and zero biases, or MATLAB's Nguyen-Widrow (initnw)",
    )
    ap.add_argument(
        "--log-gain", action="store_true", help="optimise W = e^g v: a log-gain g per unit"
    )
    ap.add_argument("--save", type=Path, help="write the kept weights (flattened, .npy)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true", help="print one JSON line instead of text")
    args = ap.parse_args()

    if args.synthetic == (args.dataset is not None):
        raise SystemExit("give either DATASET or --synthetic")
    x = synthetic() if args.synthetic else load(args.dataset)
    rows, n = x.shape
    rng = np.random.default_rng(args.seed)
    order = rng.permutation(rows)
    n_val = int(rows * args.validation_fraction)
    val, train = order[:n_val], order[n_val:]
    mu = x[train].mean(0)
    sd = x[train].std(0)
    if args.loss == "standardized":
        s = np.where(sd <= 1e-12 * (1 + np.abs(mu)), 1.0, sd)
    elif args.loss == "raw":
        mu, s = np.zeros(n), np.ones(n)
    else:
        c = np.sqrt(np.mean(sd**2))
        s = np.full(n, c if c > 0 else 1.0)
    if args.odd:
        mu = np.zeros(n)
    y = jnp.asarray((x - mu) / s)

    sizes = architecture(n, args.latent, args.hidden_layers)
    half = (args.hidden_layers + 1) // 2
    flags = [k + 1 < half for k in range(half)] * 2
    if args.init == "nguyen-widrow":
        params = init_nguyen_widrow(sizes, flags, jax.random.PRNGKey(args.seed))
    else:
        params = init(sizes, jax.random.PRNGKey(args.seed), args.init_gain)
    if args.log_gain:
        params = [(w, jnp.zeros(w.shape[1]), b) for w, b in params]
    gain = args.input_gain

    def loss(p, batch):
        rec = jnp.mean((forward(p, gain * batch, flags, args.odd) - batch) ** 2)
        return rec + args.lam / n * sum(jnp.sum(w * w) for w, _ in effective(p)), rec

    steps = args.epochs * -(-len(train) // args.batch_size)
    rate = (
        args.learning_rate
        if args.final_lr_factor == 1.0
        else optax.exponential_decay(args.learning_rate, steps, args.final_lr_factor)
    )
    opt = optax.adam(rate)
    state = opt.init(params)

    @jax.jit
    def step(p, st, batch):
        g, rec = jax.grad(loss, has_aux=True)(p, batch)
        upd, st = opt.update(g, st, p)
        return optax.apply_updates(p, upd), st, rec

    @jax.jit
    def mse(p, data):
        return jnp.mean((forward(p, gain * data, flags, args.odd) - data) ** 2)

    best, best_val, times = params, np.inf, []
    y_train, y_val = y[train], y[val]
    for epoch in range(args.epochs):
        t0 = time.perf_counter()
        perm = rng.permutation(len(train))
        batch_sum = 0.0
        for k in range(0, len(train), args.batch_size):
            batch = y_train[perm[k : k + args.batch_size]]
            params, state, rec = step(params, state, batch)
            if not n_val:
                batch_sum = batch_sum + rec * batch.shape[0]
        # the validation loss, or without validation rows the mean batch loss (as gvsrom)
        v = float(mse(params, y_val)) if n_val else float(batch_sum) / len(train)
        times.append(time.perf_counter() - t0)
        if v < best_val:
            best, best_val = params, v
    rec = np.asarray(forward(best, gain * y, flags, args.odd)) * s + mu
    rmse = float(np.sqrt(np.mean((rec - x) ** 2)))
    epoch_s = float(np.mean(times[1:])) if len(times) > 1 else float(times[0])
    out = {
        "dataset": str(args.dataset),
        "rows": rows,
        "features": n,
        "sizes": sizes,
        "loss": args.loss,
        "epochs": args.epochs,
        "learning_rate": args.learning_rate,
        "final_lr_factor": args.final_lr_factor,
        "seed": args.seed,
        "input_gain": gain,
        "odd": args.odd,
        "init": args.init,
        "init_gain": args.init_gain,
        "log_gain": args.log_gain,
        "largest_weight": float(max(jnp.max(jnp.abs(w)) for w, _ in effective(best))),
        "sum_squared_weights": float(sum(jnp.sum(w * w) for w, _ in effective(best))),
        "latent": args.latent,
        "rmse_full": rmse,
        "epoch_s": epoch_s,
        "epoch_min_s": float(np.min(times[1:])) if len(times) > 1 else float(times[0]),
        "backend": jax.default_backend(),
    }
    if args.save:
        np.save(args.save, np.asarray(ravel_pytree(effective(best))[0]))
    if args.json:
        print(json.dumps(out))
    else:
        print(f"network    {'-'.join(map(str, sizes))}, loss {args.loss}, {args.epochs} epochs")
        print(f"RMSE       {rmse:.4e} over all {rows} snapshots (physical units)")
        print(
            f"epoch      {epoch_s * 1e3:.1f} ms mean after the first, fastest"
            f" {out['epoch_min_s'] * 1e3:.1f} ({jax.default_backend()})"
        )


if __name__ == "__main__":
    main()
